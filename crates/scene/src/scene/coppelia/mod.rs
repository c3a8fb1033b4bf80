//! Imports CoppeliaSim scenes (`.ttt`) and models (`.ttm`) into a [`SceneModel`].
//!
//! [`gantry_coppelia_file`] decodes the file; this module maps its objects onto gantry's
//! kinds, keeping the whole tree (an object gantry has no kind for becomes a dummy, so
//! its children stay where they are) and reporting everything it approximates or drops.
//!
//! | CoppeliaSim | gantry |
//! |---|---|
//! | tree, local poses, aliases, model bases, extension strings | [`ObjectModel`] as is (4.3+ aliases, else names) |
//! | shapes | [`ShapeModel`] (see `shape.rs`): primitives where exact, else triangles |
//! | revolute/prismatic joints | [`JointModel`]; passive, IK and motion modes kinematic |
//! | dynamic joints: free, force, velocity, position | the same modes; spring and callback as position |
//! | dependent joints | kinematic with a [`MimicModel`] |
//! | spherical joints | fixed (warned) |
//! | proximity sensors: ray, cone, pyramid, cylinder, disc | [`ProximityModel`] |
//! | perspective and orthographic vision sensors up to 2048 px a side | [`VisionModel`] |
//! | cameras | [`CameraModel`] (a viewpoint for the viewer, with its view angle) |
//! | force sensors, graphs, dummies | the same kinds |
//! | lights | [`LightModel`] (parameters for the light API; gantry's renderers keep their own lighting) |
//! | old path objects (`PAT`) | [`PathModel`]: the control points' poses; Bézier corners approximated (`convert_path`) |
//! | point clouds, script objects, others | dummies (warned) |
//! | Lua child and customization scripts | [`ScriptModel`] on their object, old ones updated (`old_scripts.rs`) |
//! | main scripts | dropped (gantry runs its own loop; a custom one is warned) |
//! | Python, disabled scripts | dropped (warned) |
//! | collections (`GRP`) | [`CollectionModel`] (`sim.getCollectionHandle`) |
//! | IK groups (`IKO`, 4.0-4.2 built-in kinematics) | [`IkGroupModel`] (`sim.getIkGroupHandle`); see `convert_ik_groups` |
//! | texture objects (`TEX`), a mesh's texture (`Toj`) | [`SceneModel::textures`], [`VisualModel::texture`] (for the API, vision sensors and the viewer); a vision sensor's image as texture is warned |
//! | time step, gravity, engine step | [`SimSettings`] (`substeps = round(dt / engine step)`) |
//! | environment fog colour (`ENV`), what vision sensors show where they see nothing | [`SimSettings::background`] |
//!
//! Joint motors keep CoppeliaSim's targets, limits and maximum forces. Position
//! control is made as stiff as CoppeliaSim's (gains scaled by the maximum force, see
//! `convert_joint`); other modes use gantry's PD gains ([`DEFAULT_KP`], [`DEFAULT_KD`]).
//! CoppeliaSim's engine-specific PID arrays are not decoded. No floor is added: a scene file has its own, and a model joins a scene.

pub(super) mod old_scripts;
mod pose;
mod shape;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use gantry_coppelia_file as cf;

use super::files::{Files, stem};
use super::floor::put_on_floor;
use super::model::*;
use super::urdf::{DEFAULT_KD, DEFAULT_KP};
use super::{LoadError, ServerSettings};
use pose::to_pose;

/// Position error at which an imported position-controlled joint's motor reaches its
/// maximum force, rad (m for prismatic joints); see `convert_joint`.
const POSITION_ERROR_AT_FULL_FORCE: f64 = 1e-4;
/// Speed at which the same motor's damping reaches the maximum force, rad/s (m/s).
/// Measured on seven library arms: 0.02 keeps a 0.2 rad step free of overshoot (the
/// UR10's shoulder rings for seconds at 0.1 and above), stiffer position gains do not
/// hold the Panda better (its floor is its 1 kg fingers' motors).
const SPEED_AT_FULL_DAMPING: f64 = 0.02;

/// Solver velocity iterations per substep for imported scenes and models
/// ([`SimSettings::solver_iterations`]). CoppeliaSim's Bullet runs 100 constraint
/// iterations per engine step by default; rapier's single pass per substep left the
/// library Panda and XArm7 sagging 1.3 mm at the tip under gravity (their motors are
/// coupled through the arm's mass matrix); 4 passes hold them within 0.47 and 0.41 mm
/// for at most 10 % more time per step (Panda, XArm7, UR10, the Panda reach scene; the
/// differences are within the timing noise).
pub const COPPELIA_SOLVER_ITERATIONS: u32 = 4;

/// What an import kept, changed and dropped, beyond the model itself.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ImportReport {
    /// The CoppeliaSim version that wrote the file, e.g. `4.1.0`.
    pub program_version: String,
    /// Whether the file is a model (`.ttm`) rather than a scene: the header says, or for
    /// files whose header does not, the extension.
    pub is_model: bool,
    /// Objects imported, all kinds.
    pub objects: usize,
    /// The file's handle of each imported object, by model index (object `k` of the
    /// model was CoppeliaSim's handle `file_handles[k]`).
    pub file_handles: Vec<i32>,
    /// Objects imported as dummies, with why: `(name, reason)`.
    pub as_dummies: Vec<(String, String)>,
    /// Scripts attached to objects.
    pub scripts_attached: usize,
    /// Scripts not imported, with why: `(where, reason)`.
    pub scripts_dropped: Vec<(String, String)>,
    /// Everything approximated, in file order (also in [`SceneModel::warnings`]).
    pub warnings: Vec<String>,
}

/// Reads and imports a CoppeliaSim scene (`.ttt`, as saved) or model (`.ttm`, placed
/// on a 5 x 5 m floor, as a bare URDF is), for `gantry run`, `sim.loadScene` and the
/// clients. The import's warnings are the model's.
///
/// # Errors
/// [`LoadError::Io`] when the file cannot be read, else as [`load_coppelia`].
pub fn load_coppelia_file(files: &dyn Files, path: &Path) -> Result<SceneModel, LoadError> {
    let bytes = files.read(path).map_err(|source| LoadError::Io {
        path: path.to_owned(),
        source,
        hint: String::new(),
    })?;
    let (mut model, report) = load_coppelia(&bytes, path)?;
    if report.is_model {
        put_on_floor(&mut model);
    }
    Ok(model)
}

