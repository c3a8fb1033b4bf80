//! Point clouds (`sim.createPointCloud`): scene objects that hold coloured points in
//! their own frame, so the points follow the cloud when it (or its parent) moves.
//!
//! The model follows CoppeliaSim's `CPointCloud` and its geometry plugin's point-cloud
//! tree, as its manual describes them:
//! - points are stored relative to the cloud's frame; callers convert world-frame
//!   points with the cloud's pose before inserting ([`PointCloud::insert`] takes
//!   cloud-frame points);
//! - the cloud is organised in voxels of at most `max_voxel_size` holding at most
//!   `max_points_per_voxel` points; CoppeliaSim splits a full voxel into 8 smaller ones,
//!   so neither setting ever drops a point: they only shape the calculation structure.
//!   Here the structure is a hash grid of `max_voxel_size` cells;
//! - a point closer than the insertion tolerance (m, strictly) to a point already in
//!   the cloud, or to one inserted before it in the same call, is not inserted;
//!   removal and intersection compare distances the same way (strictly less);
//! - option [`POINTCLOUD_NO_STRUCTURE`] ("do not use an OC-tree structure") appends
//!   points as given: no duplicate check, as in CoppeliaSim.
//!
//! Points keep their insertion order (CoppeliaSim returns them in its tree's order;
//! scripts should not depend on either). A cloud holds at most
//! [`MAX_POINT_CLOUD_POINTS`]; an insertion that would go past it is refused as a whole.
//!
//! Non-goals: point clouds are not collidable, measurable or detectable here (no
//! collision, distance or proximity-sensor queries), and vision sensors do not render
//! them; the viewer draws them.

use std::collections::HashMap;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::SimError;
use crate::math::Vec3;

/// Most points one cloud holds (about 40 MB with its index). Insertions that would
/// exceed it fail and insert nothing.
pub const MAX_POINT_CLOUD_POINTS: usize = 1_000_000;

/// `createPointCloud` option bit 0: points are shown in random colours.
pub const POINTCLOUD_RANDOM_COLORS: i64 = 1;
/// Option bit 1: show the OC-tree structure (kept and reported; the viewer does not draw it).
pub const POINTCLOUD_SHOW_OCTREE: i64 = 2;
/// Option bit 3: do not use a calculation structure; insertions skip the duplicate check.
pub const POINTCLOUD_NO_STRUCTURE: i64 = 8;
/// Option bit 4: the colour is emissive (kept and reported; the viewer draws unlit points).
pub const POINTCLOUD_EMISSIVE: i64 = 16;
/// The option bits CoppeliaSim keeps; others are dropped, as `getPointCloudOptions`
/// reports only these.
const OPTION_BITS: i64 =
    POINTCLOUD_RANDOM_COLORS | POINTCLOUD_SHOW_OCTREE | POINTCLOUD_NO_STRUCTURE | POINTCLOUD_EMISSIVE;

/// CoppeliaSim's range of the maximum voxel size, m; other values are clamped.
pub const VOXEL_SIZE_RANGE: (f64, f64) = (0.001, 1.0);
/// CoppeliaSim's range of the maximum point count per voxel; other values are clamped.
pub const POINTS_PER_VOXEL_RANGE: (i64, i64) = (1, 100);
/// CoppeliaSim's range of the point size, pixels; other values are clamped.
pub const POINT_SIZE_RANGE: (i64, i64) = (1, 8);
/// Largest insertion tolerance, m (CoppeliaSim clamps to it).
pub const MAX_INSERTION_TOLERANCE: f64 = 1.0;
/// The colour of points inserted without one: CoppeliaSim's default white.
pub const DEFAULT_POINT_COLOR: [u8; 3] = [255, 255, 255];

/// Source of [`PointCloud::generation`] numbers, shared by every cloud of the process so
/// a number never names two contents, even across worlds rebuilt at a stop.
static GENERATIONS: AtomicU64 = AtomicU64::new(1);

fn next_generation() -> u64 {
    GENERATIONS.fetch_add(1, Ordering::Relaxed)
}

