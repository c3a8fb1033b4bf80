//! Laser scans from a depth sensor's work image: `simVision.coordinatesFromWorkImg` and
//! `simVision.velodyneDataFromWorkImg`, what CoppeliaSim's scanner models (Hokuyo, SICK,
//! Velodyne) call after `simVision.sensorDepthMapToWorkImg`.
//!
//! # Points
//! Both functions sample the depth map at a grid of directions and return the points
//! seen there, in the sensor's frame (+Z the viewing axis, +Y image up, +X image left)
//! or, on request, the world frame. The result is CoppeliaSim's packet of `f32`s: the
//! two point counts, then `x, y, z, distance` per point, the first count varying
//! fastest for `coordinatesFromWorkImg` and the second for `velodyneDataFromWorkImg`.
//! Directions run from image right to image left (local X rising) and from the bottom up.
//!
//! A direction that sees nothing (or something beyond the far plane) gives the point
//! where the ray leaves the view, at the far clipping distance, with distance = far:
//! scripts tell returns from misses by comparing the distance with `far` (CoppeliaSim's
//! models use `far * 0.9999`).
//!
//! # Where gantry differs from the simVision plugin, and why
//! - The sample directions span the outermost **pixel centres**, not the image edges, so
//!   that a scan of as many points as pixels (a Hokuyo's 342 on a 342 x 1 sensor) reads
//!   each pixel exactly along its own ray. The plugin spans the edges and takes the
//!   depth of a nearby pixel, which puts points on oblique surfaces off the surface by
//!   up to half a pixel's footprint.
//! - Between pixel centres, the inverse depth is interpolated from the four pixels
//!   around the direction. A plane's inverse depth is affine across the image, so a
//!   point on a plane lands on it exactly; where the four depths differ by more than
//!   [`EDGE_RATIO`] (an object's silhouette), the nearest pixel's depth is taken instead
//!   of inventing a point between foreground and background. Either way a direction
//!   within a pixel of a silhouette or of a corner (two faces of a box, a pillar's foot
//!   on the floor) may give a point up to a pixel's footprint off the surface: about
//!   1 % of a 3-D scan of the bundled scanners scene (crates/sim-core/tests/scanner.rs).
//! - Colours (`returnRgb`) come from buffer 1 (`simVision.workImgToBuffer1` of the
//!   colour image, as CoppeliaSim's models do it) at the pixel nearest each direction,
//!   as bytes `v * 255.1` (the plugin's rounding). Without a buffer 1 of the sensor's
//!   size none are returned, as the plugin returns none when that buffer is empty.
//! - The depth of the work image must be a depth map: grey levels in 0..1, as
//!   `sensorDepthMapToWorkImg` makes it. A colour image or an edge mask is refused
//!   rather than read as depth.

use super::{VisionStates, Work, sensor_model};
use crate::error::SimError;
use crate::math::{Pose, Vec3};
use crate::scene::{Projection, VisionModel};
use crate::world::{Handle, World};

/// Most points in one packet (a 2048 x 2048 sensor's pixels): bounds what one call may
/// allocate.
pub const MAX_POINTS: usize = 2048 * 2048;

/// Largest ratio between the depths of the four pixels around a direction that are
/// still read as one surface and interpolated. Adjacent pixels on a plane seen at 80°
/// from its normal differ by 3.5 % in a 342-pixel, 120° scan; silhouettes differ by far
/// more.
pub const EDGE_RATIO: f64 = 1.05;

/// What a scan returns: CoppeliaSim's packet of points and, when colours were asked for
/// and buffer 1 holds an image, three bytes (R, G, B) per point in the packet's order.
#[derive(Debug, Clone, PartialEq)]
pub struct Scan {
    /// The counts, then `x, y, z, distance` per point.
    pub packet: Vec<f32>,
    /// `3 * points` bytes, or `None`.
    pub colours: Option<Vec<u8>>,
}

/// The frame the points of a packet are expressed in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointFrame {
    /// The vision sensor's own frame.
    Sensor,
    /// The world frame (`sim.handleflag_abscoords` on the handle).
    World,
}

