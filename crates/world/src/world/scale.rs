//! Scaling a shape along its own axes (`sim.setShapeBB`, `sim.scaleObject`): its collision
//! and visual geometry, where its parts sit, and its mass at the same density.

use nalgebra::Matrix3;

use super::edit::invalid;
use super::object::Handle;
use super::world::World;
use crate::error::SimError;
use crate::math::Pose;
use crate::scene::{Geometry, MassModel, MeshData, ShapeModel};

/// Relative tolerance under which two factors count as equal (a uniform scale of a round
/// primitive) and a rotated part counts as aligned with the shape's axes.
const SAME: f64 = 1e-9;

impl World {
    /// Scales shape `h` by `factors` along its own X, Y and Z axes: every part's geometry
    /// and position in the shape frame. Its mass scales with its volume (the density stays),
    /// as do its centre of mass and inertia. Boxes and meshes scale along any axes; spheres
    /// and capsules only uniformly, cylinders only equally across their axis (otherwise
    /// they would stop being what rapier simulates), which is refused with a message.
    ///
    /// # Errors
    /// No such object, not a shape, factors that are not finite and positive, or a round
    /// part that the factors would distort.
    pub fn scale_shape(&mut self, h: Handle, factors: [f64; 3]) -> Result<(), SimError> {
        if !factors.iter().all(|f| f.is_finite() && *f > 0.0) {
            return Err(invalid(format!(
                "scale factors must be finite and > 0, got {factors:?}"
            )));
        }
        let shape = self.shape(h)?;
        let scaled = scaled_shape(shape, factors).map_err(invalid)?;
        *self.shape_mut(h)? = scaled;
        self.rebuild_physics(&[h]);
        self.geometry_changed(h);
        Ok(())
    }
}

/// The shape scaled by `f` along its axes; an error names the part that cannot be.
fn scaled_shape(shape: &ShapeModel, f: [f64; 3]) -> Result<ShapeModel, String> {
    let mut out = shape.clone();
    for g in &mut out.geoms {
        (g.geometry, g.local) = scaled_part(&g.geometry, &g.local, f)?;
    }
    for v in &mut out.visuals {
        (v.geometry, v.local) = scaled_part(&v.geometry, &v.local, f)?;
    }
    let volume = f[0] * f[1] * f[2];
    out.mass = match shape.mass {
        MassModel::Density(d) => MassModel::Density(d),
        MassModel::Mass(m) => MassModel::Mass(m * volume),
        MassModel::Inertial {
            mass,
            com,
            frame,
            inertia,
        } => {
            let (frame, inertia) = scaled_inertia(frame, inertia, f, volume);
            MassModel::Inertial {
                mass: mass * volume,
                com: [com[0] * f[0], com[1] * f[1], com[2] * f[2]],
                frame,
                inertia,
            }
        }
    };
    Ok(out)
}

/// One part scaled: its position in the shape frame by `f`, its geometry by `f` seen in
/// the part's own (rotated) frame.
fn scaled_part(g: &Geometry, local: &Pose, f: [f64; 3]) -> Result<(Geometry, Pose), String> {
    let r = local.rotation.to_rotation_matrix().into_inner();
    // The shape-frame scaling seen in the part frame: Rᵀ S R (diagonal when the part's
    // axes are the shape's axes, in any order).
    let m = r.transpose() * Matrix3::from_diagonal(&crate::math::Vec3::from(f)) * r;
    let aligned = (0..3).all(|i| (0..3).all(|j| i == j || m[(i, j)].abs() <= SAME * m.amax()));
    let d = [m[(0, 0)], m[(1, 1)], m[(2, 2)]];
    let same = |a: f64, b: f64| (a - b).abs() <= SAME * a.abs().max(b.abs());
    let geometry = match g {
        Geometry::Mesh(mesh) => Geometry::Mesh(std::sync::Arc::new(scaled_mesh(mesh, &m))),
        _ if !aligned => {
            return Err("a primitive part turned away from the shape's axes can only be scaled uniformly".into());
        }
        Geometry::Box { half_extents } => Geometry::Box {
            half_extents: [half_extents[0] * d[0], half_extents[1] * d[1], half_extents[2] * d[2]],
        },
        Geometry::Sphere { radius } if same(d[0], d[1]) && same(d[1], d[2]) => {
            Geometry::Sphere { radius: radius * d[0] }
        }
        Geometry::Cylinder { radius, length } if same(d[0], d[1]) => Geometry::Cylinder {
            radius: radius * d[0],
            length: length * d[2],
        },
        Geometry::Capsule { radius, length } if same(d[0], d[1]) && same(d[1], d[2]) => Geometry::Capsule {
            radius: radius * d[0],
            length: length * d[0],
        },
        Geometry::Sphere { .. } => return Err("a sphere can only be scaled uniformly".into()),
        Geometry::Capsule { .. } => return Err("a capsule can only be scaled uniformly".into()),
        Geometry::Cylinder { .. } => return Err("a cylinder can only be scaled equally across its axis".into()),
    };
    let mut local = *local;
    local
        .translation
        .vector
        .component_mul_assign(&crate::math::Vec3::from(f));
    Ok((geometry, local))
}

