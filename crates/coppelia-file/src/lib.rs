//! A pure, bounded reader for CoppeliaSim's binary scene (`.ttt`) and model (`.ttm`)
//! files, as written by V-REP 3.2 (2014) through CoppeliaSim 4.10.
//!
//! Bytes in, typed values out: [`read`] takes the whole file and returns a
//! [`CoppeliaFile`] with the header facts, the objects in file order (parents first)
//! with their poses, flags and type-specific data, the embedded scripts and the
//! simulation settings. The caller does the I/O. Each layer of the format is described
//! in its module: [`header`] (the fixed header), [`huffman`] (the body's compression),
//! [`chunk`] (the tagged stream), then one module per part.
//!
//! What is read: shapes (mass properties, dynamic and respondable flags, collision mask,
//! Bullet friction and restitution, primitive type and size, meshes with their vertex
//! frame and colour, compounds as their leaves), joints, dummies, proximity, vision and
//! force sensors, scripts (main, child, customization; Lua or Python; the text decoded),
//! the extension strings, collections, IK groups (not yet imported), lights (type, on/off,
//! spot exponent and cutoff, attenuation, diffuse and specular colours: [`light`]), old
//! path objects' control points and attributes ([`path`]), the time step, engine,
//! gravity and engine step, and the environment's colours and fog ([`Environment`]).
//! Textures: the texture objects' images and each mesh leaf's texture (which texture,
//! mapping, fixed coordinates, flags: [`texture`]).
//! What is not: thumbnails, old collision/distance objects, custom data, graphs' streams,
//! cameras' display settings, engine-specific joint and material arrays beyond Bullet
//! friction and restitution. Unknown chunks are skipped whole; values that do not apply
//! are ignored.
//!
//! Bounds: the decoded body is capped at [`MAX_BODY_LEN`] and can be no longer than the
//! coded bits allow; every length is checked against the bytes that remain before any
//! allocation; nesting is capped at [`chunk::MAX_DEPTH`]; objects, scripts, mesh leaves,
//! buffer elements, collections and their items, path points have caps too ([`MAX_OBJECTS`], [`MAX_SCRIPTS`],
//! [`path::MAX_POINTS`],
//! [`MAX_COLLECTIONS`], [`collection::MAX_ITEMS`],
//! [`shape::MAX_LEAVES`], [`mesh::MAX_BUFFER_ELEMENTS`], [`texture::MAX_TEXTURES`],
//! [`texture::MAX_TEXTURE_SIDE`]). Shared mesh buffers are
//! reference-counted, never copied per mesh. The reader never panics; it is fuzzed
//! (`fuzz/fuzz_targets/coppelia_file.rs`).
//!
//! Files older than serialization version 18 are refused, as CoppeliaSim refuses them.

pub mod camera;
pub mod chunk;
pub mod collection;
pub mod dummy;
mod error;
mod field;
pub mod header;
pub mod huffman;
pub mod ik_group;
pub mod joint;
pub mod light;
pub mod mesh;
mod object;
pub mod path;
mod pose;
pub mod script;
pub mod sensor;
pub mod settings;
pub mod shape;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod testutil;
pub mod texture;

pub use camera::Camera;
pub use collection::{Collection, CollectionItem, CollectionItemKind};
pub use dummy::{Dummy, DummyLink};
pub use error::ReadError;
pub use header::{FileType, Header};
pub use ik_group::{IkElement, IkGroup};
pub use joint::{DynamicControl, Joint, JointDependency, JointMode, JointType};
pub use light::{Light, LightType};
pub use mesh::MeshBuffers;
pub use object::{ObjectKind, SceneObject, UserParameter};
pub use path::{OldPath, PathPoint};
pub use pose::Pose;
pub use script::{Script, ScriptLanguage, ScriptOrigin, ScriptType};
pub use sensor::{ForceSensor, ProximitySensor, ProximityVolume, VisionSensor};
pub use settings::{Engine, Environment, Settings};
pub use shape::{PrimitiveKind, Shape, ShapeLeaf};
pub use texture::{Texture, TextureMapping, TextureProperty};

use chunk::{At, Chunk, Chunks, Item};

/// Largest decoded body accepted, bytes (the largest public files decode to ~10 MB).
pub const MAX_BODY_LEN: usize = 512 * 1024 * 1024;
/// Most objects in one file.
pub const MAX_OBJECTS: usize = 1 << 20;
/// Most collections in one file.
pub const MAX_COLLECTIONS: usize = 1 << 16;
/// Most IK groups in one file.
pub const MAX_IK_GROUPS: usize = 1 << 16;
/// Most scripts in one file.
pub const MAX_SCRIPTS: usize = 1 << 16;

