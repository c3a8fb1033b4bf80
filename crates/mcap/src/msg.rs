//! The messages the recorder writes, encoded as CDR (see [`crate::cdr`]) in the field
//! order of their schemas ([`crate::schema`]). Borrowed strings: encoding allocates
//! only the output buffer.

use crate::cdr::CdrWriter;

/// `builtin_interfaces/msg/Time`: a simulation time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Time {
    /// Whole seconds.
    pub sec: i32,
    /// Nanoseconds past `sec`, below 1e9.
    pub nanosec: u32,
}

impl Time {
    /// The time `ns` nanoseconds after zero (saturating at `i32::MAX` seconds, 68 years).
    pub fn from_nanos(ns: u64) -> Self {
        Self {
            sec: i32::try_from(ns / 1_000_000_000).unwrap_or(i32::MAX),
            // Below 1e9, so it fits.
            nanosec: (ns % 1_000_000_000) as u32,
        }
    }

    fn encode(self, w: &mut CdrWriter) {
        w.i32(self.sec);
        w.u32(self.nanosec);
    }
}

/// Simulation seconds as nanoseconds (negative and non-finite times become 0).
pub fn nanos_from_secs(t: f64) -> u64 {
    if t.is_finite() && t > 0.0 {
        // Saturating float-to-int cast; 584 years of simulation fit.
        (t * 1e9).round() as u64
    } else {
        0
    }
}

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

/// `std_msgs/msg/Header`.
fn header(w: &mut CdrWriter, stamp: Time, frame_id: &str) {
    stamp.encode(w);
    w.string(frame_id);
}

/// `sensor_msgs/msg/JointState`: one entry per name, in rad (rad/s, N·m) for revolute
/// joints and m (m/s, N) for prismatic ones. `velocity` and `effort` are either empty
/// or as long as `names`.
pub fn joint_state(stamp: Time, names: &[&str], position: &[f64], velocity: &[f64], effort: &[f64]) -> Vec<u8> {
    let mut w = CdrWriter::with_capacity(32 + names.len() * 48);
    header(&mut w, stamp, "");
    w.sequence_len(names.len());
    for n in names {
        w.string(n);
    }
    w.f64_sequence(position);
    w.f64_sequence(velocity);
    w.f64_sequence(effort);
    w.into_bytes()
}

/// Levels of `rcl_interfaces/msg/Log`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum LogLevel {
    /// `DEBUG`.
    Debug = 10,
    /// `INFO`.
    Info = 20,
    /// `WARN`.
    Warn = 30,
    /// `ERROR`.
    Error = 40,
}

impl LogLevel {
    /// The level of a CoppeliaSim verbosity (200 errors, 300 warnings, 450 script
    /// infos, 500 infos, above that debug and trace).
    pub fn from_verbosity(v: i64) -> Self {
        match v {
            ..=200 => LogLevel::Error,
            201..=300 => LogLevel::Warn,
            301..=500 => LogLevel::Info,
            _ => LogLevel::Debug,
        }
    }
}

/// `rcl_interfaces/msg/Log`: a line `msg` from `name` (a script).
pub fn log(stamp: Time, level: LogLevel, name: &str, msg: &str) -> Vec<u8> {
    let mut w = CdrWriter::with_capacity(32 + name.len() * 2 + msg.len());
    stamp.encode(&mut w);
    w.u8(level as u8);
    w.string(name);
    w.string(msg);
    w.string(name); // file: the script's name is also where the line came from
    w.string(""); // function: not known
    w.u32(0); // line: not known
    w.into_bytes()
}

/// `std_msgs/msg/Float64`.
pub fn float64(v: f64) -> Vec<u8> {
    let mut w = CdrWriter::with_capacity(16);
    w.f64(v);
    w.into_bytes()
}

/// `std_msgs/msg/Int32`.
pub fn int32(v: i32) -> Vec<u8> {
    let mut w = CdrWriter::with_capacity(8);
    w.i32(v);
    w.into_bytes()
}

/// `std_msgs/msg/String`.
pub fn string(v: &str) -> Vec<u8> {
    let mut w = CdrWriter::with_capacity(16 + v.len());
    w.string(v);
    w.into_bytes()
}

