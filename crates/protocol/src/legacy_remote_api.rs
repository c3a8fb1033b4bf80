//! CoppeliaSim's legacy remote API (the `simx*` functions of `remoteApi.so`, `sim.py`,
//! `vrep.py`): packets, messages and commands.
//!
//! The client and the server talk over one TCP connection in strict turns: the client
//! sends a message (every few milliseconds, empty when it has nothing to ask) and the
//! server answers each with exactly one message. All integers are little-endian.
//!
//! * A **packet** is a 6-byte header (`i16` 1, so the peer can detect byte order; `i16`
//!   payload length; `i16` packets still to come after this one) and at most
//!   [`MAX_PACKET_PAYLOAD`] bytes of payload. A message is the payloads of its packets
//!   concatenated, the last packet saying 0 to come.
//! * A **message** is an 18-byte header (CRC, which clients neither set nor check, the
//!   protocol version, the message ID, the client's and the server's clock in ms, a
//!   scene ID and the server's state bits) followed by commands.
//! * A **command** is a 26-byte sub-header (its size, its full size when it is one chunk
//!   of a larger command, the size of its identifying data, the chunk's offset, the
//!   command code plus operation mode, the streaming delay or split size, the execution
//!   time, a status byte) followed by its identifying data (by code range: nothing, one
//!   or two `i32`, a NUL-terminated string, or an `i32` and two strings) and its *pure
//!   data*, the arguments or the results.
//!
//! A reply command repeats the request's code and identifying data, so the client can
//! match it, and carries the results as pure data; status bit 0 reports a failure on the
//! server side. Everything here is pure and bounded: [`PacketReader`] refuses messages
//! over [`MAX_MESSAGE_LEN`], and [`decode_message`] rejects any size field that points
//! outside the message.

use thiserror::Error;

/// Bytes of a packet header.
pub const PACKET_HEADER_LEN: usize = 6;
/// Most bytes of payload in one packet: the client's receive buffer is 1300 bytes per
/// packet, header included.
pub const MAX_PACKET_PAYLOAD: usize = 1300 - PACKET_HEADER_LEN;
/// Largest message accepted from a peer (a 4K RGB image set by a client fits).
pub const MAX_MESSAGE_LEN: usize = 64 * 1024 * 1024;
/// Bytes of a message header.
pub const MESSAGE_HEADER_LEN: usize = 18;
/// Bytes of a command sub-header.
pub const COMMAND_HEADER_LEN: usize = 26;
/// The protocol version this server writes (CoppeliaSim 4's; V-REP 3.3 clients send 10
/// and understand it: the versions differ only in commands added at the end of a range).
pub const SERVER_VERSION: u8 = 11;

/// Mask of the command code in a command's `cmd` field; the rest is the operation mode.
pub const CMD_MASK: i32 = 0xffff;

/// Operation modes (the bits above [`CMD_MASK`]).
pub mod opmode {
    /// Execute once; the client does not wait.
    pub const ONESHOT: i32 = 0x00_0000;
    /// Execute once; the client waits for the reply.
    pub const BLOCKING: i32 = 0x01_0000;
    /// Execute now and at every later message until discontinued.
    pub const STREAMING: i32 = 0x02_0000;
    /// [`ONESHOT`] for large data, sent in chunks.
    pub const ONESHOT_SPLIT: i32 = 0x03_0000;
    /// [`STREAMING`] for large data, sent in chunks.
    pub const STREAMING_SPLIT: i32 = 0x04_0000;
    /// Stop a streaming command.
    pub const DISCONTINUE: i32 = 0x05_0000;
    /// Client-side only: read the last reply (never sent).
    pub const BUFFER: i32 = 0x06_0000;
    /// Client-side only: drop the last reply (never sent).
    pub const REMOVE: i32 = 0x07_0000;
}

/// How a command is identified beyond its code, by the code's range.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IdKind {
    /// Codes below 0x1000: the code alone.
    None,
    /// 0x1000-0x1fff: one `i32` (usually an object handle).
    Int,
    /// 0x2000-0x2fff: two `i32`.
    IntInt,
    /// 0x3000-0x33ff and 0x3800-0x3fff: a string (an object name, a signal name).
    Str,
    /// 0x3400-0x34ff: an `i32` and two strings (`simxCallScriptFunction`).
    IntStrStr,
}