/// Imports a CoppeliaSim scene or model from its bytes. `path` names the file in
/// messages and gives the model its name and base folder; nothing is read from it.
///
/// # Errors
/// [`LoadError::Coppelia`] when the file cannot be decoded (see
/// [`gantry_coppelia_file::ReadError`]), and [`LoadError::Invalid`] when two objects
/// share a handle or the object tree has a cycle.
pub fn load_coppelia(bytes: &[u8], path: &Path) -> Result<(SceneModel, ImportReport), LoadError> {
    let file = cf::read(bytes).map_err(|source| LoadError::Coppelia {
        path: path.to_owned(),
        source,
    })?;
    let mut report = ImportReport {
        program_version: file.header.program_version_text(),
        // V-REP 3.5 and older leave the header's file type at 0 (PyRep's test model
        // `loadable_model.ttm`): then the extension says, as it did for V-REP.
        is_model: match file.header.file_type {
            cf::FileType::Model => true,
            cf::FileType::Scene => false,
            cf::FileType::Unspecified(_) => path.extension().is_some_and(|e| e.eq_ignore_ascii_case("ttm")),
        },
        ..ImportReport::default()
    };
    let mut warnings = Vec::new();

    // Hierarchy order with parents first (CoppeliaSim writes it so; checked, not assumed).
    let order = hierarchy_order(&file, path, &mut warnings)?;
    let index: HashMap<i32, usize> = order
        .iter()
        .enumerate()
        .map(|(k, &i)| (file.objects[i].handle, k))
        .collect();
    let mut objects = Vec::with_capacity(order.len());
    for &i in &order {
        let o = &file.objects[i];
        let label = o.alias.clone().unwrap_or_else(|| o.name.clone());
        let kind = convert_kind(o, &label, path, &index, &mut report, &mut warnings);
        objects.push(ObjectModel {
            alias: label,
            parent: o.parent.and_then(|p| index.get(&p).copied()),
            local: to_pose(&o.local_pose),
            model_base: o.model_base,
            extension: o.extension.clone(),
            layer: o.layer,
            kind,
        });
    }
    let (textures, texture_index) = shape::convert_textures(&file);
    for (object, &i) in objects.iter_mut().zip(&order) {
        if let (ObjectModelKind::Shape(shape), cf::ObjectKind::Shape(s)) = (&mut object.kind, &file.objects[i].kind) {
            shape::attach_textures(shape, &s.leaves, &texture_index, &object.alias, &mut warnings);
        }
    }
    cap_vision_memory(&mut objects, &mut report, &mut warnings);
    report.objects = objects.len();
    report.file_handles = order.iter().map(|&i| file.objects[i].handle).collect();

    let (dummy_links, ball_links) = loop_closures(&file, &index);
    let referenced_handles = referenced_handles(&file, &index, &mut warnings);
    let user_parameters = user_parameters(&file, &index);
    let collections = convert_collections(&file, &index, &mut warnings);
    let ik_groups = convert_ik_groups(&file, &index, &mut warnings);
    let scripts = convert_scripts(&file, path, &index, &mut report, &mut warnings);
    let settings = convert_settings(&file.settings, &mut warnings);
    report.warnings = warnings.clone();
    let model = SceneModel {
        name: stem(path),
        base_dir: path.parent().map(Path::to_owned).unwrap_or_default(),
        path: path.to_owned(),
        settings,
        server: ServerSettings::default(),
        objects,
        scripts,
        dummy_links,
        ball_links,
        referenced_handles,
        user_parameters,
        ik_groups,
        collections,
        urdf_robots: Vec::new(),
        warnings,
        textures,
    };
    Ok((model, report))
}

/// Indices of the file's objects, parents before children. An object whose parent is
/// missing becomes a root (warned); a cycle is an error.
fn hierarchy_order(file: &cf::CoppeliaFile, path: &Path, warnings: &mut Vec<String>) -> Result<Vec<usize>, LoadError> {
    let by_handle: HashMap<i32, usize> = file.objects.iter().enumerate().map(|(i, o)| (o.handle, i)).collect();
    if by_handle.len() != file.objects.len() {
        return Err(invalid(path, "two objects share a handle".into()));
    }
    let mut children: HashMap<Option<usize>, Vec<usize>> = HashMap::new();
    for (i, o) in file.objects.iter().enumerate() {
        let parent = match o.parent {
            None => None,
            Some(p) => match by_handle.get(&p) {
                Some(&pi) => Some(pi),
                None => {
                    warnings.push(format!("{}: parent {p} does not exist; imported at the root", o.name));
                    None
                }
            },
        };
        children.entry(parent).or_default().push(i);
    }
    // Depth-first from the roots, children in file order.
    let mut order = Vec::with_capacity(file.objects.len());
    let mut stack: Vec<usize> = children.get(&None).cloned().unwrap_or_default();
    stack.reverse();
    while let Some(i) = stack.pop() {
        order.push(i);
        if let Some(c) = children.get(&Some(i)) {
            stack.extend(c.iter().rev());
        }
    }
    if order.len() != file.objects.len() {
        return Err(invalid(path, "the object tree has a cycle".into()));
    }
    Ok(order)
}

fn invalid(path: &Path, message: String) -> LoadError {
    LoadError::Invalid {
        path: path.to_owned(),
        line: 1,
        column: 1,
        message,
    }
}

/// The gantry kind of one object.
fn convert_kind(
    o: &cf::SceneObject,
    label: &str,
    path: &Path,
    index: &HashMap<i32, usize>,
    report: &mut ImportReport,
    warnings: &mut Vec<String>,
) -> ObjectModelKind {
    let mut as_dummy = |why: String| {
        warnings.push(format!("{label}: {why}; imported as a dummy"));
        report.as_dummies.push((label.to_owned(), why));
        ObjectModelKind::Dummy
    };
    match &o.kind {
        cf::ObjectKind::Shape(s) => {
            let mut shape = shape::convert(s, label, path, o.detectable, o.measurable, warnings);
            shape.collidable = o.collidable;
            ObjectModelKind::Shape(shape)
        }
        cf::ObjectKind::Joint(j) => ObjectModelKind::Joint(convert_joint(j, label, index, warnings)),
        cf::ObjectKind::Dummy(_) => ObjectModelKind::Dummy,
        cf::ObjectKind::ProximitySensor(p) => match p.volume {
            cf::ProximityVolume::Ray { offset, range } => {
                ObjectModelKind::ProximitySensor(ProximityModel::Ray { offset, range })
            }
            cf::ProximityVolume::Cone {
                offset, range, angle, ..
            } => ObjectModelKind::ProximitySensor(ProximityModel::Cone {
                offset,
                range,
                half_angle: angle / 2.0,
            }),
            cf::ProximityVolume::Pyramid {
                offset,
                range,
                near_size,
                far_size,
            } => ObjectModelKind::ProximitySensor(ProximityModel::Pyramid {
                offset,
                range,
                near_size,
                far_size,
            }),
            cf::ProximityVolume::Cylinder {
                offset,
                range,
                radius,
                radius_far,
            } => ObjectModelKind::ProximitySensor(ProximityModel::Cylinder {
                offset,
                range,
                radius,
                radius_far,
            }),
            cf::ProximityVolume::Disc {
                offset,
                range,
                angle,
                thickness,
                ..
            } => ObjectModelKind::ProximitySensor(ProximityModel::Disc {
                offset,
                range,
                half_angle: (angle / 2.0).min(std::f64::consts::PI),
                thickness,
            }),
            cf::ProximityVolume::Other(kind) => as_dummy(format!("proximity sensor volume type {kind} is not known")),
        },
        cf::ObjectKind::VisionSensor(v) => match convert_vision(v) {
            Ok(m) => ObjectModelKind::VisionSensor(m),
            Err(why) => as_dummy(why),
        },
        cf::ObjectKind::ForceSensor(_) => ObjectModelKind::ForceSensor,
        cf::ObjectKind::Graph => ObjectModelKind::Graph,
        cf::ObjectKind::Camera(c) => ObjectModelKind::Camera(convert_camera(c, label, warnings)),
        cf::ObjectKind::Light(l) => match convert_light(l, &o.extension) {
            Some(m) => ObjectModelKind::Light(m),
            None => as_dummy(format!("light type {} is not known", l.light_type.code())),
        },
        cf::ObjectKind::Script => ObjectModelKind::Dummy,
        cf::ObjectKind::Path(p) => ObjectModelKind::Path(convert_path(p)),
        cf::ObjectKind::PointCloud => as_dummy("point clouds are not imported".into()),
        cf::ObjectKind::Other(tag) => {
            as_dummy(format!("object type {} is not supported", String::from_utf8_lossy(tag)))
        }
    }
}

