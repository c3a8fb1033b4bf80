//! The typed encoders (`ros::typed`) against the catalog's codec: what each writes
//! decodes with the catalog's definition of its type and re-encodes to the same bytes,
//! so the hand-written layouts cannot drift from the `.msg` definitions.

use gantry_protocol::ros::message_type;
use gantry_protocol::ros::typed::{self, Time, TransformStamped};

/// Decodes `bytes` as `ty` and encodes the value again: the same bytes.
fn agrees(ty: &str, bytes: &[u8]) {
    let t = message_type(ty).unwrap_or_else(|e| panic!("{e}"));
    let value = t.decode(bytes).unwrap_or_else(|e| panic!("{ty} does not decode: {e}"));
    let again = t.encode(&value).unwrap_or_else(|e| panic!("{ty} does not encode: {e}"));
    assert_eq!(again, bytes, "{ty}: the typed encoder and the catalog disagree");
}

const STAMP: Time = Time {
    sec: 12,
    nanosec: 345_678_901,
};

#[test]
fn tf_messages_agree() {
    let frames = [
        TransformStamped {
            stamp: STAMP,
            frame_id: "world",
            child_frame_id: "robot",
            translation: [1.0, -2.0, 0.25],
            rotation: [0.0, 0.0, 0.6, 0.8],
        },
        TransformStamped {
            stamp: STAMP,
            frame_id: "robot",
            child_frame_id: "robot/wheel[1]",
            translation: [0.0; 3],
            rotation: [0.0, 0.0, 0.0, 1.0],
        },
    ];
    agrees("tf2_msgs/msg/TFMessage", &typed::tf_message(&frames));
    agrees("tf2_msgs/msg/TFMessage", &typed::tf_message(&[]));
}

#[test]
fn joint_states_agree() {
    agrees(
        "sensor_msgs/msg/JointState",
        &typed::joint_state(STAMP, &["a", "arm/b"], &[0.5, -1.0], &[], &[2.0, f64::NAN]),
    );
}

#[test]
fn scalars_and_the_clock_agree() {
    agrees("std_msgs/msg/Float64", &typed::float64(-0.125));
    agrees("std_msgs/msg/Int32", &typed::int32(i32::MIN));
    agrees("std_msgs/msg/String", &typed::string("<robot name=\"r\"/>"));
    agrees("rosgraph_msgs/msg/Clock", &typed::clock(STAMP));
}

#[test]
fn sensor_messages_agree() {
    agrees(
        "sensor_msgs/msg/Range",
        &typed::range(STAMP, "sensor", 0.5, 0.01, 2.0, f32::INFINITY),
    );
    agrees(
        "sensor_msgs/msg/Image",
        &typed::image(STAMP, "cam", 2, 1, &[1, 2, 3, 4, 5, 6]),
    );
    agrees(
        "sensor_msgs/msg/Image",
        &typed::depth_image(STAMP, "cam", 1, 2, &[0.5, f32::INFINITY]),
    );
    agrees(
        "sensor_msgs/msg/CameraInfo",
        &typed::camera_info(STAMP, "cam", 640, 480, 554.3, 319.5, 239.5),
    );
}