/// The identifying kind of command code `code` (see [`IdKind`]); `None` for codes no
/// client sends (0x4000 and above).
pub fn id_kind(code: i32) -> Option<IdKind> {
    match code {
        0..=0x0fff => Some(IdKind::None),
        0x1000..=0x1fff => Some(IdKind::Int),
        0x2000..=0x2fff => Some(IdKind::IntInt),
        0x3400..=0x34ff => Some(IdKind::IntStrStr),
        0x3000..=0x3fff => Some(IdKind::Str),
        _ => None,
    }
}

/// A command's identifying data, decoded.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum CommandId {
    /// See [`IdKind::None`].
    None,
    /// See [`IdKind::Int`].
    Int(i32),
    /// See [`IdKind::IntInt`].
    IntInt(i32, i32),
    /// See [`IdKind::Str`]; the bytes without the terminating NUL.
    Str(Vec<u8>),
    /// See [`IdKind::IntStrStr`].
    IntStrStr(i32, Vec<u8>, Vec<u8>),
}

impl CommandId {
    fn encode(&self, out: &mut Vec<u8>) {
        match self {
            CommandId::None => {}
            CommandId::Int(a) => out.extend_from_slice(&a.to_le_bytes()),
            CommandId::IntInt(a, b) => {
                out.extend_from_slice(&a.to_le_bytes());
                out.extend_from_slice(&b.to_le_bytes());
            }
            CommandId::Str(s) => {
                out.extend_from_slice(s);
                out.push(0);
            }
            CommandId::IntStrStr(a, s1, s2) => {
                out.extend_from_slice(&a.to_le_bytes());
                out.extend_from_slice(s1);
                out.push(0);
                out.extend_from_slice(s2);
                out.push(0);
            }
        }
    }

    fn encoded_len(&self) -> usize {
        match self {
            CommandId::None => 0,
            CommandId::Int(_) => 4,
            CommandId::IntInt(..) => 8,
            CommandId::Str(s) => s.len() + 1,
            CommandId::IntStrStr(_, a, b) => 4 + a.len() + b.len() + 2,
        }
    }
}

/// The header of a message.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MessageHeader {
    /// The protocol version of the sender.
    pub version: u8,
    /// Chosen by the client, echoed by the server (the client waits for it).
    pub message_id: i32,
    /// The client's clock, ms, echoed by the server.
    pub client_time: i32,
    /// The server's clock, ms.
    pub server_time: i32,
    /// Changes when another scene is loaded.
    pub scene_id: u16,
    /// Bit 0: the simulation is not stopped; bit 1: it is paused.
    pub server_state: u8,
}

/// One command of a message: a request from the client, or a reply.
#[derive(Debug, Clone, PartialEq)]
pub struct Command {
    /// The command code (`cmd & CMD_MASK`).
    pub code: i32,
    /// The operation mode (`cmd & !CMD_MASK`, see [`opmode`]).
    pub opmode: i32,
    /// Streaming: the least delay between two executions, ms; split modes: the chunk size.
    pub delay_or_split: u16,
    /// The command's identifying data.
    pub id: CommandId,
    /// Arguments (request) or results (reply).
    pub data: Vec<u8>,
    /// Request: bit 1 set means "do not overwrite"; reply: bit 0 set means it failed.
    pub status: u8,
    /// Reply: the simulation time when it was executed, ms (0 while stopped).
    pub sim_time_ms: i32,
}

/// A decoded message.
#[derive(Debug, Clone, PartialEq)]
pub struct Message {
    /// Its header.
    pub header: MessageHeader,
    /// Its whole commands, in order.
    pub commands: Vec<Command>,
    /// Chunks of split commands (`simx_opmode_oneshot_split` requests): put them
    /// together with a [`SplitAssembler`].
    pub chunks: Vec<Chunk>,
}

/// One chunk of a command sent in several messages.
#[derive(Debug, Clone, PartialEq)]
pub struct Chunk {
    /// The command, with only this chunk's part of the data in `data`.
    pub command: Command,
    /// Where this part goes in the whole pure data.
    pub offset: usize,
    /// The size of the whole pure data.
    pub total: usize,
}

