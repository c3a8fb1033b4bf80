//! Drawing objects (`sim.addDrawingObject`): points, lines, line strips and triangles
//! that scripts draw into the scene, kept in the simulation ([`crate::sim::Sim::drawings`])
//! for the viewer and the API.
//!
//! The model follows CoppeliaSim's `CDrawingObject`:
//! - an object holds up to `max_items` items of one kind; a full object either refuses
//!   new items or, with [`DRAWING_CYCLIC`], drops its oldest item;
//! - items are stored in the frame of the parent object (the world frame when there is
//!   none), so they follow the parent when it moves. Coordinates passed in are world
//!   coordinates, or parent-frame coordinates with [`DRAWING_LOCAL`];
//! - a positive duplicate tolerance rejects a single-vertex item that lies within that
//!   distance (m, inclusive) of an item already stored.
//!
//! Non-goals: per-item colours, sizes and transparency (the `itemcolors`, `vertexcolors`,
//! `itemsizes` and `itemtransparency` flags) are parsed so packed item data keeps its
//! stride, but only the object's colour is kept. The oriented point types (triangle,
//! quad, disc and cube points) are stored as plain points: their normal or quaternion is
//! skipped.

use std::collections::{BTreeMap, VecDeque};

use crate::error::SimError;
use crate::handle::Handle;
use crate::math::{Pose, Vec3};
use crate::world::World;

/// The first drawing object handle. Drawing objects, collections and scene objects
/// never share handles, so passing one where another is expected fails clearly.
pub const FIRST_DRAWING_HANDLE: Handle = 3_000_000;

/// `sim.handleflag_addmultiple` (CoppeliaSim 4.6's 32-bit value): OR-ed on the handle
/// passed to `sim.addDrawingObjectItem`, it makes the item data a packed list of items.
/// Handles stay below this bit (see [`Drawings::create`]).
pub const HANDLEFLAG_ADD_MULTIPLE: Handle = 0x0100_0000;

/// Items kept when `maxItemCount` is 0 (CoppeliaSim 4.6's default).
pub const DEFAULT_DRAWING_ITEMS: usize = 1000;

/// Absolute cap on the items of one object, whatever `maxItemCount` asks for, so a
/// script cannot grow memory without bound (CoppeliaSim clamps at 1,000,000; at most
/// 100,000 triangles are 7.2 MB here).
pub const MAX_DRAWING_ITEMS: usize = 100_000;

/// Cap on live drawing objects; creating more fails. Guards against a script that
/// creates an object every step and never removes it.
pub const MAX_DRAWING_OBJECTS: usize = 10_000;

/// `sim.drawing_cyclic`: when full, the oldest item is dropped to make room.
pub const DRAWING_CYCLIC: i64 = 0x1000;
/// `sim.drawing_local`: item coordinates are given in the parent object's frame.
pub const DRAWING_LOCAL: i64 = 0x80_0000;

/// The low bits of the object type select the item kind; the rest are flags.
const TYPE_MASK: i64 = 0x1f;
const DRAWING_ITEM_COLORS: i64 = 0x20;
const DRAWING_VERTEX_COLORS: i64 = 0x40;
const DRAWING_ITEM_SIZES: i64 = 0x80;
const DRAWING_FACING_CAMERA: i64 = 0x2_0000;
const DRAWING_ITEM_TRANSPARENCY: i64 = 0x8_0000;

/// Smallest and largest size CoppeliaSim accepts (pixels or m); others are clamped.
const SIZE_RANGE: (f64, f64) = (0.0001, 100.0);

/// What the items of a drawing object are, from the low 5 bits of its type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DrawingKind {
    /// `sim.drawing_points` (0): one vertex per item, drawn `size` pixels wide. Also
    /// every type gantry does not draw specially (oriented point types 3-6 and 9-12,
    /// unknown codes).
    Points,
    /// `sim.drawing_lines` (1): two vertices per item, a segment `size` pixels wide.
    Lines,
    /// `sim.drawing_triangles` (2): three vertices per item.
    Triangles,
    /// `sim.drawing_spherepts` (7): one vertex per item, a sphere of diameter `size` m.
    SpherePoints,
    /// `sim.drawing_linestrip` (8): one vertex per item; consecutive vertices are joined
    /// by segments `size` pixels wide.
    LineStrip,
}

