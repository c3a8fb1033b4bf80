//! OC trees (`sim.createOctree`): scene objects made of equal cubic voxels, each with a
//! colour and a user tag, stored in the octree's own frame so they follow the object.
//!
//! The model follows CoppeliaSim's `COctree` and its geometry plugin, as its manual and
//! API reference describe them:
//! - the voxels of an octree with voxel size `s` tile space on a grid aligned with the
//!   octree's frame: voxel `(i, j, k)` spans `[i·s, (i+1)·s]` on x (and so on), and its
//!   centre is `((i+½)·s, ...)`. CoppeliaSim's tree is centred on the frame and grows by
//!   doubling, which keeps exactly this grid; here the grid is a sorted map of occupied
//!   voxels, which answers the same questions without the tree;
//! - a voxel holds a point when the point lies inside the voxel grown by
//!   [`VOXEL_TOLERANCE`] of its size on every side (CoppeliaSim tests against a half
//!   size of `0.5001·s`). A point on a face, edge or corner therefore lands in the 2, 4
//!   or 8 voxels that share it, as in CoppeliaSim, and insertion, removal and the
//!   occupancy check all use the same rule, so an inserted point is always found;
//! - inserting an object voxelises its surface: every voxel (grown the same way) that a
//!   triangle of the object's mesh touches is occupied; the inside of a closed mesh is
//!   not filled, as in CoppeliaSim. Subtracting an object removes the voxels its
//!   surface touches.
//!
//! Voxels are reported in the grid's order (x, then y, then z), so results do not depend
//! on insertion order. An octree holds at most [`MAX_OCTREE_VOXELS`]; an operation that
//! would go past it fails as a whole.
//!
//! Octrees count in collision checks against shapes and other octrees, and in distance
//! queries against shapes and dummies (`World::collision`, `World::distance`), voxel by
//! voxel. Non-goals: proximity sensors do not detect them, octree-to-octree distances
//! are not measured, and vision sensors and the viewer do not draw them.

use std::collections::BTreeMap;

use crate::error::SimError;
use crate::math::Vec3;

/// Most voxels one octree holds (about 100 MB with the map). Operations that would
/// exceed it fail and change nothing.
pub const MAX_OCTREE_VOXELS: usize = 2_000_000;
/// How much a voxel is grown on every side, in voxel sizes, when testing what it holds
/// (CoppeliaSim's half size of `0.5001·s`).
pub const VOXEL_TOLERANCE: f64 = 1e-4;
/// Farthest voxel index from the octree's origin on any axis (2^40 voxels): beyond it a
/// point is refused, which keeps every index and index difference exact.
pub const MAX_VOXEL_INDEX: f64 = 1_099_511_627_776.0;
/// The colour of voxels inserted without one: CoppeliaSim's default octree grey.
pub const DEFAULT_VOXEL_COLOR: [u8; 3] = [128, 128, 128];

/// What a voxel holds besides its place.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Voxel {
    /// RGB bytes.
    pub color: [u8; 3],
    /// User value (`tag` of `sim.insertVoxelsIntoOctree`).
    pub tag: u32,
}

/// An octree's voxels and settings.
#[derive(Clone)]
pub struct Octree {
    voxel_size: f64,
    options: i64,
    point_size: f64,
    /// Occupied voxels by grid index.
    voxels: BTreeMap<[i64; 3], Voxel>,
}

impl std::fmt::Debug for Octree {
    /// A summary: an octree may hold millions of voxels.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Octree")
            .field("voxel_size", &self.voxel_size)
            .field("options", &self.options)
            .field("voxels", &self.voxels.len())
            .finish()
    }
}

/// A triangle in the octree's frame, m.
pub type Triangle = [Vec3; 3];

