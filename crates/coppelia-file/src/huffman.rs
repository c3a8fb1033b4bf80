//! The body's static Huffman coding (Marcus Geelnard's scheme, as CoppeliaSim writes it).
//!
//! The tree comes first, one bit per node in pre-order: `1` is a leaf followed by its 8-bit
//! symbol, `0` an internal node followed by its 0-branch and then its 1-branch. The codes
//! follow with no padding, most significant bit of each byte first. The decoded length
//! comes from the file header; the coded stream carries no end marker.
//!
//! Decoding is table-driven: one state per internal node, and for each state and input
//! byte the symbols that byte completes and the state it ends in. A 10 MB body then costs
//! one table look-up per input byte instead of one tree step per bit.

use crate::error::ReadError;

/// Inputs shorter than this decode bit by bit: the 255 × 256-entry table is not worth
/// building for them.
const SMALL_INPUT: usize = 16 * 1024;

/// Most nodes a tree over 256 symbols can have (256 leaves, 255 internal nodes).
const MAX_TREE_NODES: usize = 511;

/// One node of the recovered tree.
#[derive(Debug, Clone, Copy)]
enum Node {
    Leaf(u8),
    /// Indices of the 0-branch and 1-branch children.
    Internal(u16, u16),
}

/// Reads bits most significant first from a byte slice.
struct Bits<'a> {
    bytes: &'a [u8],
    /// Next bit to read, counted from the start of `bytes`.
    pos: usize,
}

impl Bits<'_> {
    fn bit(&mut self) -> Option<bool> {
        let byte = *self.bytes.get(self.pos / 8)?;
        let bit = byte >> (7 - self.pos % 8) & 1 == 1;
        self.pos += 1;
        Some(bit)
    }

    fn byte(&mut self) -> Option<u8> {
        let mut v = 0u8;
        for _ in 0..8 {
            v = v << 1 | u8::from(self.bit()?);
        }
        Some(v)
    }
}

/// One table entry: the symbols an input byte completes from a state, and the state
/// after it (an internal node index, the root when the byte ends on a symbol boundary).
#[derive(Debug, Clone, Copy, Default)]
struct Step {
    symbols: [u8; 8],
    count: u8,
    next: u16,
}

/// Decodes `compressed` (the bytes after the header) into exactly `out_len` bytes.
///
/// `file_offset` is where `compressed` starts in the file, for error messages.
///
/// # Errors
/// [`ReadError::Huffman`] if the tree is malformed or truncated, or the coded data ends
/// before `out_len` symbols; [`ReadError::BodyLength`] if `out_len` is more symbols than
/// the coded bits could hold (every symbol takes at least one bit), which also bounds the
/// allocation by the input size.
pub fn decode(compressed: &[u8], out_len: usize, file_offset: usize) -> Result<Vec<u8>, ReadError> {
    let mut bits = Bits {
        bytes: compressed,
        pos: 0,
    };
    let huffman = |pos: usize, why| ReadError::Huffman {
        offset: file_offset + pos / 8,
        why,
    };
    if out_len == 0 {
        return Ok(Vec::new());
    }
    let nodes = read_tree(&mut bits).map_err(|why| huffman(bits.pos, why))?;
    let data_bits = compressed.len().saturating_mul(8) - bits.pos;
    if out_len > data_bits {
        return Err(ReadError::BodyLength {
            len: out_len as i64,
            why: "more symbols than coded bits",
        });
    }
    let mut out = Vec::with_capacity(out_len);
    let root = match nodes[0] {
        Node::Leaf(symbol) => {
            // A one-symbol tree codes each symbol with zero bits.
            out.resize(out_len, symbol);
            return Ok(out);
        }
        Node::Internal(..) => 0u16,
    };

    // Bit by bit up to the first byte boundary (or throughout for small inputs, where
    // building the table would cost more than it saves), then a byte per table step.
    let mut node = root;
    let small = compressed.len() < SMALL_INPUT;
    while (small || !bits.pos.is_multiple_of(8)) && out.len() < out_len {
        let bit = bits.bit().ok_or_else(|| huffman(bits.pos, "coded data ends early"))?;
        node = step(&nodes, node, bit, root, &mut out);
    }
    if out.len() == out_len {
        return Ok(out);
    }
    let (states, table) = build_table(&nodes, root);
    let mut state = states[usize::from(node)];
    let mut pos = bits.pos / 8;
    while out.len() < out_len {
        let byte = *compressed
            .get(pos)
            .ok_or_else(|| huffman(pos * 8, "coded data ends early"))?;
        let entry = &table[usize::from(state) * 256 + usize::from(byte)];
        let take = usize::from(entry.count).min(out_len - out.len());
        out.extend_from_slice(&entry.symbols[..take]);
        state = entry.next;
        pos += 1;
    }
    Ok(out)
}

