//! `sensor_msgs/msg/Range`: a proximity sensor's reading.

use super::cdr_writer::CdrWriter;
use super::header::header;
use super::time::Time;

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
    fn a_range_is_header_radiation_type_then_four_floats() {
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