/// A light's parameters, or `None` for a light type CoppeliaSim does not define. The
/// POV-Ray shadow flag is read from the extension string, where CoppeliaSim keeps it.
/// Gantry's renderers keep their own lighting: the parameters are for the light API.
fn convert_light(l: &cf::Light, extension: &str) -> Option<LightModel> {
    let light_type = match l.light_type {
        cf::LightType::Omnidirectional => LightType::Omnidirectional,
        cf::LightType::Spot => LightType::Spot,
        cf::LightType::Directional => LightType::Directional,
        cf::LightType::Other(_) => return None,
    };
    let unit = |c: [f64; 3]| c.map(|v| if v.is_finite() { v.clamp(0.0, 1.0) } else { 0.0 });
    let non_negative = |v: f64| if v.is_finite() { v.max(0.0) } else { 0.0 };
    Some(LightModel {
        light_type,
        on: l.on,
        diffuse: unit(l.diffuse),
        specular: unit(l.specular),
        spot_exponent: l.spot_exponent.clamp(0, LightModel::MAX_SPOT_EXPONENT),
        spot_cutoff: if l.spot_cutoff.is_finite() {
            l.spot_cutoff
                .clamp(LightModel::MIN_SPOT_CUTOFF, LightModel::MAX_SPOT_CUTOFF)
        } else {
            LightModel::MAX_SPOT_CUTOFF
        },
        attenuation: l.attenuation.map(non_negative),
        casts_shadows: cf::light::pov_casts_shadows(extension),
    })
}

/// An old path's curve. The control points keep their poses. CoppeliaSim rounds each
/// corner by its own Bézier point count and factors; gantry rounds every corner with one
/// strength, so a path whose points have Bézier points (a count above 1) gets the mean
/// of their factors as its smoothness and their total count as its number of curve
/// points, and a path without any stays the polyline through its points.
fn convert_path(p: &cf::OldPath) -> PathModel {
    let ctrl_points = p
        .points
        .iter()
        .filter(|c| c.position.iter().chain(&c.rotation).all(|v| v.is_finite()))
        .map(|c| {
            let [x, y, z] = c.position;
            let [w, qx, qy, qz] = c.rotation;
            [x, y, z, qx, qy, qz, w]
        })
        .collect();
    let curved: Vec<&cf::PathPoint> = p.points.iter().filter(|c| c.bezier_points > 1).collect();
    let (smoothness, subdiv) = if curved.is_empty() {
        (0.0, 2)
    } else {
        let factors: f64 = curved
            .iter()
            .flat_map(|c| c.bezier_factors)
            .map(|f| if f.is_finite() { f.clamp(0.0, 1.0) } else { 0.5 })
            .sum();
        let count: usize = p.points.iter().map(|c| c.bezier_points.clamp(1, 1000) as usize).sum();
        (factors / (2 * curved.len()) as f64, count.clamp(2, 1_000_000))
    };
    PathModel {
        ctrl_points,
        closed: p.closed(),
        smoothness,
        subdiv,
    }
}

/// A vision sensor as CoppeliaSim has it, or why it cannot be one. Both the view
/// angle and the ortho size are kept, as CoppeliaSim keeps them, so that
/// `sim.visionintparam_perspective_operation` can switch the projection; the unused
/// one is replaced by a valid default when the file holds none.
fn convert_vision(v: &cf::VisionSensor) -> Result<VisionModel, String> {
    let side = |n: i32| {
        u32::try_from(n)
            .ok()
            .filter(|&n| (1..=MAX_VISION_RESOLUTION).contains(&n))
    };
    let (Some(w), Some(h)) = (side(v.resolution[0]), side(v.resolution[1])) else {
        return Err(format!(
            "vision sensor resolution {}x{} is outside 1..{MAX_VISION_RESOLUTION}",
            v.resolution[0], v.resolution[1]
        ));
    };
    let projection = if v.perspective {
        Projection::Perspective
    } else {
        Projection::Orthographic
    };
    let fov_ok = v.view_angle > 0.0 && v.view_angle < std::f64::consts::PI;
    let size_ok = v.ortho_size > 0.0 && v.ortho_size.is_finite();
    match projection {
        Projection::Perspective if !fov_ok => {
            return Err(format!("vision sensor view angle {} rad is out of range", v.view_angle));
        }
        Projection::Orthographic if !size_ok => {
            return Err(format!("vision sensor ortho size {} m is out of range", v.ortho_size));
        }
        _ => {}
    }
    if !(v.near > 0.0 && v.far > v.near && v.far.is_finite()) {
        return Err(format!(
            "vision sensor clipping planes {}..{} m are out of range",
            v.near, v.far
        ));
    }
    Ok(VisionModel {
        resolution: [w, h],
        projection,
        // CoppeliaSim's defaults for a new sensor.
        fov: if fov_ok { v.view_angle } else { 60f64.to_radians() },
        ortho_size: if size_ok { v.ortho_size } else { 0.01 },
        near: v.near,
        far: v.far,
        // Not decoded from the files (reference/coppelia-files.md lists no such chunk).
        render_mode: RenderMode::Visible,
        ignore_rgb: false,
        ignore_depth: false,
        ros2_rate: None,
        // CoppeliaSim's null-pixel colour is not read from files: the scene's applies.
        background: None,
    })
}

/// A camera: its view angle, or 60 degrees (warned) when the file's is out of range.
fn convert_camera(c: &cf::Camera, label: &str, warnings: &mut Vec<String>) -> CameraModel {
    if c.view_angle > 0.0 && c.view_angle < std::f64::consts::PI {
        return CameraModel { fov: c.view_angle };
    }
    warnings.push(format!(
        "{label}: camera view angle {} rad is out of range; 60 degrees used",
        c.view_angle
    ));
    CameraModel {
        fov: 60f64.to_radians(),
    }
}

/// Keeps the vision sensors' images within [`MAX_VISION_IMAGE_BYTES`] together: the
/// sensors past the cap, in tree order, become dummies (warned), so that the rest of
/// the file still loads.
fn cap_vision_memory(objects: &mut [ObjectModel], report: &mut ImportReport, warnings: &mut Vec<String>) {
    let mut total = 0u64;
    for o in objects {
        let ObjectModelKind::VisionSensor(v) = &o.kind else {
            continue;
        };
        let bytes = vision_image_bytes(v.resolution);
        if total + bytes <= MAX_VISION_IMAGE_BYTES {
            total += bytes;
            continue;
        }
        let why = format!(
            "vision sensor {}x{} would bring the images of the file's vision sensors over {} MiB",
            v.resolution[0],
            v.resolution[1],
            MAX_VISION_IMAGE_BYTES >> 20
        );
        warnings.push(format!("{}: {why}; imported as a dummy", o.alias));
        report.as_dummies.push((o.alias.clone(), why));
        o.kind = ObjectModelKind::Dummy;
    }
}

