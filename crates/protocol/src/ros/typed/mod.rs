//! Typed ROS 2 messages: the messages gantry itself publishes and records (`/tf`,
//! `/joint_states`, `/rosout`, `/clock`, images, camera info, ranges and the `std_msgs`
//! scalars), encoded straight from Rust values into CDR, and the [`CdrWriter`] they
//! write with.
//!
//! The dynamic codec of this module's parent ([`MsgType::encode`](super::MsgType::encode))
//! encodes any catalog type from a [`Value`](crate::Value) map, which is what scripts
//! hand over. For the messages gantry makes itself after every step that would mean
//! building a map of boxed values (and a string key per field) only to walk it again: a
//! 30-frame `TFMessage` took about 20 times longer through a `Value` (the map built and
//! encoded) than through [`tf_message`] when this module was written (27 us against
//! 1.2 us, `ci` profile), and the recorder and the ROS 2 graph encode one per step. So these
//! encoders are written by hand, on one [`CdrWriter`] whose alignment rule the dynamic
//! encoder shares, and `tests/ros_typed.rs` checks each against the catalog: the bytes
//! each writes decode with the catalog's type and re-encode to the same bytes.
//!
//! Borrowed strings: encoding allocates only the output buffer. Pure: nothing here
//! knows the simulation; gantry-ros samples the world into these messages, gantry-mcap
//! decodes them back out of recordings.

mod camera;
mod cdr_writer;
mod header;
mod joint_state;
mod log;
mod range;
mod scalar;
mod tf;
mod time;

pub use camera::{camera_info, depth_image, image};
pub use cdr_writer::CdrWriter;
pub use joint_state::joint_state;
pub use log::{LogLevel, log};
pub use range::range;
pub use scalar::{clock, float64, int32, string};
pub use tf::{TransformStamped, WORLD_FRAME, tf_message};
pub use time::{Time, nanos_from_secs};