/// Why bytes are not a valid packet stream or message.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum LegacyError {
    /// A packet header whose first field is not 1 (a big-endian peer or another protocol).
    #[error("not a legacy remote API packet (byte-order mark {0}, expected 1 little-endian)")]
    BadPacketMark(i16),
    /// A packet with a negative or oversize length.
    #[error("bad packet length {0} (at most {MAX_PACKET_PAYLOAD})")]
    BadPacketLength(i16),
    /// A message larger than [`MAX_MESSAGE_LEN`].
    #[error("message too large: more than {MAX_MESSAGE_LEN} bytes")]
    MessageTooLarge,
    /// A message shorter than its header.
    #[error("message of {0} bytes is shorter than its 18-byte header")]
    ShortMessage(usize),
    /// A command whose sizes do not fit the message.
    #[error("command at byte {at}: {why}")]
    BadCommand {
        /// Offset of the command in the message.
        at: usize,
        /// What is wrong.
        why: &'static str,
    },
}

/// Splits a byte stream into messages: feed what the socket gave, take whole messages.
#[derive(Debug, Default)]
pub struct PacketReader {
    buf: Vec<u8>,
    message: Vec<u8>,
}

impl PacketReader {
    /// A reader with nothing buffered.
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends bytes received from the peer.
    pub fn feed(&mut self, bytes: &[u8]) {
        self.buf.extend_from_slice(bytes);
    }

    /// The next whole message, if its last packet has arrived.
    ///
    /// # Errors
    /// A malformed packet header or an oversize message; the connection should close.
    pub fn next_message(&mut self) -> Result<Option<Vec<u8>>, LegacyError> {
        loop {
            if self.buf.len() < PACKET_HEADER_LEN {
                return Ok(None);
            }
            let mark = i16::from_le_bytes([self.buf[0], self.buf[1]]);
            if mark != 1 {
                return Err(LegacyError::BadPacketMark(mark));
            }
            let len = i16::from_le_bytes([self.buf[2], self.buf[3]]);
            let left = i16::from_le_bytes([self.buf[4], self.buf[5]]);
            let Ok(n) = usize::try_from(len) else {
                return Err(LegacyError::BadPacketLength(len));
            };
            if n > MAX_PACKET_PAYLOAD || left < 0 {
                return Err(LegacyError::BadPacketLength(len));
            }
            if self.buf.len() < PACKET_HEADER_LEN + n {
                return Ok(None);
            }
            if self.message.len() + n > MAX_MESSAGE_LEN {
                return Err(LegacyError::MessageTooLarge);
            }
            self.message
                .extend_from_slice(&self.buf[PACKET_HEADER_LEN..PACKET_HEADER_LEN + n]);
            self.buf.drain(..PACKET_HEADER_LEN + n);
            if left == 0 {
                return Ok(Some(std::mem::take(&mut self.message)));
            }
        }
    }

    /// Bytes buffered and not yet part of a whole message (for bounding memory).
    pub fn pending(&self) -> usize {
        self.buf.len() + self.message.len()
    }
}

/// Cuts a message into packets, each with its header.
pub fn packetize(message: &[u8]) -> Vec<u8> {
    let count = message.len().div_ceil(MAX_PACKET_PAYLOAD).max(1);
    let mut out = Vec::with_capacity(message.len() + count * PACKET_HEADER_LEN);
    let mut left = count;
    if message.is_empty() {
        out.extend_from_slice(&1i16.to_le_bytes());
        out.extend_from_slice(&0i16.to_le_bytes());
        out.extend_from_slice(&0i16.to_le_bytes());
        return out;
    }
    for chunk in message.chunks(MAX_PACKET_PAYLOAD) {
        left -= 1;
        out.extend_from_slice(&1i16.to_le_bytes());
        // MAX_PACKET_PAYLOAD < i16::MAX; a message of more than 32767 packets (42 MB)
        // would wrap the count, so the caller bounds replies below that.
        out.extend_from_slice(&(chunk.len() as i16).to_le_bytes());
        out.extend_from_slice(&(left.min(i16::MAX as usize) as i16).to_le_bytes());
        out.extend_from_slice(chunk);
    }
    out
}

/// Most bytes a reply message may have: [`packetize`] counts packets in an `i16`.
pub const MAX_REPLY_LEN: usize = MAX_PACKET_PAYLOAD * (i16::MAX as usize);

fn i32_at(b: &[u8], at: usize) -> Option<i32> {
    b.get(at..at + 4).map(|s| i32::from_le_bytes([s[0], s[1], s[2], s[3]]))
}