/// The vision and camera mapping on values built here, so it is covered where the
/// shared files are absent.
#[cfg(test)]
mod light_and_path_tests {
    use super::*;

    #[test]
    fn lights_keep_their_parameters_within_coppeliasims_ranges() {
        let l = cf::Light {
            light_type: cf::LightType::Spot,
            on: false,
            spot_exponent: 300,
            spot_cutoff: 2.0,
            attenuation: [0.5, -1.0, f64::NAN],
            diffuse: [0.25, 1.5, -0.5],
            specular: [0.1, 0.2, 0.3],
            ..cf::Light::default()
        };
        let m = convert_light(&l, "povray {shadow {true}}").unwrap();
        assert_eq!((m.light_type, m.on, m.casts_shadows), (LightType::Spot, false, true));
        assert_eq!(m.spot_exponent, 128);
        assert_eq!(m.spot_cutoff, LightModel::MAX_SPOT_CUTOFF);
        assert_eq!(m.attenuation, [0.5, 0.0, 0.0]);
        assert_eq!((m.diffuse, m.specular), ([0.25, 1.0, 0.0], [0.1, 0.2, 0.3]));
        assert!(!convert_light(&l, "").unwrap().casts_shadows);
        let other = cf::Light {
            light_type: cf::LightType::Other(7),
            ..l
        };
        assert!(convert_light(&other, "").is_none());
    }

    #[test]
    fn old_paths_keep_their_poses_and_round_corners_by_their_factors() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let point = |x: f64, rotation: [f64; 4], bezier_points: i32, f: [f64; 2]| cf::PathPoint {
            position: [x, 0.0, 0.0],
            rotation,
            bezier_factors: f,
            bezier_points,
            max_relative_velocity: 1.0,
            on_spot_distance: 0.0,
        };
        let p = cf::OldPath {
            points: vec![
                point(0.0, [1.0, 0.0, 0.0, 0.0], 1, [0.5, 0.5]),
                point(1.0, [h, 0.0, 0.0, h], 10, [0.8, 0.6]),
                point(2.0, [1.0, 0.0, 0.0, 0.0], 20, [0.4, 0.2]),
                point(f64::NAN, [1.0, 0.0, 0.0, 0.0], 1, [0.5, 0.5]),
            ],
            attributes: cf::path::CLOSED,
        };
        let m = convert_path(&p);
        // w, x, y, z in the file; x, y, z, w in the model; the NaN point left out.
        assert_eq!(m.ctrl_points.len(), 3);
        assert_eq!(m.ctrl_points[1], [1.0, 0.0, 0.0, 0.0, 0.0, h, h]);
        assert!(m.closed);
        // The mean factor of the two curved points, their counts plus the sharp ones.
        assert!((m.smoothness - 0.5).abs() < 1e-12);
        assert_eq!(m.subdiv, 1 + 10 + 20 + 1);
        let sharp = cf::OldPath {
            points: vec![point(0.0, [1.0, 0.0, 0.0, 0.0], 1, [0.5, 0.5])],
            attributes: 0,
        };
        let m = convert_path(&sharp);
        assert_eq!((m.smoothness, m.closed), (0.0, false));
    }
}

#[cfg(test)]
mod vision_tests {
    use super::*;

    fn sensor(perspective: bool, resolution: [i32; 2], ortho_size: f64) -> cf::VisionSensor {
        cf::VisionSensor {
            resolution,
            perspective,
            view_angle: 0.5,
            ortho_size,
            near: 0.01,
            far: 2.0,
        }
    }

    #[test]
    fn orthographic_and_large_sensors_are_kept_and_bad_ones_explained() {
        let m = convert_vision(&sensor(false, [2048, 16], 0.3)).expect("kept");
        assert_eq!(m.projection, Projection::Orthographic);
        assert_eq!((m.resolution, m.ortho_size, m.fov), ([2048, 16], 0.3, 0.5));
        // A perspective sensor without an ortho size gets CoppeliaSim's default for a switch.
        let m = convert_vision(&sensor(true, [640, 480], 0.0)).expect("kept");
        assert_eq!((m.projection, m.ortho_size), (Projection::Perspective, 0.01));
        let why = convert_vision(&sensor(false, [16, 16], 0.0)).expect_err("no size");
        assert!(why.contains("ortho size 0 m"), "{why}");
        let why = convert_vision(&sensor(true, [2049, 16], 0.1)).expect_err("too large");
        assert!(why.contains("2049x16"), "{why}");
    }

    #[test]
    fn sensors_past_the_memory_cap_become_dummies() {
        let big = |alias: &str| ObjectModel {
            alias: alias.into(),
            parent: None,
            local: crate::math::Pose::identity(),
            model_base: false,
            extension: String::new(),
            layer: 1,
            kind: ObjectModelKind::VisionSensor(convert_vision(&sensor(true, [2048, 2048], 0.1)).expect("kept")),
        };
        // 36 fit in 1 GiB (28 MiB each); the 37th does not.
        let mut objects: Vec<ObjectModel> = (0..37).map(|k| big(&format!("cam{k}"))).collect();
        let (mut report, mut warnings) = (ImportReport::default(), Vec::new());
        cap_vision_memory(&mut objects, &mut report, &mut warnings);
        assert!(
            objects[..36]
                .iter()
                .all(|o| matches!(o.kind, ObjectModelKind::VisionSensor(_)))
        );
        assert!(matches!(objects[36].kind, ObjectModelKind::Dummy));
        assert_eq!(report.as_dummies.len(), 1);
        assert!(
            warnings[0].starts_with("cam36: vision sensor 2048x2048"),
            "{warnings:?}"
        );
    }

    #[test]
    fn cameras_keep_their_view_angle_or_get_60_degrees() {
        let mut warnings = Vec::new();
        let c = cf::Camera {
            view_angle: 0.7,
            ..cf::Camera::default()
        };
        assert_eq!(convert_camera(&c, "cam", &mut warnings).fov, 0.7);
        assert!(warnings.is_empty());
        let c = convert_camera(&cf::Camera::default(), "cam", &mut warnings);
        assert!((c.fov - 60f64.to_radians()).abs() < 1e-12);
        assert_eq!(warnings.len(), 1);
    }
}

