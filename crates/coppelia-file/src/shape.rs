//! Shapes: mass properties, dynamic flags, material and geometry.
//!
//! A shape's type-specific part holds `Ge2` (its geometry), `Mat` (engine materials),
//! `Dc2` (respondable mask), `Sss` and `Ss3` (dynamic and respondable flags). `Ge2`
//! holds one geometry node: `Gst` for a single mesh or `Gsg` for a compound whose `Geo`
//! (mesh) and `Wrp` (sub-compound) children may nest. A mesh node has two parts, each
//! ending in `EOO`: the wrapper part shared with compounds (name, mass, inertia), then
//! the mesh part (buffer numbers, primitive type and size, vertex frame, colour,
//! texture).
//!
//! Frames: vertices are stored in the leaf's vertex frame; `Ppf`/`_pf` places that frame
//! in the shape frame. Every version writes `Ppf`/`_pf` that way (4.5.2+ files compute it
//! from their newer `Ifr`/`Bbf` frames), so one rule covers all files. Mass properties
//! come from the root node: the centre of mass and the per-kg inertia in the shape
//! frame, from `Com`/`Imx` (4.5.2+) or else from `Ine`/`_ne` (principal frame and
//! moments), which all versions write.

use std::sync::Arc;

use crate::chunk::{At, Chunk, Chunks};
use crate::error::ReadError;
use crate::field::{Fields, is_double};
use crate::mesh::MeshBuffers;
use crate::pose::Pose;
use crate::texture::{self, TextureProperty};

/// Most mesh leaves in one file.
pub const MAX_LEAVES: usize = 1 << 20;

/// A shape object's own part.
#[derive(Debug, Clone, PartialEq)]
pub struct Shape {
    /// Simulated as a dynamic body (`Sss` bit 7); otherwise static.
    pub dynamic: bool,
    /// Takes part in collision responses (`Ss3` bit 0).
    pub respondable: bool,
    /// CoppeliaSim's 16-bit collision mask: 8 bits within a model, 8 across models.
    pub respondable_mask: u16,
    /// Mass, kg. Static shapes store one too; it does not act in CoppeliaSim.
    pub mass: f64,
    /// Centre of mass in the shape frame, m.
    pub centre_of_mass: [f64; 3],
    /// Inertia per kg of mass (m²) about the centre of mass, shape-frame axes,
    /// row-major. Multiply by [`Shape::mass`] for kg·m².
    pub inertia_per_kg: [[f64; 3]; 3],
    /// Bullet friction coefficient, when the shape carries an engine material.
    pub friction: Option<f64>,
    /// Bullet restitution, when the shape carries an engine material.
    pub restitution: Option<f64>,
    /// Whether the geometry is a compound (`Gsg`) rather than one mesh (`Gst`).
    pub compound: bool,
    /// The meshes: one for a simple shape, the leaves of the tree for a compound.
    pub leaves: Vec<ShapeLeaf>,
}

/// The primitive a mesh was created as (its triangles are stored either way).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PrimitiveKind {
    /// A free-form mesh.
    None,
    /// A plane, x × y.
    Plane,
    /// A disc of diameter x.
    Disc,
    /// A box, x × y × z.
    Cuboid,
    /// An ellipsoid of diameters x, y, z (a sphere when they are equal).
    Spheroid,
    /// A cylinder of diameter x (elliptic if y differs) and height z, along z.
    Cylinder,
    /// A cone of base diameter x and height z, along z.
    Cone,
    /// A heightfield.
    Heightfield,
    /// A capsule of diameter x and height z, along z.
    Capsule,
    /// A value this reader does not know.
    Other(i32),
}

impl PrimitiveKind {
    fn from_code(code: i32) -> PrimitiveKind {
        match code {
            0 => PrimitiveKind::None,
            1 => PrimitiveKind::Plane,
            2 => PrimitiveKind::Disc,
            3 => PrimitiveKind::Cuboid,
            4 => PrimitiveKind::Spheroid,
            5 => PrimitiveKind::Cylinder,
            6 => PrimitiveKind::Cone,
            7 => PrimitiveKind::Heightfield,
            8 => PrimitiveKind::Capsule,
            other => PrimitiveKind::Other(other),
        }
    }
}

/// One mesh of a shape.
#[derive(Debug, Clone, PartialEq)]
pub struct ShapeLeaf {
    /// The mesh's own name (`sub__0` and the like; not an object name).
    pub name: String,
    /// Mass of this leaf, kg (the shape's mass is the root's).
    pub mass: f64,
    /// The frame the vertices are expressed in, relative to the shape frame.
    pub frame: Pose,
    /// The primitive it was created as.
    pub primitive: PrimitiveKind,
    /// Primitive sizes x, y, z, m (see [`PrimitiveKind`] for their meaning).
    pub size: [f64; 3],
    /// Diffuse colour, RGB 0-1, when stored.
    pub colour: Option<[f32; 3]>,
    /// Vertices, m, in [`ShapeLeaf::frame`].
    pub vertices: Arc<[[f32; 3]]>,
    /// Triangles, three indices into [`ShapeLeaf::vertices`] each; every index is
    /// checked to be in range.
    pub indices: Arc<[u32]>,
    /// One normal per index, when the file's buffer exists.
    pub normals: Option<Arc<[[f32; 3]]>>,
    /// The texture it wears (`Toj`), if any.
    pub texture: Option<TextureProperty>,
}