/// A mesh's vertices and convex parts through the linear map `m` (part frame).
fn scaled_mesh(mesh: &MeshData, m: &Matrix3<f64>) -> MeshData {
    let map = |v: &[f32; 3]| {
        let p = m * nalgebra::Vector3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]));
        [p.x as f32, p.y as f32, p.z as f32]
    };
    MeshData {
        source: mesh.source.clone(),
        vertices: mesh.vertices.iter().map(map).collect(),
        indices: mesh.indices.clone(),
        parts: mesh.parts.iter().map(|p| p.iter().map(map).collect()).collect(),
    }
}

/// An inertia tensor (`[ixx, ixy, ixz, iyy, iyz, izz]` in the rotated `frame`, quaternion
/// `[x, y, z, w]`) after scaling the body by `f` in the shape frame and its mass by
/// `volume`: through the second moment `C = ∫ r rᵀ dm = tr(I)/2 · 1 − I`, which scales as
/// `volume · S C S`. The result is in the shape frame (identity `frame`).
fn scaled_inertia(frame: [f64; 4], i: [f64; 6], f: [f64; 3], volume: f64) -> ([f64; 4], [f64; 6]) {
    let q = crate::math::quat_from_array(frame).unwrap_or_else(nalgebra::UnitQuaternion::identity);
    let r = q.to_rotation_matrix().into_inner();
    let local = Matrix3::new(i[0], i[1], i[2], i[1], i[3], i[4], i[2], i[4], i[5]);
    let inertia = r * local * r.transpose();
    let c = Matrix3::identity() * (inertia.trace() / 2.0) - inertia;
    let s = Matrix3::from_diagonal(&crate::math::Vec3::from(f));
    let c = s * c * s * volume;
    let out = Matrix3::identity() * c.trace() - c;
    (
        [0.0, 0.0, 0.0, 1.0],
        [
            out[(0, 0)],
            out[(0, 1)],
            out[(0, 2)],
            out[(1, 1)],
            out[(1, 2)],
            out[(2, 2)],
        ],
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_box_inertia_scales_as_the_box_it_becomes() {
        // A 2 kg box 0.2 x 0.4 x 0.6 m: I = m/12 (b² + c²) ...
        let (m, [a, b, c]) = (2.0, [0.2f64, 0.4, 0.6]);
        let diag = |m: f64, a: f64, b: f64, c: f64| {
            [
                m / 12.0 * (b * b + c * c),
                0.0,
                0.0,
                m / 12.0 * (a * a + c * c),
                0.0,
                m / 12.0 * (a * a + b * b),
            ]
        };
        let f = [2.0, 0.5, 3.0];
        let volume = f[0] * f[1] * f[2];
        let (_, got) = scaled_inertia([0.0, 0.0, 0.0, 1.0], diag(m, a, b, c), f, volume);
        let want = diag(m * volume, a * f[0], b * f[1], c * f[2]);
        for k in 0..6 {
            assert!((got[k] - want[k]).abs() < 1e-12, "{got:?} vs {want:?}");
        }
    }

    #[test]
    fn rotated_boxes_scale_along_the_shape_axes() {
        // A box turned 90° about Z: the shape's X is its Y.
        let local = Pose::from_parts(
            nalgebra::Translation3::new(1.0, 2.0, 3.0),
            nalgebra::UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2),
        );
        let g = Geometry::Box {
            half_extents: [0.1, 0.2, 0.3],
        };
        let (g, local) = scaled_part(&g, &local, [2.0, 3.0, 4.0]).expect("a box scales");
        let Geometry::Box { half_extents } = g else { panic!() };
        for (got, want) in half_extents.iter().zip([0.3, 0.4, 1.2]) {
            assert!((got - want).abs() < 1e-12, "{half_extents:?}");
        }
        assert!((local.translation.vector - nalgebra::Vector3::new(2.0, 6.0, 12.0)).norm() < 1e-12);
        let ball = Geometry::Sphere { radius: 0.1 };
        assert!(
            scaled_part(&ball, &Pose::identity(), [1.0, 2.0, 1.0])
                .unwrap_err()
                .contains("uniformly")
        );
    }
}