impl Octree {
    /// An empty octree of voxels `voxel_size` m wide; `options` and `point_size` (the
    /// display settings of `sim.createOctree`) are kept as given.
    ///
    /// # Errors
    /// A voxel size that is not a finite number > 0, or a point size that is not finite.
    pub fn new(voxel_size: f64, options: i64, point_size: f64) -> Result<Self, SimError> {
        if !(voxel_size.is_finite() && voxel_size > 0.0) {
            return Err(SimError::bad_argument(format!(
                "voxel size must be a finite number > 0 (m), got {voxel_size}"
            )));
        }
        if !point_size.is_finite() {
            return Err(SimError::bad_argument(format!(
                "point size must be a finite number, got {point_size}"
            )));
        }
        Ok(Self {
            voxel_size,
            options,
            point_size,
            voxels: BTreeMap::new(),
        })
    }

    /// Voxel edge, m.
    pub fn voxel_size(&self) -> f64 {
        self.voxel_size
    }

    /// `sim.createOctree`'s option bits, as given.
    pub fn options(&self) -> i64 {
        self.options
    }

    /// `sim.createOctree`'s point size, as given.
    pub fn point_size(&self) -> f64 {
        self.point_size
    }

    /// Number of occupied voxels.
    pub fn len(&self) -> usize {
        self.voxels.len()
    }

    /// Whether no voxel is occupied.
    pub fn is_empty(&self) -> bool {
        self.voxels.is_empty()
    }

    /// The occupied voxels by grid index, in grid order.
    pub fn voxels(&self) -> impl Iterator<Item = (&[i64; 3], &Voxel)> {
        self.voxels.iter()
    }

