//! `tf2_msgs/msg/TFMessage`: frames' poses in their parents' frames (`/tf`,
//! `/tf_static`).

use super::cdr_writer::CdrWriter;
use super::header::header;
use super::time::Time;

/// The frame of the world, parent of every root object (REP 105's fixed frame, as
/// gantry names it on `/tf` and in recordings).
pub const WORLD_FRAME: &str = "world";

/// One `geometry_msgs/msg/TransformStamped`: the pose of `child_frame_id` in
/// `frame_id` (translation in m, rotation as a unit quaternion x, y, z, w).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TransformStamped<'a> {
    /// When.
    pub stamp: Time,
    /// The parent frame.
    pub frame_id: &'a str,
    /// The frame whose pose this is.
    pub child_frame_id: &'a str,
    /// Position of the child's origin in the parent frame, m.
    pub translation: [f64; 3],
    /// Orientation of the child in the parent frame: x, y, z, w.
    pub rotation: [f64; 4],
}

/// `tf2_msgs/msg/TFMessage` of `transforms`.
pub fn tf_message(transforms: &[TransformStamped<'_>]) -> Vec<u8> {
    let mut w = CdrWriter::with_capacity(8 + transforms.len() * 128);
    w.sequence_len(transforms.len());
    for t in transforms {
        header(&mut w, t.stamp, t.frame_id);
        w.string(t.child_frame_id);
        for v in t.translation {
            w.f64(v);
        }
        for v in t.rotation {
            w.f64(v);
        }
    }
    w.into_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tf_message_has_the_layout_ros2_expects() {
        let bytes = tf_message(&[TransformStamped {
            stamp: Time { sec: 1, nanosec: 2 },
            frame_id: "world",
            child_frame_id: "a",
            translation: [1.0, 2.0, 3.0],
            rotation: [0.0, 0.0, 0.0, 1.0],
        }]);
        let mut expected = vec![0, 1, 0, 0];
        expected.extend([1, 0, 0, 0]); // one transform
        expected.extend([1, 0, 0, 0, 2, 0, 0, 0]); // stamp
        expected.extend([6, 0, 0, 0]);
        expected.extend(b"world\0"); // frame_id, ends at offset 22
        expected.extend([0, 0]); // pad to 24
        expected.extend([2, 0, 0, 0, b'a', 0]); // child_frame_id, ends at 30
        expected.extend([0, 0]); // pad to 32 for the first float64
        for v in [1.0f64, 2.0, 3.0, 0.0, 0.0, 0.0, 1.0] {
            expected.extend(v.to_le_bytes());
        }
        assert_eq!(bytes, expected);
    }
}