fn u16_at(b: &[u8], at: usize) -> Option<u16> {
    b.get(at..at + 2).map(|s| u16::from_le_bytes([s[0], s[1]]))
}

/// The bytes up to the first NUL of `b`, and how many bytes that took with the NUL.
fn c_string(b: &[u8]) -> Option<(&[u8], usize)> {
    let end = b.iter().position(|&c| c == 0)?;
    Some((&b[..end], end + 1))
}

fn decode_id(kind: IdKind, b: &[u8]) -> Option<(CommandId, usize)> {
    Some(match kind {
        IdKind::None => (CommandId::None, 0),
        IdKind::Int => (CommandId::Int(i32_at(b, 0)?), 4),
        IdKind::IntInt => (CommandId::IntInt(i32_at(b, 0)?, i32_at(b, 4)?), 8),
        IdKind::Str => {
            let (s, n) = c_string(b)?;
            (CommandId::Str(s.to_vec()), n)
        }
        IdKind::IntStrStr => {
            let a = i32_at(b, 0)?;
            let (s1, n1) = c_string(b.get(4..)?)?;
            let (s2, n2) = c_string(b.get(4 + n1..)?)?;
            (CommandId::IntStrStr(a, s1.to_vec(), s2.to_vec()), 4 + n1 + n2)
        }
    })
}

/// Decodes a whole message (see [`PacketReader`]).
///
/// # Errors
/// A message shorter than its header, or a command whose sizes do not fit.
pub fn decode_message(m: &[u8]) -> Result<Message, LegacyError> {
    if m.len() < MESSAGE_HEADER_LEN {
        return Err(LegacyError::ShortMessage(m.len()));
    }
    let header = MessageHeader {
        version: m[2],
        message_id: i32_at(m, 3).unwrap_or_default(),
        client_time: i32_at(m, 7).unwrap_or_default(),
        server_time: i32_at(m, 11).unwrap_or_default(),
        scene_id: u16_at(m, 15).unwrap_or_default(),
        server_state: m[17],
    };
    let mut commands = Vec::new();
    let mut chunks = Vec::new();
    let mut at = MESSAGE_HEADER_LEN;
    while at < m.len() {
        let bad = |why| LegacyError::BadCommand { at, why };
        let rest = &m[at..];
        let size = i32_at(rest, 0).ok_or(bad("truncated sub-header"))?;
        let full = i32_at(rest, 4).ok_or(bad("truncated sub-header"))?;
        let id_len = u16_at(rest, 8).ok_or(bad("truncated sub-header"))? as usize;
        let offset = i32_at(rest, 10).ok_or(bad("truncated sub-header"))?;
        let cmd = i32_at(rest, 14).ok_or(bad("truncated sub-header"))?;
        let delay_or_split = u16_at(rest, 18).ok_or(bad("truncated sub-header"))?;
        let sim_time_ms = i32_at(rest, 20).ok_or(bad("truncated sub-header"))?;
        let status = *rest.get(24).ok_or(bad("truncated sub-header"))?;
        let size = usize::try_from(size).map_err(|_| bad("negative size"))?;
        if size < COMMAND_HEADER_LEN + id_len || size > rest.len() {
            return Err(bad("size outside the message"));
        }
        let code = cmd & CMD_MASK;
        let kind = id_kind(code).ok_or(bad("unknown command range"))?;
        let body = &rest[COMMAND_HEADER_LEN..size];
        let (id, used) = decode_id(kind, &body[..id_len]).ok_or(bad("identifying data too short"))?;
        if used != id_len {
            return Err(bad("identifying data of the wrong size"));
        }
        let command = Command {
            code,
            opmode: cmd & !CMD_MASK,
            delay_or_split,
            id,
            data: body[id_len..].to_vec(),
            status,
            sim_time_ms,
        };
        let full = usize::try_from(full).map_err(|_| bad("negative full size"))?;
        let offset = usize::try_from(offset).map_err(|_| bad("negative offset"))?;
        if full == size && offset == 0 {
            commands.push(command);
        } else {
            let total = full
                .checked_sub(COMMAND_HEADER_LEN + id_len)
                .filter(|&t| t <= MAX_MESSAGE_LEN)
                .ok_or(bad("bad full size"))?;
            if offset.checked_add(command.data.len()).is_none_or(|end| end > total) {
                return Err(bad("chunk outside its command"));
            }
            chunks.push(Chunk { command, offset, total });
        }
        at += size;
    }
    Ok(Message {
        header,
        commands,
        chunks,
    })
}