/// A point cloud's settings, as `sim.getPointCloudOptions` reports them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointCloudOptions {
    /// Largest voxel edge, m, in [`VOXEL_SIZE_RANGE`].
    pub max_voxel_size: f64,
    /// Most points per voxel before CoppeliaSim splits it, in [`POINTS_PER_VOXEL_RANGE`].
    pub max_points_per_voxel: i64,
    /// Option bits ([`POINTCLOUD_RANDOM_COLORS`], ...).
    pub options: i64,
    /// Point size in pixels, in [`POINT_SIZE_RANGE`].
    pub point_size: i64,
}

impl PointCloudOptions {
    /// Settings from `sim.createPointCloud`'s or `sim.setPointCloudOptions`'s arguments,
    /// clamped into CoppeliaSim's ranges (the point size is rounded to whole pixels);
    /// unknown option bits are dropped.
    ///
    /// # Errors
    /// A negative or non-finite size or count.
    pub fn new(
        max_voxel_size: f64,
        max_points_per_voxel: i64,
        options: i64,
        point_size: f64,
    ) -> Result<Self, SimError> {
        if !max_voxel_size.is_finite() || max_voxel_size < 0.0 {
            return Err(SimError::BadArgument(format!(
                "max voxel size must be a finite number >= 0 (m), got {max_voxel_size}"
            )));
        }
        if max_points_per_voxel < 0 {
            return Err(SimError::BadArgument(format!(
                "max point count per voxel must be >= 0, got {max_points_per_voxel}"
            )));
        }
        if !point_size.is_finite() || point_size < 0.0 {
            return Err(SimError::BadArgument(format!(
                "point size must be a finite number >= 0 (pixels), got {point_size}"
            )));
        }
        // The size is finite and non-negative, so the rounded value fits once clamped.
        let pixels = (point_size + 0.5).floor().min(POINT_SIZE_RANGE.1 as f64) as i64;
        Ok(Self {
            max_voxel_size: max_voxel_size.clamp(VOXEL_SIZE_RANGE.0, VOXEL_SIZE_RANGE.1),
            max_points_per_voxel: max_points_per_voxel.clamp(POINTS_PER_VOXEL_RANGE.0, POINTS_PER_VOXEL_RANGE.1),
            options: options & OPTION_BITS,
            point_size: pixels.clamp(POINT_SIZE_RANGE.0, POINT_SIZE_RANGE.1),
        })
    }

    /// Whether points are shown in random colours.
    pub fn random_colors(&self) -> bool {
        self.options & POINTCLOUD_RANDOM_COLORS != 0
    }

    /// Whether the calculation structure is off (no duplicate check on insertion).
    pub fn no_structure(&self) -> bool {
        self.options & POINTCLOUD_NO_STRUCTURE != 0
    }
}

impl Default for PointCloudOptions {
    /// CoppeliaSim's defaults for a point cloud added from its menu.
    fn default() -> Self {
        Self {
            max_voxel_size: 0.02,
            max_points_per_voxel: 20,
            options: 0,
            point_size: 4,
        }
    }
}

/// The colours of points being inserted, RGB bytes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PointColors<'a> {
    /// [`DEFAULT_POINT_COLOR`] for every point.
    Default,
    /// One colour for every point.
    Uniform([u8; 3]),
    /// One colour per point, in the points' order.
    PerPoint(&'a [[u8; 3]]),
}

/// A point cloud's points, colours and settings.
#[derive(Clone)]
pub struct PointCloud {
    options: PointCloudOptions,
    /// Points in the cloud's frame, m, in insertion order.
    points: Vec<Vec3>,
    /// `colors[i]` is the colour of `points[i]`.
    colors: Vec<[u8; 3]>,
    /// Indices into `points` by voxel (cells of `options.max_voxel_size`).
    grid: HashMap<[i64; 3], Vec<u32>>,
    generation: u64,
}

impl std::fmt::Debug for PointCloud {
    /// A summary: a cloud may hold a million points.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PointCloud")
            .field("options", &self.options)
            .field("points", &self.points.len())
            .field("generation", &self.generation)
            .finish()
    }
}

