//! ZMTP 3.x, the framing under ZeroMQ sockets (RFC 23 and RFC 37), as much of it as a
//! ROUTER socket serving REQ clients with the NULL security mechanism needs.
//!
//! A connection starts with a 64-byte greeting from each side ([`encode_greeting`]), then a
//! `READY` command from each side naming its socket type ([`Command`]), then traffic:
//! commands (`PING`, `ERROR`...) and messages of one or more frames ([`encode_frame`]). Each
//! frame is a flags byte (MORE, LONG, COMMAND), a 1- or 8-byte big-endian length and
//! a body.
//!
//! [`Decoder`] follows one peer's byte stream through those phases over a caller-owned
//! receive buffer, with the usual three outcomes: an [`Event`] and the bytes it used
//! taken off the buffer, `Ok(None)` for "need more bytes", or a [`Violation`], after
//! which the connection is to be closed. It is total and bounded: lengths a peer
//! announces are checked against [`MAX_FRAME_LEN`], [`MAX_MESSAGE_LEN`] and
//! [`MAX_MESSAGE_FRAMES`] as soon as their header is visible, and nothing is reserved
//! for them, so a peer only makes the buffer grow by actually sending bytes, and never
//! past [`MAX_BUFFERED`]. The encoders append to a `Vec<u8>` that the connection then
//! writes out.
//!
//! Non-goals: the PLAIN, CURVE and GSSAPI mechanisms (a greeting naming one is a
//! violation), ZMTP 1.0 and 2.0 peers, and the routing of messages between sockets,
//! which is the server's business.

mod command;
mod decoder;
mod frame;
mod greeting;
mod rules;
mod socket_type;

pub use command::{Command, Ready};
pub use decoder::{Decoder, Event};
pub use frame::{encode_frame, encode_message};
pub use greeting::{GREETING_LEN, encode_greeting};
pub use rules::{MAX_BUFFERED, MAX_FRAME_LEN, MAX_HEADER_LEN, MAX_MESSAGE_FRAMES, MAX_MESSAGE_LEN, Violation};
pub use socket_type::SocketType;
