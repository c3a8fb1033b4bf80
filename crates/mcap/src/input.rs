//! What reached the simulation from outside during a recorded run: remote calls, text
//! packets, start/pause/stop and stepping requests, each with the step it arrived at.
//! `gantry verify` feeds them to a fresh simulation of the recorded scene at the same
//! steps and compares the result with the recording.
//!
//! An input travels on `/gantry/input` as a `gantry_msgs/msg/Input` ([`schema::INPUT`]):
//! `step` (steps the engine had taken when it arrived), `boundary` (0: between steps;
//! `k > 0`: at the `k`-th phase boundary inside the step after `step`, where a call may be
//! served mid-step), `kind`, `name`, `client` and `args`, the arguments as one CBOR
//! array (exact: CBOR keeps integers, floats, strings and byte strings apart, as the
//! simulation's values do). The engine decides what the kinds and names mean; this
//! module only carries them.
//!
//! [`schema::INPUT`]: crate::schema::INPUT

use gantry_protocol::Value;
use gantry_protocol::cbor;
use gantry_protocol::ros::CDR_LE_HEADER;
use gantry_protocol::ros::typed::CdrWriter;

/// `/gantry/input`.
pub const INPUT_TOPIC: &str = "/gantry/input";

/// Longest encoded input accepted when reading one back (a packet or call that big
/// never reaches the simulation: the transports' own limits are far lower).
pub const MAX_INPUT_BYTES: usize = 64 << 20;

/// One input, at the step it arrived.
#[derive(Debug, Clone, PartialEq)]
pub struct Input {
    /// Steps the engine had taken when it arrived.
    pub step: u64,
    /// 0: served between steps; `k > 0`: served at the `k`-th boundary inside the
    /// step after `step`.
    pub boundary: u32,
    /// What it is (`call`, `packet`, `control`, `remote`, `load_scene`).
    pub kind: String,
    /// The function, action or path it names.
    pub name: String,
    /// The remote client it came from (0: none or not relevant).
    pub client: i64,
    /// Its arguments.
    pub args: Vec<Value>,
}

/// Why bytes on `/gantry/input` are not an input.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum InputDecodeError {
    /// The message ends before its last field.
    #[error("the input message ends early (at byte {0})")]
    Truncated(usize),
    /// Not little-endian plain CDR.
    #[error("the input message is not little-endian CDR")]
    Encapsulation,
    /// A string is not UTF-8 or lacks its terminating NUL.
    #[error("the input message has a malformed string at byte {0}")]
    BadString(usize),
    /// The arguments are not a CBOR array.
    #[error("the input's arguments are not a CBOR array: {0}")]
    BadArgs(String),
    /// Larger than [`MAX_INPUT_BYTES`].
    #[error("the input message is larger than {MAX_INPUT_BYTES} bytes")]
    TooLarge,
}

impl Input {
    /// The message's CDR bytes.
    pub fn encode(&self) -> Vec<u8> {
        let mut args = Vec::new();
        cbor::encode(&Value::Array(self.args.clone()), &mut args);
        let mut w = CdrWriter::with_capacity(64 + self.name.len() + args.len());
        w.u64(self.step);
        w.u32(self.boundary);
        w.string(&self.kind);
        w.string(&self.name);
        w.i64(self.client);
        w.bytes(&args);
        w.into_bytes()
    }

    /// An input from its CDR bytes. Total: any bytes give an input or an error.
    ///
    /// # Errors
    /// The bytes are not an encoded input.
    pub fn decode(bytes: &[u8]) -> Result<Self, InputDecodeError> {
        if bytes.len() > MAX_INPUT_BYTES {
            return Err(InputDecodeError::TooLarge);
        }
        let Some(body) = bytes.strip_prefix(&CDR_LE_HEADER[..]) else {
            return Err(InputDecodeError::Encapsulation);
        };
        let mut r = Reader { buf: body, at: 0 };
        let step = u64::from_le_bytes(r.fixed::<8>()?);
        let boundary = u32::from_le_bytes(r.fixed::<4>()?);
        let kind = r.string()?;
        let name = r.string()?;
        let client = i64::from_le_bytes(r.fixed::<8>()?);
        let n = u32::from_le_bytes(r.fixed::<4>()?) as usize;
        let raw = r.take(n)?;
        let args = match cbor::decode(raw) {
            Ok(Value::Array(a)) => a,
            Ok(other) => return Err(InputDecodeError::BadArgs(format!("a {}", other.type_name()))),
            Err(e) => return Err(InputDecodeError::BadArgs(e.to_string())),
        };
        Ok(Self {
            step,
            boundary,
            kind,
            name,
            client,
            args,
        })
    }
}

/// Reads CDR fields in order (alignment counted from the end of the header).
struct Reader<'a> {
    buf: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], InputDecodeError> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.buf.len());
        let end = end.ok_or(InputDecodeError::Truncated(self.at))?;
        let out = &self.buf[self.at..end];
        self.at = end;
        Ok(out)
    }

    fn fixed<const N: usize>(&mut self) -> Result<[u8; N], InputDecodeError> {
        self.at = self.at.next_multiple_of(N).min(self.buf.len());
        let b = self.take(N)?;
        let mut out = [0; N];
        out.copy_from_slice(b);
        Ok(out)
    }

    fn string(&mut self) -> Result<String, InputDecodeError> {
        let n = u32::from_le_bytes(self.fixed::<4>()?) as usize;
        let start = self.at;
        let raw = self.take(n)?;
        match raw.split_last() {
            Some((0, text)) => std::str::from_utf8(text)
                .map(str::to_owned)
                .map_err(|_| InputDecodeError::BadString(start)),
            _ => Err(InputDecodeError::BadString(start)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Input {
        Input {
            step: 41,
            boundary: 2,
            kind: "call".into(),
            name: "sim.setJointTargetVelocity".into(),
            client: 7,
            args: vec![
                Value::Int(16),
                Value::Float(-0.1),
                Value::Str("é".into()),
                Value::Bytes(vec![0, 255]),
                Value::Map(vec![(Value::Int(1), Value::Nil)]),
            ],
        }
    }

    #[test]
    fn an_input_round_trips_exactly() {
        let i = sample();
        assert_eq!(Input::decode(&i.encode()), Ok(i));
        let empty = Input {
            args: Vec::new(),
            name: String::new(),
            ..sample()
        };
        assert_eq!(Input::decode(&empty.encode()), Ok(empty));
    }

    #[test]
    fn every_cut_of_a_message_is_an_error_not_a_panic() {
        let bytes = sample().encode();
        for n in 0..bytes.len() {
            assert!(Input::decode(&bytes[..n]).is_err(), "cut at {n}");
        }
        let mut flipped = bytes.clone();
        for i in 0..flipped.len() {
            flipped[i] ^= 0xff;
            let _ = Input::decode(&flipped);
            flipped[i] ^= 0xff;
        }
        assert_eq!(Input::decode(b"\x00\x00\x00\x00"), Err(InputDecodeError::Encapsulation));
    }
}