impl PointCloud {
    /// An empty cloud with these settings.
    pub fn new(options: PointCloudOptions) -> Self {
        Self {
            options,
            points: Vec::new(),
            colors: Vec::new(),
            grid: HashMap::new(),
            generation: next_generation(),
        }
    }

    /// The settings.
    pub fn options(&self) -> PointCloudOptions {
        self.options
    }

    /// Changes the settings (`sim.setPointCloudOptions`); the points stay.
    pub fn set_options(&mut self, options: PointCloudOptions) {
        let regrid = options.max_voxel_size != self.options.max_voxel_size;
        self.options = options;
        if regrid {
            self.rebuild_grid();
        }
        self.generation = next_generation();
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the cloud holds no point.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The points in the cloud's frame, m, in insertion order.
    pub fn points(&self) -> &[Vec3] {
        &self.points
    }

    /// The points' colours, RGB bytes, in the order of [`PointCloud::points`].
    pub fn colors(&self) -> &[[u8; 3]] {
        &self.colors
    }

    /// A number that changes whenever the points or settings do, and never names
    /// another content in this process: the viewer sends a cloud again only when it
    /// changes.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Inserts points given in the cloud's frame, skipping any closer than `tolerance`
    /// (m) to a point already in the cloud or inserted before it in this call (unless
    /// the cloud has no calculation structure, or `tolerance` is 0). Returns the number
    /// of points in the cloud.
    ///
    /// # Errors
    /// A negative or non-finite tolerance (larger ones are clamped to
    /// [`MAX_INSERTION_TOLERANCE`]), a colour per point for another number of points, a
    /// non-finite coordinate, or more than [`MAX_POINT_CLOUD_POINTS`] in the cloud
    /// afterwards; then nothing is inserted.
    pub fn insert(&mut self, points: &[Vec3], colors: PointColors<'_>, tolerance: f64) -> Result<usize, SimError> {
        if !tolerance.is_finite() || tolerance < 0.0 {
            return Err(SimError::BadArgument(format!(
                "duplicate tolerance must be a finite number >= 0 (m), got {tolerance}"
            )));
        }
        if let PointColors::PerPoint(c) = colors
            && c.len() != points.len()
        {
            return Err(SimError::BadArgument(format!(
                "{} colours for {} points: give one colour per point",
                c.len(),
                points.len()
            )));
        }
        if let Some(i) = points.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
            return Err(SimError::BadArgument(format!(
                "point {} has a non-finite coordinate",
                i + 1
            )));
        }
        let tolerance = tolerance.min(MAX_INSERTION_TOLERANCE);
        let check = tolerance > 0.0 && !self.options.no_structure();
        let before = self.points.len();
        for (i, p) in points.iter().enumerate() {
            if check && self.any_closer_than(p, tolerance) {
                continue;
            }
            if self.points.len() >= MAX_POINT_CLOUD_POINTS {
                self.truncate(before);
                return Err(SimError::Refused(format!(
                    "a point cloud holds at most {MAX_POINT_CLOUD_POINTS} points; remove some first \
                     (sim.removePointsFromPointCloud)"
                )));
            }
            let color = match colors {
                PointColors::Default => DEFAULT_POINT_COLOR,
                PointColors::Uniform(c) => c,
                PointColors::PerPoint(c) => c[i],
            };
            self.push(*p, color);
        }
        if self.points.len() != before {
            self.generation = next_generation();
        }
        Ok(self.points.len())
    }

    /// Removes every point closer than `tolerance` (m) to one of `near` (cloud frame).
    /// Returns how many were removed.
    ///
    /// # Errors
    /// A negative or non-finite tolerance, or a non-finite coordinate.
    pub fn remove_near(&mut self, near: &[Vec3], tolerance: f64) -> Result<usize, SimError> {
        let hit = self.hits(near, tolerance)?;
        let removed = hit.iter().filter(|h| **h).count();
        if removed > 0 {
            self.retain(|i| !hit[i]);
        }
        Ok(removed)
    }