impl DrawingKind {
    /// The kind for an object type (flags are ignored), and whether gantry knows the
    /// type code exactly (`false`: drawn as points).
    pub fn from_type(object_type: i64) -> (Self, bool) {
        match object_type & TYPE_MASK {
            0 => (DrawingKind::Points, true),
            1 => (DrawingKind::Lines, true),
            2 => (DrawingKind::Triangles, true),
            7 => (DrawingKind::SpherePoints, true),
            8 => (DrawingKind::LineStrip, true),
            _ => (DrawingKind::Points, false),
        }
    }

    /// Vertices per item: 2 for lines, 3 for triangles, 1 otherwise.
    pub fn vertices_per_item(self) -> usize {
        match self {
            DrawingKind::Lines => 2,
            DrawingKind::Triangles => 3,
            DrawingKind::Points | DrawingKind::SpherePoints | DrawingKind::LineStrip => 1,
        }
    }
}

/// Numbers per item in packed item data, as CoppeliaSim counts them: the vertices, then
/// a normal (3) or quaternion (4) for oriented point types, per-item or per-vertex
/// colours (3 each), a size and a transparency.
fn floats_per_item(object_type: i64, kind: DrawingKind) -> usize {
    let code = object_type & TYPE_MASK;
    let has = |flag: i64| object_type & flag != 0;
    let mut n = 3 * kind.vertices_per_item();
    match code {
        // Old oriented types (trianglepoints .. cubepoints) take a normal.
        3..=6 => n += 3,
        // New oriented types (trianglepts .. cubepts) take a quaternion unless they
        // always face the camera.
        9..=12 if !has(DRAWING_FACING_CAMERA) => n += 4,
        _ => {}
    }
    let vertex_colors = has(DRAWING_VERTEX_COLORS) && !has(DRAWING_ITEM_COLORS) && matches!(code, 1 | 2 | 8);
    if has(DRAWING_ITEM_COLORS) {
        n += 3;
    }
    if vertex_colors {
        n += 3 * kind.vertices_per_item();
    }
    // CoppeliaSim drops `itemsizes` for triangles and `itemtransparency` together
    // with vertex colours.
    if has(DRAWING_ITEM_SIZES) && code != 2 {
        n += 1;
    }
    if has(DRAWING_ITEM_TRANSPARENCY) && !vertex_colors {
        n += 1;
    }
    n
}

/// What `sim.addDrawingObject` asks for, before normalisation.
#[derive(Debug, Clone, PartialEq)]
pub struct DrawingParams {
    /// CoppeliaSim's object type: a kind code OR-ed with flags ([`DRAWING_CYCLIC`],
    /// [`DRAWING_LOCAL`], ...).
    pub object_type: i64,
    /// Point size or line width in pixels; sphere diameter in m. Clamped to
    /// [0.0001, 100] as in CoppeliaSim.
    pub size: f64,
    /// Distance (m) within which a new single-vertex item counts as a duplicate and is
    /// refused; 0 (or negative) disables the check.
    pub duplicate_tolerance: f64,
    /// The object the items follow; `None` for the world.
    pub parent: Option<Handle>,
    /// Maximum item count; 0 means [`DEFAULT_DRAWING_ITEMS`], values above [`MAX_DRAWING_ITEMS`]
    /// are capped.
    pub max_items: usize,
    /// Ambient/diffuse colour, RGB in [0, 1].
    pub color: [f64; 3],
    /// Emission colour, RGB in [0, 1], if given (4.1 form).
    pub emission: Option<[f64; 3]>,
}