/// Encodes a reply message: `header` and `commands` (their `status` and `sim_time_ms`
/// as the server sets them).
pub fn encode_message(header: &MessageHeader, commands: &[Command]) -> Vec<u8> {
    let mut out = Vec::with_capacity(
        MESSAGE_HEADER_LEN
            + commands
                .iter()
                .map(|c| COMMAND_HEADER_LEN + c.id.encoded_len() + c.data.len())
                .sum::<usize>(),
    );
    out.extend_from_slice(&0u16.to_le_bytes()); // CRC: clients neither set nor check it
    out.push(header.version);
    out.extend_from_slice(&header.message_id.to_le_bytes());
    out.extend_from_slice(&header.client_time.to_le_bytes());
    out.extend_from_slice(&header.server_time.to_le_bytes());
    out.extend_from_slice(&header.scene_id.to_le_bytes());
    out.push(header.server_state);
    for c in commands {
        let id_len = c.id.encoded_len();
        let size = (COMMAND_HEADER_LEN + id_len + c.data.len()) as i32;
        out.extend_from_slice(&size.to_le_bytes());
        out.extend_from_slice(&size.to_le_bytes());
        out.extend_from_slice(&(id_len as u16).to_le_bytes());
        out.extend_from_slice(&0i32.to_le_bytes());
        out.extend_from_slice(&(c.code | c.opmode).to_le_bytes());
        out.extend_from_slice(&c.delay_or_split.to_le_bytes());
        out.extend_from_slice(&c.sim_time_ms.to_le_bytes());
        out.push(c.status);
        out.push(0);
        c.id.encode(&mut out);
        out.extend_from_slice(&c.data);
    }
    out
}

/// Puts split commands back together across messages.
#[derive(Debug, Default)]
pub struct SplitAssembler {
    partial: Vec<(i32, CommandId, Vec<u8>, Vec<bool>)>,
}

/// Most split commands in progress at once per connection.
pub const MAX_SPLIT_IN_PROGRESS: usize = 16;

