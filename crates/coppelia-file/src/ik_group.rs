//! IK groups (`IKO`, top level): CoppeliaSim 4.0-4.2's built-in kinematics, which
//! PyRep's arms look up as `<Name>_ik`. Read here; `gantry-scene`'s coppelia loader maps
//! them onto the scene's IK groups.
//!
//! An `IKO` stream holds `Oid` (i32 handle), `Nme` (name), `Mit` (i32 maximum
//! iterations), `Cmt` (i32 method: 0 pseudo-inverse, 1 damped least squares), `Dpg` (f32
//! damping), `Var`/`Va2` (u8 flags, meanings open) and one nested `Ike` stream per
//! element: `Ik2` (i32 tip handle, i32 base handle, -1 for the world), `Abc` (i32
//! alternative base for the constraints), `Ctr` (i32 constraint bits: x 1, y 2, z 4,
//! alpha-beta 8, gamma 16) and `Var` (bit 0 active). The target is the tip dummy's linked
//! dummy. Meanings inferred from PyRep's Panda.

use crate::chunk::{At, Chunk, Chunks};
use crate::error::ReadError;
use crate::field::Fields;

/// Most elements in one IK group.
pub const MAX_ELEMENTS: usize = 1 << 12;

/// One IK group.
#[derive(Debug, Clone, PartialEq)]
pub struct IkGroup {
    /// Its handle in the file (`Oid`).
    pub handle: i32,
    /// Its name (`Nme`), e.g. `Panda_ik`.
    pub name: String,
    /// Maximum solver iterations (`Mit`).
    pub max_iterations: i32,
    /// Method (`Cmt`): 0 pseudo-inverse, 1 damped least squares.
    pub method: i32,
    /// Damping of damped least squares (`Dpg`).
    pub damping: f64,
    /// The `Var` flags as stored (meanings not settled).
    pub flags: u8,
    /// The elements, in order.
    pub elements: Vec<IkElement>,
}

/// One element of an IK group.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IkElement {
    /// The tip dummy's handle.
    pub tip: i32,
    /// The chain's base handle, -1 for the world.
    pub base: i32,
    /// Constraint bits (x 1, y 2, z 4, alpha-beta 8, gamma 16).
    pub constraints: i32,
    /// Whether the element is active (`Var` bit 0).
    pub active: bool,
}

/// Reads an `IKO` chunk.
pub fn read(c: &Chunk, top: &At) -> Result<IkGroup, ReadError> {
    let at = top.child(c.tag, c.offset);
    let (chunks, _) = Chunks::new(c.payload, &at).part(false)?;
    let mut g = IkGroup {
        handle: -1,
        name: String::new(),
        max_iterations: 3,
        method: 0,
        damping: 0.1,
        flags: 0,
        elements: Vec::new(),
    };
    for c in &chunks {
        let mut f = Fields::new(c, &at);
        match &c.tag {
            b"Oid" => g.handle = f.i32()?,
            b"Nme" => g.name = f.string()?,
            b"Mit" => g.max_iterations = f.i32()?,
            b"Cmt" => g.method = f.i32()?,
            b"Dpg" => g.damping = f.f32()?,
            b"Var" => g.flags = f.u8()?,
            b"Ike" => {
                if g.elements.len() == MAX_ELEMENTS {
                    return Err(ReadError::TooMany {
                        what: "IK elements",
                        max: MAX_ELEMENTS,
                    });
                }
                g.elements.push(read_element(c, &at)?);
            }
            _ => {}
        }
    }
    Ok(g)
}

/// Reads one `Ike` element stream.
fn read_element(c: &Chunk, parent: &At) -> Result<IkElement, ReadError> {
    let at = parent.child(c.tag, c.offset);
    at.check_depth()?;
    let (chunks, _) = Chunks::new(c.payload, &at).part(false)?;
    let mut e = IkElement {
        tip: -1,
        base: -1,
        constraints: 0x1f,
        active: true,
    };
    let mut has_tip = false;
    for c in &chunks {
        let mut f = Fields::new(c, &at);
        match &c.tag {
            b"Ik2" => {
                e.tip = f.i32()?;
                e.base = f.i32()?;
                has_tip = true;
            }
            b"Ctr" => e.constraints = f.i32()?,
            b"Var" => e.active = f.u8()? & 0x01 != 0,
            _ => {}
        }
    }
    if !has_tip {
        return Err(at.value_error("IK element names no tip (no Ik2 chunk)"));
    }
    Ok(e)
}