/// One drawing object and its items.
#[derive(Debug, Clone, PartialEq)]
pub struct DrawingObject {
    object_type: i64,
    kind: DrawingKind,
    size: f64,
    duplicate_tolerance: f64,
    parent: Option<Handle>,
    max_items: usize,
    floats_per_item: usize,
    color: [f64; 3],
    emission: Option<[f64; 3]>,
    /// Item vertices, oldest first, `kind.vertices_per_item()` per item, in the parent's
    /// frame (world frame without a parent). The length is always a multiple of the
    /// vertices per item.
    vertices: VecDeque<Vec3>,
}

impl DrawingObject {
    /// The object type as created (kind code and flags).
    pub fn object_type(&self) -> i64 {
        self.object_type
    }

    /// The item kind.
    pub fn kind(&self) -> DrawingKind {
        self.kind
    }

    /// Point size or line width in pixels; sphere diameter in m.
    pub fn size(&self) -> f64 {
        self.size
    }

    /// Duplicate tolerance, m (0: no check).
    pub fn duplicate_tolerance(&self) -> f64 {
        self.duplicate_tolerance
    }

    /// The object the items follow; `None` for the world.
    pub fn parent(&self) -> Option<Handle> {
        self.parent
    }

    /// Whether the oldest item is dropped when full.
    pub fn is_cyclic(&self) -> bool {
        self.object_type & DRAWING_CYCLIC != 0
    }

    /// Whether item coordinates are given in the parent's frame.
    pub fn is_local(&self) -> bool {
        self.object_type & DRAWING_LOCAL != 0
    }

    /// Maximum item count, after defaults and the [`MAX_DRAWING_ITEMS`] cap.
    pub fn max_items(&self) -> usize {
        self.max_items
    }

    /// Numbers one item takes in packed item data (`sim.handleflag_addmultiple`).
    pub fn floats_per_item(&self) -> usize {
        self.floats_per_item
    }

    /// Ambient/diffuse colour, RGB in [0, 1].
    pub fn color(&self) -> [f64; 3] {
        self.color
    }

    /// Emission colour, RGB in [0, 1], if one was given.
    pub fn emission(&self) -> Option<[f64; 3]> {
        self.emission
    }

    /// Number of items (for a line strip, of vertices).
    pub fn item_count(&self) -> usize {
        self.vertices.len() / self.kind.vertices_per_item()
    }