/// Mass properties of a geometry node.
#[derive(Default)]
struct NodeMass {
    mass: f64,
    com: [f64; 3],
    inertia: [[f64; 3]; 3],
    /// `Com`/`Imx` seen (they win over `Ine`).
    has_matrix: bool,
    name: String,
}

/// Reads a shape's type-specific chunks.
pub fn read(chunks: &[Chunk], at: &At, buffers: &MeshBuffers) -> Result<Shape, ReadError> {
    let mut shape = Shape {
        dynamic: false,
        respondable: false,
        respondable_mask: 0xffff,
        mass: 0.0,
        centre_of_mass: [0.0; 3],
        inertia_per_kg: [[0.0; 3]; 3],
        friction: None,
        restitution: None,
        compound: false,
        leaves: Vec::new(),
    };
    for c in chunks {
        let mut f = Fields::new(c, at);
        match &c.tag {
            b"Ge2" => {
                let here = at.child(c.tag, c.offset);
                let (nodes, _) = Chunks::new(c.payload, &here).part(false)?;
                for node in nodes.iter().filter(|n| matches!(&n.tag, b"Gst" | b"Gsg")) {
                    shape.compound = &node.tag == b"Gsg";
                    shape.leaves.clear();
                    let m = read_node(node, &here, buffers, &mut shape.leaves)?;
                    shape.mass = m.mass;
                    shape.centre_of_mass = m.com;
                    shape.inertia_per_kg = m.inertia;
                }
            }
            b"Mat" => read_material(c, at, &mut shape)?,
            b"Dc2" => shape.respondable_mask = f.u16()?,
            b"Sss" => shape.dynamic = f.u8()? & 0x80 != 0,
            b"Ss3" => shape.respondable = f.u8()? & 0x01 != 0,
            _ => {}
        }
    }
    Ok(shape)
}

/// The Bullet material values: `BuN`/`_uN` hold a float count, an int count, then the
/// floats, of which 0 is the restitution and 2 the friction (1 is an older friction).
fn read_material(c: &Chunk, at: &At, shape: &mut Shape) -> Result<(), ReadError> {
    let here = at.child(c.tag, c.offset);
    let (chunks, _) = Chunks::new(c.payload, &here).part(false)?;
    for m in chunks.iter().filter(|m| matches!(&m.tag, b"BuN" | b"_uN")) {
        let mut f = Fields::new(m, &here);
        let floats = f.i32()?;
        let _ints = f.i32()?;
        if floats >= 3 {
            let [restitution, _old_friction, friction] = f.reals::<3>(is_double(m.tag))?;
            shape.restitution = Some(restitution);
            shape.friction = Some(friction);
        }
    }
    Ok(())
}

/// Reads a geometry node (`Gst`/`Geo` mesh or `Gsg`/`Wrp` compound), appending its
/// leaves, and returns its mass properties.
fn read_node(
    node: &Chunk,
    parent: &At,
    buffers: &MeshBuffers,
    leaves: &mut Vec<ShapeLeaf>,
) -> Result<NodeMass, ReadError> {
    let at = parent.child(node.tag, node.offset);
    at.check_depth()?;
    let mut stream = Chunks::new(node.payload, &at);
    let (wrapper, end) = stream.part(false)?;
    if end.is_none() {
        return Err(at.chunk_error(stream.offset(), "geometry node lacks its EOO"));
    }
    let mut mass = NodeMass::default();
    let mut ine: Option<(Pose, [f64; 3])> = None;
    for c in &wrapper {
        let mut f = Fields::new(c, &at);
        match &c.tag {
            b"Nme" => mass.name = f.string()?,
            b"Mas" | b"_as" => mass.mass = f.reals::<1>(is_double(c.tag))?[0],
            b"Ine" | b"_ne" => {
                let frame = Pose::from_position_first(f.reals::<7>(is_double(c.tag))?);
                ine = Some((frame, f.reals::<3>(is_double(c.tag))?));
            }
            b"Com" => {
                mass.com = f.reals::<3>(true)?;
                mass.has_matrix = true;
            }
            b"Imx" => {
                let v = f.reals::<9>(true)?;
                mass.inertia = [[v[0], v[1], v[2]], [v[3], v[4], v[5]], [v[6], v[7], v[8]]];
                mass.has_matrix = true;
            }
            b"Geo" | b"Wrp" => {
                read_node(c, &at, buffers, leaves)?;
            }
            _ => {}
        }
    }
    if !mass.has_matrix
        && let Some((frame, moments)) = ine
    {
        mass.com = frame.position;
        mass.inertia = principal_to_matrix(&frame, moments);
    }
    if matches!(&node.tag, b"Gst" | b"Geo") {
        let (mesh, end) = stream.part(false)?;
        if end.is_none() {
            return Err(at.chunk_error(stream.offset(), "mesh part lacks its EOO"));
        }
        if leaves.len() == MAX_LEAVES {
            return Err(ReadError::TooMany {
                what: "shape meshes",
                max: MAX_LEAVES,
            });
        }
        leaves.push(read_mesh(&mesh, &at, buffers, &mass)?);
    }
    Ok(mass)
}

