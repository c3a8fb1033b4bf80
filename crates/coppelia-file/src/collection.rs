//! Collections (`GRP`, top level): named sets of objects built from items, which scripts
//! find with `sim.getCollectionHandle` (PyRep's arms check collisions with `<Name>_arm`).
//!
//! A `GRP` stream holds `Grn` (name), `Gix` (i32 handle), `Par`, `Uis` and one nested
//! `Asg` stream per item: `Obj` (i32 object handle, then an i32 the reader ignores),
//! `Gty` (u8 item kind) and `Var` (u8, bit 0: the item adds objects, else it removes
//! them). Item kinds 0 (one object) and 1 (the tree from an object, itself included) are
//! verified on the public files (a mobile base's collection lists its objects with 0, an
//! arm's names its base with 1); 2 to 5 follow the order of CoppeliaSim's collection
//! element kinds (tree without its base, chain to the root with and without its tip,
//! everything), which is inferred, not seen.

use crate::chunk::{At, Chunk, Chunks, show};
use crate::error::ReadError;
use crate::field::Fields;

/// Most items in one collection.
pub const MAX_ITEMS: usize = 1 << 20;

/// One collection.
#[derive(Debug, Clone, PartialEq)]
pub struct Collection {
    /// Its handle in the file (`Gix`).
    pub handle: i32,
    /// Its name (`Grn`), e.g. `Panda_arm`.
    pub name: String,
    /// The items, applied in order.
    pub items: Vec<CollectionItem>,
}

/// One item of a collection.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CollectionItem {
    /// The object the item starts from (unused for [`CollectionItemKind::Everything`]).
    pub object: i32,
    /// What the item covers.
    pub kind: CollectionItemKind,
    /// Whether the item adds its objects (else it removes them).
    pub additive: bool,
}

/// What a collection item covers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CollectionItemKind {
    /// The object alone (0).
    Object,
    /// The object and everything below it (1), or only what is below it (2).
    Tree {
        /// Whether the object itself belongs.
        include_base: bool,
    },
    /// The object and its ancestors up to the root (3), or only the ancestors (4).
    Chain {
        /// Whether the object itself belongs.
        include_tip: bool,
    },
    /// Every object of the scene (5).
    Everything,
    /// A kind the reader does not know, as stored.
    Unknown(u8),
}

impl CollectionItemKind {
    fn from_code(code: u8) -> Self {
        match code {
            0 => Self::Object,
            1 => Self::Tree { include_base: true },
            2 => Self::Tree { include_base: false },
            3 => Self::Chain { include_tip: true },
            4 => Self::Chain { include_tip: false },
            5 => Self::Everything,
            other => Self::Unknown(other),
        }
    }
}

/// Reads a `GRP` chunk.
pub fn read(c: &Chunk, top: &At) -> Result<Collection, ReadError> {
    let at = top.child(c.tag, c.offset);
    let (chunks, _) = Chunks::new(c.payload, &at).part(false)?;
    let mut out = Collection {
        handle: -1,
        name: String::new(),
        items: Vec::new(),
    };
    for c in &chunks {
        let mut f = Fields::new(c, &at);
        match &c.tag {
            b"Grn" => out.name = f.string()?,
            b"Gix" => out.handle = f.i32()?,
            b"Asg" => {
                if out.items.len() == MAX_ITEMS {
                    return Err(ReadError::TooMany {
                        what: "collection items",
                        max: MAX_ITEMS,
                    });
                }
                out.items.push(read_item(c, &at)?);
            }
            _ => {}
        }
    }
    Ok(out)
}

/// Reads one `Asg` item stream.
fn read_item(c: &Chunk, parent: &At) -> Result<CollectionItem, ReadError> {
    let at = parent.child(c.tag, c.offset);
    at.check_depth()?;
    let (chunks, _) = Chunks::new(c.payload, &at).part(false)?;
    let mut item = CollectionItem {
        object: -1,
        kind: CollectionItemKind::Object,
        additive: true,
    };
    let mut has_object = false;
    for c in &chunks {
        let mut f = Fields::new(c, &at);
        match &c.tag {
            b"Obj" => {
                item.object = f.i32()?;
                has_object = true;
            }
            b"Gty" => item.kind = CollectionItemKind::from_code(f.u8()?),
            b"Var" => item.additive = f.u8()? & 0x01 != 0,
            _ => {}
        }
    }
    if !has_object && item.kind != CollectionItemKind::Everything {
        return Err(at.value_error(format!("{} item names no object (no Obj chunk)", show(c.tag))));
    }
    Ok(item)
}
