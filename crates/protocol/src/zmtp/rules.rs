//! The limits and framing rules every part of the ZMTP codec checks against, and how a
//! peer breaks them ([`Violation`]).

use thiserror::Error;

use super::socket_type::SocketType;

/// Longest frame a peer may announce, in bytes. The largest legitimate request is one
/// CBOR argument list (a pose, a joint list, at most an image for
/// `setVisionSensorImg`: 786,432 bytes at the largest sensor resolution, 512×512 RGB),
/// far below this.
pub const MAX_FRAME_LEN: u64 = 16 * 1024 * 1024;

/// Most bytes in one multipart message, all frames together. A message is kept until
/// its last frame, so many frames under [`MAX_FRAME_LEN`] must not add up without
/// bound.
pub const MAX_MESSAGE_LEN: u64 = MAX_FRAME_LEN;

/// Most frames in one multipart message. A REQ client sends two (the empty delimiter
/// and the request). Each frame costs a header and a handle however short it is, so
/// endless empty frames would grow memory as surely as one long frame.
pub const MAX_MESSAGE_FRAMES: u32 = 64;

/// Longest frame header: the flags byte and an 8-byte length.
pub const MAX_HEADER_LEN: usize = 9;

/// The most bytes `Decoder::decode` may need in the buffer before it can return an
/// event: a message of [`MAX_MESSAGE_LEN`] bytes in [`MAX_MESSAGE_FRAMES`] frames with
/// the longest headers (a command is one frame, so it needs less). It returns
/// `Ok(None)` only while the buffer holds fewer bytes than this, so a connection that
/// stops reading at this size never stalls a legitimate peer.
// Both terms are far below usize::MAX on every target gantry builds for.
pub const MAX_BUFFERED: usize = MAX_MESSAGE_LEN as usize + MAX_MESSAGE_FRAMES as usize * MAX_HEADER_LEN;

/// How a peer broke ZMTP 3 or the limits. The connection is to be closed; the
/// decoder keeps returning the same violation.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum Violation {
    /// The greeting is not ZMTP 3: byte 0 must be 0xFF, byte 9 0x7F, byte 10 (the
    /// major version) 3.
    #[error("not a ZMTP 3 greeting: byte {offset} is {byte:#04x}")]
    Greeting {
        /// Position in the greeting.
        offset: u8,
        /// The byte found there.
        byte: u8,
    },
    /// The greeting names a security mechanism other than NULL.
    #[error("the greeting asks for the {0:?} security mechanism; only NULL is served")]
    Mechanism(String),
    /// A frame's flags set reserved bits (only MORE, LONG and COMMAND exist).
    #[error("frame flags {0:#04x} set reserved bits")]
    Flags(u8),
    /// A frame announced more than [`MAX_FRAME_LEN`] bytes.
    #[error("a frame of {0} bytes was announced; the limit is {MAX_FRAME_LEN}")]
    FrameTooLong(u64),
    /// A multipart message grew past [`MAX_MESSAGE_LEN`] bytes.
    #[error("a message of more than {MAX_MESSAGE_LEN} bytes was sent")]
    MessageTooLong,
    /// A multipart message grew past [`MAX_MESSAGE_FRAMES`] frames.
    #[error("a message of more than {MAX_MESSAGE_FRAMES} frames was sent")]
    TooManyFrames,
    /// A command frame has the MORE flag: commands are always one frame.
    #[error("a command frame has the MORE flag set")]
    MoreOnCommand,
    /// A command frame came between the frames of a multipart message.
    #[error("a command frame came inside a multipart message")]
    CommandInMessage,
    /// A command's body does not parse; the text says which part.
    #[error("malformed {command} command: {problem}")]
    MalformedCommand {
        /// The command's name (lossy UTF-8), or `"a"` when even the name is broken.
        command: String,
        /// What is wrong.
        problem: &'static str,
    },
    /// Something other than `READY` (or `ERROR`) came right after the greeting.
    #[error("expected the READY command after the greeting, got {0}")]
    NotReady(String),
    /// A second `READY` came after the handshake.
    #[error("a READY command came after the handshake")]
    ReadyAgain,
    /// The peer's `READY` names no ZeroMQ socket type.
    #[error("unknown socket type {0:?}")]
    UnknownSocketType(String),
    /// The peer's socket type cannot talk to ours (e.g. a PUB to a ROUTER).
    #[error("a {peer} socket cannot talk to a {local} socket")]
    SocketType {
        /// The peer's `Socket-Type` property (lossy UTF-8).
        peer: String,
        /// Ours.
        local: SocketType,
    },
}

/// Frame flags (RFC 23): bit 0 "more frames follow", bit 1 "8-byte length", bit 2
/// "command"; the others are reserved and must be zero.
pub(super) const FLAG_MORE: u8 = 0b001;
pub(super) const FLAG_LONG: u8 = 0b010;
pub(super) const FLAG_COMMAND: u8 = 0b100;
pub(super) const FLAGS_RESERVED: u8 = !(FLAG_MORE | FLAG_LONG | FLAG_COMMAND);

/// Frames that fit a 1-byte length are written short, as libzmq does.
pub(super) const SHORT_MAX: usize = u8::MAX as usize;