impl SplitAssembler {
    /// Adds a chunk; returns the whole command once its every byte has arrived.
    ///
    /// # Errors
    /// Too many split commands in progress at once.
    pub fn add(&mut self, chunk: Chunk) -> Result<Option<Command>, LegacyError> {
        let key = (chunk.command.code, chunk.command.id.clone());
        let i = match self
            .partial
            .iter()
            .position(|(c, id, data, _)| (*c, id) == (key.0, &key.1) && data.len() == chunk.total)
        {
            Some(i) => i,
            None => {
                self.partial.retain(|(c, id, ..)| (*c, id) != (key.0, &key.1));
                if self.partial.len() >= MAX_SPLIT_IN_PROGRESS {
                    return Err(LegacyError::BadCommand {
                        at: 0,
                        why: "too many split commands in progress",
                    });
                }
                self.partial
                    .push((key.0, key.1, vec![0; chunk.total], vec![false; chunk.total]));
                self.partial.len() - 1
            }
        };
        let (_, _, data, seen) = &mut self.partial[i];
        let end = chunk.offset + chunk.command.data.len();
        data[chunk.offset..end].copy_from_slice(&chunk.command.data);
        seen[chunk.offset..end].iter_mut().for_each(|s| *s = true);
        if seen.iter().all(|&s| s) {
            let (_, _, data, _) = self.partial.swap_remove(i);
            let mut command = chunk.command;
            command.data = data;
            return Ok(Some(command));
        }
        Ok(None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request(code: i32, opmode: i32, id: CommandId, data: &[u8]) -> Command {
        Command {
            code,
            opmode,
            delay_or_split: 0,
            id,
            data: data.to_vec(),
            status: 0,
            sim_time_ms: 0,
        }
    }

    #[test]
    fn messages_round_trip_through_packets() {
        let header = MessageHeader {
            version: 10,
            message_id: 42,
            client_time: 7,
            ..Default::default()
        };
        let commands = vec![
            request(0x1008, opmode::ONESHOT, CommandId::Int(17), &1.5f32.to_le_bytes()),
            request(0x3001, opmode::BLOCKING, CommandId::Str(b"/robot/joint".to_vec()), &[]),
            request(
                0x3401,
                opmode::BLOCKING,
                CommandId::IntStrStr(6, b"robot".to_vec(), b"f".to_vec()),
                &[0; 16],
            ),
            request(0x200e, opmode::STREAMING, CommandId::IntInt(3, -1), &[]),
            request(0x0003, opmode::BLOCKING, CommandId::None, &[]),
            // Larger than one packet.
            request(0x1006, opmode::ONESHOT, CommandId::Int(5), &vec![7u8; 5000]),
        ];
        let bytes = packetize(&encode_message(&header, &commands));
        let mut reader = PacketReader::new();
        // Byte by byte: a message is whole only once its last packet is in.
        let mut got = None;
        for b in &bytes {
            reader.feed(std::slice::from_ref(b));
            if let Some(m) = reader.next_message().unwrap() {
                got = Some(m);
            }
        }
        let decoded = decode_message(&got.expect("a whole message")).unwrap();
        assert_eq!(decoded.header.message_id, 42);
        assert_eq!(decoded.header.version, 10);
        assert_eq!(decoded.commands, commands);
        assert!(decoded.chunks.is_empty());
        assert_eq!(reader.pending(), 0);
    }

    #[test]
    fn an_empty_message_is_one_packet() {
        let bytes = packetize(&encode_message(&MessageHeader::default(), &[]));
        assert_eq!(bytes.len(), PACKET_HEADER_LEN + MESSAGE_HEADER_LEN);
        let mut r = PacketReader::new();
        r.feed(&bytes);
        let m = decode_message(&r.next_message().unwrap().unwrap()).unwrap();
        assert!(m.commands.is_empty());
    }

    #[test]
    fn bad_input_is_refused_not_trusted() {
        let mut r = PacketReader::new();
        r.feed(&[0, 1, 10, 0, 0, 0]);
        assert_eq!(r.next_message(), Err(LegacyError::BadPacketMark(256)));
        let mut r = PacketReader::new();
        r.feed(&[1, 0, 0xff, 0x7f, 0, 0]);
        assert!(matches!(r.next_message(), Err(LegacyError::BadPacketLength(_))));
        assert_eq!(decode_message(&[0; 5]), Err(LegacyError::ShortMessage(5)));
        // A command claiming more bytes than the message has.
        let mut m = encode_message(&MessageHeader::default(), &[request(0x1001, 0, CommandId::Int(1), &[])]);
        m[MESSAGE_HEADER_LEN..MESSAGE_HEADER_LEN + 4].copy_from_slice(&1000i32.to_le_bytes());
        assert!(matches!(decode_message(&m), Err(LegacyError::BadCommand { .. })));
        // A string id without its NUL.
        let mut m = encode_message(
            &MessageHeader::default(),
            &[request(0x3001, 0, CommandId::Str(b"abc".to_vec()), &[])],
        );
        let last = m.len() - 1;
        m[last] = b'd';
        assert!(matches!(decode_message(&m), Err(LegacyError::BadCommand { .. })));
    }

    #[test]
    fn split_commands_are_put_back_together() {
        let whole: Vec<u8> = (0..=255u8).cycle().take(3000).collect();
        let mut asm = SplitAssembler::default();
        let mut result = None;
        for (i, part) in whole.chunks(1000).enumerate().rev() {
            let chunk = Chunk {
                command: request(0x1006, opmode::ONESHOT_SPLIT, CommandId::Int(9), part),
                offset: i * 1000,
                total: whole.len(),
            };
            if let Some(c) = asm.add(chunk).unwrap() {
                result = Some(c);
            }
        }
        assert_eq!(result.expect("complete").data, whole);
    }

    #[test]
    fn code_ranges_match_the_client() {
        assert_eq!(id_kind(0x0003), Some(IdKind::None)); // synchronous_next
        assert_eq!(id_kind(0x1008), Some(IdKind::Int)); // set_joint_target_velocity
        assert_eq!(id_kind(0x200e), Some(IdKind::IntInt)); // get_object_position2
        assert_eq!(id_kind(0x3001), Some(IdKind::Str)); // get_object_handle
        assert_eq!(id_kind(0x3401), Some(IdKind::IntStrStr)); // call_script_function
        assert_eq!(id_kind(0x4000), None);
    }
}
