//! Old path objects (`PAT`, V-REP 3 to CoppeliaSim 4.2; 4.3+ paths are dummies with
//! custom data): a curve through control points, read by `sim.getPositionOnPath` and
//! friends.
//!
//! The type-specific part holds `Ntp`, the path proper, a nested stream of:
//! * `Pat`, one per control point, itself nested: `At2` (f32) or `_t2` (f64) with the
//!   pose (x, y, z then the quaternion w, x, y, z, in the path's frame), the Bézier
//!   factors before and after the point, an i32 Bézier point count (1 = a sharp
//!   corner) and the maximum relative velocity; `At3`/`_t3` the on-spot distance;
//!   `At4`/`_t4` auxiliary flags and channels (not read).
//! * `At2` (4 bytes: an i32, not a point) the path attributes (`sim.pathproperty_*`:
//!   1 show line, 2 show orientation, 4 closed, 8 automatic orientation, 32 infinite
//!   acceleration, 64 flat, 128 show position, 1024 end points at zero, 2048 keep x up).
//! * `Si2`, `Cl0`, `Jm2`, `Av2`/`Av3`/`Av9`: display and velocity-profile settings (not
//!   read).
//!
//! The tube shaping beside `Ntp` (`Sha`, `Sec`, `Scl`) is display only.
//!
//! Established on `cartesian_path` of PyRep's `test_scene.ttt` (4.1): three control
//! points on a 0.051 m arc in the xy plane (0°, 22.5°, 45°), each with a 180° turn whose
//! x axis points back along the arc, factors 0.95, 15 Bézier points, attributes 1187
//! (lines, orientation and position shown, infinite acceleration, end points at zero).
//! The order of the point values was checked against that geometry; the meaning of the
//! attribute bits is CoppeliaSim's documented `sim.pathproperty_*` constants.

use crate::chunk::{At, Chunk, Chunks};
use crate::error::ReadError;
use crate::field::{Fields, is_double};

/// Most control points in one path.
pub const MAX_POINTS: usize = 1 << 20;

/// `sim.pathproperty_closed_path`.
pub const CLOSED: i32 = 4;
/// `sim.pathproperty_automatic_orientation`.
pub const AUTOMATIC_ORIENTATION: i32 = 8;

/// One control point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathPoint {
    /// Position in the path's frame, m.
    pub position: [f64; 3],
    /// Orientation in the path's frame, quaternion `[w, x, y, z]` (as stored).
    pub rotation: [f64; 4],
    /// Bézier interpolation factors before and after the point (0..1).
    pub bezier_factors: [f64; 2],
    /// Bézier points that round the corner at this point (1: a sharp corner).
    pub bezier_points: i32,
    /// Maximum relative velocity at the point.
    pub max_relative_velocity: f64,
    /// On-spot distance (`At3`/`_t3`).
    pub on_spot_distance: f64,
}

/// An old path object's own part.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct OldPath {
    /// The control points, in order.
    pub points: Vec<PathPoint>,
    /// `sim.pathproperty_*` bits.
    pub attributes: i32,
}

impl OldPath {
    /// The last control point links back to the first.
    pub fn closed(&self) -> bool {
        self.attributes & CLOSED != 0
    }
}

/// Reads a path object's type-specific chunks.
pub fn read(chunks: &[Chunk], at: &At) -> Result<OldPath, ReadError> {
    let mut path = OldPath::default();
    for c in chunks.iter().filter(|c| &c.tag == b"Ntp") {
        let here = at.child(c.tag, c.offset);
        here.check_depth()?;
        let (inner, _) = Chunks::new(c.payload, &here).part(false)?;
        for c in &inner {
            match &c.tag {
                b"Pat" => {
                    if path.points.len() == MAX_POINTS {
                        return Err(ReadError::TooMany {
                            what: "path control points",
                            max: MAX_POINTS,
                        });
                    }
                    path.points.push(read_point(c, &here)?);
                }
                // The container's At2 is the attributes; a point's At2 sits inside Pat.
                b"At2" if c.payload.len() == 4 => path.attributes = Fields::new(c, &here).i32()?,
                _ => {}
            }
        }
    }
    Ok(path)
}

/// One `Pat` control point.
fn read_point(c: &Chunk, at: &At) -> Result<PathPoint, ReadError> {
    let here = at.child(c.tag, c.offset);
    here.check_depth()?;
    let (chunks, _) = Chunks::new(c.payload, &here).part(false)?;
    let mut p = PathPoint {
        position: [0.0; 3],
        rotation: [1.0, 0.0, 0.0, 0.0],
        bezier_factors: [0.5; 2],
        bezier_points: 1,
        max_relative_velocity: 1.0,
        on_spot_distance: 0.0,
    };
    for c in &chunks {
        let mut f = Fields::new(c, &here);
        let double = is_double(c.tag);
        match &c.tag {
            b"At2" | b"_t2" => {
                let v: [f64; 9] = f.reals(double)?;
                p.position = [v[0], v[1], v[2]];
                p.rotation = [v[3], v[4], v[5], v[6]];
                p.bezier_factors = [v[7], v[8]];
                p.bezier_points = f.i32()?;
                [p.max_relative_velocity] = f.reals(double)?;
            }
            b"At3" | b"_t3" => [p.on_spot_distance] = f.reals(double)?,
            _ => {}
        }
    }
    Ok(p)
}