/// `R diag(m) Rᵀ`: the inertia matrix of principal moments `m` about axes `frame`.
fn principal_to_matrix(frame: &Pose, m: [f64; 3]) -> [[f64; 3]; 3] {
    let r = frame.rotation_matrix();
    let mut out = [[0.0; 3]; 3];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = (0..3).map(|k| r[i][k] * m[k] * r[j][k]).sum();
        }
    }
    out
}

/// The mesh part of a leaf.
fn read_mesh(chunks: &[Chunk], at: &At, buffers: &MeshBuffers, mass: &NodeMass) -> Result<ShapeLeaf, ReadError> {
    let mut vertices = None;
    let mut indices = None;
    let mut normals = None;
    let mut leaf_frame = Pose::IDENTITY;
    let mut primitive = PrimitiveKind::None;
    let mut size = [0.0; 3];
    let mut colour = None;
    let mut toj = None;
    for c in chunks {
        let mut f = Fields::new(c, at);
        match &c.tag {
            b"Vev" => vertices = Some((f.i32()?, c)),
            b"Inv" => indices = Some((f.i32()?, c)),
            b"Nov" => normals = Some(f.i32()?),
            b"Ppr" | b"_pr" => {
                primitive = PrimitiveKind::from_code(f.i32()?);
                size = f.reals::<3>(is_double(c.tag))?;
            }
            b"Ppf" | b"_pf" => leaf_frame = Pose::from_position_first(f.reals::<7>(is_double(c.tag))?),
            b"Cl0" => colour = read_colour(c, at)?,
            b"Toj" => toj = Some(c),
            _ => {}
        }
    }
    let buffer_error = |what: &str, n: Option<(i32, &Chunk)>| match n {
        Some((n, c)) => at
            .child(c.tag, c.offset)
            .value_error(format!("{what} buffer {n} does not exist")),
        None => at.value_error(format!("mesh has no {what} buffer number")),
    };
    let vert = vertices
        .and_then(|(n, _)| usize::try_from(n).ok())
        .and_then(|n| buffers.vertices.get(n))
        .ok_or_else(|| buffer_error("vertex", vertices))?;
    let index_number = indices.and_then(|(n, _)| usize::try_from(n).ok());
    let ind = index_number
        .and_then(|n| buffers.indices.get(n))
        .ok_or_else(|| buffer_error("index", indices))?;
    if ind.len() % 3 != 0 {
        return Err(at.value_error(format!("{} indices are not whole triangles", ind.len())));
    }
    if let Some(max) = index_number.and_then(|n| buffers.index_max(n))
        && max as usize >= vert.len()
    {
        return Err(at.value_error(format!("index {max} is beyond the mesh's {} vertices", vert.len())));
    }
    let normals = normals
        .and_then(|n| usize::try_from(n).ok())
        .and_then(|n| buffers.normals.get(n))
        .filter(|n| n.len() == ind.len())
        .cloned();
    // Read once the index count is known: fixed coordinates must fit it.
    let texture = match toj {
        Some(c) => texture::read_property(c, at, ind.len())?,
        None => None,
    };
    Ok(ShapeLeaf {
        name: mass.name.clone(),
        mass: mass.mass,
        frame: leaf_frame,
        primitive,
        size,
        colour,
        vertices: Arc::clone(vert),
        indices: Arc::clone(ind),
        normals,
        texture,
    })
}

/// A colour object (`Cl0`): `Cl2`/`Cl3` hold 15 f32, the first three the diffuse RGB.
fn read_colour(c: &Chunk, at: &At) -> Result<Option<[f32; 3]>, ReadError> {
    let here = at.child(c.tag, c.offset);
    let (chunks, _) = Chunks::new(c.payload, &here).part(false)?;
    let mut colour = None;
    for c in chunks.iter().filter(|c| matches!(&c.tag, b"Cl2" | b"Cl3")) {
        let rgb = Fields::new(c, &here).reals::<3>(false)?;
        colour = Some(rgb.map(|v| v as f32));
    }
    Ok(colour)
}