/// A joint, its mode mapped as the module table says.
fn convert_joint(j: &cf::Joint, label: &str, index: &HashMap<i32, usize>, warnings: &mut Vec<String>) -> JointModel {
    let joint_type = match j.joint_type {
        cf::JointType::Revolute => JointType::Revolute,
        cf::JointType::Prismatic => JointType::Prismatic,
        cf::JointType::Spherical | cf::JointType::Other(_) => {
            warnings.push(format!(
                "{label}: spherical joints have no gantry equivalent; imported as fixed (a loop closure below a free one turns freely)"
            ));
            JointType::Fixed
        }
    };
    let mut mimic = None;
    let mode = match j.mode {
        _ if joint_type == JointType::Fixed => JointMode::Kinematic,
        cf::JointMode::Passive => JointMode::Kinematic,
        cf::JointMode::Motion | cf::JointMode::InverseKinematics => {
            warnings.push(format!(
                "{label}: deprecated motion/IK joint mode imported as kinematic"
            ));
            JointMode::Kinematic
        }
        cf::JointMode::Dependent => {
            match j
                .dependency
                .and_then(|d| index.get(&d.master).map(|&leader| (d, leader)))
            {
                Some((d, leader)) => {
                    mimic = Some(MimicModel {
                        leader,
                        multiplier: d.multiplier,
                        offset: d.offset,
                    });
                }
                None => warnings.push(format!(
                    "{label}: dependent joint without a master; imported as kinematic"
                )),
            }
            JointMode::Kinematic
        }
        cf::JointMode::Dynamic | cf::JointMode::Hybrid => match j.dynamic_control {
            cf::DynamicControl::Free => JointMode::Free,
            cf::DynamicControl::Force => JointMode::Force,
            cf::DynamicControl::Velocity => JointMode::Velocity,
            cf::DynamicControl::Position => JointMode::Position,
            other => {
                warnings.push(format!(
                    "{label}: dynamic control {other:?} imported as position control"
                ));
                JointMode::Position
            }
        },
        cf::JointMode::Other(m) => {
            warnings.push(format!("{label}: joint mode {m} unknown; imported as kinematic"));
            JointMode::Kinematic
        }
    };
    // Values a file leaves unset can be any bit pattern, NaN and infinities included:
    // rapier would carry them into its solver (a NaN motor bound aborts the step), so
    // each is checked here and replaced by a neutral value, with a warning.
    let mut finite = |v: f64, fallback: f64, what: &str| {
        if v.is_finite() {
            v
        } else {
            warnings.push(format!("{label}: {what} is not a finite number; {fallback} used"));
            fallback
        }
    };
    let min = finite(j.min, 0.0, "the lower limit");
    let range = finite(j.range, 0.0, "the range").max(0.0);
    let initial = finite(j.position, 0.0, "the position");
    let target_position = finite(j.target_position, initial, "the target position");
    let target_velocity = finite(j.target_velocity, 0.0, "the target velocity");
    let max_force = finite(j.max_force, 0.0, "the maximum force or torque").abs();
    if let Some(m) = &mut mimic {
        m.multiplier = finite(m.multiplier, 1.0, "the dependency multiplier");
        m.offset = finite(m.offset, 0.0, "the dependency offset");
    }
    let limits = (!j.cyclic && joint_type != JointType::Fixed).then_some((min, min + range));
    // CoppeliaSim's position controller commands a velocity proportional to the error
    // and lets the joint's maximum force reach it: stiff up to that force, so a library
    // arm holds its pose under gravity. A spring-damper with gantry's URDF gains sags
    // instead (16 mm at the Panda's tip in 10 s). Gains scaled by the maximum force give
    // the full force at an error of 0.1 mrad (0.1 mm) or 0.02 rad/s (m/s); the
    // saturation stays CoppeliaSim's.
    let (kp, kd) = if mode == JointMode::Position && max_force > 0.0 {
        (
            max_force / POSITION_ERROR_AT_FULL_FORCE,
            max_force / SPEED_AT_FULL_DAMPING,
        )
    } else {
        (DEFAULT_KP, DEFAULT_KD)
    };
    JointModel {
        joint_type,
        mode,
        limits,
        cyclic: j.cyclic && joint_type == JointType::Revolute,
        initial,
        target_position,
        target_velocity,
        max_force,
        kp,
        kd,
        damping: 0.0,
        friction: 0.0,
        max_velocity: j.max_velocity.filter(|v| v.is_finite() && *v > 0.0),
        mimic,
    }
}

/// The dynamic loop closures: each linked pair of dummies once, by model index, split
/// into those that hold the dummies' frames together and those that hold only their
/// origins (see [`SceneModel::ball_links`]). IK tip/target links are kinematics only and
/// stay out of the physics.
fn loop_closures(file: &cf::CoppeliaFile, index: &HashMap<i32, usize>) -> (Vec<[usize; 2]>, Vec<[usize; 2]>) {
    let mut links: Vec<([usize; 2], bool)> = file
        .objects
        .iter()
        .filter_map(|o| match &o.kind {
            cf::ObjectKind::Dummy(d) if d.link == cf::DummyLink::DynamicLoopClosure => {
                let linked = d.linked?;
                let (a, b) = (*index.get(&o.handle)?, *index.get(&linked)?);
                let ball = below_free_spherical_joint(file, o.handle) || below_free_spherical_joint(file, linked);
                (a != b).then_some(([a.min(b), a.max(b)], ball))
            }
            _ => None,
        })
        .collect();
    links.sort_unstable();
    links.dedup();
    let (ball, fixed): (Vec<_>, Vec<_>) = links.into_iter().partition(|&(_, ball)| ball);
    (
        fixed.into_iter().map(|(l, _)| l).collect(),
        ball.into_iter().map(|(l, _)| l).collect(),
    )
}

/// Whether a dynamic (free) spherical joint lies between `dummy` and the nearest shape
/// above it: the loop that dummy closes turns freely about the joint. gantry imports the
/// joint as fixed and frees the rotation at the closure instead, which is the same
/// mechanism when nothing but dummies hangs below the joint (the RG2 gripper's case).
fn below_free_spherical_joint(file: &cf::CoppeliaFile, dummy: i32) -> bool {
    let mut cur = file.object(dummy).and_then(|o| o.parent);
    // The file's tree may be broken or cyclic: never walk more steps than objects.
    for _ in 0..file.objects.len() {
        let Some(o) = cur.and_then(|h| file.object(h)) else {
            return false;
        };
        match &o.kind {
            cf::ObjectKind::Shape(_) => return false,
            cf::ObjectKind::Joint(j)
                if j.joint_type == cf::JointType::Spherical && j.mode == cf::JointMode::Dynamic =>
            {
                return true;
            }
            _ => cur = o.parent,
        }
    }
    false
}

/// The objects' user parameters (up to 4.2), by object index, in file order. A name an
/// object gives twice keeps its first value, as CoppeliaSim's lookup by name finds it.
fn user_parameters(file: &cf::CoppeliaFile, index: &HashMap<i32, usize>) -> Vec<UserParameter> {
    let mut out: Vec<UserParameter> = Vec::new();
    for o in &file.objects {
        let Some(&object) = index.get(&o.handle) else {
            continue;
        };
        for p in &o.user_parameters {
            if p.name.is_empty() || out.iter().any(|q| q.object == object && q.name == p.name) {
                continue;
            }
            out.push(UserParameter {
                object,
                name: p.name.clone(),
                unit: p.unit.clone(),
                value: p.value.clone(),
            });
        }
    }
    out
}

/// The objects' referenced handles (4.7+), as object indices. A handle the file does not
/// hold an object for (CoppeliaSim keeps -1 for a removed one) is dropped, with a warning.
fn referenced_handles(
    file: &cf::CoppeliaFile,
    index: &HashMap<i32, usize>,
    warnings: &mut Vec<String>,
) -> Vec<ReferencedHandles> {
    let mut out = Vec::new();
    for o in &file.objects {
        let Some(&object) = index.get(&o.handle) else {
            continue;
        };
        for (tag, handles) in &o.referenced {
            let targets = handles.iter().filter_map(|h| index.get(h).copied()).collect::<Vec<_>>();
            if targets.len() < handles.len() {
                warnings.push(format!(
                    "{}: {} of the handles referenced as '{tag}' name no object in the file",
                    o.name,
                    handles.len() - targets.len()
                ));
            }
            out.push(ReferencedHandles {
                object,
                tag: tag.clone(),
                targets,
            });
        }
    }
    out
}