    /// The stored vertices, oldest first, in the parent's frame (world frame without a
    /// parent).
    pub fn stored_vertices(&self) -> impl ExactSizeIterator<Item = Vec3> + '_ {
        self.vertices.iter().copied()
    }

    /// The vertices in the world frame, oldest first, given the parent's current world
    /// pose (identity without a parent).
    pub fn world_vertices<'a>(&'a self, parent_frame: &'a Pose) -> impl ExactSizeIterator<Item = Vec3> + 'a {
        self.vertices
            .iter()
            .map(move |v| parent_frame.transform_point(&(*v).into()).coords)
    }

    /// World pose of the parent, which stored vertices are relative to: identity
    /// without a parent, or when the parent no longer exists (the items then stay
    /// where they were stored).
    pub fn frame(&self, world: &World) -> Pose {
        self.parent
            .and_then(|p| world.object(p).ok())
            .map_or_else(Pose::identity, |o| o.world)
    }

    /// Removes every item.
    pub fn clear(&mut self) {
        self.vertices.clear();
    }

    /// Adds one item from the first `3 * vertices_per_item` numbers of `data` (the
    /// rest, e.g. the distance `sim.checkDistance` appends to a segment, is ignored, as
    /// in CoppeliaSim). Coordinates are world-frame, or parent-frame for a local object;
    /// `parent_frame` is the parent's current world pose.
    ///
    /// Returns whether the item was added: `false` for a duplicate, or when the object
    /// is full and not cyclic.
    ///
    /// # Errors
    /// Too few numbers, or a non-finite one.
    pub fn add_item(&mut self, data: &[f64], parent_frame: &Pose) -> Result<bool, SimError> {
        let vpi = self.kind.vertices_per_item();
        let Some(coords) = data.get(..3 * vpi) else {
            return Err(SimError::BadArgument(format!(
                "item data needs at least {} numbers ({vpi} vertices), got {}",
                3 * vpi,
                data.len()
            )));
        };
        if let Some(i) = coords.iter().position(|v| !v.is_finite()) {
            return Err(SimError::BadArgument(format!(
                "item data element {} must be a finite number, got {}",
                i + 1,
                coords[i]
            )));
        }
        // Stored in the parent's frame so the items follow it (CoppeliaSim does the
        // same); a local object's coordinates already are.
        let to_stored = |p: &[f64]| {
            let v = Vec3::new(p[0], p[1], p[2]);
            if self.parent.is_some() && !self.is_local() {
                parent_frame.inverse_transform_point(&v.into()).coords
            } else {
                v
            }
        };
        let new: smallvec::SmallVec<[Vec3; 3]> = coords.chunks_exact(3).map(to_stored).collect();
        if self.duplicate_tolerance > 0.0 && vpi == 1 {
            let tol = self.duplicate_tolerance;
            if self.vertices.iter().any(|w| (w - new[0]).norm() <= tol) {
                return Ok(false);
            }
        }
        if self.item_count() >= self.max_items {
            if !self.is_cyclic() {
                return Ok(false);
            }
            for _ in 0..vpi {
                self.vertices.pop_front();
            }
        }
        self.vertices.extend(new);
        Ok(true)
    }

    /// Adds packed items, [`floats_per_item`](Self::floats_per_item) numbers each
    /// (`sim.handleflag_addmultiple`); trailing numbers that do not fill an item are
    /// ignored. Returns how many items were added.
    ///
    /// # Errors
    /// Fewer numbers than one item, or a non-finite coordinate. Items before the bad
    /// one stay added.
    pub fn add_items(&mut self, data: &[f64], parent_frame: &Pose) -> Result<usize, SimError> {
        let stride = self.floats_per_item;
        if data.len() < stride {
            return Err(SimError::BadArgument(format!(
                "item data needs at least {stride} numbers per item, got {}",
                data.len()
            )));
        }
        let mut added = 0;
        for item in data.chunks_exact(stride) {
            if self.add_item(item, parent_frame)? {
                added += 1;
            }
        }
        Ok(added)
    }
}

/// A drawing object with the world pose its items are relative to, for the viewer.
#[derive(Debug, Clone, Copy)]
pub struct DrawingView<'a> {
    /// The drawing object's handle.
    pub handle: Handle,
    /// The object.
    pub object: &'a DrawingObject,
    /// World pose of the parent (identity without one).
    pub frame: Pose,
}

impl DrawingView<'_> {
    /// The vertices in the world frame, oldest first, `kind().vertices_per_item()` per
    /// item (a line strip joins consecutive vertices).
    pub fn vertices(&self) -> impl ExactSizeIterator<Item = Vec3> + '_ {
        self.object.world_vertices(&self.frame)
    }
}

/// Every drawing object of the scene, by handle. Handles are allocated in increasing
/// order and never reused until [`Drawings::clear`], so iteration is creation order.
#[derive(Debug, Clone)]
pub struct Drawings {
    objects: BTreeMap<Handle, DrawingObject>,
    next_handle: Handle,
}

impl Default for Drawings {
    fn default() -> Self {
        Self {
            objects: BTreeMap::new(),
            next_handle: FIRST_DRAWING_HANDLE,
        }
    }
}

