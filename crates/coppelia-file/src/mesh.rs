//! Mesh buffers: the shared `VIN` section and the packed index and normal encodings.
//!
//! Since serialization version 18 the vertices, indices and normals of every mesh live in
//! one top-level `VIN` stream, and each mesh refers to its buffers by number (`Vev`,
//! `Inv`, `Nov`), so identical meshes are stored once. The buffers are numbered by kind in
//! the order they appear: `Ver` (f32 xyz) on their own, `Ind` (raw i32) and `In2`
//! (packed) together, `Nor` (f32 xyz) and `No2` (packed) together.
//!
//! Buffers are reference-counted: many meshes may name the same buffer, and sharing it
//! keeps a small hostile file from multiplying a large buffer.

use std::sync::Arc;

use crate::chunk::{At, Chunk, Chunks};
use crate::error::ReadError;

/// Most vertices, indices or normals in one buffer.
pub const MAX_BUFFER_ELEMENTS: usize = 64 * 1024 * 1024;

/// The `VIN` buffers, by number.
#[derive(Debug, Clone, Default)]
pub struct MeshBuffers {
    /// Vertex buffers, metres, in the frame of the mesh that uses them.
    pub vertices: Vec<Arc<[[f32; 3]]>>,
    /// Triangle index buffers (three per triangle), raw and unpacked alike.
    pub indices: Vec<Arc<[u32]>>,
    /// Normal buffers (one per index), raw and unpacked alike; unit length.
    pub normals: Vec<Arc<[[f32; 3]]>>,
    /// Largest index of each index buffer, so a mesh can check its indices against its
    /// vertices in constant time however many meshes share the buffer.
    index_max: Vec<Option<u32>>,
}

impl MeshBuffers {
    /// Reads the payload of a `VIN` chunk.
    ///
    /// # Errors
    /// [`ReadError::Chunk`] for a malformed stream, [`ReadError::Value`] for a buffer
    /// whose length is not a whole number of elements, a negative index or a count
    /// beyond the payload.
    pub fn read(chunk: &Chunk, parent: &At) -> Result<MeshBuffers, ReadError> {
        let at = parent.child(chunk.tag, chunk.offset);
        let mut buffers = MeshBuffers::default();
        let (chunks, _) = Chunks::new(chunk.payload, &at).part(false)?;
        for c in chunks {
            let here = at.child(c.tag, c.offset);
            match &c.tag {
                b"Ver" => buffers.vertices.push(xyz_f32(c.payload, &here)?.into()),
                b"Nor" => buffers.normals.push(xyz_f32(c.payload, &here)?.into()),
                b"Ind" => buffers.push_indices(raw_indices(c.payload, &here)?),
                b"In2" => buffers.push_indices(packed_indices(c.payload, &here)?),
                b"No2" => buffers.normals.push(packed_normals(c.payload, &here)?.into()),
                _ => {}
            }
        }
        Ok(buffers)
    }

    fn push_indices(&mut self, indices: Vec<u32>) {
        self.index_max.push(indices.iter().copied().max());
        self.indices.push(indices.into());
    }

    /// The largest index in index buffer `n` (`None` for an empty or missing buffer).
    pub fn index_max(&self, n: usize) -> Option<u32> {
        self.index_max.get(n).copied().flatten()
    }
}

fn check_count(n: usize, at: &At) -> Result<(), ReadError> {
    if n > MAX_BUFFER_ELEMENTS {
        return Err(at.value_error(format!("{n} elements, more than {MAX_BUFFER_ELEMENTS}")));
    }
    Ok(())
}

/// f32 triples.
fn xyz_f32(payload: &[u8], at: &At) -> Result<Vec<[f32; 3]>, ReadError> {
    if !payload.len().is_multiple_of(12) {
        return Err(at.value_error(format!(
            "{} bytes is not a whole number of xyz f32 triples",
            payload.len()
        )));
    }
    check_count(payload.len() / 12, at)?;
    Ok(payload
        .chunks_exact(12)
        .map(|c| {
            let f = |i: usize| f32::from_le_bytes([c[i], c[i + 1], c[i + 2], c[i + 3]]);
            [f(0), f(4), f(8)]
        })
        .collect())
}

fn to_index(v: i64, at: &At) -> Result<u32, ReadError> {
    u32::try_from(v).map_err(|_| at.value_error(format!("index {v} is negative or too large")))
}

/// Raw little-endian i32 indices.
fn raw_indices(payload: &[u8], at: &At) -> Result<Vec<u32>, ReadError> {
    if !payload.len().is_multiple_of(4) {
        return Err(at.value_error(format!("{} bytes is not a whole number of i32 indices", payload.len())));
    }
    check_count(payload.len() / 4, at)?;
    payload
        .chunks_exact(4)
        .map(|c| to_index(i64::from(i32::from_le_bytes([c[0], c[1], c[2], c[3]])), at))
        .collect()
}

