//! Test-only writer: builds small .ttt/.ttm files (header, Huffman-coded body, chunk
//! stream) so the reader's tests and the fuzz seeds need no public file.

use crate::header::HEADER_LEN;

/// Huffman-codes `data` in the layout the reader expects (tree first, MSB-first codes).
pub fn huffman_encode(data: &[u8]) -> Vec<u8> {
    #[derive(Clone)]
    enum Tree {
        Leaf(u8),
        Node(Box<Tree>, Box<Tree>),
    }
    let mut freq = [0usize; 256];
    for &b in data {
        freq[usize::from(b)] += 1;
    }
    let mut forest: Vec<(usize, Tree)> = (0..=255u8)
        .filter(|&s| freq[usize::from(s)] > 0)
        .map(|s| (freq[usize::from(s)], Tree::Leaf(s)))
        .collect();
    // A tree needs two leaves for every symbol to get a code.
    while forest.len() < 2 {
        let spare = (0..=255u8).find(|s| forest.iter().all(|(_, t)| !matches!(t, Tree::Leaf(x) if x == s)));
        forest.push((0, Tree::Leaf(spare.unwrap_or(0))));
    }
    while forest.len() > 1 {
        forest.sort_by_key(|t| std::cmp::Reverse(t.0));
        let (fa, a) = forest.pop().expect("two trees left");
        let (fb, b) = forest.pop().expect("two trees left");
        forest.push((fa + fb, Tree::Node(Box::new(a), Box::new(b))));
    }
    let tree = forest.pop().expect("one tree").1;

    let mut bits: Vec<bool> = Vec::new();
    let mut codes: Vec<Vec<bool>> = vec![Vec::new(); 256];
    fn walk(t: &Tree, prefix: &mut Vec<bool>, bits: &mut Vec<bool>, codes: &mut Vec<Vec<bool>>) {
        match t {
            Tree::Leaf(s) => {
                bits.push(true);
                bits.extend((0..8).rev().map(|k| s >> k & 1 == 1));
                codes[usize::from(*s)] = prefix.clone();
            }
            Tree::Node(a, b) => {
                bits.push(false);
                prefix.push(false);
                walk(a, prefix, bits, codes);
                prefix.pop();
                prefix.push(true);
                walk(b, prefix, bits, codes);
                prefix.pop();
            }
        }
    }
    walk(&tree, &mut Vec::new(), &mut bits, &mut codes);
    for &b in data {
        bits.extend_from_slice(&codes[usize::from(b)]);
    }
    bits.chunks(8)
        .map(|c| {
            c.iter()
                .enumerate()
                .fold(0u8, |acc, (i, &bit)| acc | u8::from(bit) << (7 - i))
        })
        .collect()
}

/// A whole file: header for `ser_version`/`program_version`/`file_type`, then `body`
/// Huffman-coded.
pub fn file(ser_version: i32, program_version: u16, file_type: u8, body: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER_LEN + body.len());
    out.extend_from_slice(b"VREP");
    out.extend_from_slice(&ser_version.to_le_bytes());
    out.extend_from_slice(&18i32.to_le_bytes());
    out.push(1);
    out.extend_from_slice(&(body.len() as i32).to_le_bytes());
    out.extend_from_slice(&0i32.to_le_bytes());
    out.extend_from_slice(&program_version.to_le_bytes());
    out.extend_from_slice(&4096u32.to_le_bytes());
    out.push(0);
    out.push(file_type);
    out.resize(HEADER_LEN, 0);
    out.extend_from_slice(&huffman_encode(body));
    out
}

/// Builds a chunk stream: `chunk` writes tag + i32 length + payload, `marker` a bare
/// `EOO`/`NXT`/`EOF`.
#[derive(Default, Clone)]
pub struct Stream(pub Vec<u8>);

impl Stream {
    pub fn new() -> Self {
        Self::default()
    }
    pub fn chunk(mut self, tag: &str, payload: &[u8]) -> Self {
        self.0.extend_from_slice(tag.as_bytes());
        self.0.extend_from_slice(&(payload.len() as i32).to_le_bytes());
        self.0.extend_from_slice(payload);
        self
    }
    pub fn marker(mut self, tag: &str) -> Self {
        self.0.extend_from_slice(tag.as_bytes());
        self
    }
    /// A nested stream as a chunk: its items then `EOO`.
    pub fn nested(self, tag: &str, inner: Stream) -> Self {
        let inner = inner.marker("EOO");
        self.chunk(tag, &inner.0)
    }
    pub fn bytes(self) -> Vec<u8> {
        self.0
    }
}

/// Little-endian payload builder.
#[derive(Default)]
pub struct Payload(pub Vec<u8>);

impl Payload {
    pub fn new() -> Self {
        Self::default()
    }
    pub fn i32(mut self, v: i32) -> Self {
        self.0.extend_from_slice(&v.to_le_bytes());
        self
    }
    pub fn u16(mut self, v: u16) -> Self {
        self.0.extend_from_slice(&v.to_le_bytes());
        self
    }
    pub fn f32s(mut self, v: &[f32]) -> Self {
        for x in v {
            self.0.extend_from_slice(&x.to_le_bytes());
        }
        self
    }
    pub fn f64s(mut self, v: &[f64]) -> Self {
        for x in v {
            self.0.extend_from_slice(&x.to_le_bytes());
        }
        self
    }
    pub fn str(mut self, s: &str) -> Self {
        self.0.extend_from_slice(&(s.len() as i32).to_le_bytes());
        self.0.extend_from_slice(s.as_bytes());
        self
    }
    pub fn raw(mut self, b: &[u8]) -> Self {
        self.0.extend_from_slice(b);
        self
    }
    pub fn done(self) -> Vec<u8> {
        self.0
    }
}

/// Inverse of CoppeliaSim's light script decoding, for building `Ste` chunks.
pub fn light_encode(text: &[u8]) -> Vec<u8> {
    let mut b = text.to_vec();
    let n = b.len();
    if n < 3 {
        return b;
    }
    let start = i32::from(b[0] as i8) / 2;
    let end = i32::from(b[n - 1] as i8) * 3;
    for (i, byte) in b.iter_mut().enumerate().take(n - 1).skip(1) {
        let i = i as i32;
        let mut v = i32::from(*byte as i8);
        // Undo the decoder's three steps in reverse order.
        if i & 4 != 0 {
            v -= i / 2 + end;
        }
        if i & 2 != 0 {
            v += 3 * i + start;
        }
        if i & 1 != 0 {
            v -= i + start + end;
        }
        *byte = v as u8;
    }
    b
}

/// Packs indices the way `In2` stores them: a count, then each delta from the previous
/// index in 1-4 bytes (top two bits of the first byte = extra bytes).
pub fn pack_indices(indices: &[i32]) -> Vec<u8> {
    let mut out = (indices.len() as i32).to_le_bytes().to_vec();
    let mut prev = 0i32;
    for &i in indices {
        let diff = i - prev;
        prev = i;
        let biases = [31i64, 8191, 2_097_151, 536_870_911];
        let extra = (0..4).find(|&k| {
            let v = i64::from(diff) + biases[k];
            v >= 0 && v < 1i64 << (6 + 8 * k)
        });
        let extra = extra.expect("delta fits in 30 bits");
        let v = (i64::from(diff) + biases[extra]) as u32;
        out.push((v & 0x3f) as u8 | (extra as u8) << 6);
        for k in 0..extra {
            out.push((v >> (6 + 8 * k)) as u8);
        }
    }
    out
}