    /// The occupied voxels whose indices lie in the box `lo..=hi`, in grid order. The
    /// cost follows the voxels in the box's x range, not the box's volume.
    pub fn voxels_in(&self, lo: [i64; 3], hi: [i64; 3]) -> impl Iterator<Item = [i64; 3]> + '_ {
        let empty = (0..3).any(|a| lo[a] > hi[a]);
        let range = if empty {
            self.voxels.range([0, 0, 0]..[0, 0, 0])
        } else {
            self.voxels
                .range([lo[0], i64::MIN, i64::MIN]..=[hi[0], i64::MAX, i64::MAX])
        };
        range
            .map(|(k, _)| *k)
            .filter(move |k| (1..3).all(|a| (lo[a]..=hi[a]).contains(&k[a])))
    }

    /// The indices of the voxels that may overlap the box `min..max` (octree frame, m),
    /// clamped to [`MAX_VOXEL_INDEX`].
    pub fn index_box(&self, min: &Vec3, max: &Vec3) -> ([i64; 3], [i64; 3]) {
        let idx = |v: f64| (v / self.voxel_size).floor().clamp(-MAX_VOXEL_INDEX, MAX_VOXEL_INDEX) as i64;
        (
            [idx(min.x), idx(min.y), idx(min.z)],
            [idx(max.x), idx(max.y), idx(max.z)],
        )
    }

    /// The centre of voxel `index`, in the octree's frame, m.
    pub fn voxel_center(&self, index: &[i64; 3]) -> Vec3 {
        let s = self.voxel_size;
        Vec3::new(
            (index[0] as f64 + 0.5) * s,
            (index[1] as f64 + 0.5) * s,
            (index[2] as f64 + 0.5) * s,
        )
    }

    /// The voxels' centres in grid order, octree frame, m.
    pub fn centers(&self) -> Vec<Vec3> {
        self.voxels.keys().map(|k| self.voxel_center(k)).collect()
    }

    /// Occupies the voxels holding each point (octree frame), with the point's colour
    /// and tag (`colors` and `tags` have one entry for all points, or one per point).
    /// A voxel already occupied takes the new colour and tag. Returns the voxel count.
    ///
    /// # Errors
    /// A non-finite or too distant point, colours or tags that are neither one nor one
    /// per point, or more than [`MAX_OCTREE_VOXELS`] afterwards; then nothing changes.
    pub fn insert_points(&mut self, points: &[Vec3], colors: &[[u8; 3]], tags: &[u32]) -> Result<usize, SimError> {
        for (what, n) in [("colours", colors.len()), ("tags", tags.len())] {
            if n != 1 && n != points.len() {
                return Err(SimError::bad_argument(format!(
                    "{n} {what} for {} points: give one for all points or one per point",
                    points.len()
                )));
            }
        }
        let mut added = BTreeMap::new();
        for (i, p) in points.iter().enumerate() {
            let voxel = Voxel {
                color: colors[if colors.len() == 1 { 0 } else { i }],
                tag: tags[if tags.len() == 1 { 0 } else { i }],
            };
            for key in self.holding(p, i)? {
                added.insert(key, voxel);
            }
        }
        self.merge(added)
    }

    /// Empties the voxels holding each point (octree frame). Returns the voxel count.
    ///
    /// # Errors
    /// A non-finite or too distant point; then nothing changes.
    pub fn remove_points(&mut self, points: &[Vec3]) -> Result<usize, SimError> {
        let mut keys = Vec::new();
        for (i, p) in points.iter().enumerate() {
            keys.extend(self.holding(p, i)?);
        }
        for k in keys {
            self.voxels.remove(&k);
        }
        Ok(self.voxels.len())
    }

    /// Empties every voxel.
    pub fn clear(&mut self) {
        self.voxels.clear();
    }

    /// The first occupied voxel holding one of the points (octree frame), if any.
    ///
    /// # Errors
    /// A non-finite or too distant point.
    pub fn occupied(&self, points: &[Vec3]) -> Result<Option<Voxel>, SimError> {
        for (i, p) in points.iter().enumerate() {
            for key in self.holding(p, i)? {
                if let Some(v) = self.voxels.get(&key) {
                    return Ok(Some(*v));
                }
            }
        }
        Ok(None)
    }

    /// Occupies every voxel the triangles (octree frame) touch, with this colour and
    /// tag. Returns the voxel count.
    ///
    /// # Errors
    /// A non-finite or too distant vertex, or more than [`MAX_OCTREE_VOXELS`]
    /// afterwards; then nothing changes.
    pub fn insert_triangles(&mut self, triangles: &[Triangle], voxel: Voxel) -> Result<usize, SimError> {
        let Some(start) = self.bounds(triangles)? else {
            return Ok(self.voxels.len());
        };
        let cells = self.to_cells(triangles);
        let mut added = BTreeMap::new();
        let all: Vec<usize> = (0..cells.len()).collect();
        let budget = MAX_OCTREE_VOXELS - self.voxels.len().min(MAX_OCTREE_VOXELS);
        let mut visit = |key: [i64; 3]| {
            added.insert(key, voxel);
            added.len() <= budget
        };
        if !descend(&cells, start, &all, &mut visit) {
            return Err(Self::too_many());
        }
        self.merge(added)
    }

    /// Empties every voxel the triangles (octree frame) touch. Returns the voxel count.
    ///
    /// # Errors
    /// A non-finite or too distant vertex, or a surface touching more than
    /// [`MAX_OCTREE_VOXELS`] voxels around the occupied ones (a huge object against
    /// small voxels); then nothing changes.
    pub fn subtract_triangles(&mut self, triangles: &[Triangle]) -> Result<usize, SimError> {
        let Some(start) = self.bounds(triangles)? else {
            return Ok(self.voxels.len());
        };
        // Only the part of the surface around occupied voxels matters.
        let (Some(first), Some(last)) = (self.voxels.keys().next(), self.voxels.keys().next_back()) else {
            return Ok(0);
        };
        let (mut lo, mut hi) = ([first[0], i64::MAX, i64::MAX], [last[0], i64::MIN, i64::MIN]);
        for k in self.voxels.keys() {
            for a in 1..3 {
                lo[a] = lo[a].min(k[a]);
                hi[a] = hi[a].max(k[a]);
            }
        }
        let start = (
            [0, 1, 2].map(|a| start.0[a].max(lo[a])),
            [0, 1, 2].map(|a| start.1[a].min(hi[a])),
        );
        if (0..3).any(|a| start.0[a] > start.1[a]) {
            return Ok(self.voxels.len());
        }
        let cells = self.to_cells(triangles);
        let all: Vec<usize> = (0..cells.len()).collect();
        let mut visited = 0usize;
        let mut hit = Vec::new();
        let voxels = &self.voxels;
        let mut visit = |key: [i64; 3]| {
            visited += 1;
            if voxels.contains_key(&key) {
                hit.push(key);
            }
            visited <= MAX_OCTREE_VOXELS
        };
        if !descend(&cells, start, &all, &mut visit) {
            return Err(SimError::refused(format!(
                "the object's surface spans more than {MAX_OCTREE_VOXELS} voxels of this octree; \
                 use larger voxels or a smaller object"
            )));
        }
        for k in hit {
            self.voxels.remove(&k);
        }
        Ok(self.voxels.len())
    }

    fn too_many() -> SimError {
        SimError::refused(format!(
            "an octree holds at most {MAX_OCTREE_VOXELS} voxels; use larger voxels or remove some first \
             (sim.removeVoxelsFromOctree)"
        ))
    }

    /// Adds `added` to the voxels unless that would pass the limit.
    fn merge(&mut self, added: BTreeMap<[i64; 3], Voxel>) -> Result<usize, SimError> {
        let new = added.keys().filter(|k| !self.voxels.contains_key(*k)).count();
        if self.voxels.len() + new > MAX_OCTREE_VOXELS {
            return Err(Self::too_many());
        }
        self.voxels.extend(added);
        Ok(self.voxels.len())
    }

    /// `p` in voxel units, checked finite and within [`MAX_VOXEL_INDEX`]; `i` numbers
    /// the point in messages.
    fn scaled(&self, p: &Vec3, i: usize) -> Result<Vec3, SimError> {
        if !p.iter().all(|v| v.is_finite()) {
            return Err(SimError::bad_argument(format!(
                "point {} has a non-finite coordinate",
                i + 1
            )));
        }
        let u = p / self.voxel_size;
        if u.iter().any(|v| v.abs() > MAX_VOXEL_INDEX) {
            return Err(SimError::bad_argument(format!(
                "point {} ({}, {}, {}) is too far from the octree for its voxel size ({} m)",
                i + 1,
                p.x,
                p.y,
                p.z,
                self.voxel_size
            )));
        }
        Ok(u)
    }

    /// The voxels holding `p` (octree frame): 1 inside a voxel, up to 8 at a corner.
    fn holding(&self, p: &Vec3, i: usize) -> Result<Vec<[i64; 3]>, SimError> {
        let u = self.scaled(p, i)?;
        // Voxel n holds u when n - tol < u < n + 1 + tol, per axis.
        let range = |v: f64| {
            let lo = (v - 1.0 - VOXEL_TOLERANCE).floor() as i64 + 1;
            let hi = (v + VOXEL_TOLERANCE).ceil() as i64 - 1;
            lo..=hi
        };
        let mut keys = Vec::with_capacity(8);
        for x in range(u.x) {
            for y in range(u.y) {
                for z in range(u.z) {
                    keys.push([x, y, z]);
                }
            }
        }
        Ok(keys)
    }

    /// The voxel box around the triangles (grown by the tolerance), checking every
    /// vertex; `None` without triangles.
    #[expect(clippy::type_complexity, reason = "a pair of corner indices")]
    fn bounds(&self, triangles: &[Triangle]) -> Result<Option<([i64; 3], [i64; 3])>, SimError> {
        let mut lo = [i64::MAX; 3];
        let mut hi = [i64::MIN; 3];
        for (t, tri) in triangles.iter().enumerate() {
            for p in tri {
                let u = self.scaled(p, t).map_err(|e| e.prefixed("triangle vertex: "))?;
                for a in 0..3 {
                    lo[a] = lo[a].min((u[a] - VOXEL_TOLERANCE).floor() as i64);
                    hi[a] = hi[a].max((u[a] + VOXEL_TOLERANCE).floor() as i64);
                }
            }
        }
        Ok((!triangles.is_empty()).then_some((lo, hi)))
    }

    fn to_cells(&self, triangles: &[Triangle]) -> Vec<Triangle> {
        triangles.iter().map(|t| t.map(|p| p / self.voxel_size)).collect()
    }
}