/// `In2`: an i32 count, then each index as a delta from the previous one (starting at
/// 0) in 1-4 bytes. The top two bits of the first byte give the number of extra bytes;
/// the remaining 6 bits and the extra bytes (least significant first) hold the delta
/// plus a bias of half the range (31, 8191, 2097151, 536870911).
pub fn packed_indices(payload: &[u8], at: &At) -> Result<Vec<u32>, ReadError> {
    let Some(count) = payload.get(..4) else {
        return Err(at.value_error("packed index buffer shorter than its count"));
    };
    let count = i32::from_le_bytes([count[0], count[1], count[2], count[3]]);
    let data = &payload[4..];
    // Every index takes at least one byte: refuse counts the payload cannot hold before
    // allocating for them.
    let count = usize::try_from(count)
        .ok()
        .filter(|&n| n <= data.len())
        .ok_or_else(|| at.value_error(format!("packed index count {count} does not fit {} bytes", data.len())))?;
    check_count(count, at)?;
    const BIAS: [i64; 4] = [31, 8_191, 2_097_151, 536_870_911];
    let mut out = Vec::with_capacity(count);
    let mut pos = 0usize;
    let mut prev = 0i64;
    for _ in 0..count {
        let Some(&first) = data.get(pos) else {
            return Err(at.value_error(format!("packed indices end after {} of {count}", out.len())));
        };
        let extra = usize::from(first >> 6);
        let Some(more) = data.get(pos + 1..pos + 1 + extra) else {
            return Err(at.value_error(format!("packed indices end inside index {}", out.len())));
        };
        let mut v = i64::from(first & 0x3f);
        for (k, &b) in more.iter().enumerate() {
            v |= i64::from(b) << (6 + 8 * k);
        }
        pos += 1 + extra;
        prev += v - BIAS[extra];
        out.push(to_index(prev, at)?);
    }
    Ok(out)
}

/// `No2`: one u16 per normal, three 5-bit components each offset by 15, normalised.
fn packed_normals(payload: &[u8], at: &At) -> Result<Vec<[f32; 3]>, ReadError> {
    if !payload.len().is_multiple_of(2) {
        return Err(at.value_error(format!(
            "{} bytes is not a whole number of packed normals",
            payload.len()
        )));
    }
    check_count(payload.len() / 2, at)?;
    Ok(payload
        .chunks_exact(2)
        .map(|c| {
            let w = u16::from_le_bytes([c[0], c[1]]);
            let comp = |shift: u16| f32::from((w >> shift & 0x1f) as i8 - 15);
            let v = [comp(0), comp(5), comp(10)];
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if n > 0.0 { v.map(|x| x / n) } else { v }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{Payload, Stream, pack_indices};

    #[test]
    fn packed_indices_round_trip_every_width() {
        let indices = [0, 1, 2, 40, 3, 9000, 2, 3_000_000, 5, 200_000_000, 0];
        let packed = pack_indices(&indices);
        let top = At::top();
        let got = packed_indices(&packed, &top).unwrap();
        assert_eq!(got, indices.map(|i| i as u32));
        // Widths 1, 2, 3 and 4 bytes all appear.
        let mut widths = Vec::new();
        let mut pos = 4;
        while pos < packed.len() {
            let extra = usize::from(packed[pos] >> 6);
            widths.push(extra + 1);
            pos += extra + 1;
        }
        for w in 1..=4 {
            assert!(widths.contains(&w), "{widths:?}");
        }
    }

    #[test]
    fn packed_indices_refuse_bad_counts_and_negatives() {
        let top = At::top();
        // Count larger than the bytes.
        let p = Payload::new().i32(1_000_000).raw(&[31]).done();
        assert!(packed_indices(&p, &top).is_err());
        assert!(packed_indices(&Payload::new().i32(-1).done(), &top).is_err());
        // A delta of -1 from 0.
        let p = Payload::new().i32(1).raw(&[30]).done();
        assert!(packed_indices(&p, &top).is_err());
        // Cut inside a 4-byte index.
        let p = Payload::new().i32(1).raw(&[0xc0, 1]).done();
        assert!(packed_indices(&p, &top).is_err());
    }

    #[test]
    fn reads_a_vin_section() {
        let ver = Payload::new()
            .f32s(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0])
            .done();
        let ind = Payload::new().i32(0).i32(1).i32(2).done();
        let no2 = Payload::new().u16(15 | 15 << 5 | 16 << 10).done();
        let stream = Stream::new()
            .chunk("Ver", &ver)
            .chunk("In2", &pack_indices(&[2, 1, 0]))
            .chunk("Ind", &ind)
            .chunk("No2", &no2)
            .chunk("Nor", &Payload::new().f32s(&[0.0, 0.0, 1.0]).done())
            .chunk("Ved", &[1, 2, 3])
            .marker("EOO")
            .bytes();
        let top = At::top();
        let chunk = Chunk {
            tag: *b"VIN",
            payload: &stream,
            offset: 0,
        };
        let b = MeshBuffers::read(&chunk, &top).unwrap();
        assert_eq!(b.vertices.len(), 1);
        assert_eq!(b.vertices[0][1], [1.0, 0.0, 0.0]);
        assert_eq!(&b.indices[0][..], &[2, 1, 0]);
        assert_eq!(&b.indices[1][..], &[0, 1, 2]);
        assert_eq!(b.normals[0][0], [0.0, 0.0, 1.0]);
        assert_eq!(b.normals.len(), 2);

        let bad = Stream::new().chunk("Ver", &[0; 10]).marker("EOO").bytes();
        let chunk = Chunk {
            tag: *b"VIN",
            payload: &bad,
            offset: 0,
        };
        let err = MeshBuffers::read(&chunk, &top).unwrap_err();
        assert!(err.to_string().contains("VIN/Ver"), "{err}");
    }
}
