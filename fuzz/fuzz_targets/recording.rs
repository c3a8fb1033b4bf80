//! Recording reader: `Recording::from_bytes` (MCAP framing, chunk decompression and CRCs,
//! CDR decoding of every gantry message) never panics and never allocates beyond its
//! limits, whatever the bytes; a recording that reads answers every query. The CDR
//! decoders alone get the same bytes, and what they decode re-encodes to a message that
//! decodes to the same values; so does a recorded input (`/gantry/input`).
#![no_main]

use std::path::Path;

use gantry_mcap::{Input, Recording, decode};
use gantry_protocol::ros::typed as msg;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(rec) = Recording::from_bytes(data.to_vec(), Path::new("fuzz.mcap")) {
        let (start, end) = (rec.start_ns(), rec.end_ns());
        assert!(start <= end);
        for t in [0, start, start + (end - start) / 2, end, u64::MAX] {
            for f in rec.tree_at(t) {
                assert!(f.child.0 < rec.frames().len() as u32 && f.parent.0 < rec.frames().len() as u32);
            }
            let _ = rec.joints_at(t);
            assert!(rec.logs_until(t).len() <= rec.logs().len());
            let topics: Vec<String> = rec.image_topics().map(str::to_owned).collect();
            for topic in topics {
                let _ = rec.image_at(&topic, t);
            }
        }
    }
    if let Ok(ts) = decode::tf_message(data) {
        let written: Vec<msg::TransformStamped<'_>> = ts
            .iter()
            .map(|t| msg::TransformStamped {
                stamp: t.stamp,
                frame_id: t.frame_id,
                child_frame_id: t.child_frame_id,
                translation: [t.pose[0], t.pose[1], t.pose[2]],
                rotation: [t.pose[3], t.pose[4], t.pose[5], t.pose[6]],
            })
            .collect();
        let again = msg::tf_message(&written);
        let back = decode::tf_message(&again).expect("an encoded TFMessage decodes");
        assert_eq!(back.len(), ts.len());
        for (a, b) in back.iter().zip(&ts) {
            assert_eq!((a.stamp, a.frame_id, a.child_frame_id), (b.stamp, b.frame_id, b.child_frame_id));
            assert_eq!(a.pose.map(f64::to_bits), b.pose.map(f64::to_bits));
        }
    }
    if let Ok(js) = decode::joint_state(data) {
        let again = msg::joint_state(js.stamp, &js.name, &js.position, &js.velocity, &js.effort);
        let back = decode::joint_state(&again).expect("an encoded JointState decodes");
        assert_eq!((back.stamp, &back.name), (js.stamp, &js.name));
        assert_eq!(back.position.len(), js.position.len());
    }
    if let Ok(i) = Input::decode(data) {
        // Compared as bytes: a NaN argument is not equal to itself.
        let bytes = i.encode();
        let again = Input::decode(&bytes).map(|j| j.encode());
        assert_eq!(again.ok(), Some(bytes), "an input re-encodes to itself");
    }
    let _ = decode::log(data);
    let _ = decode::image(data);
    let _ = decode::float64(data);
});
