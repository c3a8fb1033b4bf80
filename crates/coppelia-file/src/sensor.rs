//! Proximity, vision and force sensors.
//!
//! A proximity sensor's volume (`Vod`) stores every size field whatever its type; the
//! fields a type does not use hold leftover memory, so only the ones that apply are
//! returned. Lengths are metres, angles radians.

use crate::chunk::{At, Chunk, Chunks};
use crate::error::ReadError;
use crate::field::{Fields, is_double};

/// The detection volume of a proximity sensor, with the parameters that apply to it.
/// `offset` is where detection starts along the sensor's z axis, `range` how far it
/// reaches beyond that.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ProximityVolume {
    /// A ray along z.
    Ray {
        /// Start along z, m.
        offset: f64,
        /// Length, m.
        range: f64,
    },
    /// A truncated pyramid along z.
    Pyramid {
        /// Start along z, m.
        offset: f64,
        /// Depth, m.
        range: f64,
        /// Near face size x, y, m.
        near_size: [f64; 2],
        /// Far face size x, y, m.
        far_size: [f64; 2],
    },
    /// A truncated cone with flat ends along z.
    Cylinder {
        /// Start along z, m.
        offset: f64,
        /// Depth, m.
        range: f64,
        /// Near radius, m.
        radius: f64,
        /// Far radius, m.
        radius_far: f64,
    },
    /// A disc sector in the xz plane, `thickness` along y.
    Disc {
        /// Start along z, m.
        offset: f64,
        /// Radial depth, m.
        range: f64,
        /// Inner radius, m.
        radius: f64,
        /// Opening angle, rad.
        angle: f64,
        /// Thickness along y, m.
        thickness: f64,
    },
    /// A spherical cone sector around z.
    Cone {
        /// Start along z, m.
        offset: f64,
        /// Radial depth, m.
        range: f64,
        /// Inner radius, m.
        radius: f64,
        /// Opening angle, rad.
        angle: f64,
    },
    /// A volume type this reader does not know.
    Other(i32),
}

/// A proximity sensor's own part.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProximitySensor {
    /// CoppeliaSim's sensor type code (`Snt`), kept as stored; the volume says more.
    pub sensor_type: i32,
    /// The detection volume.
    pub volume: ProximityVolume,
}

/// A vision sensor's own part.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VisionSensor {
    /// Image width and height, pixels.
    pub resolution: [i32; 2],
    /// Perspective projection; orthographic otherwise.
    pub perspective: bool,
    /// Full view angle of a perspective sensor, rad.
    pub view_angle: f64,
    /// Width of an orthographic sensor's view, m.
    pub ortho_size: f64,
    /// Near clipping distance, m.
    pub near: f64,
    /// Far clipping distance, m.
    pub far: f64,
}

/// A force sensor's own part.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForceSensor {
    /// Force at which the sensor breaks, N (when breaking is enabled in CoppeliaSim).
    pub force_threshold: f64,
    /// Torque at which the sensor breaks, N·m.
    pub torque_threshold: f64,
    /// Consecutive over-threshold steps before it breaks.
    pub consecutive_violations: i32,
    /// Samples averaged by the filter.
    pub filter_samples: i32,
    /// Filter type code (0 average, 1 median).
    pub filter_type: i32,
}

/// Reads a proximity sensor's type-specific chunks.
pub fn read_proximity(chunks: &[Chunk], at: &At) -> Result<ProximitySensor, ReadError> {
    let mut s = ProximitySensor {
        sensor_type: 0,
        volume: ProximityVolume::Other(-1),
    };
    for c in chunks {
        match &c.tag {
            b"Snt" => s.sensor_type = Fields::new(c, at).i32()?,
            b"Vod" => s.volume = read_volume(c, at)?,
            _ => {}
        }
    }
    Ok(s)
}

/// The convex volume stream: `Snt` (0 pyramid, 1 cylinder, 2 disc, 3 cone, 4 ray) and
/// `Ss3`/`_s3` (offset, range, x, y, x far, y far, radius, radius far, angle).
fn read_volume(c: &Chunk, at: &At) -> Result<ProximityVolume, ReadError> {
    let here = at.child(c.tag, c.offset);
    let (chunks, _) = Chunks::new(c.payload, &here).part(false)?;
    let mut kind = -1;
    let mut v = None;
    for c in &chunks {
        let mut f = Fields::new(c, &here);
        match &c.tag {
            b"Snt" => kind = f.i32()?,
            b"Ss3" | b"_s3" => v = Some(f.reals::<9>(is_double(c.tag))?),
            _ => {}
        }
    }
    let Some([offset, range, x, y, x_far, y_far, radius, radius_far, angle]) = v else {
        return Ok(ProximityVolume::Other(kind));
    };
    Ok(match kind {
        0 => ProximityVolume::Pyramid {
            offset,
            range,
            near_size: [x, y],
            far_size: [x_far, y_far],
        },
        1 => ProximityVolume::Cylinder {
            offset,
            range,
            radius,
            radius_far,
        },
        2 => ProximityVolume::Disc {
            offset,
            range,
            radius,
            angle,
            thickness: y,
        },
        3 => ProximityVolume::Cone {
            offset,
            range,
            radius,
            angle,
        },
        4 => ProximityVolume::Ray { offset, range },
        other => ProximityVolume::Other(other),
    })
}

/// Reads a vision sensor's type-specific chunks.
pub fn read_vision(chunks: &[Chunk], at: &At) -> Result<VisionSensor, ReadError> {
    let mut s = VisionSensor {
        resolution: [0, 0],
        perspective: false,
        view_angle: 0.0,
        ortho_size: 0.0,
        near: 0.0,
        far: 0.0,
    };
    for c in chunks {
        let mut f = Fields::new(c, at);
        match &c.tag {
            b"Res" => s.resolution = [f.i32()?, f.i32()?],
            b"Ccp" | b"_cp" => [s.ortho_size, s.view_angle, s.near, s.far] = f.reals(is_double(c.tag))?,
            // `Var` in old files, `Va3` since; the later one wins.
            b"Var" | b"Va3" => s.perspective = f.u8()? & 0x01 != 0,
            _ => {}
        }
    }
    Ok(s)
}

/// Reads a force sensor's type-specific chunks.
pub fn read_force(chunks: &[Chunk], at: &At) -> Result<ForceSensor, ReadError> {
    let mut s = ForceSensor {
        force_threshold: 0.0,
        torque_threshold: 0.0,
        consecutive_violations: 0,
        filter_samples: 1,
        filter_type: 0,
    };
    for c in chunks {
        let mut f = Fields::new(c, at);
        match &c.tag {
            b"Tre" | b"_ri" => {
                [s.force_threshold, s.torque_threshold] = f.reals(is_double(c.tag))?;
                s.consecutive_violations = f.i32()?;
            }
            b"Fil" => {
                s.filter_samples = f.i32()?;
                s.filter_type = f.i32()?;
            }
            _ => {}
        }
    }
    Ok(s)
}