/// `simVision.coordinatesFromWorkImg`: `counts[0] x counts[1]` points from sensor `h`'s
/// depth work image. With `angular`, the directions are evenly spaced in angle about
/// the sensor's Y and X axes; otherwise evenly spaced across the image (in metres
/// across the view for an orthographic sensor, whose points then lie on parallel rays
/// and whose distance is the depth). A count of 1 samples the middle of the view.
///
/// # Errors
/// As [`velodyne_from_work`], apart from the projection: both projections are read.
pub fn coordinates_from_work(
    world: &World,
    states: &VisionStates,
    h: Handle,
    counts: [usize; 2],
    angular: bool,
    frame: PointFrame,
    rgb: bool,
) -> Result<Scan, SimError> {
    let depth = DepthMap::new(world, states, h, counts, rgb)?;
    let [nx, ny] = counts;
    // Image-plane coordinates of each column and row of samples, worked out once: the
    // tangents cost more than reading a pixel.
    let along = |n: usize, extent: f64| -> Vec<f64> {
        (0..n)
            .map(|k| {
                if angular {
                    spread(k, n, extent.atan()).tan()
                } else {
                    spread(k, n, extent)
                }
            })
            .collect()
    };
    let (us, vs) = (along(nx, depth.extent_x), along(ny, depth.extent_y));
    let mut out = depth.scan(counts);
    for &v in &vs {
        for &u in &us {
            depth.push_point(u, v, frame, &mut out)?;
        }
    }
    Ok(out)
}

/// `simVision.velodyneDataFromWorkImg`: `counts[0]` azimuths evenly spaced in angle
/// across the view, and at each `counts[1]` beams evenly spaced in elevation over
/// `vertical_angle` (rad, centred on the sensor's XZ plane), as the lasers of a spinning
/// lidar stacked in a column. The elevation is the beam's true angle above the XZ
/// plane, so a beam keeps its elevation whatever the azimuth.
///
/// # Errors
/// [`SimError::BadArgument`] when the counts are 0 or give more than [`MAX_POINTS`],
/// `vertical_angle` is not in 0..π or reaches beyond the image at the view's sides,
/// the sensor is orthographic, it has no work image, or the work image is not a depth
/// map (see the module docs); no such object or not a vision sensor otherwise.
pub fn velodyne_from_work(
    world: &World,
    states: &VisionStates,
    h: Handle,
    counts: [usize; 2],
    vertical_angle: f64,
    frame: PointFrame,
    rgb: bool,
) -> Result<Scan, SimError> {
    let depth = DepthMap::new(world, states, h, counts, rgb)?;
    if depth.model.projection == Projection::Orthographic {
        return Err(SimError::bad_argument(format!(
            "vision sensor {h} is orthographic: velodyneDataFromWorkImg needs a perspective sensor"
        )));
    }
    if !(vertical_angle.is_finite() && (0.0..std::f64::consts::PI).contains(&vertical_angle)) {
        return Err(SimError::bad_argument(format!(
            "vertical angle must be in 0..pi rad, got {vertical_angle}"
        )));
    }
    let [nx, ny] = counts;
    let half_azimuth = depth.extent_x.atan();
    // The highest beam at the widest azimuth must fall inside the image (its edge: the
    // last half pixel is read from the outermost pixel centre).
    let reach = (vertical_angle / 2.0).tan() / half_azimuth.cos();
    if reach > depth.extent_y * (1.0 + 1e-9) {
        return Err(SimError::bad_argument(format!(
            "vertical angle {vertical_angle} rad reaches beyond vision sensor {h}'s image at the sides of its view \
             (at most {:.6} rad there): make the image taller or the angle smaller",
            2.0 * (depth.extent_y * half_azimuth.cos()).atan()
        )));
    }
    // The beams' elevations, as tangents, once for every azimuth.
    let tan_elevations: Vec<f64> = (0..ny)
        .map(|j| {
            if ny > 1 {
                (-vertical_angle / 2.0 + vertical_angle * j as f64 / (ny - 1) as f64).tan()
            } else {
                0.0
            }
        })
        .collect();
    let mut out = depth.scan(counts);
    for i in 0..nx {
        let azimuth = spread(i, nx, half_azimuth);
        let (u, secant) = (azimuth.tan(), 1.0 / azimuth.cos());
        for &tan_elevation in &tan_elevations {
            // The beam (sin az cos el, sin el, cos az cos el) crosses the image plane
            // z = 1 at u = tan az, v = tan el / cos az.
            depth.push_point(u, tan_elevation * secant, frame, &mut out)?;
        }
    }
    Ok(out)
}

/// Sample `k` of `n` spread evenly over `-half..=half` (0 for a single sample).
fn spread(k: usize, n: usize, half: f64) -> f64 {
    if n > 1 {
        -half + 2.0 * half * k as f64 / (n - 1) as f64
    } else {
        0.0
    }
}

