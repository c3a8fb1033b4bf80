//! The rules of plain little-endian CDR (XCDR1) that every encoder here follows: the
//! encapsulation header and the alignment of primitives. The dynamic codec
//! (`encode.rs`) and the typed messages' [`CdrWriter`](super::typed::CdrWriter) share
//! them.

/// The 4-byte encapsulation header of little-endian plain CDR (`CDR_LE`, no options),
/// which [`MsgType::encode`](super::MsgType::encode) and the typed messages write.
pub const CDR_LE_HEADER: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// Pads `out` with zeros to a multiple of `n` bytes counted from `origin`, the index of
/// the body's first byte (the end of the encapsulation header): CDR aligns each
/// primitive to its own size from there, not from the start of the buffer.
pub(crate) fn pad(out: &mut Vec<u8>, origin: usize, n: usize) {
    let offset = out.len().saturating_sub(origin);
    let pad = (n - offset % n) % n;
    out.resize(out.len() + pad, 0);
}
