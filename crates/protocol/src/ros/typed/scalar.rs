//! The one-field messages: `std_msgs` scalars (graph streams, signals, robot
//! descriptions) and `rosgraph_msgs/msg/Clock`.

use super::cdr_writer::CdrWriter;
use super::time::Time;

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

/// `rosgraph_msgs/msg/Clock` (`/clock`): simulation time, for `use_sim_time` nodes.
pub fn clock(stamp: Time) -> Vec<u8> {
    let mut w = CdrWriter::with_capacity(12);
    stamp.encode(&mut w);
    w.into_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scalars_are_the_header_then_the_value() {
        let mut f = vec![0, 1, 0, 0];
        f.extend(1.25f64.to_le_bytes());
        assert_eq!(float64(1.25), f);
        assert_eq!(int32(-2), vec![0, 1, 0, 0, 0xfe, 0xff, 0xff, 0xff]);
        assert_eq!(string("a"), vec![0, 1, 0, 0, 2, 0, 0, 0, b'a', 0]);
        assert_eq!(
            clock(Time { sec: 1, nanosec: 2 }),
            vec![0, 1, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0]
        );
    }
}
