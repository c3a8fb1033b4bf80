//! Scene objects: the common part every object has, and the dispatch to each type.
//!
//! An object chunk (`SHP`, `JNT`, ...) holds the common part, `NXT`, the type-specific
//! part and `EOO`. The common part carries the pose relative to the parent (`Cfq` f32 or
//! `_fq` f64: qw qx qy qz x y z), `Ids` (handle, parent handle), `Nme`, `Ali` (alias,
//! 4.3+), `Omp` (object special properties), the model-base bit in `Var`/`Va2`/`Va3` and,
//! from 4.7, `Cr2`: one per tag of the object's referenced handles
//! (`sim.setReferencedHandles`), a string then an i32 count and that many handles.
//! `Rst` (serialization 18+) is the extension string (`sim.getExtensionString`): a
//! string, empty when the object has none.

use crate::camera::{self, Camera};
use crate::chunk::{At, Chunk, Chunks, Item, show};
use crate::dummy::{self, Dummy};
use crate::error::ReadError;
use crate::field::{Fields, is_double};
use crate::joint::{self, Joint};
use crate::light::{self, Light};
use crate::mesh::MeshBuffers;
use crate::path::{self, OldPath};
use crate::pose::Pose;
use crate::script::{self, Script, ScriptOrigin};
use crate::sensor::{self, ForceSensor, ProximitySensor, VisionSensor};
use crate::shape::{self, Shape};

/// `Omp` bit: collidable.
const COLLIDABLE: i32 = 0x001;
/// `Omp` bit: measurable (distance calculations).
const MEASURABLE: i32 = 0x002;
/// `Omp` bits: detectable by the various proximity-sensor kinds.
const DETECTABLE: i32 = 0x1f0;
/// Most referenced handles under one tag (a model's IK helper references three).
const MAX_REFERENCED: usize = 1 << 16;

/// Most user parameters one object may hold (the public files hold at most a dozen).
const MAX_USER_PARAMETERS: usize = 4096;

/// One user parameter (`Lsp` → `Par`): a name, the unit its dialog showed and the value,
/// all text as CoppeliaSim keeps them (a number is its decimal text).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UserParameter {
    /// The name scripts ask for.
    pub name: String,
    /// The unit the model's dialog showed (free text).
    pub unit: String,
    /// The value, as text.
    pub value: String,
    /// CoppeliaSim's property bits, kept as read (bit 0 is set on every parameter of the
    /// public files).
    pub properties: i32,
}

/// `Lsp`: a nested stream whose `Par` chunk holds a count, then per parameter its name,
/// unit and value (length-prefixed strings) and its property bits (i32).
fn read_user_parameters(c: &Chunk, at: &At) -> Result<Vec<UserParameter>, ReadError> {
    let here = at.child(c.tag, c.offset);
    let (chunks, _) = Chunks::new(c.payload, &here).part(false)?;
    let mut out = Vec::new();
    for c in chunks.iter().filter(|c| &c.tag == b"Par") {
        let mut f = Fields::new(c, &here);
        let n = f.i32()?;
        let Some(n) = usize::try_from(n).ok().filter(|&n| n <= MAX_USER_PARAMETERS) else {
            return Err(here.value_error(format!("{n} user parameters")));
        };
        // Read one by one (each string is bounds-checked), so a huge count in a short
        // chunk fails on the data rather than on an allocation.
        for _ in 0..n {
            out.push(UserParameter {
                name: f.string()?,
                unit: f.string()?,
                value: f.string()?,
                properties: f.i32()?,
            });
        }
    }
    Ok(out)
}

