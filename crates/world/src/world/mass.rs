//! A shape's mass properties as its model gives them (`sim.getShapeInertia`,
//! `sim.getShapeMassAndInertia`): the mass spread uniformly over the collision parts,
//! or the explicit inertial of a URDF link.

use nalgebra::Matrix3;

use super::object::Handle;
use super::physics::geometry_volume;
use super::world::World;
use crate::error::SimError;
use crate::math::{self, Vec3};
use crate::scene::{Geometry, MassModel};

/// A rigid body's mass properties in a shape's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassProperties {
    /// Mass, kg.
    pub mass: f64,
    /// Centre of mass in the shape frame, m.
    pub com: Vec3,
    /// Inertia tensor about the centre of mass, with the shape frame's axes, kg·m².
    pub inertia: Matrix3<f64>,
}

impl World {
    /// The mass properties of a shape: for a density or a total mass, the mass spread
    /// uniformly over its collision parts (a mesh counts as its bounding box, as
    /// [`World::shape_mass`] does); for an explicit inertial, that inertial.
    ///
    /// # Errors
    /// No such object, or not a shape.
    pub fn shape_mass_properties(&self, h: Handle) -> Result<MassProperties, SimError> {
        let mass = self.shape_mass(h)?;
        let s = self.shape(h)?;
        if let MassModel::Inertial {
            com, frame, inertia, ..
        } = s.mass
        {
            let [ixx, ixy, ixz, iyy, iyz, izz] = inertia;
            let i = Matrix3::new(ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz);
            let r = math::quat_from_array(frame).unwrap_or_else(math::Quat::identity);
            let r = r.to_rotation_matrix().into_inner();
            return Ok(MassProperties {
                mass,
                com: Vec3::from(com),
                inertia: r * i * r.transpose(),
            });
        }
        // Unit density first: each part's volume, centre and inertia in the shape frame.
        let parts: Vec<(f64, Vec3, Matrix3<f64>)> = s
            .geoms
            .iter()
            .map(|g| {
                let (volume, center, own) = unit_density_part(&g.geometry);
                let r = g.local.rotation.to_rotation_matrix().into_inner();
                (
                    volume,
                    g.local * nalgebra::Point3::from(center),
                    r * own * r.transpose(),
                )
            })
            .map(|(v, c, i)| (v, c.coords, i))
            .collect();
        let volume: f64 = parts.iter().map(|p| p.0).sum();
        if volume <= 0.0 {
            return Ok(MassProperties {
                mass,
                com: Vec3::zeros(),
                inertia: Matrix3::zeros(),
            });
        }
        let com = parts.iter().map(|(v, c, _)| c * *v).sum::<Vec3>() / volume;
        let density = mass / volume;
        let mut inertia = Matrix3::zeros();
        for (v, c, own) in &parts {
            // Parallel axes: the part's own inertia moved to the common centre.
            let d = c - com;
            let shift = Matrix3::identity() * d.norm_squared() - d * d.transpose();
            inertia += (own + shift * *v) * density;
        }
        Ok(MassProperties { mass, com, inertia })
    }
}

/// Volume, centre (in the part's frame) and inertia about that centre of one part at
/// unit density. A mesh counts as its bounding box.
pub(super) fn unit_density_part(g: &Geometry) -> (f64, Vec3, Matrix3<f64>) {
    use std::f64::consts::PI;
    let v = geometry_volume(g);
    let diag = |x: f64, y: f64, z: f64| Matrix3::from_diagonal(&Vec3::new(x, y, z));
    let box_inertia = |[a, b, c]: [f64; 3]| {
        // Full sizes a, b, c.
        diag(b * b + c * c, a * a + c * c, a * a + b * b) * (v / 12.0)
    };
    match g {
        Geometry::Box { half_extents } => (v, Vec3::zeros(), box_inertia(half_extents.map(|h| 2.0 * h))),
        Geometry::Sphere { radius } => {
            let i = 0.4 * v * radius * radius;
            (v, Vec3::zeros(), diag(i, i, i))
        }
        Geometry::Cylinder { radius, length } => {
            let r2 = radius * radius;
            let side = v * (3.0 * r2 + length * length) / 12.0;
            (v, Vec3::zeros(), diag(side, side, 0.5 * v * r2))
        }
        Geometry::Capsule { radius, length } => {
            // A cylinder plus two half balls whose centres sit at ±length/2.
            let (r, l) = (*radius, *length);
            let vc = PI * r * r * l;
            let vb = 4.0 / 3.0 * PI * r.powi(3);
            let axial = 0.5 * vc * r * r + 0.4 * vb * r * r;
            let half_ball_side = vb * (0.4 * r * r + l * l / 4.0 + 3.0 * l * r / 8.0);
            let side = vc * (3.0 * r * r + l * l) / 12.0 + half_ball_side;
            (v, Vec3::zeros(), diag(side, side, axial))
        }
        Geometry::Mesh(m) => {
            let mut lo = [f64::MAX; 3];
            let mut hi = [f64::MIN; 3];
            for p in &m.vertices {
                for k in 0..3 {
                    lo[k] = lo[k].min(f64::from(p[k]));
                    hi[k] = hi[k].max(f64::from(p[k]));
                }
            }
            if m.vertices.is_empty() {
                return (0.0, Vec3::zeros(), Matrix3::zeros());
            }
            let size = [0, 1, 2].map(|k| (hi[k] - lo[k]).max(0.0));
            let center = Vec3::new((lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0, (lo[2] + hi[2]) / 2.0);
            (v, center, box_inertia(size))
        }
    }
}
