//! Cameras (`CMA`): the viewpoints CoppeliaSim's views look through.
//!
//! Only the projection is read: `Cp3`/`_p3` (ortho size, view angle) and `Ccp`/`_cp`
//! (near, far clipping). Tracking, manipulation permissions, render modes and colours
//! are not. Lengths are metres, angles radians.

use crate::chunk::{At, Chunk};
use crate::error::ReadError;
use crate::field::{Fields, is_double};

/// A camera's own part. Fields not found in the file stay 0.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Camera {
    /// Perspective view angle, rad (of the larger side of the view).
    pub view_angle: f64,
    /// Extent of the view along its larger side in an orthographic view, m.
    pub ortho_size: f64,
    /// Near clipping distance, m.
    pub near: f64,
    /// Far clipping distance, m.
    pub far: f64,
}

/// Reads a camera's type-specific chunks.
pub fn read(chunks: &[Chunk], at: &At) -> Result<Camera, ReadError> {
    let mut cam = Camera::default();
    for c in chunks {
        let mut f = Fields::new(c, at);
        match &c.tag {
            b"Cp3" | b"_p3" => [cam.ortho_size, cam.view_angle] = f.reals(is_double(c.tag))?,
            b"Ccp" | b"_cp" => [cam.near, cam.far] = f.reals(is_double(c.tag))?,
            _ => {}
        }
    }
    Ok(cam)
}