/// Visits every voxel of the box `lo..=hi` (inclusive indices) that one of the triangles
/// `tris` (indices into `cells`, in voxel units) touches, splitting the box in halves
/// and keeping only the triangles that touch each half, so the work follows the surface
/// rather than the box's volume. Stops, returning false, when `visit` does.
fn descend(
    cells: &[Triangle],
    (lo, hi): ([i64; 3], [i64; 3]),
    tris: &[usize],
    visit: &mut impl FnMut([i64; 3]) -> bool,
) -> bool {
    let min = Vec3::new(lo[0] as f64, lo[1] as f64, lo[2] as f64).add_scalar(-VOXEL_TOLERANCE);
    let max = Vec3::new(hi[0] as f64 + 1.0, hi[1] as f64 + 1.0, hi[2] as f64 + 1.0).add_scalar(VOXEL_TOLERANCE);
    let center = (min + max) / 2.0;
    let half = (max - min) / 2.0;
    let touching: Vec<usize> = tris
        .iter()
        .copied()
        .filter(|&t| triangle_touches_box(&cells[t], &center, &half))
        .collect();
    if touching.is_empty() {
        return true;
    }
    // The longest side is split; a single voxel is visited.
    let axis = (0..3).max_by_key(|&a| hi[a] - lo[a]).unwrap_or(0);
    if hi[axis] == lo[axis] {
        return visit(lo);
    }
    let mid = lo[axis] + (hi[axis] - lo[axis]) / 2;
    let mut first_hi = hi;
    first_hi[axis] = mid;
    let mut second_lo = lo;
    second_lo[axis] = mid + 1;
    descend(cells, (lo, first_hi), &touching, visit) && descend(cells, (second_lo, hi), &touching, visit)
}