/// The file's collections (`GRP`), with object indices. A collection without a name or
/// with a name taken before is dropped, and so is an item of an unknown kind or naming
/// no object of the file; each with a warning.
fn convert_collections(
    file: &cf::CoppeliaFile,
    index: &HashMap<i32, usize>,
    warnings: &mut Vec<String>,
) -> Vec<CollectionModel> {
    let mut out: Vec<CollectionModel> = Vec::new();
    for c in &file.collections {
        if c.name.is_empty() || out.iter().any(|o| o.name == c.name) {
            warnings.push(format!(
                "collection '{}': no name or a name used twice; dropped",
                c.name
            ));
            continue;
        }
        let mut items = Vec::with_capacity(c.items.len());
        for i in &c.items {
            let (scope, exclude_base) = match i.kind {
                cf::CollectionItemKind::Object => (CollectionScope::Object, false),
                cf::CollectionItemKind::Tree { include_base } => (CollectionScope::Tree, !include_base),
                cf::CollectionItemKind::Chain { include_tip } => (CollectionScope::Chain, !include_tip),
                cf::CollectionItemKind::Everything => (CollectionScope::All, false),
                cf::CollectionItemKind::Unknown(k) => {
                    warnings.push(format!("collection '{}': an item of unknown kind {k}; dropped", c.name));
                    continue;
                }
            };
            let object = if scope == CollectionScope::All {
                None
            } else if let Some(&k) = index.get(&i.object) {
                Some(k)
            } else {
                warnings.push(format!(
                    "collection '{}': item object {} is not in the file; dropped",
                    c.name, i.object
                ));
                continue;
            };
            items.push(CollectionItemModel {
                scope,
                object,
                remove: !i.additive,
                exclude_base,
            });
        }
        out.push(CollectionModel {
            name: c.name.clone(),
            items,
        });
    }
    out
}

/// `Var` bit of an IK group: the group is active (CoppeliaSim skips inactive groups).
const IK_GROUP_ACTIVE: u8 = 0x01;
/// `Var` bit of an IK group taken as "explicit handling". Not documented: inferred from
/// PyRep's files, where it is set on every arm's `<Name>_ik` (0x59; PyRep solves those
/// itself with `sim.handleIkGroup`, and an automatic one would drag each arm onto its
/// target every step) and clear on the groups that must run every step (the Robotiq's
/// finger loops, the youBot's groups: 0x19, 0x1b). Bits 3 and 4 (set everywhere) are
/// probably "restore if position / orientation not reached", bit 1 "correct joint
/// limits"; gantry's solver has no such options and ignores them.
const IK_GROUP_EXPLICIT: u8 = 0x40;
/// The most iterations gantry's IK groups accept (as `[[ik_group]]` does).
const MAX_IK_ITERATIONS: u32 = 100_000;

/// IK groups (`IKO`) as gantry's scene IK groups, which `sim.getIkGroupHandle`,
/// `sim.handleIkGroup` and the other 4.1 functions reach. Each element's target is its
/// tip dummy's linked dummy (`Lli`), as CoppeliaSim's built-in IK takes it. What cannot
/// be imported is warned and dropped, so that the scene still loads: an element whose
/// tip, target or base is not in the file, or that is inactive (CoppeliaSim leaves it out
/// of the solve), and a group left without elements (`sim.getIkGroupHandle` then fails,
/// naming the group). An inactive group is imported as explicitly handled: the main
/// script never handles it, as in CoppeliaSim, but a script's `sim.handleIkGroup` on it
/// solves it (CoppeliaSim's would not; warned). The element's alternative constraint
/// base (`Abc`) is not read: constraints are in the base's frame.
fn convert_ik_groups(
    file: &cf::CoppeliaFile,
    index: &HashMap<i32, usize>,
    warnings: &mut Vec<String>,
) -> Vec<IkGroupModel> {
    let mut out: Vec<IkGroupModel> = Vec::new();
    for g in &file.ik_groups {
        let name = &g.name;
        if name.is_empty() || out.iter().any(|o| &o.name == name) {
            warnings.push(format!("IK group '{name}': no name or a name used twice; dropped"));
            continue;
        }
        let method = match g.method {
            0 => IkMethodModel::PseudoInverse,
            1 => IkMethodModel::DampedLeastSquares,
            other => {
                warnings.push(format!(
                    "IK group '{name}': calculation method {other} is not known; pseudo-inverse used"
                ));
                IkMethodModel::PseudoInverse
            }
        };
        let damping = if g.damping.is_finite() && g.damping >= 0.0 {
            shortest_decimal(g.damping)
        } else {
            warnings.push(format!(
                "IK group '{name}': damping {} is not a number >= 0; 0.1 used",
                g.damping
            ));
            0.1
        };
        let max_iterations = u32::try_from(g.max_iterations).unwrap_or(0).clamp(1, MAX_IK_ITERATIONS);
        if i64::from(max_iterations) != i64::from(g.max_iterations) {
            warnings.push(format!(
                "IK group '{name}': {} iterations; {max_iterations} used",
                g.max_iterations
            ));
        }
        let active = g.flags & IK_GROUP_ACTIVE != 0;
        if !active {
            warnings.push(format!(
                "IK group '{name}': inactive; imported as explicitly handled (sim.handleIkGroup on it still solves it)"
            ));
        }
        let mut elements = Vec::with_capacity(g.elements.len());
        for e in &g.elements {
            match convert_ik_element(file, index, name, e, warnings) {
                Ok(m) => elements.push(m),
                Err(why) => warnings.push(format!("IK group '{name}': {why}; element dropped")),
            }
        }
        if elements.is_empty() {
            warnings.push(format!("IK group '{name}': no element left; group dropped"));
            continue;
        }
        out.push(IkGroupModel {
            name: name.clone(),
            elements,
            method,
            damping,
            max_iterations,
            explicit: !active || g.flags & IK_GROUP_EXPLICIT != 0,
        });
    }
    out
}

/// A value stored as f32 as the shortest decimal that reads back as the same f32 (0.1,
/// not 0.10000000149011612), so a converted scene shows the value CoppeliaSim's dialog
/// showed.
fn shortest_decimal(x: f64) -> f64 {
    let single = x as f32;
    single.to_string().parse().unwrap_or(x)
}

/// One IK element, or why it cannot be imported.
fn convert_ik_element(
    file: &cf::CoppeliaFile,
    index: &HashMap<i32, usize>,
    group: &str,
    e: &cf::IkElement,
    warnings: &mut Vec<String>,
) -> Result<IkElementModel, String> {
    if !e.active {
        return Err(format!("the element tipped at object {} is inactive", e.tip));
    }
    let Some(&tip) = index.get(&e.tip) else {
        return Err(format!("tip object {} is not in the file", e.tip));
    };
    let tip_object = file.objects.iter().find(|o| o.handle == e.tip);
    let Some(cf::ObjectKind::Dummy(d)) = tip_object.map(|o| &o.kind) else {
        return Err(format!("tip object {} is not a dummy", e.tip));
    };
    let tip_name = tip_object.map_or("", |o| o.alias.as_deref().unwrap_or(&o.name));
    // A tip linked to nothing (PyRep's Dobot) keeps its element with the tip as its own
    // target: the group still exists for `sim.getIkGroupHandle`, and handling it leaves
    // the chain where it is, as CoppeliaSim, which skips such an element, does.
    let target = match d.linked {
        None => {
            warnings.push(format!(
                "IK group '{group}': tip '{tip_name}' is linked to no target dummy; its element keeps the chain where it is"
            ));
            tip
        }
        Some(linked) => *index
            .get(&linked)
            .ok_or_else(|| format!("the target {linked} of tip '{tip_name}' is not in the file"))?,
    };
    let base = match e.base {
        -1 => None,
        b => Some(
            *index
                .get(&b)
                .ok_or_else(|| format!("base object {b} of tip '{tip_name}' is not in the file"))?,
        ),
    };
    let constraints = u8::try_from(e.constraints)
        .ok()
        .filter(|c| (1..=31).contains(c))
        .ok_or_else(|| {
            format!(
                "tip '{tip_name}': constraints {} are not a combination of x, y, z, alpha-beta and gamma",
                e.constraints
            )
        })?;
    Ok(IkElementModel {
        tip,
        target,
        base,
        constraints,
    })
}

