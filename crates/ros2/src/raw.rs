//! RustDDS adapters that pass CDR bodies through untouched: gantry encodes and decodes
//! messages itself (gantry-protocol's `ros` codec, total and fuzzed), so the DDS layer
//! never interprets what a peer sent.

use rustdds::RepresentationIdentifier;
use rustdds::bytes::Bytes;
use rustdds::no_key::{Decode, DefaultDecoder, DeserializerAdapter, SerializerAdapter};

/// A CDR body and its byte order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct RawCdr {
    /// The bytes after the encapsulation header.
    pub(crate) body: Bytes,
    /// CDR_LE (true) or CDR_BE.
    pub(crate) little_endian: bool,
}

/// Never returned: copying bytes cannot fail. (RustDDS's traits want an error type.)
#[derive(Debug, thiserror::Error)]
#[error("unsupported representation")]
pub(crate) struct RawError;

/// The pass-through adapter (see the module docs).
pub(crate) struct RawAdapter;

impl SerializerAdapter<RawCdr> for RawAdapter {
    type Error = RawError;

    fn output_encoding() -> RepresentationIdentifier {
        RepresentationIdentifier::CDR_LE
    }

    fn to_bytes(value: &RawCdr) -> Result<Bytes, RawError> {
        // A cheap clone: `Bytes` shares the buffer.
        Ok(value.body.clone())
    }
}

/// Copies the body out of RustDDS's receive buffer.
#[derive(Debug, Clone, Copy)]
pub(crate) struct RawDecoder;

impl<'de> Decode<'de, RawCdr> for RawDecoder {
    type Error = RawError;

    fn decode_bytes(self, bytes: &'de [u8], encoding: RepresentationIdentifier) -> Result<RawCdr, RawError> {
        let little_endian = if encoding == RepresentationIdentifier::CDR_LE {
            true
        } else if encoding == RepresentationIdentifier::CDR_BE {
            false
        } else {
            return Err(RawError);
        };
        Ok(RawCdr {
            body: Bytes::copy_from_slice(bytes),
            little_endian,
        })
    }
}

impl DeserializerAdapter<RawCdr> for RawAdapter {
    type Error = RawError;
    type Decoded = RawCdr;

    fn supported_encodings() -> &'static [RepresentationIdentifier] {
        &[RepresentationIdentifier::CDR_LE, RepresentationIdentifier::CDR_BE]
    }

    fn transform_decoded(decoded: RawCdr) -> RawCdr {
        decoded
    }
}

impl DefaultDecoder<RawCdr> for RawAdapter {
    type Decoder = RawDecoder;
    const DECODER: RawDecoder = RawDecoder;
}