/// Follows one bit from internal node `node`; on reaching a leaf pushes its symbol and
/// returns to `root`.
fn step(nodes: &[Node], node: u16, bit: bool, root: u16, out: &mut Vec<u8>) -> u16 {
    let Node::Internal(zero, one) = nodes[usize::from(node)] else {
        return root;
    };
    let child = if bit { one } else { zero };
    match nodes[usize::from(child)] {
        Node::Leaf(symbol) => {
            out.push(symbol);
            root
        }
        Node::Internal(..) => child,
    }
}

/// Recovers the tree; node 0 is the root.
fn read_tree(bits: &mut Bits) -> Result<Vec<Node>, &'static str> {
    let mut nodes: Vec<Node> = Vec::with_capacity(64);
    // Pre-order with an explicit stack of internal nodes still missing a child, so a
    // hostile tree cannot recurse deeply.
    let mut open: Vec<(usize, bool)> = Vec::new();
    loop {
        if nodes.len() == MAX_TREE_NODES {
            return Err("Huffman tree has more than 511 nodes");
        }
        let leaf = bits.bit().ok_or("Huffman tree truncated")?;
        let index = nodes.len();
        let node = if leaf {
            Node::Leaf(bits.byte().ok_or("Huffman tree truncated")?)
        } else {
            Node::Internal(0, 0)
        };
        nodes.push(node);
        // Attach to the parent waiting for a child.
        if let Some(&(parent, has_zero)) = open.last() {
            let child = index as u16;
            if let Node::Internal(zero, one) = &mut nodes[parent] {
                if has_zero {
                    *one = child;
                    open.pop();
                } else {
                    *zero = child;
                    if let Some(last) = open.last_mut() {
                        last.1 = true;
                    }
                }
            }
        }
        if !leaf {
            open.push((index, false));
        }
        if open.is_empty() {
            return Ok(nodes);
        }
    }
}

/// Numbers the internal nodes as states and builds the 256-entry step table of each.
/// Returns the node-to-state map (leaves map to 0) and the table.
fn build_table(nodes: &[Node], root: u16) -> (Vec<u16>, Vec<Step>) {
    let mut states = vec![0u16; nodes.len()];
    let mut internal = Vec::new();
    for (i, node) in nodes.iter().enumerate() {
        if matches!(node, Node::Internal(..)) {
            states[i] = internal.len() as u16;
            internal.push(i as u16);
        }
    }
    let mut table = vec![Step::default(); internal.len() * 256];
    let mut symbols = Vec::with_capacity(8);
    for (state, &start) in internal.iter().enumerate() {
        for byte in 0..=255u8 {
            symbols.clear();
            let mut node = start;
            for k in (0..8).rev() {
                node = step(nodes, node, byte >> k & 1 == 1, root, &mut symbols);
            }
            let entry = &mut table[state * 256 + usize::from(byte)];
            entry.symbols[..symbols.len()].copy_from_slice(&symbols);
            entry.count = symbols.len() as u8;
            entry.next = states[usize::from(node)];
        }
    }
    (states, table)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::huffman_encode;

    #[test]
    fn round_trips_text_and_binary() {
        let cases: [&[u8]; 5] = [
            b"abracadabra",
            &[0, 0, 0, 1, 2, 255, 255, 7],
            &(0..=255u8).cycle().take(3000).collect::<Vec<_>>(),
            // Large enough for the table-driven path.
            &(0..200_000u64).map(|i| (i * i % 251) as u8).collect::<Vec<_>>(),
            b"EOOEOOEOOxyz",
        ];
        for data in cases {
            let coded = huffman_encode(data);
            assert_eq!(decode(&coded, data.len(), 0).unwrap(), data);
        }
    }

    #[test]
    fn one_symbol_tree_repeats_the_symbol() {
        // A bare leaf: tree `1` + symbol, and zero bits per symbol. The 8x bound still
        // holds because the coded bytes carry padding bits.
        let coded = [0b1010_0000, 0b1000_0000];
        assert_eq!(decode(&coded, 3, 0).unwrap(), b"AAA");
    }

    #[test]
    fn corrupt_trees_and_short_data_are_errors() {
        // Tree cut off inside a symbol.
        assert!(matches!(decode(&[0b0100_0000], 1, 0), Err(ReadError::Huffman { .. })));
        // Only internal nodes: the tree never closes.
        assert!(matches!(decode(&[0u8; 200], 1, 0), Err(ReadError::Huffman { .. })));
        // Fine tree, but far fewer coded bits than the claimed length.
        let coded = huffman_encode(b"hello world");
        assert!(matches!(
            decode(&coded, 1_000_000, 0),
            Err(ReadError::BodyLength { .. })
        ));
        // Claimed length fits the bit budget but the data runs out mid-symbol.
        let coded = huffman_encode(&[1, 2, 3, 4, 5, 6, 7, 8, 9, 10]);
        let short = &coded[..coded.len() - 2];
        let budget = (short.len() * 8).min(60);
        assert!(decode(short, budget, 0).is_err());
    }
}
