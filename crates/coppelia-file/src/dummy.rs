//! Dummies: reference frames, optionally linked in pairs (IK tip/target, loop closures).

use crate::chunk::{At, Chunk};
use crate::error::ReadError;
use crate::field::Fields;

/// What a dummy's link to its partner means (`Dl2`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DummyLink {
    /// Dynamic loop closure: the physics engine holds the two dummies together.
    DynamicLoopClosure,
    /// Inverse-kinematics tip and target.
    IkTipTarget,
    /// Another link type (kept as stored).
    Other(i32),
}

/// A dummy object's own part.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Dummy {
    /// Handle of the linked dummy, if any.
    pub linked: Option<i32>,
    /// The meaning of the link.
    pub link: DummyLink,
}

/// Reads a dummy's type-specific chunks.
pub fn read(chunks: &[Chunk], at: &At) -> Result<Dummy, ReadError> {
    let mut d = Dummy {
        linked: None,
        link: DummyLink::Other(-1),
    };
    for c in chunks {
        let mut f = Fields::new(c, at);
        match &c.tag {
            b"Lli" => d.linked = Some(f.i32()?).filter(|&h| h >= 0),
            b"Dl2" => {
                d.link = match f.i32()? {
                    0 => DummyLink::DynamicLoopClosure,
                    5 => DummyLink::IkTipTarget,
                    other => DummyLink::Other(other),
                }
            }
            _ => {}
        }
    }
    Ok(d)
}