/// Everything [`read`] decodes from a file.
#[derive(Debug, Clone, PartialEq)]
pub struct CoppeliaFile {
    /// The header's facts.
    pub header: Header,
    /// The objects in file order; a parent always precedes its children in files
    /// CoppeliaSim writes (the reader does not rely on it).
    pub objects: Vec<SceneObject>,
    /// Embedded scripts: those of the top-level `LST` list, then those of script
    /// objects, in file order.
    pub scripts: Vec<Script>,
    /// Simulation settings.
    pub settings: Settings,
    /// Collections (`GRP`), in file order.
    pub collections: Vec<Collection>,
    /// IK groups (`IKO`), in file order (read, not yet imported by gantry's loader).
    pub ik_groups: Vec<IkGroup>,
    /// Texture objects (`TEX`), in file order.
    pub textures: Vec<Texture>,
}

impl CoppeliaFile {
    /// The object with this handle.
    pub fn object(&self, handle: i32) -> Option<&SceneObject> {
        self.objects.iter().find(|o| o.handle == handle)
    }

    /// The pose of every object in the world (or the model's) frame, in the order of
    /// [`CoppeliaFile::objects`]: local poses composed up the tree, with each joint's
    /// [`Joint::intrinsic_pose`] between a joint and its children. `None` for an object
    /// whose parent chain is broken (a missing parent or a cycle).
    pub fn world_poses(&self) -> Vec<Option<Pose>> {
        #[derive(Clone, Copy)]
        enum State {
            Unknown,
            Placed(Pose),
            Broken,
        }
        let index: std::collections::HashMap<i32, usize> =
            self.objects.iter().enumerate().map(|(i, o)| (o.handle, i)).collect();
        let mut state = vec![State::Unknown; self.objects.len()];
        let mut chain = Vec::new();
        for start in 0..self.objects.len() {
            // Walk up to the first settled ancestor (or the root), then settle the chain
            // downwards, so each object is walked once. A chain longer than the object
            // count is a cycle.
            chain.clear();
            chain.push(start);
            let mut base = Some(Pose::IDENTITY);
            while let Some(&i) = chain.last() {
                if !matches!(state[i], State::Unknown) {
                    chain.pop();
                    base = match state[i] {
                        State::Placed(_) if chain.is_empty() => None,
                        State::Placed(p) => Some(p.compose(&self.joint_motion(i))),
                        _ => None,
                    };
                    break;
                }
                if chain.len() > self.objects.len() {
                    base = None;
                    break;
                }
                let Some(parent) = self.objects[i].parent else { break };
                match index.get(&parent) {
                    Some(&p) => chain.push(p),
                    None => {
                        base = None;
                        break;
                    }
                }
            }
            let Some(mut pose) = base else {
                for &i in &chain {
                    if matches!(state[i], State::Unknown) {
                        state[i] = State::Broken;
                    }
                }
                continue;
            };
            for k in (0..chain.len()).rev() {
                let i = chain[k];
                if k + 1 < chain.len() {
                    pose = pose.compose(&self.joint_motion(chain[k + 1]));
                }
                pose = pose.compose(&self.objects[i].local_pose);
                state[i] = State::Placed(pose);
            }
        }
        state
            .into_iter()
            .map(|s| match s {
                State::Placed(p) => Some(p),
                _ => None,
            })
            .collect()
    }

    /// Checks the guarantees [`read`] gives about what it returns: every mesh's indices
    /// form whole triangles within its vertices, normals (when present) number one per
    /// index, and the caps (objects, scripts, path points) hold. The fuzz target asserts
    /// this on every file that reads.
    ///
    /// # Errors
    /// A description of the first broken guarantee.
    pub fn check_guarantees(&self) -> Result<(), String> {
        if self.objects.len() > MAX_OBJECTS || self.scripts.len() > MAX_SCRIPTS {
            return Err("object or script cap exceeded".into());
        }
        for o in &self.objects {
            if let ObjectKind::Path(p) = &o.kind
                && p.points.len() > path::MAX_POINTS
            {
                return Err(format!("{}: {} path points", o.name, p.points.len()));
            }
            let ObjectKind::Shape(s) = &o.kind else { continue };
            for leaf in &s.leaves {
                if !leaf.indices.len().is_multiple_of(3) {
                    return Err(format!("{}: {} indices", o.name, leaf.indices.len()));
                }
                if let Some(&i) = leaf.indices.iter().find(|&&i| i as usize >= leaf.vertices.len()) {
                    return Err(format!("{}: index {i} of {} vertices", o.name, leaf.vertices.len()));
                }
                if leaf.normals.as_ref().is_some_and(|n| n.len() != leaf.indices.len()) {
                    return Err(format!("{}: normals do not match indices", o.name));
                }
            }
        }
        if self.world_poses().len() != self.objects.len() {
            return Err("world_poses length".into());
        }
        Ok(())
    }