impl Drawings {
    /// Creates a drawing object and returns its handle. The parent must already have
    /// been checked to exist (the world does this in `sim.addDrawingObject`).
    ///
    /// # Errors
    /// Non-finite size or tolerance, [`MAX_DRAWING_OBJECTS`] live objects, or the
    /// handle space exhausted (about 13.7 million creations since the last clear).
    pub fn create(&mut self, params: DrawingParams) -> Result<Handle, SimError> {
        if !params.size.is_finite() {
            return Err(SimError::BadArgument(format!(
                "size must be a finite number, got {}",
                params.size
            )));
        }
        if !params.duplicate_tolerance.is_finite() {
            return Err(SimError::BadArgument(format!(
                "duplicate tolerance must be a finite number, got {}",
                params.duplicate_tolerance
            )));
        }
        if self.objects.len() >= MAX_DRAWING_OBJECTS {
            return Err(SimError::BadArgument(format!(
                "too many drawing objects ({MAX_DRAWING_OBJECTS}); remove some with sim.removeDrawingObject"
            )));
        }
        // Handles must stay below the add-multiple flag bit, which callers OR onto them.
        if self.next_handle >= HANDLEFLAG_ADD_MULTIPLE {
            return Err(SimError::BadArgument(
                "drawing object handles exhausted; remove all drawing objects to start over".into(),
            ));
        }
        let (kind, _) = DrawingKind::from_type(params.object_type);
        let max_items = match params.max_items {
            0 => DEFAULT_DRAWING_ITEMS,
            n => n.min(MAX_DRAWING_ITEMS),
        };
        let clamp01 = |c: [f64; 3]| c.map(|v| if v.is_finite() { v.clamp(0.0, 1.0) } else { 0.0 });
        let object = DrawingObject {
            object_type: params.object_type,
            kind,
            size: params.size.clamp(SIZE_RANGE.0, SIZE_RANGE.1),
            duplicate_tolerance: params.duplicate_tolerance.max(0.0),
            parent: params.parent,
            max_items,
            floats_per_item: floats_per_item(params.object_type, kind),
            color: clamp01(params.color),
            emission: params.emission.map(clamp01),
            vertices: VecDeque::new(),
        };
        let handle = self.next_handle;
        self.next_handle += 1;
        self.objects.insert(handle, object);
        Ok(handle)
    }

    /// The drawing object behind a handle, if any.
    pub fn get(&self, handle: Handle) -> Option<&DrawingObject> {
        self.objects.get(&handle)
    }

    /// The drawing object behind a handle.
    ///
    /// # Errors
    /// No drawing object has this handle.
    pub fn object(&self, handle: Handle) -> Result<&DrawingObject, SimError> {
        self.objects.get(&handle).ok_or_else(|| no_such(handle))
    }

    /// The drawing object behind a handle, mutably.
    ///
    /// # Errors
    /// No drawing object has this handle.
    pub fn object_mut(&mut self, handle: Handle) -> Result<&mut DrawingObject, SimError> {
        self.objects.get_mut(&handle).ok_or_else(|| no_such(handle))
    }

    /// Removes one drawing object.
    ///
    /// # Errors
    /// No drawing object has this handle.
    pub fn remove(&mut self, handle: Handle) -> Result<(), SimError> {
        self.objects.remove(&handle).map(|_| ()).ok_or_else(|| no_such(handle))
    }

    /// Removes every drawing object (`sim.removeDrawingObject(sim.handle_all)`, and
    /// simulation end) and restarts handle allocation.
    pub fn clear(&mut self) {
        *self = Self::default();
    }

    /// Number of drawing objects.
    pub fn len(&self) -> usize {
        self.objects.len()
    }

    /// Whether there are no drawing objects.
    pub fn is_empty(&self) -> bool {
        self.objects.is_empty()
    }

    /// Every drawing object with its handle, in creation order.
    pub fn iter(&self) -> impl Iterator<Item = (Handle, &DrawingObject)> {
        self.objects.iter().map(|(&h, o)| (h, o))
    }

    /// Every drawing object in creation order, with the current world pose of its
    /// parent so [`DrawingView::vertices`] yields world-frame vertices.
    pub fn iter_world<'a>(&'a self, world: &'a World) -> impl Iterator<Item = DrawingView<'a>> + 'a {
        self.iter().map(move |(handle, object)| DrawingView {
            handle,
            object,
            frame: object.frame(world),
        })
    }
}