/// A sensor's depth work image with the projection that reads it.
struct DepthMap<'a> {
    model: &'a VisionModel,
    pose: Pose,
    width: usize,
    height: usize,
    /// The work image: RGB floats, R = G = B = normalised depth.
    work: &'a [f32],
    /// Buffer 1 (float RGB) when point colours were asked for and it holds an image of
    /// the sensor's size.
    colours: Option<&'a [f32]>,
    /// Where the outermost pixel centres are: the image-plane coordinate X/Z (Y/Z) of a
    /// perspective sensor, or X (Y) in metres for an orthographic one.
    extent_x: f64,
    extent_y: f64,
    /// Half the view at the image edges, in the same units.
    half_x: f64,
    half_y: f64,
    handle: Handle,
}

impl<'a> DepthMap<'a> {
    fn new(
        world: &'a World,
        states: &'a VisionStates,
        h: Handle,
        counts: [usize; 2],
        rgb: bool,
    ) -> Result<DepthMap<'a>, SimError> {
        let points = counts[0].saturating_mul(counts[1]);
        if counts.contains(&0) || points > MAX_POINTS {
            return Err(SimError::bad_argument(format!(
                "point counts {{{}, {}}}: each must be at least 1, and at most {MAX_POINTS} points in all",
                counts[0], counts[1]
            )));
        }
        // Validated there: resolution, view angle, clipping planes.
        let (model, pose) = sensor_model(world, h)?;
        let [w, hgt] = model.resolution.map(|v| v as usize);
        let no_work = || {
            SimError::bad_argument(format!(
                "vision sensor {h} has no depth work image: call simVision.sensorDepthMapToWorkImg first"
            ))
        };
        let state = states.sensors.get(&h);
        let colours = state
            .map(|s| s.buffers[0].as_slice())
            .filter(|b| rgb && b.len() == 3 * w * hgt);
        let work = match state.and_then(|s| s.work.as_ref()) {
            None => return Err(no_work()),
            Some(Work::Float(f)) if f.len() == 3 * w * hgt => f.as_slice(),
            Some(Work::Float(_)) => return Err(no_work()),
            Some(Work::Bytes(_) | Work::Binary(_)) => {
                return Err(SimError::bad_argument(format!(
                    "vision sensor {h}'s work image is a colour image or an edge mask, not a depth map: \
                     call simVision.sensorDepthMapToWorkImg first"
                )));
            }
        };
        // The view spans the larger image side; the other follows from the aspect.
        let half = match model.projection {
            Projection::Perspective => (model.fov / 2.0).tan(),
            Projection::Orthographic => model.ortho_size / 2.0,
        };
        let (wf, hf) = (w as f64, hgt as f64);
        let (half_x, half_y) = if w >= hgt {
            (half, half * hf / wf)
        } else {
            (half * wf / hf, half)
        };
        Ok(DepthMap {
            model,
            pose,
            width: w,
            height: hgt,
            work,
            colours,
            extent_x: half_x * (1.0 - 1.0 / wf),
            extent_y: half_y * (1.0 - 1.0 / hf),
            half_x,
            half_y,
            handle: h,
        })
    }

    /// Metric planar depth of pixel `(col, row)` (column from the left, row from the
    /// bottom), and whether something was seen there (nearer than the far plane).
    fn pixel(&self, col: usize, row: usize) -> Result<(f64, bool), SimError> {
        let i = 3 * (col + row * self.width);
        let px = &self.work[i..i + 3];
        let d = px[0];
        if !(d.is_finite() && (0.0..=1.0).contains(&d)) || px[1] != d || px[2] != d {
            return Err(SimError::bad_argument(format!(
                "pixel ({col}, {row}) of vision sensor {}'s work image is {{{}, {}, {}}}, not a depth (a grey \
                 level in 0..1): call simVision.sensorDepthMapToWorkImg first",
                self.handle, px[0], px[1], px[2]
            )));
        }
        let (near, far) = (self.model.near, self.model.far);
        Ok((near + f64::from(d) * (far - near), d < 1.0))
    }

    /// The planar depth seen along image-plane coordinates `(u, v)`: inverse depth (depth,
    /// orthographic) interpolated between the pixel centres around it when they see one
    /// surface, the nearest pixel's depth otherwise (see the module docs).
    fn depth(&self, u: f64, v: f64) -> Result<(f64, usize), SimError> {
        // Continuous pixel coordinates, pixel centres at integers; image right is -X.
        let sx = self.width as f64 / 2.0 * (1.0 - u / self.half_x) - 0.5;
        let sy = self.height as f64 / 2.0 * (1.0 + v / self.half_y) - 0.5;
        let cols = taps(sx, self.width);
        let rows = taps(sy, self.height);
        // (weight, depth, pixel index) of the pixel nearest the direction.
        let mut nearest = (f64::NEG_INFINITY, 0.0, 0);
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        let mut all_hit = true;
        let mut sum = 0.0;
        let perspective = self.model.projection == Projection::Perspective;
        for &(col, wc) in cols.iter().flatten() {
            for &(row, wr) in rows.iter().flatten() {
                let (z, hit) = self.pixel(col, row)?;
                let weight = wc * wr;
                if weight > nearest.0 {
                    nearest = (weight, z, col + row * self.width);
                }
                lo = lo.min(z);
                hi = hi.max(z);
                all_hit &= hit;
                sum += if perspective { weight / z } else { weight * z };
            }
        }
        let z = if all_hit && hi <= lo * EDGE_RATIO {
            if perspective { 1.0 / sum } else { sum }
        } else {
            nearest.1
        };
        Ok((z, nearest.2))
    }

    /// An empty scan of `counts` points: the packet's header (the two counts), and room
    /// for colours when they are returned.
    fn scan(&self, counts: [usize; 2]) -> Scan {
        let points = counts[0] * counts[1];
        let mut packet = Vec::with_capacity(2 + 4 * points);
        packet.extend([counts[0] as f32, counts[1] as f32]);
        Scan {
            packet,
            colours: self.colours.map(|_| Vec::with_capacity(3 * points)),
        }
    }

    /// Appends the point seen along `(u, v)`: `x, y, z, distance`, and its colour.
    fn push_point(&self, u: f64, v: f64, frame: PointFrame, out: &mut Scan) -> Result<(), SimError> {
        let (z, pixel) = self.depth(u, v)?;
        if let (Some(colours), Some(buffer)) = (out.colours.as_mut(), self.colours) {
            let rgb = buffer.get(3 * pixel..3 * pixel + 3).unwrap_or(&[0.0; 3]);
            // The plugin's `(unsigned char)(v * 255.1)`, clamped.
            colours.extend(rgb.iter().map(|&c| (c * 255.1).clamp(0.0, 255.0) as u8));
        }
        let far = self.model.far;
        let (p, distance) = match self.model.projection {
            Projection::Perspective => {
                let p = Vec3::new(u * z, v * z, z);
                let l = p.norm();
                // Beyond the far plane along the ray (including pixels that saw nothing):
                // the ray's exit from the view, at the far distance.
                if l > far { (p * (far / l), far) } else { (p, l) }
            }
            Projection::Orthographic => (Vec3::new(u, v, z), z),
        };
        let p = match frame {
            PointFrame::Sensor => p,
            PointFrame::World => self.pose.transform_point(&p.into()).coords,
        };
        out.packet.extend([p.x as f32, p.y as f32, p.z as f32, distance as f32]);
        Ok(())
    }
}

