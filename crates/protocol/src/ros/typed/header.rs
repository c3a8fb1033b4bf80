//! `std_msgs/msg/Header`, first in most sensor messages.

use super::cdr_writer::CdrWriter;
use super::time::Time;

/// `std_msgs/msg/Header`: a stamp and a frame id.
pub(super) fn header(w: &mut CdrWriter, stamp: Time, frame_id: &str) {
    stamp.encode(w);
    w.string(frame_id);
}