/// Lua child and customization scripts, on their objects.
fn convert_scripts(
    file: &cf::CoppeliaFile,
    path: &Path,
    index: &HashMap<i32, usize>,
    report: &mut ImportReport,
    warnings: &mut Vec<String>,
) -> Vec<ScriptModel> {
    let mut out = Vec::new();
    for s in &file.scripts {
        let owner = s.object.and_then(|h| file.object(h));
        let place = owner.map_or_else(|| "main script".to_owned(), |o| format!("script of {}", o.name));
        let mut drop = |why: &str, warn: bool| {
            if warn {
                warnings.push(format!("{place}: {why}; not imported"));
            }
            report.scripts_dropped.push((place.clone(), why.to_owned()));
        };
        if s.script_type == cf::ScriptType::Main {
            // gantry runs its own loop; the default main script is what it does anyway.
            if s.default_main || s.text.contains("defaultMainScript") {
                drop("default main script (gantry runs its own loop)", false);
            } else {
                drop("custom main script (gantry runs its own loop)", true);
            }
            continue;
        }
        if s.language != cf::ScriptLanguage::Lua {
            drop("only Lua scripts run in gantry", true);
            continue;
        }
        if s.disabled {
            drop("the script is disabled", true);
            continue;
        }
        // A 4.7+ script object runs as itself: `.` is the script, `..` the object it
        // sits on (what its paths say), so it is attached to its own (dummy) object.
        let attached = match s.origin {
            cf::ScriptOrigin::Object(h) => Some(h),
            cf::ScriptOrigin::List => s.object,
        };
        let Some(object) = attached.and_then(|h| index.get(&h).copied()) else {
            drop("its object does not exist", true);
            continue;
        };
        let (source, rewrites) = old_scripts::modernize(&s.text, s.threaded);
        if rewrites.any() {
            let mut what = Vec::new();
            if rewrites.renamed > 0 {
                what.push(format!("{} V-REP 3 flat names renamed", rewrites.renamed));
            }
            if rewrites.call_types {
                what.push("its sim_call_type passes run from the sysCall hooks".to_owned());
            }
            if rewrites.thread_body {
                what.push("its threaded code runs as sysCall_thread".to_owned());
            }
            warnings.push(format!(
                "{place}: old script updated as CoppeliaSim does on load: {}",
                what.join(", ")
            ));
        }
        report.scripts_attached += 1;
        out.push(ScriptModel {
            object,
            path: PathBuf::from(format!("{}#{}", path.display(), owner.map_or("", |o| o.name.as_str()))),
            source,
        });
    }
    out
}