/// One scene object, in file order (parents come before their children).
#[derive(Debug, Clone, PartialEq)]
pub struct SceneObject {
    /// The object's handle in the file (unique within it).
    pub handle: i32,
    /// The parent's handle, `None` at the scene root.
    pub parent: Option<i32>,
    /// Name (`Nme`).
    pub name: String,
    /// Alias (`Ali`, 4.3+), what 4.3+ scripts look objects up by.
    pub alias: Option<String>,
    /// Pose relative to the parent (or the world at the root).
    pub local_pose: Pose,
    /// Collidable (`Omp` bit 0).
    pub collidable: bool,
    /// Measurable (`Omp` bit 1).
    pub measurable: bool,
    /// Detectable by proximity sensors (any of `Omp` bits 4-8).
    pub detectable: bool,
    /// Base of a model (the object a model file or a model in a scene hangs from).
    pub model_base: bool,
    /// Referenced handles (4.7+, `Cr2`) by tag, in file order: the objects a model's
    /// scripts find with `sim.getReferencedHandle(s)`.
    pub referenced: Vec<(String, Vec<i32>)>,
    /// Visibility layer bits (`Lar`; bit k is layer k + 1). CoppeliaSim shows the objects
    /// on its active layers, 1 to 8 unless a scene changed them: models keep their
    /// respondable shapes, joints and helpers on layers 9 to 16, hidden.
    pub layer: u16,
    /// User parameters (`Lsp`, CoppeliaSim up to 4.2's "script simulation parameters"),
    /// in file order: what a model's script reads with `sim.getScriptSimulationParameter`
    /// (resolutions, angles, options the model's dialog offered).
    pub user_parameters: Vec<UserParameter>,
    /// Extension string (`Rst`), empty when none: free text plugins and task models read
    /// with `sim.getExtensionString` (RLBench's waypoints: `open_gripper()`, ...).
    pub extension: String,
    /// The type and its own part.
    pub kind: ObjectKind,
    /// Offset of the object's chunk payload in the decoded body.
    pub offset: usize,
}

/// The type of an object, with its own part where the reader decodes it.
#[derive(Debug, Clone, PartialEq)]
pub enum ObjectKind {
    /// A shape (`SHP`).
    Shape(Box<Shape>),
    /// A joint (`JNT`).
    Joint(Joint),
    /// A dummy (`DMY`).
    Dummy(Dummy),
    /// A proximity sensor (`SNR`).
    ProximitySensor(ProximitySensor),
    /// A vision sensor (`RSN`).
    VisionSensor(VisionSensor),
    /// A force sensor (`FSE`).
    ForceSensor(ForceSensor),
    /// A graph (`GRH`).
    Graph,
    /// A camera (`CMA`).
    Camera(Camera),
    /// A light (`LGT`).
    Light(Light),
    /// A script object (`SCT`, 4.7+); its script is in
    /// [`CoppeliaFile::scripts`](crate::CoppeliaFile::scripts) with origin
    /// [`ScriptOrigin::Object`] of this handle.
    Script,
    /// An old path object (`PAT`).
    Path(OldPath),
    /// A point cloud (`PTC`).
    PointCloud,
    /// Another object type (`OCT` octree, `MIR` mirror, `MIL` mill, ...), with its tag.
    Other([u8; 3]),
}

/// Whether a top-level tag is an object chunk.
pub fn is_object_tag(tag: &[u8; 3]) -> bool {
    matches!(
        tag,
        b"SHP"
            | b"JNT"
            | b"DMY"
            | b"SNR"
            | b"RSN"
            | b"FSE"
            | b"GRH"
            | b"CMA"
            | b"LGT"
            | b"PAT"
            | b"OCT"
            | b"PTC"
            | b"MIR"
            | b"MKR"
            | b"CSO"
            | b"SCT"
            | b"MIL"
    )
}