    /// Keeps only the points closer than `tolerance` (m) to one of `near` (cloud frame)
    /// (`sim.intersectPointsWithPointCloud`). Returns the number of points left.
    ///
    /// # Errors
    /// As [`PointCloud::remove_near`].
    pub fn intersect(&mut self, near: &[Vec3], tolerance: f64) -> Result<usize, SimError> {
        let hit = self.hits(near, tolerance)?;
        if hit.iter().any(|h| !*h) {
            self.retain(|i| hit[i]);
        }
        Ok(self.points.len())
    }

    /// Removes every point.
    pub fn clear(&mut self) {
        if !self.points.is_empty() {
            self.points.clear();
            self.colors.clear();
            self.grid.clear();
            self.generation = next_generation();
        }
    }

    /// Which stored points lie closer than `tolerance` to one of `near`.
    fn hits(&self, near: &[Vec3], tolerance: f64) -> Result<Vec<bool>, SimError> {
        if !tolerance.is_finite() || tolerance < 0.0 {
            return Err(SimError::BadArgument(format!(
                "tolerance must be a finite number >= 0 (m), got {tolerance}"
            )));
        }
        if let Some(i) = near.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
            return Err(SimError::BadArgument(format!(
                "point {} has a non-finite coordinate",
                i + 1
            )));
        }
        let mut hit = vec![false; self.points.len()];
        for p in near {
            self.for_each_candidate(p, tolerance, |i| {
                if (self.points[i] - p).norm_squared() < tolerance * tolerance {
                    hit[i] = true;
                }
                false
            });
        }
        Ok(hit)
    }

    /// Whether a stored point lies closer than `tolerance` to `p`.
    fn any_closer_than(&self, p: &Vec3, tolerance: f64) -> bool {
        let t2 = tolerance * tolerance;
        let mut found = false;
        self.for_each_candidate(p, tolerance, |i| {
            found = (self.points[i] - p).norm_squared() < t2;
            found
        });
        found
    }

    /// Calls `f` with the index of every stored point in the voxels that the cube of
    /// half-size `reach` around `p` overlaps (a superset of the points within `reach`),
    /// until `f` returns true. When that cube spans more voxels than are occupied, every
    /// occupied voxel is visited instead, so a large reach costs at most a full scan.
    fn for_each_candidate(&self, p: &Vec3, reach: f64, mut f: impl FnMut(usize) -> bool) {
        let lo = self.cell(&p.add_scalar(-reach));
        let hi = self.cell(&p.add_scalar(reach));
        let span: f64 = (0..3).map(|k| (hi[k] as f64 - lo[k] as f64) + 1.0).product();
        if span > self.grid.len() as f64 {
            for i in self.grid.values().flatten() {
                if f(*i as usize) {
                    return;
                }
            }
            return;
        }
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    for i in self.grid.get(&[x, y, z]).into_iter().flatten() {
                        if f(*i as usize) {
                            return;
                        }
                    }
                }
            }
        }
    }

    /// The voxel holding `p`. Coordinates far beyond the grid saturate, which only
    /// makes distant voxels share a key.
    fn cell(&self, p: &Vec3) -> [i64; 3] {
        let s = self.options.max_voxel_size;
        [p.x, p.y, p.z].map(|v| (v / s).floor() as i64)
    }

    fn push(&mut self, p: Vec3, color: [u8; 3]) {
        // Below MAX_POINT_CLOUD_POINTS, so the index fits a u32.
        let i = self.points.len() as u32;
        self.grid.entry(self.cell(&p)).or_default().push(i);
        self.points.push(p);
        self.colors.push(color);
    }

    /// Drops the points from index `len` on (an insertion refused part-way).
    fn truncate(&mut self, len: usize) {
        self.points.truncate(len);
        self.colors.truncate(len);
        self.rebuild_grid();
    }

    /// Keeps the points whose index passes `keep`, in order.
    fn retain(&mut self, keep: impl Fn(usize) -> bool) {
        let mut i = 0;
        self.points.retain(|_| {
            i += 1;
            keep(i - 1)
        });
        let mut i = 0;
        self.colors.retain(|_| {
            i += 1;
            keep(i - 1)
        });
        self.rebuild_grid();
        self.generation = next_generation();
    }

    fn rebuild_grid(&mut self) {
        self.grid.clear();
        for (i, p) in self.points.iter().enumerate() {
            let key = self.cell(p);
            self.grid.entry(key).or_default().push(i as u32);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cloud(voxel: f64) -> PointCloud {
        PointCloud::new(PointCloudOptions::new(voxel, 10, 0, 2.0).expect("options"))
    }

    #[test]
    fn options_are_clamped_into_coppeliasims_ranges() {
        let o = PointCloudOptions::new(100.0, 1000, 0xff, 10.0).expect("options");
        assert_eq!(
            (o.max_voxel_size, o.max_points_per_voxel, o.options, o.point_size),
            (1.0, 100, 27, 8)
        );
        let o = PointCloudOptions::new(0.0, 0, 0, 0.4).expect("options");
        assert_eq!((o.max_voxel_size, o.max_points_per_voxel, o.point_size), (0.001, 1, 1));
        assert_eq!(PointCloudOptions::new(0.01, 10, 0, 2.5).expect("options").point_size, 3);
        assert!(PointCloudOptions::new(-0.01, 10, 0, 2.0).is_err());
        assert!(PointCloudOptions::new(0.01, -1, 0, 2.0).is_err());
        assert!(PointCloudOptions::new(0.01, 10, 0, f64::NAN).is_err());
    }

    #[test]
    fn duplicates_are_skipped_within_the_tolerance_across_voxels() {
        let mut c = cloud(0.01);
        // 4 mm apart across a voxel boundary: a duplicate within 5 mm, not within 3 mm.
        let a = Vec3::new(0.0099, 0.0, 0.0);
        let b = Vec3::new(0.0139, 0.0, 0.0);
        assert_eq!(c.insert(&[a, b], PointColors::Default, 0.005).expect("insert"), 1);
        let mut c = cloud(0.01);
        assert_eq!(c.insert(&[a, b], PointColors::Default, 0.003).expect("insert"), 2);
        // A tolerance far larger than a voxel scans everything instead of 10^6 cells.
        let mut c = cloud(0.001);
        c.insert(&[a], PointColors::Default, 0.0).expect("insert");
        assert_eq!(
            c.insert(&[Vec3::new(0.5, 0.5, 0.5)], PointColors::Default, 1.0)
                .expect("insert"),
            1
        );
    }

    #[test]
    fn removal_and_intersection_keep_order_and_colours() {
        let mut c = cloud(0.05);
        let pts: Vec<Vec3> = (0..5).map(|i| Vec3::new(f64::from(i) * 0.1, 0.0, 0.0)).collect();
        let cols: Vec<[u8; 3]> = (0..5u8).map(|i| [i, 0, 0]).collect();
        c.insert(&pts, PointColors::PerPoint(&cols), 0.0).expect("insert");
        assert_eq!(c.remove_near(&[Vec3::new(0.1, 0.0, 0.0)], 0.01).expect("remove"), 1);
        assert_eq!(c.colors().iter().map(|c| c[0]).collect::<Vec<_>>(), [0, 2, 3, 4]);
        assert_eq!(c.intersect(&[Vec3::new(0.31, 0.0, 0.0)], 0.02).expect("intersect"), 1);
        assert_eq!(c.colors(), [[3, 0, 0]]);
        // The index follows the compaction: the kept point is found again.
        assert_eq!(c.remove_near(&[Vec3::new(0.3, 0.0, 0.0)], 0.001).expect("remove"), 1);
        assert!(c.is_empty());
    }

    #[test]
    fn generation_changes_with_content_only() {
        let mut c = cloud(0.01);
        let g0 = c.generation();
        c.insert(&[Vec3::zeros()], PointColors::Default, 0.0).expect("insert");
        let g1 = c.generation();
        assert_ne!(g0, g1);
        c.insert(&[Vec3::zeros()], PointColors::Default, 0.001)
            .expect("duplicate");
        assert_eq!(c.generation(), g1, "nothing was inserted");
        assert_eq!(c.remove_near(&[Vec3::new(1.0, 0.0, 0.0)], 0.1).expect("remove"), 0);
        assert_eq!(c.generation(), g1, "nothing was removed");
    }
}
