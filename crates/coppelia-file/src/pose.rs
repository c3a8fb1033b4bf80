//! Rigid poses as CoppeliaSim stores them: a position (m) and a unit quaternion.

/// A rigid transform: `rotation` then `position`, i.e. `p' = R p + position`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Translation, metres.
    pub position: [f64; 3],
    /// Unit quaternion `[w, x, y, z]`.
    pub rotation: [f64; 4],
}

impl Default for Pose {
    fn default() -> Self {
        Pose::IDENTITY
    }
}

impl Pose {
    /// No rotation, no translation.
    pub const IDENTITY: Pose = Pose {
        position: [0.0; 3],
        rotation: [1.0, 0.0, 0.0, 0.0],
    };

    /// A pose from a quaternion `[w, x, y, z]` (normalised here, as CoppeliaSim does when
    /// it reads one; a zero quaternion becomes the identity rotation) and a position.
    pub fn new(rotation: [f64; 4], position: [f64; 3]) -> Pose {
        let n = rotation.iter().map(|v| v * v).sum::<f64>().sqrt();
        let rotation = if n > 0.0 && n.is_finite() {
            rotation.map(|v| v / n)
        } else {
            [1.0, 0.0, 0.0, 0.0]
        };
        Pose { position, rotation }
    }

    /// The object-pose layout (`Cfq`/`_fq`): `qw qx qy qz x y z`.
    pub fn from_quaternion_first(v: [f64; 7]) -> Pose {
        Pose::new([v[0], v[1], v[2], v[3]], [v[4], v[5], v[6]])
    }

    /// The frame layout of shapes (`Ppf`/`_pf`, `Ine`/`_ne`): `x y z qw qx qy qz`.
    pub fn from_position_first(v: [f64; 7]) -> Pose {
        Pose::new([v[3], v[4], v[5], v[6]], [v[0], v[1], v[2]])
    }

    /// Rotates `v` by this pose's rotation.
    pub fn rotate(&self, v: [f64; 3]) -> [f64; 3] {
        let [w, x, y, z] = self.rotation;
        // v + 2 w (q × v) + 2 q × (q × v)
        let t = [
            2.0 * (y * v[2] - z * v[1]),
            2.0 * (z * v[0] - x * v[2]),
            2.0 * (x * v[1] - y * v[0]),
        ];
        [
            v[0] + w * t[0] + (y * t[2] - z * t[1]),
            v[1] + w * t[1] + (z * t[0] - x * t[2]),
            v[2] + w * t[2] + (x * t[1] - y * t[0]),
        ]
    }

    /// Maps a point from this pose's frame to its parent frame.
    pub fn transform_point(&self, p: [f64; 3]) -> [f64; 3] {
        let r = self.rotate(p);
        [
            r[0] + self.position[0],
            r[1] + self.position[1],
            r[2] + self.position[2],
        ]
    }

    /// `self * child`: the pose of `child` (given relative to this frame) in this frame's
    /// parent.
    pub fn compose(&self, child: &Pose) -> Pose {
        let [aw, ax, ay, az] = self.rotation;
        let [bw, bx, by, bz] = child.rotation;
        let rotation = [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ];
        Pose {
            position: self.transform_point(child.position),
            rotation,
        }
    }

    /// The 3×3 rotation matrix, row-major.
    pub fn rotation_matrix(&self) -> [[f64; 3]; 3] {
        let c = |v| self.rotate(v);
        let (ex, ey, ez) = (c([1.0, 0.0, 0.0]), c([0.0, 1.0, 0.0]), c([0.0, 0.0, 1.0]));
        [[ex[0], ey[0], ez[0]], [ex[1], ey[1], ez[1]], [ex[2], ey[2], ez[2]]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12)
    }

    #[test]
    fn composes_rotations_and_translations() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        // 90° about z, then 1 m along the rotated x.
        let a = Pose::new([h, 0.0, 0.0, h], [1.0, 0.0, 0.0]);
        let b = Pose::new([1.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
        let ab = a.compose(&b);
        assert!(close(ab.position, [1.0, 1.0, 0.0]));
        assert!(close(ab.transform_point([1.0, 0.0, 0.0]), [1.0, 2.0, 0.0]));
        let m = a.rotation_matrix();
        assert!(close(m[0], [0.0, -1.0, 0.0]));
        // Layouts and normalisation.
        let p = Pose::from_position_first([1.0, 2.0, 3.0, 2.0, 0.0, 0.0, 0.0]);
        assert_eq!(p.position, [1.0, 2.0, 3.0]);
        assert_eq!(p.rotation, [1.0, 0.0, 0.0, 0.0]);
        assert_eq!(Pose::from_quaternion_first([0.0; 7]).rotation, [1.0, 0.0, 0.0, 0.0]);
    }
}