/// Reads an object chunk; a script object's script goes to `scripts`.
pub fn read(c: &Chunk, top: &At, buffers: &MeshBuffers, scripts: &mut Vec<Script>) -> Result<SceneObject, ReadError> {
    let at = top.child(c.tag, c.offset);
    let mut stream = Chunks::new(c.payload, &at);
    let (common, end) = stream.part(true)?;
    if end != Some(Item::Next) {
        return Err(at.chunk_error(stream.offset(), format!("{} object lacks its NXT marker", show(c.tag))));
    }
    let (own, end) = stream.part(false)?;
    if end != Some(Item::EndOfObject) {
        return Err(at.chunk_error(stream.offset(), format!("{} object lacks its EOO marker", show(c.tag))));
    }
    let mut o = SceneObject {
        handle: -1,
        parent: None,
        name: String::new(),
        alias: None,
        local_pose: Pose::IDENTITY,
        collidable: false,
        measurable: false,
        detectable: false,
        model_base: false,
        referenced: Vec::new(),
        user_parameters: Vec::new(),
        layer: 1,
        extension: String::new(),
        kind: ObjectKind::Other(c.tag),
        offset: c.offset,
    };
    let mut has_ids = false;
    for c in &common {
        let mut f = Fields::new(c, &at);
        match &c.tag {
            b"Cfq" | b"_fq" => o.local_pose = Pose::from_quaternion_first(f.reals::<7>(is_double(c.tag))?),
            b"Ids" => {
                o.handle = f.i32()?;
                o.parent = Some(f.i32()?).filter(|&h| h >= 0);
                has_ids = true;
            }
            b"Nme" => o.name = f.string()?,
            b"Ali" => o.alias = Some(f.string()?),
            b"Rst" => o.extension = f.string()?,
            b"Omp" => {
                let p = f.i32()?;
                o.collidable = p & COLLIDABLE != 0;
                o.measurable = p & MEASURABLE != 0;
                o.detectable = p & DETECTABLE != 0;
            }
            b"Var" | b"Va2" | b"Va3" => o.model_base = f.u8()? & 0x01 != 0,
            b"Cr2" => {
                let tag = f.string()?;
                let n = f.i32()?;
                let Some(n) = usize::try_from(n).ok().filter(|&n| n <= MAX_REFERENCED) else {
                    return Err(at.value_error(format!("{n} referenced handles under '{tag}'")));
                };
                // Each handle is read (and bounds-checked) before it is kept, so a huge
                // count in a short chunk fails without a large allocation.
                let mut handles = Vec::new();
                for _ in 0..n {
                    handles.push(f.i32()?);
                }
                o.referenced.push((tag, handles));
            }
            b"Lsp" => o.user_parameters = read_user_parameters(c, &at)?,
            b"Lar" => o.layer = f.u16()?,
            _ => {}
        }
    }
    if !has_ids {
        return Err(at.value_error("object has no Ids chunk (handle and parent)"));
    }
    o.kind = match &c.tag {
        b"SHP" => ObjectKind::Shape(Box::new(shape::read(&own, &at, buffers)?)),
        b"JNT" => ObjectKind::Joint(joint::read(&own, &at)?),
        b"DMY" => ObjectKind::Dummy(dummy::read(&own, &at)?),
        b"SNR" => ObjectKind::ProximitySensor(sensor::read_proximity(&own, &at)?),
        b"RSN" => ObjectKind::VisionSensor(sensor::read_vision(&own, &at)?),
        b"FSE" => ObjectKind::ForceSensor(sensor::read_force(&own, &at)?),
        b"GRH" => ObjectKind::Graph,
        b"CMA" => ObjectKind::Camera(camera::read(&own, &at)?),
        b"LGT" => ObjectKind::Light(light::read(&own, &at)?),
        b"PAT" => ObjectKind::Path(path::read(&own, &at)?),
        b"PTC" => ObjectKind::PointCloud,
        b"SCT" => {
            for soo in own.iter().filter(|c| &c.tag == b"Soo") {
                let mut s = script::read(soo, &at, ScriptOrigin::Object(o.handle))?;
                // The stream names the script object itself; the script acts for its parent.
                s.object = o.parent;
                scripts.push(s);
            }
            ObjectKind::Script
        }
        other => ObjectKind::Other(*other),
    };
    Ok(o)
}