/// `dt`, gravity, substeps and the vision sensors' background; CoppeliaSim's defaults
/// where the file says nothing.
fn convert_settings(s: &cf::Settings, warnings: &mut Vec<String>) -> SimSettings {
    let mut out = SimSettings {
        solver_iterations: COPPELIA_SOLVER_ITERATIONS,
        ..SimSettings::default()
    };
    if let Some(dt) = s.time_step.filter(|dt| dt.is_finite() && *dt > 0.0) {
        out.dt = dt;
    }
    if let Some(g) = s.gravity.filter(|g| g.iter().all(|v| v.is_finite())) {
        out.gravity = g;
    }
    if let Some(step) = s.engine_step.filter(|st| st.is_finite() && *st > 0.0) {
        out.substeps = (out.dt / step).round().clamp(1.0, 1000.0) as u32;
    }
    // What CoppeliaSim's vision sensors show where they see nothing: the environment's
    // fog colour (not the background gradient its views draw).
    out.background = s
        .environment
        .fog_color
        .filter(|c| c.iter().all(|v| v.is_finite()))
        .map(|c| c.map(|v| v.clamp(0.0, 1.0)));
    if let Some(engine) = s.engine.filter(|e| *e != cf::Engine::Bullet) {
        warnings.push(format!(
            "the scene was set up for {engine:?}; gantry simulates with rapier"
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn joint(mode: cf::JointMode, control: cf::DynamicControl) -> cf::Joint {
        cf::Joint {
            joint_type: cf::JointType::Revolute,
            min: -1.0,
            range: 2.5,
            position: 0.3,
            cyclic: false,
            mode,
            dynamic_control: control,
            target_velocity: 0.1,
            max_force: -5.0,
            target_position: 0.2,
            dependency: Some(cf::JointDependency {
                master: 7,
                multiplier: 2.0,
                offset: 0.5,
            }),
            max_velocity: Some(3.0),
            spherical_rotation: [1.0, 0.0, 0.0, 0.0],
        }
    }

    #[test]
    fn joints_keep_limits_targets_and_map_their_modes() {
        let index = HashMap::from([(7, 4usize)]);
        let mut w = Vec::new();
        let j = convert_joint(
            &joint(cf::JointMode::Dynamic, cf::DynamicControl::Position),
            "j",
            &index,
            &mut w,
        );
        assert_eq!(
            (j.mode, j.limits, j.initial, j.target_position),
            (JointMode::Position, Some((-1.0, 1.5)), 0.3, 0.2)
        );
        assert_eq!((j.max_force, j.max_velocity, j.mimic), (5.0, Some(3.0), None));
        let cases = [
            (
                cf::JointMode::Dynamic,
                cf::DynamicControl::Velocity,
                JointMode::Velocity,
            ),
            (cf::JointMode::Dynamic, cf::DynamicControl::Free, JointMode::Free),
            (cf::JointMode::Dynamic, cf::DynamicControl::Force, JointMode::Force),
            (cf::JointMode::Dynamic, cf::DynamicControl::Spring, JointMode::Position),
            (
                cf::JointMode::Passive,
                cf::DynamicControl::Position,
                JointMode::Kinematic,
            ),
            (
                cf::JointMode::InverseKinematics,
                cf::DynamicControl::Free,
                JointMode::Kinematic,
            ),
        ];
        for (mode, control, want) in cases {
            assert_eq!(convert_joint(&joint(mode, control), "j", &index, &mut w).mode, want);
        }
        let d = convert_joint(
            &joint(cf::JointMode::Dependent, cf::DynamicControl::Free),
            "j",
            &index,
            &mut w,
        );
        assert_eq!(
            d.mimic,
            Some(MimicModel {
                leader: 4,
                multiplier: 2.0,
                offset: 0.5
            })
        );
        let mut s = joint(cf::JointMode::Passive, cf::DynamicControl::Free);
        s.joint_type = cf::JointType::Spherical;
        assert_eq!(convert_joint(&s, "ball", &index, &mut w).joint_type, JointType::Fixed);
        assert!(w.iter().any(|m| m.contains("ball: spherical")), "{w:?}");
    }

    #[test]
    fn settings_give_dt_gravity_and_substeps() {
        let mut w = Vec::new();
        let s = cf::Settings {
            time_step: Some(0.05),
            engine: Some(cf::Engine::Ode),
            gravity: Some([0.0, 0.0, -9.81]),
            engine_step: Some(0.005),
            environment: cf::Environment {
                fog_color: Some([0.25, 0.5, 1.5]),
                background_up: Some([0.8, 0.8, 0.9]),
                ..Default::default()
            },
        };
        let out = convert_settings(&s, &mut w);
        assert_eq!((out.dt, out.substeps, out.gravity), (0.05, 10, [0.0, 0.0, -9.81]));
        // The sensors' background is the fog colour (clamped), not the views' gradient.
        assert_eq!(out.background, Some([0.25, 0.5, 1.0]));
        assert_eq!(w.len(), 1);
        assert_eq!(
            convert_settings(&cf::Settings::default(), &mut w),
            SimSettings {
                solver_iterations: COPPELIA_SOLVER_ITERATIONS,
                ..SimSettings::default()
            }
        );
    }

    fn dummy(handle: i32, parent: Option<i32>) -> cf::SceneObject {
        cf::SceneObject {
            referenced: Vec::new(),
            user_parameters: Vec::new(),
            layer: 1,
            extension: String::new(),
            handle,
            parent,
            name: format!("d{handle}"),
            alias: None,
            local_pose: cf::Pose::IDENTITY,
            collidable: false,
            measurable: false,
            detectable: false,
            model_base: false,
            kind: cf::ObjectKind::Dummy(cf::Dummy {
                linked: None,
                link: cf::DummyLink::Other(0),
            }),
            offset: 0,
        }
    }

    fn file_of(objects: Vec<cf::SceneObject>) -> cf::CoppeliaFile {
        cf::CoppeliaFile {
            header: cf::Header {
                serialization_version: 25,
                oldest_reader_version: 24,
                compression: 1,
                body_len: 0,
                program_version: 40700,
                revision: 0,
                file_type: cf::FileType::Scene,
            },
            objects,
            collections: Vec::new(),
            ik_groups: Vec::new(),
            scripts: Vec::new(),
            settings: cf::Settings::default(),
            textures: Vec::new(),
        }
    }

    #[test]
    fn tree_order_puts_parents_first_and_refuses_cycles() {
        let p = Path::new("x.ttt");
        let mut w = Vec::new();
        // Children listed before their parents, and one orphan.
        let f = file_of(vec![
            dummy(3, Some(2)),
            dummy(2, Some(1)),
            dummy(1, None),
            dummy(4, Some(99)),
        ]);
        let order = hierarchy_order(&f, p, &mut w).unwrap();
        let handles: Vec<i32> = order.iter().map(|&i| f.objects[i].handle).collect();
        assert_eq!(handles, [1, 2, 3, 4]);
        assert!(w[0].contains("d4: parent 99 does not exist"), "{w:?}");
        let cycle = file_of(vec![dummy(1, None), dummy(2, Some(3)), dummy(3, Some(2))]);
        assert!(
            hierarchy_order(&cycle, p, &mut w)
                .unwrap_err()
                .to_string()
                .contains("cycle")
        );
        let twice = file_of(vec![dummy(1, None), dummy(1, None)]);
        assert!(hierarchy_order(&twice, p, &mut w).is_err());
    }

    fn ik_group(name: &str, flags: u8, elements: Vec<cf::IkElement>) -> cf::IkGroup {
        cf::IkGroup {
            handle: 2_030_000,
            name: name.into(),
            max_iterations: 6,
            method: 1,
            damping: f64::from(0.1f32),
            flags,
            elements,
        }
    }

    fn element(tip: i32, base: i32, constraints: i32, active: bool) -> cf::IkElement {
        cf::IkElement {
            tip,
            base,
            constraints,
            active,
        }
    }

    #[test]
    fn ik_groups_take_the_tip_link_as_target_and_drop_what_is_missing() {
        // 1 base, 2 tip linked to 3 target, 4 an unlinked dummy.
        let mut tip = dummy(2, Some(1));
        tip.kind = cf::ObjectKind::Dummy(cf::Dummy {
            linked: Some(3),
            link: cf::DummyLink::IkTipTarget,
        });
        let mut f = file_of(vec![dummy(1, None), tip, dummy(3, None), dummy(4, Some(1))]);
        f.ik_groups = vec![
            ik_group("arm_ik", 0x59, vec![element(2, 1, 7, true)]),
            ik_group("fingers", 0x19, vec![element(2, -1, 31, true)]),
            ik_group("lost_tip", 0x59, vec![element(99, 1, 31, true)]),
            ik_group("unlinked", 0x59, vec![element(4, 1, 31, true)]),
            ik_group(
                "sleeping",
                0x58,
                vec![element(2, 1, 31, true), element(2, 1, 31, false)],
            ),
            ik_group("arm_ik", 0x59, vec![element(2, 1, 31, true)]),
        ];
        let index: HashMap<i32, usize> = [(1, 0), (2, 1), (3, 2), (4, 3)].into();
        let mut w = Vec::new();
        let out = convert_ik_groups(&f, &index, &mut w);
        let names: Vec<&str> = out.iter().map(|g| g.name.as_str()).collect();
        assert_eq!(names, ["arm_ik", "fingers", "unlinked", "sleeping"]);
        assert_eq!(
            out[0],
            IkGroupModel {
                name: "arm_ik".into(),
                elements: vec![IkElementModel {
                    tip: 1,
                    target: 2,
                    base: Some(0),
                    constraints: 7
                }],
                method: IkMethodModel::DampedLeastSquares,
                damping: 0.1,
                max_iterations: 6,
                explicit: true,
            }
        );
        // Bit 6 clear: handled by the main script; base -1: the world.
        assert!(!out[1].explicit);
        assert_eq!(out[1].elements[0].base, None);
        // A tip linked to nothing is its own target.
        assert_eq!((out[2].elements[0].tip, out[2].elements[0].target), (3, 3));
        // Inactive: explicit, and its inactive element left out.
        assert!(out[3].explicit);
        assert_eq!(out[3].elements.len(), 1);
        for part in [
            "IK group 'lost_tip': tip object 99 is not in the file; element dropped",
            "IK group 'lost_tip': no element left; group dropped",
            "IK group 'unlinked': tip 'd4' is linked to no target dummy",
            "IK group 'sleeping': inactive",
            "IK group 'sleeping': the element tipped at object 2 is inactive; element dropped",
            "IK group 'arm_ik': no name or a name used twice; dropped",
        ] {
            assert!(w.iter().any(|m| m.contains(part)), "{part}: {w:?}");
        }
    }

    #[test]
    fn undecodable_files_name_the_file_and_the_problem() {
        let err = load_coppelia(b"not a scene", Path::new("dir/x.ttt")).unwrap_err();
        assert!(matches!(err, LoadError::Coppelia { .. }));
        assert!(err.to_string().starts_with("dir/x.ttt: not a CoppeliaSim"), "{err}");
    }
}
