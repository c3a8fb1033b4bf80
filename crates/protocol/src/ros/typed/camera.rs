//! A camera's messages: `sensor_msgs/msg/Image` (colour and depth) and
//! `sensor_msgs/msg/CameraInfo`.
//!
//! gantry's vision sensors hold their pixels bottom row first (OpenGL's order); ROS
//! images are top row first, so the rows are written in reverse order.

use super::cdr_writer::CdrWriter;
use super::header::header;
use super::time::Time;

/// `sensor_msgs/msg/Image` of an RGB image `width` x `height` in frame `frame_id`,
/// from bottom-row-first pixels `rgb` (3 bytes each).
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

/// `sensor_msgs/msg/Image` of a depth image (`32FC1`, REP 118) `width` x `height` in
/// frame `frame_id`, from bottom-row-first distances `depth_m` in m (`+inf` where
/// nothing is seen).
pub fn depth_image(stamp: Time, frame_id: &str, width: u32, height: u32, depth_m: &[f32]) -> Vec<u8> {
    let row = width as usize;
    let mut w = CdrWriter::with_capacity(64 + frame_id.len() + depth_m.len() * 4);
    header(&mut w, stamp, frame_id);
    w.u32(height);
    w.u32(width);
    w.string("32FC1");
    w.u8(0);
    w.u32(4 * width);
    w.sequence_len(depth_m.len() * 4);
    if row > 0 {
        for r in depth_m.chunks_exact(row).rev() {
            for &v in r {
                w.raw(&v.to_le_bytes());
            }
        }
    }
    w.into_bytes()
}

/// `sensor_msgs/msg/CameraInfo` of an undistorted pinhole camera (`plumb_bob`, zero
/// distortion) with focal length `fx` (pixels, the same on both axes) and principal
/// point `cx`, `cy` (pixels). All three 0 is ROS's "uncalibrated" (a camera without
/// a pinhole model, such as an orthographic one).
pub fn camera_info(stamp: Time, frame_id: &str, width: u32, height: u32, fx: f64, cx: f64, cy: f64) -> Vec<u8> {
    let mut c = CdrWriter::with_capacity(400 + frame_id.len());
    header(&mut c, stamp, frame_id);
    c.u32(height);
    c.u32(width);
    c.string("plumb_bob");
    c.f64_sequence(&[0.0; 5]);
    // K, R (identity: a monocular camera), P.
    for v in [fx, 0.0, cx, 0.0, fx, cy, 0.0, 0.0, 1.0] {
        c.f64(v);
    }
    for v in [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0] {
        c.f64(v);
    }
    for v in [fx, 0.0, cx, 0.0, 0.0, fx, cy, 0.0, 0.0, 0.0, 1.0, 0.0] {
        c.f64(v);
    }
    // binning_x, binning_y, then the region of interest (all of the image).
    c.u32(0);
    c.u32(0);
    for _ in 0..4 {
        c.u32(0);
    }
    c.u8(0);
    c.into_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn images_are_written_top_row_first() {
        let bytes = image(Time::default(), "", 1, 2, &[1, 2, 3, 4, 5, 6]);
        assert_eq!(&bytes[bytes.len() - 6..], &[4, 5, 6, 1, 2, 3]);
        let bytes = depth_image(Time::default(), "", 1, 2, &[1.0, f32::INFINITY]);
        let mut last = f32::INFINITY.to_le_bytes().to_vec();
        last.extend(1.0f32.to_le_bytes());
        assert_eq!(&bytes[bytes.len() - 8..], &last[..]);
    }
}
