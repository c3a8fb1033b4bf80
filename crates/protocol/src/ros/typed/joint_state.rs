//! `sensor_msgs/msg/JointState` (`/joint_states`).

use super::cdr_writer::CdrWriter;
use super::header::header;
use super::time::Time;

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

#[cfg(test)]
mod tests {
    use super::*;

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
}
