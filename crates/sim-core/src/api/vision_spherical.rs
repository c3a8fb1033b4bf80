//! `simVision.handleSpherical`: a 360-degree camera made of six 90-degree vision
//! sensors looking out of the faces of a cube (CoppeliaSim's spherical vision sensor
//! model, PyRep's `SphericalVisionSensor`).
//!
//! The six sensors render, then each pixel of the panorama takes the face pixel its
//! ray passes through (nearest pixel). The panorama is equirectangular: its centre
//! column looks where the front sensor looks, its top row towards the top sensor's
//! view, longitude grows to the right (`right = front × top`), over the given
//! horizontal and vertical sweeps. Depth goes into the second passive sensor's image as
//! grey, the distance along the ray normalised between the faces' clipping planes (as
//! CoppeliaSim's plugin writes it; PyRep reads its red channel).

use super::{Args, CallContext, Ret};
use crate::Value;
use crate::error::SimError;
use crate::math::Vec3;
use crate::sim::Sim;
use crate::vision;
use crate::world::Handle;

/// One rendered face: its axes in the world, its view and its images.
struct Face {
    x: Vec3,
    y: Vec3,
    z: Vec3,
    /// tan of half the view angle.
    tan_half: f64,
    near: f64,
    far: f64,
    side: usize,
    rgb: Vec<u8>,
    depth: Vec<f32>,
}

impl Face {
    /// The face pixel (bottom row first) and the ray's share of the face's depth for a
    /// unit direction `d` that this face sees (`d · z > 0`).
    fn pixel(&self, d: &Vec3) -> (usize, f64) {
        let c = d.dot(&self.z);
        // Image right is the sensor's -x, image up its +y.
        let u = -d.dot(&self.x) / (c * self.tan_half);
        let v = d.dot(&self.y) / (c * self.tan_half);
        let to_index = |t: f64| (((t + 1.0) * 0.5 * self.side as f64) as usize).min(self.side - 1);
        (to_index(v) * self.side + to_index(u), c)
    }
}

/// `simVision.handleSpherical(passiveRgb, {front, top, back, bottom, left, right},
/// horizontalAngle, verticalAngle, passiveDepth=-1)` → true. The six sensors render
/// now (they become explicitly handled), with one square resolution and one view angle;
/// the passive sensors' resolutions set the panorama's. Angles in radians: the
/// horizontal sweep 0 < a ≤ 2π, the vertical 0 < a ≤ π.
pub(super) fn handle_spherical(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let rgb_out = a.handle(0)?;
    let faces = a.numbers(1)?;
    let horizontal = a.finite(2)?;
    let vertical = a.finite(3)?;
    let depth_out = a.opt_int(4, -1)?;
    if faces.len() != 6 {
        return Err(SimError::bad_argument(format!(
            "argument 2: six vision sensors (front, top, back, bottom, left, right), got {}",
            faces.len()
        )));
    }
    if !(horizontal > 0.0 && horizontal <= std::f64::consts::TAU) {
        return Err(SimError::bad_argument(format!(
            "argument 3: the horizontal sweep is 0 < angle <= 2 pi radians, got {horizontal}"
        )));
    }
    if !(vertical > 0.0 && vertical <= std::f64::consts::PI) {
        return Err(SimError::bad_argument(format!(
            "argument 4: the vertical sweep is 0 < angle <= pi radians, got {vertical}"
        )));
    }
    let handles: Vec<Handle> = faces.iter().map(|&h| h as Handle).collect();
    let mut rendered = Vec::with_capacity(6);
    for &h in &handles {
        vision::handle_vision_sensor(&sim.world, &mut sim.vision, h)?;
        let (model, pose) = vision::sensor_model(&sim.world, h)?;
        let (model, rot) = (*model, pose.rotation);
        if model.resolution[0] != model.resolution[1] {
            return Err(SimError::bad_argument(format!(
                "argument 2: vision sensor {h} is {}x{}: the six sensors are square",
                model.resolution[0], model.resolution[1]
            )));
        }
        let image = vision::read(&sim.world, &mut sim.vision, h)?;
        rendered.push(Face {
            x: rot * Vec3::x(),
            y: rot * Vec3::y(),
            z: rot * Vec3::z(),
            tan_half: (model.fov * 0.5).tan(),
            near: model.near,
            far: model.far,
            side: model.resolution[0] as usize,
            rgb: image.rgb().to_vec(),
            depth: image.depth().to_vec(),
        });
    }
    if rendered.iter().any(|f| f.side != rendered[0].side) {
        return Err(SimError::bad_argument(
            "argument 2: the six vision sensors have one resolution",
        ));
    }
    let forward = rendered[0].z;
    let up = rendered[1].z;
    let right = forward.cross(&up);

    let (&out_model, _) = vision::sensor_model(&sim.world, rgb_out)?;
    let [width, height] = out_model.resolution.map(|v| v as usize);
    let mut colour = vec![0u8; width * height * 3];
    let mut grey = vec![0u8; width * height * 3];
    for row in 0..height {
        // Row 0 is the bottom of the image.
        let lat = ((row as f64 + 0.5) / height as f64 - 0.5) * vertical;
        for col in 0..width {
            let lon = ((col as f64 + 0.5) / width as f64 - 0.5) * horizontal;
            let d = right * (lat.cos() * lon.sin()) + up * lat.sin() + forward * (lat.cos() * lon.cos());
            let face = rendered
                .iter()
                .max_by(|p, q| d.dot(&p.z).total_cmp(&d.dot(&q.z)))
                .expect("six faces");
            let (at, along) = face.pixel(&d);
            let out = 3 * (row * width + col);
            colour[out..out + 3].copy_from_slice(&face.rgb[3 * at..3 * at + 3]);
            let planar = face.near + f64::from(face.depth[at]) * (face.far - face.near);
            let radial = ((planar / along - face.near) / (face.far - face.near)).clamp(0.0, 1.0);
            grey[out..out + 3].fill((radial * 255.0).round() as u8);
        }
    }
    write_rgb(sim, rgb_out, &colour)?;
    if depth_out >= 0 {
        let (&depth_model, _) = vision::sensor_model(&sim.world, depth_out as Handle)?;
        if depth_model.resolution != out_model.resolution {
            return Err(SimError::bad_argument(format!(
                "argument 5: the depth sensor's resolution {:?} is not the RGB sensor's {:?}",
                depth_model.resolution, out_model.resolution
            )));
        }
        write_rgb(sim, depth_out as Handle, &grey)?;
    }
    Ok(vec![Value::Bool(true)])
}

/// Writes a whole RGB image (bottom row first) into passive sensor `h`.
fn write_rgb(sim: &mut Sim, h: Handle, rgb: &[u8]) -> Result<(), SimError> {
    let image = vision::write(&sim.world, &mut sim.vision, h)?;
    image.rgb_mut().copy_from_slice(rgb);
    Ok(())
}