fn no_such(handle: Handle) -> SimError {
    SimError::NoSuchItem(format!("drawing object does not exist (handle {handle})"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::pose_from_euler;

    fn params(object_type: i64, max_items: usize) -> DrawingParams {
        DrawingParams {
            object_type,
            size: 2.0,
            duplicate_tolerance: 0.0,
            parent: None,
            max_items,
            color: [1.0, 1.0, 0.0],
            emission: None,
        }
    }

    #[test]
    fn floats_per_item_follows_coppeliasim() {
        let f = |t: i64| floats_per_item(t, DrawingKind::from_type(t).0);
        assert_eq!(f(0), 3);
        assert_eq!(f(1), 6);
        assert_eq!(f(2), 9);
        assert_eq!(f(7), 3);
        assert_eq!(f(8 | DRAWING_CYCLIC), 3);
        assert_eq!(f(3), 6, "trianglepoints: vertex and normal");
        assert_eq!(f(9), 7, "trianglepts: vertex and quaternion");
        assert_eq!(f(9 | DRAWING_FACING_CAMERA), 3);
        assert_eq!(f(1 | DRAWING_ITEM_COLORS), 9);
        assert_eq!(f(1 | DRAWING_VERTEX_COLORS), 12);
        assert_eq!(f(2 | DRAWING_ITEM_SIZES), 9, "no item sizes on triangles");
        assert_eq!(f(DRAWING_ITEM_SIZES | DRAWING_ITEM_TRANSPARENCY), 5);
    }

    #[test]
    fn cyclic_line_strip_drops_oldest_and_plain_one_refuses() {
        let mut d = Drawings::default();
        let strip = d.create(params(8 | DRAWING_CYCLIC, 3)).expect("create");
        let plain = d.create(params(0, 3)).expect("create");
        let id = Pose::identity();
        for i in 0..5 {
            let p = [f64::from(i), 0.0, 0.0];
            assert!(d.object_mut(strip).expect("strip").add_item(&p, &id).expect("add"));
            let added = d.object_mut(plain).expect("plain").add_item(&p, &id).expect("add");
            assert_eq!(added, i < 3);
        }
        let xs: Vec<f64> = d.object(strip).expect("strip").stored_vertices().map(|v| v.x).collect();
        assert_eq!(xs, [2.0, 3.0, 4.0]);
        assert_eq!(d.object(plain).expect("plain").item_count(), 3);
    }

    #[test]
    fn parent_frame_items_follow_the_parent() {
        let mut d = Drawings::default();
        let mut p = params(0, 0);
        p.parent = Some(0);
        let h = d.create(p).expect("create");
        let at = pose_from_euler([1.0, 0.0, 0.0], [0.0, 0.0, std::f64::consts::FRAC_PI_2]);
        let o = d.object_mut(h).expect("object");
        o.add_item(&[1.0, 1.0, 0.0], &at).expect("add");
        // Stored relative to the parent: (0, 1) in the world is (1, 0) in a frame
        // rotated by 90 degrees about z at x = 1.
        let stored: Vec<Vec3> = o.stored_vertices().collect();
        assert!((stored[0] - Vec3::new(1.0, 0.0, 0.0)).norm() < 1e-12);
        let moved = pose_from_euler([2.0, 0.0, 0.0], [0.0, 0.0, std::f64::consts::FRAC_PI_2]);
        let w: Vec<Vec3> = o.world_vertices(&moved).collect();
        assert!((w[0] - Vec3::new(2.0, 1.0, 0.0)).norm() < 1e-12);
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        let mut d = Drawings::default();
        let h = d.create(params(2, 0)).expect("create");
        let id = Pose::identity();
        let o = d.object_mut(h).expect("object");
        assert!(o.add_item(&[0.0; 8], &id).is_err());
        assert!(
            o.add_item(&[0.0, f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], &id)
                .is_err()
        );
        assert!(o.add_items(&[], &id).is_err());
        let mut bad = params(0, 0);
        bad.size = f64::INFINITY;
        assert!(d.create(bad).is_err());
        assert!(d.remove(h + 100).is_err());
    }
}