    /// The intrinsic motion of object `i` when it is a joint, else the identity.
    fn joint_motion(&self, i: usize) -> Pose {
        match &self.objects[i].kind {
            ObjectKind::Joint(j) => j.intrinsic_pose(),
            _ => Pose::IDENTITY,
        }
    }
}

/// Reads a whole .ttt or .ttm file.
///
/// # Errors
/// A [`ReadError`] saying what is wrong and where (file or body offset, chunk path):
/// a bad header, a serialization version before 18, corrupt Huffman data, a malformed
/// chunk stream, a decoded value that cannot be valid, or a cap exceeded.
pub fn read(bytes: &[u8]) -> Result<CoppeliaFile, ReadError> {
    let header = Header::parse(bytes)?;
    let body_len = header.body_len as usize;
    if body_len > MAX_BODY_LEN {
        return Err(ReadError::BodyLength {
            len: i64::from(header.body_len),
            why: "above the reader's 512 MiB cap",
        });
    }
    let body = huffman::decode(&bytes[header::HEADER_LEN..], body_len, header::HEADER_LEN)?;
    read_body(header, &body)
}

/// Walks the decoded body.
fn read_body(header: Header, body: &[u8]) -> Result<CoppeliaFile, ReadError> {
    let top = At::top();
    let mut file = CoppeliaFile {
        header,
        objects: Vec::new(),
        scripts: Vec::new(),
        settings: Settings::default(),
        collections: Vec::new(),
        ik_groups: Vec::new(),
        textures: Vec::new(),
    };
    let mut buffers = MeshBuffers::default();
    let mut stream = Chunks::new(body, &top);
    let mut list_scripts = Vec::new();
    let mut object_scripts = Vec::new();
    while let Some(item) = stream.next_item()? {
        let (tag, payload, offset) = match item {
            Item::Chunk { tag, payload, offset } => (tag, payload, offset),
            Item::EndOfFile => break,
            // Stray markers at the top level carry nothing.
            Item::EndOfObject | Item::Next => continue,
        };
        let c = Chunk { tag, payload, offset };
        match &tag {
            b"VIN" => buffers = MeshBuffers::read(&c, &top)?,
            b"LST" => list_scripts.push(script::read(&c, &top, ScriptOrigin::List)?),
            b"SIM" => settings::read_simulation(&c, &top, &mut file.settings)?,
            b"DYN" => settings::read_dynamics(&c, &top, &mut file.settings)?,
            b"ENV" => settings::read_environment(&c, &top, &mut file.settings)?,
            b"GRP" => {
                if file.collections.len() == MAX_COLLECTIONS {
                    return Err(ReadError::TooMany {
                        what: "collections",
                        max: MAX_COLLECTIONS,
                    });
                }
                file.collections.push(collection::read(&c, &top)?);
            }
            b"TEX" => {
                if file.textures.len() == texture::MAX_TEXTURES {
                    return Err(ReadError::TooMany {
                        what: "textures",
                        max: texture::MAX_TEXTURES,
                    });
                }
                file.textures.push(texture::read_texture(&c, &top)?);
            }
            b"IKO" => {
                if file.ik_groups.len() == MAX_IK_GROUPS {
                    return Err(ReadError::TooMany {
                        what: "IK groups",
                        max: MAX_IK_GROUPS,
                    });
                }
                file.ik_groups.push(ik_group::read(&c, &top)?);
            }
            t if object::is_object_tag(t) => {
                if file.objects.len() == MAX_OBJECTS {
                    return Err(ReadError::TooMany {
                        what: "objects",
                        max: MAX_OBJECTS,
                    });
                }
                file.objects
                    .push(object::read(&c, &top, &buffers, &mut object_scripts)?);
            }
            _ => {}
        }
        if list_scripts.len() + object_scripts.len() > MAX_SCRIPTS {
            return Err(ReadError::TooMany {
                what: "scripts",
                max: MAX_SCRIPTS,
            });
        }
    }
    file.scripts = list_scripts;
    file.scripts.append(&mut object_scripts);
    Ok(file)
}