/// Whether a triangle and an axis-aligned box (centre, half sizes) overlap, by the
/// separating axis theorem: the box's 3 axes, the triangle's normal and the 9 cross
/// products of edges. Degenerate axes (zero cross products) separate nothing.
fn triangle_touches_box(tri: &Triangle, center: &Vec3, half: &Vec3) -> bool {
    let v = tri.map(|p| p - center);
    let separated = |axis: &Vec3| {
        let p = [axis.dot(&v[0]), axis.dot(&v[1]), axis.dot(&v[2])];
        let r = half.x * axis.x.abs() + half.y * axis.y.abs() + half.z * axis.z.abs();
        let (mn, mx) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
        mn > r || mx < -r
    };
    let units = [Vec3::x(), Vec3::y(), Vec3::z()];
    if units.iter().any(&separated) {
        return false;
    }
    let edges = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
    if separated(&edges[0].cross(&edges[1])) {
        return false;
    }
    for u in &units {
        for e in &edges {
            if separated(&u.cross(e)) {
                return false;
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    fn octree(s: f64) -> Octree {
        Octree::new(s, 0, 1.0).expect("octree")
    }

    const GREY: [[u8; 3]; 1] = [DEFAULT_VOXEL_COLOR];

    #[test]
    fn a_point_fills_the_voxels_that_share_it() {
        let mut o = octree(0.1);
        assert_eq!(
            o.insert_points(&[Vec3::new(0.05, 0.05, 0.05)], &GREY, &[0])
                .expect("inside"),
            1
        );
        assert_eq!(o.centers(), [Vec3::new(0.05, 0.05, 0.05)]);
        o.clear();
        // On a face: 2 voxels; on an edge: 4; on a corner: 8.
        assert_eq!(
            o.insert_points(&[Vec3::new(0.1, 0.05, 0.05)], &GREY, &[0])
                .expect("face"),
            2
        );
        o.clear();
        assert_eq!(
            o.insert_points(&[Vec3::new(0.1, 0.2, 0.05)], &GREY, &[0])
                .expect("edge"),
            4
        );
        o.clear();
        assert_eq!(o.insert_points(&[Vec3::zeros()], &GREY, &[0]).expect("corner"), 8);
        assert!(o.occupied(&[Vec3::zeros()]).expect("check").is_some());
        assert_eq!(o.remove_points(&[Vec3::zeros()]).expect("remove"), 0);
    }

    #[test]
    fn occupancy_reports_the_voxel_tag() {
        let mut o = octree(0.5);
        let pts = [Vec3::new(0.2, 0.2, 0.2), Vec3::new(1.2, 0.2, 0.2)];
        o.insert_points(&pts, &[[1, 2, 3], [4, 5, 6]], &[7, 8]).expect("insert");
        let v = o
            .occupied(&[Vec3::new(1.3, 0.3, 0.3)])
            .expect("check")
            .expect("occupied");
        assert_eq!(
            v,
            Voxel {
                color: [4, 5, 6],
                tag: 8
            }
        );
        assert!(o.occupied(&[Vec3::new(-0.2, 0.2, 0.2)]).expect("check").is_none());
    }

    #[test]
    fn bad_points_change_nothing() {
        let mut o = octree(0.01);
        o.insert_points(&[Vec3::new(0.005, 0.005, 0.005)], &GREY, &[0])
            .expect("insert");
        let bad = [Vec3::new(0.5, 0.5, 0.5), Vec3::new(f64::NAN, 0.0, 0.0)];
        assert!(o.insert_points(&bad, &GREY, &[0]).is_err());
        assert!(o.insert_points(&[Vec3::new(1e300, 0.0, 0.0)], &GREY, &[0]).is_err());
        assert!(o.insert_points(&bad[..1], &[[0; 3]; 2], &[0]).is_err());
        assert!(Octree::new(0.0, 0, 1.0).is_err());
        assert!(Octree::new(f64::INFINITY, 0, 1.0).is_err());
        assert_eq!(o.len(), 1);
    }

    #[test]
    fn sat_test_separates_and_touches() {
        let c = Vec3::new(0.5, 0.5, 0.5);
        let h = Vec3::new(0.5, 0.5, 0.5);
        let inside = [
            Vec3::new(0.2, 0.2, 0.2),
            Vec3::new(0.3, 0.2, 0.2),
            Vec3::new(0.2, 0.3, 0.2),
        ];
        assert!(triangle_touches_box(&inside, &c, &h));
        // A large triangle passing through the box with every vertex outside it.
        let through = [
            Vec3::new(-5.0, -5.0, 0.5),
            Vec3::new(5.0, -5.0, 0.5),
            Vec3::new(0.0, 10.0, 0.5),
        ];
        assert!(triangle_touches_box(&through, &c, &h));
        // Beside the box's vertical edge at (1, 1): the bounding boxes overlap and the
        // plane cuts the box; only the hypotenuse (x + y = 2.1) separates them.
        let beside = [
            Vec3::new(1.6, 0.5, 0.5),
            Vec3::new(0.5, 1.6, 0.5),
            Vec3::new(1.6, 1.6, 0.5),
        ];
        assert!(!triangle_touches_box(&beside, &c, &h));
    }

    #[test]
    fn a_large_triangle_costs_its_area_not_its_box() {
        // A 1 m diagonal triangle against 4 mm voxels: about 10^5 voxels in its plane,
        // 1.6·10^7 in its bounding box.
        let mut o = octree(0.004);
        let tri = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
        ];
        let n = o
            .insert_triangles(&[tri], Voxel { color: [0; 3], tag: 0 })
            .expect("insert");
        assert!((50_000..200_000).contains(&n), "{n} voxels");
    }
}