/// The pixels (index, weight) around continuous coordinate `s` along an axis of `n`
/// pixels: the two neighbours with linear weights, one pixel for a 1-pixel axis or a
/// weight within rounding of 0 (a direction through a pixel centre reads that pixel
/// alone).
fn taps(s: f64, n: usize) -> [Option<(usize, f64)>; 2] {
    if n == 1 {
        return [Some((0, 1.0)), None];
    }
    let first = s.floor().clamp(0.0, (n - 2) as f64);
    let f = (s - first).clamp(0.0, 1.0);
    let i = first as usize;
    const ROUNDING: f64 = 1e-9;
    if f < ROUNDING {
        [Some((i, 1.0)), None]
    } else if f > 1.0 - ROUNDING {
        [Some((i + 1, 1.0)), None]
    } else {
        [Some((i, 1.0 - f)), Some((i + 1, f))]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn as_many_samples_as_pixels_read_each_pixel_centre_alone() {
        // The image-plane sample k of n spans the outermost pixel centres, so it falls
        // on column n - 1 - k (image right first) with no neighbour.
        let n = 342;
        let half = (60f64).to_radians().tan();
        let extent = half * (1.0 - 1.0 / n as f64);
        for k in 0..n {
            let u = spread(k, n, extent);
            let s = n as f64 / 2.0 * (1.0 - u / half) - 0.5;
            assert_eq!(taps(s, n), [Some((n - 1 - k, 1.0)), None], "sample {k}");
        }
    }

    #[test]
    fn taps_interpolate_between_centres_and_clamp_at_the_ends() {
        assert_eq!(taps(2.25, 5), [Some((2, 0.75)), Some((3, 0.25))]);
        assert_eq!(taps(-0.3, 5), [Some((0, 1.0)), None]);
        assert_eq!(taps(4.4, 5), [Some((4, 1.0)), None]);
        assert_eq!(taps(0.7, 1), [Some((0, 1.0)), None]);
    }
}
