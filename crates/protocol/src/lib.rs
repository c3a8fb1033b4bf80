//! Pure codecs for gantry's wire protocols: bytes in, typed values out.
//!
//! No I/O, no physics, no Lua. Every decoder here is total (never panics on any input)
//! and bounded (refuses oversize input before buffering it), and is fuzzed (see `fuzz/`).
//!
//! * [`line`](mod@line): splits the text command channel into lines.
//! * [`packet`]: parses and formats `<CODE#KEY=VALUE,...>` command packets.
//! * [`cbor`]: CBOR (RFC 8949) to and from [`Value`].
//! * [`remote_api`]: the CoppeliaSim ZMQ remote API v2 request and reply messages.
//! * [`legacy_remote_api`]: CoppeliaSim's legacy remote API (`simx*`): packets, messages,
//!   commands.
//! * [`zmtp`]: ZMTP 3.x, the framing under ZeroMQ sockets (greeting, commands, frames), as
//!   the ZMQ remote API's ROUTER socket speaks it.
//! * [`dap`]: the Debug Adapter Protocol: `Content-Length` frames, typed requests, and the
//!   adapter's responses and events.
//! * [`ros`]: ROS 2 messages as CDR to and from [`Value`] for the known message and
//!   service types, typed encoders of the messages gantry publishes and records
//!   ([`ros::typed`]), and ROS 2 names to DDS topic names.

pub mod cbor;
pub mod dap;
pub mod legacy_remote_api;
pub mod line;
pub mod packet;
pub mod remote_api;
pub mod ros;
pub mod value;
pub mod zmtp;

pub use cbor::CborError;
pub use line::{LineDecoder, LineError};
pub use packet::{Field, Packet, PacketError, encode_error, parse_packet};
pub use remote_api::{Reply, Request, RequestError, decode_request};
pub use value::Value;