/// `sensor_msgs/msg/Image` of an RGB image `width` x `height` in frame `frame_id`,
/// from gantry's bottom-row-first pixels `rgb` (3 bytes each): ROS images are top row
/// first, so the rows are written in reverse order.
pub fn image(stamp: Time, frame_id: &str, width: u32, height: u32, rgb: &[u8]) -> Vec<u8> {
    let row = 3 * width as usize;
    let mut w = CdrWriter::with_capacity(64 + frame_id.len() + rgb.len());
    header(&mut w, stamp, frame_id);
    w.u32(height);
    w.u32(width);
    w.string("rgb8");
    w.u8(0);
    w.u32(3 * width);
    w.sequence_len(rgb.len());
    if row > 0 {
        for r in rgb.chunks_exact(row).rev() {
            w.raw(r);
        }
    }
    w.into_bytes()
}

/// `sensor_msgs/msg/Range` of a proximity sensor in frame `frame_id`: `range` in m,
/// `+inf` when nothing is detected (REP 117), between `min_range` and `max_range`.
pub fn range(stamp: Time, frame_id: &str, field_of_view: f32, min_range: f32, max_range: f32, range: f32) -> Vec<u8> {
    let mut w = CdrWriter::with_capacity(48 + frame_id.len());
    header(&mut w, stamp, frame_id);
    w.u8(1); // radiation_type: INFRARED, the closer of the two to a geometric sensor
    w.f32(field_of_view);
    w.f32(min_range);
    w.f32(max_range);
    w.f32(range);
    w.into_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_splits_nanoseconds() {
        assert_eq!(
            Time::from_nanos(2_500_000_001),
            Time {
                sec: 2,
                nanosec: 500_000_001
            }
        );
        assert_eq!(nanos_from_secs(0.05), 50_000_000);
        assert_eq!(nanos_from_secs(-1.0), 0);
        assert_eq!(nanos_from_secs(f64::NAN), 0);
    }

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

    #[test]
    fn a_joint_state_is_header_names_then_three_sequences() {
        let bytes = joint_state(Time::default(), &["j"], &[0.5], &[], &[2.0]);
        let mut expected = vec![0, 1, 0, 0];
        expected.extend([0; 8]); // stamp
        expected.extend([1, 0, 0, 0, 0]); // frame_id "", ends at 13
        expected.extend([0, 0, 0]); // pad to 16
        expected.extend([1, 0, 0, 0]); // one name
        expected.extend([2, 0, 0, 0, b'j', 0]); // ends at 26
        expected.extend([0, 0]); // pad to 28
        expected.extend([1, 0, 0, 0]); // one position, ends at 32
        expected.extend(0.5f64.to_le_bytes());
        expected.extend([0, 0, 0, 0]); // no velocity
        expected.extend([1, 0, 0, 0]); // one effort, ends at 48
        expected.extend(2.0f64.to_le_bytes());
        assert_eq!(bytes, expected);
    }

    #[test]
    fn a_log_line_is_stamp_level_strings_and_line() {
        let bytes = log(Time { sec: 3, nanosec: 0 }, LogLevel::Warn, "s", "hi");
        let mut expected = vec![0, 1, 0, 0];
        expected.extend([3, 0, 0, 0, 0, 0, 0, 0]);
        expected.push(30); // level, at 8
        expected.extend([0, 0, 0]); // pad to 12
        expected.extend([2, 0, 0, 0, b's', 0]); // name, ends at 18
        expected.extend([0, 0]);
        expected.extend([3, 0, 0, 0, b'h', b'i', 0]); // msg, ends at 27
        expected.push(0);
        expected.extend([2, 0, 0, 0, b's', 0]); // file, ends at 34
        expected.extend([0, 0]);
        expected.extend([1, 0, 0, 0, 0]); // function "", ends at 41
        expected.extend([0, 0, 0]);
        expected.extend([0, 0, 0, 0]); // line
        assert_eq!(bytes, expected);
        assert_eq!(LogLevel::from_verbosity(100), LogLevel::Error);
        assert_eq!(LogLevel::from_verbosity(300), LogLevel::Warn);
        assert_eq!(LogLevel::from_verbosity(450), LogLevel::Info);
        assert_eq!(LogLevel::from_verbosity(600), LogLevel::Debug);
    }

    #[test]
    fn float64_and_range() {
        let mut f = vec![0, 1, 0, 0];
        f.extend(1.25f64.to_le_bytes());
        assert_eq!(float64(1.25), f);
        let bytes = range(Time::default(), "", 0.5, 0.0, 2.0, f32::INFINITY);
        let mut expected = vec![0, 1, 0, 0];
        expected.extend([0; 8]);
        expected.extend([1, 0, 0, 0, 0]); // ends at 13
        expected.push(1); // radiation type, at 13
        expected.extend([0, 0]); // pad to 16
        for v in [0.5f32, 0.0, 2.0, f32::INFINITY] {
            expected.extend(v.to_le_bytes());
        }
        assert_eq!(bytes, expected);
    }
}
