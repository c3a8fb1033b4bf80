//! `gantry convert`'s writer ([`write_scene`]): a model written as TOML, OBJ meshes and
//! Lua files loads back as the same model, object by object. Over every public
//! CoppeliaSim file in the shared folder (`$GANTRY_COPPELIA_FILES`, else the first
//! `shared/coppelia-files` beside an ancestor of this crate, so it is found from the
//! main checkout and from a worktree), over a URDF robot, and over hand-built models
//! that use every key the writer can emit. Where the shared folder is absent that test
//! prints a note and passes.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use gantry_sim_core::math::{Pose, pose_from_euler};
use gantry_sim_core::scene::{
    CameraModel, CollectionItemModel, CollectionModel, CollectionScope, DiskFiles, GeomModel, Geometry, IkElementModel,
    IkGroupModel, IkMethodModel, JointMode, JointModel, JointType, LightModel, LightType, LoadOptions, MassModel,
    MeshData, MimicModel, ObjectModel, ObjectModelKind, PathModel, Projection, ProximityModel, ReferencedHandles,
    RenderMode, SceneModel, ScriptModel, ServerSettings, ShapeModel, SimSettings, UserParameter, VisionModel,
    VisualModel, load_coppelia, load_scene, write_scene,
};
use gantry_test_support::repo;

/// The shared CoppeliaSim files, or `None` (with a note) where they are absent.
fn shared_folder() -> Option<PathBuf> {
    if let Some(dir) = std::env::var_os("GANTRY_COPPELIA_FILES") {
        return Some(PathBuf::from(dir));
    }
    let found = Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .map(|a| a.join("shared/coppelia-files"))
        .find(|d| d.join("SOURCES.md").is_file());
    if found.is_none() {
        println!("coppelia-files not found beside any ancestor of this crate; skipped (set GANTRY_COPPELIA_FILES)");
    }
    found
}

/// A fresh folder for one conversion.
fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("gantry-convert-{}-{tag}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// Writes `model` into a temp folder and loads the TOML back with the normal loader.
fn round_trip(model: &SceneModel, tag: &str) -> SceneModel {
    let written = write_scene(model, tag, "test").unwrap_or_else(|e| panic!("{tag}: {e}"));
    let dir = scratch(tag);
    for (rel, bytes) in &written.files {
        let path = dir.join(rel);
        std::fs::create_dir_all(path.parent().expect("in the folder")).expect("mkdir");
        std::fs::write(&path, bytes).expect("write");
    }
    let toml = dir.join(format!("{tag}.toml"));
    let back = load_scene(&DiskFiles, &toml, &LoadOptions::default()).unwrap_or_else(|e| {
        panic!(
            "{tag}: the written scene does not load: {e}\n{}",
            std::fs::read_to_string(&toml).unwrap_or_default()
        )
    });
    let unknown: Vec<_> = back.warnings.iter().filter(|w| w.contains("unknown key")).collect();
    assert!(unknown.is_empty(), "{tag}: {unknown:?}");
    std::fs::remove_dir_all(&dir).ok();
    back
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    a == b || (a - b).abs() <= tol * a.abs().max(b.abs()).max(1.0)
}

fn assert_pose(a: &Pose, b: &Pose, what: &str) {
    let dt = (a.translation.vector - b.translation.vector).norm();
    let dr = a.rotation.angle_to(&b.rotation);
    assert!(dt <= 1e-9 && dr <= 1e-9, "{what}: pose moved by {dt} m, {dr} rad");
}

/// Each triangle's three corners, bit for bit: what a mesh is, whatever its vertex list.
fn triangles(m: &MeshData) -> Vec<[[u32; 3]; 3]> {
    m.indices
        .iter()
        .map(|t| t.map(|i| m.vertices[i as usize].map(f32::to_bits)))
        .collect()
}

fn distinct_vertices(m: &MeshData) -> usize {
    let used: std::collections::HashSet<[u32; 3]> = triangles(m).into_iter().flatten().collect();
    used.len()
}

fn assert_geometry(a: &Geometry, b: &Geometry, what: &str) {
    match (a, b) {
        (Geometry::Mesh(x), Geometry::Mesh(y)) => {
            assert_eq!(x.indices.len(), y.indices.len(), "{what}: triangle count");
            assert_eq!(distinct_vertices(x), distinct_vertices(y), "{what}: vertex count");
            assert!(triangles(x) == triangles(y), "{what}: triangles differ");
            // A convex part is the hull of its points, in any order.
            let sets = |m: &MeshData| -> Vec<Vec<[u32; 3]>> {
                m.parts
                    .iter()
                    .map(|p| {
                        let mut p: Vec<[u32; 3]> = p.iter().map(|v| v.map(f32::to_bits)).collect();
                        p.sort_unstable();
                        p
                    })
                    .collect()
            };
            assert_eq!(sets(x), sets(y), "{what}: convex parts");
        }
        _ => assert_eq!(format!("{a:?}"), format!("{b:?}"), "{what}"),
    }
}

fn assert_shape(a: &ShapeModel, b: &ShapeModel, what: &str) {
    assert_eq!(
        (
            a.dynamic,
            a.respondable,
            a.detectable,
            a.measurable,
            a.collidable,
            a.self_collision
        ),
        (
            b.dynamic,
            b.respondable,
            b.detectable,
            b.measurable,
            b.collidable,
            b.self_collision
        ),
        "{what}: flags"
    );
    assert_eq!(
        (a.friction, a.restitution, a.collision_group, a.collision_mask),
        (b.friction, b.restitution, b.collision_group, b.collision_mask),
        "{what}: contact"
    );
    assert_eq!(a.mass, b.mass, "{what}: mass");
    assert_eq!(a.geoms.len(), b.geoms.len(), "{what}: collision parts");
    for (k, (g, h)) in a.geoms.iter().zip(&b.geoms).enumerate() {
        assert_geometry(&g.geometry, &h.geometry, &format!("{what} collision part {k}"));
        assert_pose(&g.local, &h.local, &format!("{what} collision part {k}"));
    }
    assert_eq!(a.visuals.len(), b.visuals.len(), "{what}: visual parts");
    for (k, (v, u)) in a.visuals.iter().zip(&b.visuals).enumerate() {
        assert_geometry(&v.geometry, &u.geometry, &format!("{what} visual part {k}"));
        assert_pose(&v.local, &u.local, &format!("{what} visual part {k}"));
        assert_eq!(v.color, u.color, "{what} visual part {k}: colour");
    }
}

fn assert_joint(a: &JointModel, b: &JointModel, what: &str) {
    let t = 1e-12;
    assert_eq!(
        (a.joint_type, a.mode, a.cyclic),
        (b.joint_type, b.mode, b.cyclic),
        "{what}"
    );
    match (a.limits, b.limits) {
        (Some((l0, h0)), Some((l1, h1))) => assert!(close(l0, l1, t) && close(h0, h1, t), "{what}: limits"),
        (x, y) => assert_eq!(x, y, "{what}: limits"),
    }
    for (name, x, y) in [
        ("initial", a.initial, b.initial),
        ("target_position", a.target_position, b.target_position),
        ("target_velocity", a.target_velocity, b.target_velocity),
        ("max_force", a.max_force, b.max_force),
        ("kp", a.kp, b.kp),
        ("kd", a.kd, b.kd),
        ("damping", a.damping, b.damping),
        ("friction", a.friction, b.friction),
        (
            "max_velocity",
            a.max_velocity.unwrap_or(-1.0),
            b.max_velocity.unwrap_or(-1.0),
        ),
    ] {
        assert!(close(x, y, t), "{what}: {name} {x} became {y}");
    }
    match (a.mimic, b.mimic) {
        (Some(m), Some(n)) => assert!(
            m.leader == n.leader && close(m.multiplier, n.multiplier, t) && close(m.offset, n.offset, t),
            "{what}: mimic {m:?} became {n:?}"
        ),
        (m, n) => assert_eq!(m, n, "{what}: mimic"),
    }
}

fn assert_kind(a: &ObjectModelKind, b: &ObjectModelKind, what: &str) {
    match (a, b) {
        (ObjectModelKind::Shape(x), ObjectModelKind::Shape(y)) => assert_shape(x, y, what),
        (ObjectModelKind::Joint(x), ObjectModelKind::Joint(y)) => assert_joint(x, y, what),
        (ObjectModelKind::ProximitySensor(x), ObjectModelKind::ProximitySensor(y)) => match (x, y) {
            (
                ProximityModel::Cone {
                    offset,
                    range,
                    half_angle,
                },
                ProximityModel::Cone {
                    offset: o,
                    range: r,
                    half_angle: h,
                },
            ) => assert!(
                offset == o && range == r && close(*half_angle, *h, 1e-12),
                "{what}: {x:?} {y:?}"
            ),
            _ => assert_eq!(x, y, "{what}"),
        },
        (ObjectModelKind::Light(x), ObjectModelKind::Light(y)) => {
            // The cutoff is written in degrees.
            assert!(close(x.spot_cutoff, y.spot_cutoff, 1e-12), "{what}: spot cutoff");
            assert_eq!(
                LightModel { spot_cutoff: 0.0, ..*x },
                LightModel { spot_cutoff: 0.0, ..*y },
                "{what}"
            );
        }
        (ObjectModelKind::Path(x), ObjectModelKind::Path(y)) => assert_eq!(x, y, "{what}"),
        (ObjectModelKind::VisionSensor(x), ObjectModelKind::VisionSensor(y)) => {
            assert!(close(x.fov, y.fov, 1e-12), "{what}: fov");
            assert_eq!(VisionModel { fov: 0.0, ..*x }, VisionModel { fov: 0.0, ..*y }, "{what}");
        }
        _ => assert_eq!(
            std::mem::discriminant(a),
            std::mem::discriminant(b),
            "{what}: {a:?} became {b:?}"
        ),
    }
}

/// The two models hold the same scene, object by object.
fn assert_same_model(a: &SceneModel, b: &SceneModel, tag: &str) {
    assert_eq!(a.user_parameters, b.user_parameters, "{tag}: user parameters");
    assert_eq!(a.settings, b.settings, "{tag}: settings");
    assert_eq!(a.server, b.server, "{tag}: server");
    assert_eq!(a.objects.len(), b.objects.len(), "{tag}: object count");
    for (k, (x, y)) in a.objects.iter().zip(&b.objects).enumerate() {
        let what = format!("{tag}: object {k} '{}'", x.alias);
        assert_eq!(
            (&x.alias, x.parent, x.model_base, &x.extension, x.layer),
            (&y.alias, y.parent, y.model_base, &y.extension, y.layer),
            "{what}"
        );
        assert_pose(&x.local, &y.local, &what);
        assert_kind(&x.kind, &y.kind, &what);
    }
    assert_eq!(a.scripts.len(), b.scripts.len(), "{tag}: script count");
    for (s, t) in a.scripts.iter().zip(&b.scripts) {
        assert_eq!(s.object, t.object, "{tag}: script of {}", s.path.display());
        assert!(s.source == t.source, "{tag}: text of {}", s.path.display());
    }
    assert_eq!(a.dummy_links, b.dummy_links, "{tag}: dummy links");
    assert_eq!(a.ball_links, b.ball_links, "{tag}: ball links");
    assert_eq!(a.referenced_handles, b.referenced_handles, "{tag}: referenced handles");
    assert_eq!(a.ik_groups, b.ik_groups, "{tag}: IK groups");
    assert_eq!(a.collections, b.collections, "{tag}: collections");
}

#[test]
fn every_shared_coppelia_file_converts_and_loads_back_the_same() {
    let Some(dir) = shared_folder() else { return };
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .expect("folder")
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".ttt") || n.ends_with(".ttm"))
        .collect();
    names.sort();
    assert!(!names.is_empty(), "no .ttt or .ttm in {}", dir.display());
    println!(
        "{:<42} {:>7} {:>6} {:>7} {:>9}",
        "file", "objects", "meshes", "scripts", "toml kB"
    );
    for name in &names {
        let path = dir.join(name);
        // As `gantry convert` reads it: a model (.ttm) on its floor.
        let model = load_scene(&DiskFiles, &path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
        let tag = name.trim_end_matches(".ttt").trim_end_matches(".ttm");
        let back = round_trip(&model, tag);
        assert_same_model(&model, &back, name);
        let written = write_scene(&model, tag, name).expect("writes");
        let count = |ext: &str| {
            written
                .files
                .iter()
                .filter(|(p, _)| p.extension().is_some_and(|e| e == ext))
                .count()
        };
        println!(
            "{:<42} {:>7} {:>6} {:>7} {:>9.1}",
            name,
            model.objects.len(),
            count("obj"),
            count("lua"),
            written.files[0].1.len() as f64 / 1e3
        );
        // The raw import (no floor) converts too.
        let (raw, _) = load_coppelia(&std::fs::read(&path).expect("read"), &path).expect("imports");
        assert_same_model(&raw, &round_trip(&raw, &format!("{tag}-raw")), name);
    }
}

#[test]
fn a_urdf_robot_converts_with_its_separate_collision_and_visual_parts() {
    let urdf = repo("assets/robots/arm6/arm6.urdf");
    let model = load_scene(&DiskFiles, &urdf, &LoadOptions::default()).expect("loads");
    assert_same_model(&model, &round_trip(&model, "arm6"), "arm6.urdf");
}

/// A tetrahedron at `offset` along X; with `parts`, two of them as two convex parts.
fn mesh(offset: f32, parts: bool) -> Arc<MeshData> {
    let tetra = |x: f32| vec![[x, 0.0, 0.0], [x + 0.1, 0.0, 0.0], [x, 0.1, 0.0], [x, 0.0, 0.1]];
    let faces = |b: u32| {
        [
            [b, b + 2, b + 1],
            [b, b + 1, b + 3],
            [b, b + 3, b + 2],
            [b + 1, b + 2, b + 3],
        ]
    };
    let mut vertices = tetra(offset);
    let mut indices = faces(0).to_vec();
    let mut convex = Vec::new();
    if parts {
        vertices.extend(tetra(offset + 1.0));
        indices.extend(faces(4));
        convex = vec![vertices[..4].to_vec(), vertices[4..].to_vec()];
    }
    Arc::new(MeshData {
        source: "hand-built".into(),
        vertices,
        indices,
        parts: convex,
    })
}

fn object(alias: &str, parent: Option<usize>, local: Pose, kind: ObjectModelKind) -> ObjectModel {
    ObjectModel {
        alias: alias.into(),
        parent,
        local,
        model_base: false,
        extension: String::new(),
        layer: 1,
        kind,
    }
}

fn joint(joint_type: JointType, mode: JointMode) -> JointModel {
    JointModel {
        joint_type,
        mode,
        limits: Some((-1.25, 2.0 / 3.0)),
        cyclic: false,
        initial: 0.1,
        target_position: -0.2,
        target_velocity: 0.3,
        max_force: 12.5,
        kp: 1e5,
        kd: 3.0,
        damping: 0.0,
        friction: 0.25,
        max_velocity: Some(std::f64::consts::PI),
        mimic: None,
    }
}

/// A model that uses every kind and every field the writer has a key for.
fn everything() -> SceneModel {
    let m = mesh(0.0, false);
    // CoppeliaSim's beta a hair off 90°: its Euler angles snap to gimbal lock there.
    let gimbal = pose_from_euler([0.1, -0.2, 1.0 / 3.0], [0.3, std::f64::consts::FRAC_PI_2 - 1e-7, -0.2]);
    let tilted = pose_from_euler([1e-7, 2.5e10, -0.0], [0.1, 0.2, 0.3]);
    let compound = ShapeModel {
        geoms: vec![
            GeomModel {
                geometry: Geometry::Mesh(m.clone()),
                local: tilted,
            },
            GeomModel {
                geometry: Geometry::Capsule {
                    radius: 0.05,
                    length: 0.2,
                },
                local: Pose::identity(),
            },
        ],
        visuals: vec![
            VisualModel {
                geometry: Geometry::Mesh(m),
                local: tilted,
                color: [0.1, 0.2, 1.0 / 3.0],
                texture: None,
            },
            VisualModel {
                geometry: Geometry::Capsule {
                    radius: 0.05,
                    length: 0.2,
                },
                local: Pose::identity(),
                color: [1.0, 0.5, 0.0],
                texture: None,
            },
        ],
        dynamic: true,
        mass: MassModel::Inertial {
            mass: 1.5,
            com: [0.01, -0.02, 0.1],
            frame: [0.0, 0.0, 0.6, 0.8],
            inertia: [0.01, 1e-5, -2e-5, 0.02, 0.0, 0.03],
        },
        friction: 0.7,
        restitution: 0.2,
        collision_group: 0b101,
        collision_mask: 0xffff_fffe,
        respondable: false,
        detectable: false,
        measurable: true,
        collidable: false,
        self_collision: false,
    };
    let visual_only = ShapeModel {
        geoms: vec![GeomModel {
            geometry: Geometry::Box {
                half_extents: [0.1, 0.2, 0.3],
            },
            local: Pose::identity(),
        }],
        visuals: vec![VisualModel {
            geometry: Geometry::Mesh(mesh(1.0, true)),
            local: gimbal,
            color: [0.3, 0.3, 0.3],
            texture: None,
        }],
        mass: MassModel::Mass(0.0),
        ..ShapeModel::single(Geometry::Sphere { radius: 0.1 }, [0.0; 3])
    };
    let mut follower = joint(JointType::Prismatic, JointMode::Kinematic);
    follower.mimic = Some(MimicModel {
        leader: 1,
        multiplier: -0.5,
        offset: 0.01,
    });
    follower.limits = None;
    follower.max_velocity = None;
    let mut wheel = joint(JointType::Revolute, JointMode::Velocity);
    wheel.limits = None;
    wheel.cyclic = true;
    let objects = vec![
        object("base/one", None, gimbal, ObjectModelKind::Shape(compound)),
        object(
            "joint",
            Some(0),
            tilted,
            ObjectModelKind::Joint(joint(JointType::Revolute, JointMode::Position)),
        ),
        object("joint", Some(1), Pose::identity(), ObjectModelKind::Joint(follower)),
        object("wheel", Some(0), Pose::identity(), ObjectModelKind::Joint(wheel)),
        object(
            "fixed",
            Some(3),
            Pose::identity(),
            ObjectModelKind::Joint(joint(JointType::Fixed, JointMode::Free)),
        ),
        object("", Some(2), Pose::identity(), ObjectModelKind::Shape(visual_only)),
        ObjectModel {
            // An RLBench waypoint's commands, with what TOML must escape.
            extension: "open_gripper();ignore_collisions;linear \"q\"\n\\ povray {x {1}}".into(),
            ..object("tip", Some(5), tilted, ObjectModelKind::Dummy)
        },
        object("target", None, gimbal, ObjectModelKind::Dummy),
        object(
            "ray",
            Some(0),
            Pose::identity(),
            ObjectModelKind::ProximitySensor(ProximityModel::Ray {
                offset: 0.01,
                range: 1.5,
            }),
        ),
        object(
            "cone",
            Some(0),
            Pose::identity(),
            ObjectModelKind::ProximitySensor(ProximityModel::Cone {
                offset: 0.0,
                range: 0.3,
                half_angle: 0.4,
            }),
        ),
        object(
            "camera",
            Some(0),
            tilted,
            ObjectModelKind::VisionSensor(VisionModel {
                resolution: [64, 48],
                projection: Projection::Orthographic,
                fov: 1.0,
                ortho_size: 0.25,
                near: 0.01,
                far: 10.0,
                // Non-default, so that the writer's keys for them are read back.
                render_mode: RenderMode::ColorCoded,
                ignore_rgb: false,
                ignore_depth: true,
                ros2_rate: Some(15.0),
                background: Some([1.0, 0.5, 0.0]),
            }),
        ),
        object("fs", Some(0), Pose::identity(), ObjectModelKind::ForceSensor),
        object("graph", None, Pose::identity(), ObjectModelKind::Graph),
        object(
            "ball",
            None,
            Pose::translation(0.0, 0.0, 1.0),
            ObjectModelKind::Shape(ShapeModel::single(Geometry::Sphere { radius: 0.1 }, [0.9, 0.1, 0.1])),
        ),
        object(
            "pyramid",
            Some(0),
            Pose::identity(),
            ObjectModelKind::ProximitySensor(ProximityModel::Pyramid {
                offset: 0.01,
                range: 0.2,
                near_size: [0.01, 0.02],
                far_size: [0.1, 0.2],
            }),
        ),
        object(
            "viewpoint",
            None,
            Pose::translation(1.0, 2.0, 3.0),
            ObjectModelKind::Camera(CameraModel { fov: 0.9 }),
        ),
        object(
            "spot",
            Some(0),
            Pose::translation(0.0, 0.0, 2.0),
            ObjectModelKind::Light(LightModel {
                on: false,
                diffuse: [0.25, 0.5, 0.75],
                specular: [0.1, 0.2, 0.3],
                spot_exponent: 9,
                spot_cutoff: 0.6,
                attenuation: [0.5, 0.125, 0.25],
                casts_shadows: true,
                ..LightModel::new(LightType::Spot)
            }),
        ),
        object(
            "old_path",
            None,
            Pose::translation(0.5, 0.0, 0.0),
            ObjectModelKind::Path(PathModel {
                ctrl_points: vec![
                    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
                    [
                        1.0,
                        0.0,
                        0.5,
                        0.0,
                        0.0,
                        std::f64::consts::FRAC_1_SQRT_2,
                        std::f64::consts::FRAC_1_SQRT_2,
                    ],
                    [1.0, 1.0, 0.5, 0.0, 0.0, 0.0, 1.0],
                ],
                closed: true,
                smoothness: 0.95,
                subdiv: 45,
            }),
        ),
    ];
    // One object on a hidden layer (CoppeliaSim's respondable shapes are on layer 9).
    let mut objects = objects;
    objects[1].layer = 0x0100;
    SceneModel {
        name: "everything".into(),
        base_dir: PathBuf::new(),
        path: PathBuf::new(),
        settings: SimSettings {
            dt: 0.01,
            substeps: 7,
            collisions_every_substep: true,
            solver_iterations: 3,
            gravity: [0.1, 0.0, -1.62],
            seed: -7,
            background: Some([0.25, 0.5, 0.75]),
        },
        server: ServerSettings {
            bind: Some("127.0.0.1".into()),
            text_port: Some(6001),
            zmq_port: None,
            http_port: Some(0),
        },
        objects,
        scripts: vec![
            ScriptModel {
                object: 0,
                path: "a".into(),
                source: "-- é \"quoted\"\r\nfunction sysCall_init() end\n".into(),
            },
            ScriptModel {
                object: 0,
                path: "b".into(),
                source: "function sysCall_thread() end".into(),
            },
            ScriptModel {
                object: 7,
                path: "c".into(),
                source: String::new(),
            },
        ],
        dummy_links: vec![[7, 6]],
        ball_links: Vec::new(),
        ik_groups: vec![IkGroupModel {
            name: "arm_ik".into(),
            elements: vec![IkElementModel {
                tip: 6,
                target: 7,
                base: Some(5),
                constraints: 7 | 16,
            }],
            method: IkMethodModel::DampedLeastSquares,
            damping: 0.05,
            max_iterations: 40,
            explicit: true,
        }],
        referenced_handles: vec![ReferencedHandles {
            object: 0,
            tag: "ik.tip".into(),
            targets: vec![7, 6],
        }],
        user_parameters: vec![UserParameter {
            object: 0,
            name: "verticalAngle".into(),
            unit: "degrees (5-180)".into(),
            value: "180".into(),
        }],
        collections: vec![
            CollectionModel {
                name: "arm".into(),
                items: vec![
                    CollectionItemModel {
                        scope: CollectionScope::Tree,
                        object: Some(0),
                        remove: false,
                        exclude_base: false,
                    },
                    CollectionItemModel {
                        scope: CollectionScope::Object,
                        object: Some(5),
                        remove: true,
                        exclude_base: false,
                    },
                    CollectionItemModel {
                        scope: CollectionScope::Chain,
                        object: Some(6),
                        remove: false,
                        exclude_base: true,
                    },
                ],
            },
            CollectionModel {
                name: "everything \"quoted\"".into(),
                items: vec![CollectionItemModel {
                    scope: CollectionScope::All,
                    object: None,
                    remove: false,
                    exclude_base: false,
                }],
            },
        ],
        urdf_robots: Vec::new(),
        warnings: vec!["line one\nline two".into()],
        textures: Vec::new(),
    }
}

#[test]
fn a_hand_built_model_with_every_key_loads_back_the_same() {
    let model = everything();
    assert_same_model(&model, &round_trip(&model, "everything"), "everything");
}

#[test]
fn written_text_is_readable_and_names_are_unique() {
    let written = write_scene(&everything(), "everything", "x.ttt").expect("writes");
    let toml = String::from_utf8(written.files[0].1.clone()).expect("utf-8");
    assert_eq!(written.files[0].0, Path::new("everything.toml"));
    assert!(
        toml.starts_with("# everything: converted by `gantry convert` from x.ttt."),
        "{toml}"
    );
    assert!(toml.contains("# import: line one line two\n"), "{toml}");
    // A '/' in an alias cannot be in a name; repeated and empty aliases get unique names.
    for line in [
        "name = \"base_one\"\nkind = \"shape\"\nalias = \"base/one\"",
        "name = \"joint_2\"\nkind = \"joint\"\nalias = \"joint\"",
        "name = \"shape\"\nkind = \"shape\"\nalias = \"\"",
        "mimic = { leader = \"joint\", multiplier = -0.5, offset = 0.01 }",
        "[[dummy_link]]\ndummies = [\"target\", \"tip\"]",
        "collision_mask = 0xfffffffe",
        "role = \"visual\"",
    ] {
        assert!(toml.contains(line), "{line}\n---\n{toml}");
    }
    // Near gimbal lock the Euler angles would lose the rotation: a quaternion is written.
    assert!(toml.contains("quaternion = ["), "{toml}");
    let paths: Vec<_> = written.files.iter().map(|(p, _)| p.display().to_string()).collect();
    assert_eq!(
        paths,
        [
            "everything.toml",
            "meshes/base_one.obj",
            "meshes/shape.obj",
            "scripts/base_one.lua",
            "scripts/base_one_2.lua",
            "scripts/target.lua",
        ]
    );
    assert!(written.notes.is_empty(), "{:?}", written.notes);
}

#[test]
fn non_finite_values_are_refused_naming_the_object() {
    let mut model = everything();
    model.objects[1].kind = ObjectModelKind::Joint(JointModel {
        max_force: f64::NAN,
        ..joint(JointType::Revolute, JointMode::Position)
    });
    let err = write_scene(&model, "x", "x.ttt").unwrap_err().to_string();
    assert_eq!(err, "object 'joint': max_force is not a finite number");
}

fn load_text(text: &str) -> Result<SceneModel, String> {
    gantry_sim_core::scene::load_scene_text(&DiskFiles, text, Path::new("keys.toml"), &LoadOptions::default())
        .map_err(|e| e.to_string())
}

/// The scene-format keys the writer needs, read by hand-written scenes too.
#[test]
fn the_keys_added_for_conversion_load_into_the_model() {
    let model = load_text(
        r#"
[[object]]
name = "body"
kind = "shape"
dynamic = true
mass = 2.0
center_of_mass = [0, 0, 0.1]
inertia = [1, 0, 0, 2, 0, 3]
inertia_frame = [0, 0, 0.6, 0.8]
self_collision = false
quaternion = [0, 0, 1, 0]

[[object.part]]
shape = "box"
size = [0.2, 0.2, 0.2]
color = [1, 0, 0]

[[object.part]]
role = "collision"
shape = "sphere"
radius = 0.1
position = [0, 0, 0.5]

[[object.part]]
role = "visual"
shape = "cylinder"
radius = 0.1
length = 0.3
orientation_deg = [90, 0, 0]

[[object]]
name = "leader"
kind = "joint"
joint = "revolute"
parent = "body"
damping = 0.5
friction = 0.25
max_velocity = 90

[[object]]
name = "follower"
kind = "joint"
joint = "revolute"
parent = "leader"
mimic = { leader = "leader", multiplier = -2, offset = 45 }

[[object]]
name = "a"
kind = "dummy"
parent = "follower"

[[object]]
name = "b"
kind = "dummy"

[[dummy_link]]
dummies = ["b", "a"]
"#,
    )
    .expect("loads");
    assert!(model.warnings.is_empty(), "{:?}", model.warnings);
    let ObjectModelKind::Shape(s) = &model.objects[0].kind else {
        panic!("a shape")
    };
    assert_eq!(
        s.mass,
        MassModel::Inertial {
            mass: 2.0,
            com: [0.0, 0.0, 0.1],
            frame: [0.0, 0.0, 0.6, 0.8],
            inertia: [1.0, 0.0, 0.0, 2.0, 0.0, 3.0],
        }
    );
    assert!(!s.self_collision);
    // Box (both), sphere (collision only), cylinder (visual only).
    assert_eq!((s.geoms.len(), s.visuals.len()), (2, 2));
    assert!(matches!(s.geoms[1].geometry, Geometry::Sphere { .. }));
    assert_eq!(s.geoms[1].local.translation.vector.z, 0.5);
    assert!(matches!(s.visuals[1].geometry, Geometry::Cylinder { .. }));
    assert_eq!(
        (s.visuals[0].color, s.visuals[1].color),
        ([1.0, 0.0, 0.0], [0.8, 0.8, 0.8])
    );
    assert!((s.visuals[1].local.rotation.angle() - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    // The quaternion [0, 0, 1, 0] is a half turn about Z.
    assert!((model.objects[0].local.rotation.angle() - std::f64::consts::PI).abs() < 1e-12);
    let joint = |k: usize| match &model.objects[k].kind {
        ObjectModelKind::Joint(j) => j.clone(),
        other => panic!("{other:?}"),
    };
    let leader = joint(1);
    assert_eq!((leader.damping, leader.friction), (0.5, 0.25));
    assert!((leader.max_velocity.expect("set") - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    let m = joint(2).mimic.expect("a mimic joint");
    assert_eq!((m.leader, m.multiplier), (1, -2.0));
    assert!(
        (m.offset - std::f64::consts::FRAC_PI_4).abs() < 1e-15,
        "offset in degrees"
    );
    // Without the keys, a joint keeps the scene format's defaults.
    assert_eq!(
        (joint(2).damping, joint(2).friction, joint(2).max_velocity),
        (0.1, 0.0, None)
    );
    assert_eq!(model.dummy_links, vec![[4, 3]]);
}

#[test]
fn the_keys_added_for_conversion_are_checked() {
    let dummy = "[[object]]\nname = \"d\"\nkind = \"dummy\"\n";
    let joint = "[[object]]\nname = \"j\"\nkind = \"joint\"\njoint = \"revolute\"\n";
    for (text, want) in [
        (
            format!("{dummy}orientation_deg = [0, 0, 0]\nquaternion = [0, 0, 0, 1]\n"),
            "object 'd': give orientation_deg or quaternion, not both",
        ),
        (
            format!("{dummy}quaternion = [0, 0, 0, 0]\n"),
            "quaternion [0.0, 0.0, 0.0, 0.0] must be finite and not zero",
        ),
        (
            "[[object]]\nname = \"s\"\nkind = \"shape\"\nshape = \"sphere\"\nradius = 1.0\n[[object.part]]\nshape = \"sphere\"\nradius = 1.0\n".into(),
            "shape 's': give `shape` or `[[object.part]]` tables, not both",
        ),
        (
            "[[object]]\nname = \"s\"\nkind = \"shape\"\n[[object.part]]\nrole = \"ghost\"\nshape = \"sphere\"\nradius = 1.0\n".into(),
            "shape 's' part 1: unknown role 'ghost'; use both, collision or visual",
        ),
        (
            "[[object]]\nname = \"s\"\nkind = \"shape\"\nshape = \"sphere\"\nradius = 1.0\ninertia = [1, 0, 0, 1, 0, 1]\n".into(),
            "shape 's': `inertia` needs `mass` (and no `density`)",
        ),
        (
            format!("{dummy}[[collection]]\nname = \"c\"\n[[collection.item]]\nscope = \"branch\"\nobject = \"d\"\n"),
            "collection 'c': unknown scope 'branch' (use object, tree, chain or all)",
        ),
        (
            format!("{dummy}[[collection]]\nname = \"c\"\n[[collection.item]]\nscope = \"tree\"\n"),
            "collection 'c': an item needs its object",
        ),
        (
            format!("{dummy}[[collection]]\nname = \"c\"\n[[collection]]\nname = \"c\"\n"),
            "collection: name 'c' is empty or used twice",
        ),
        (
            format!("{joint}mimic = {{ leader = \"d\" }}\n{dummy}"),
            "mimic leader 'd' must be another joint",
        ),
        (
            format!("{joint}mimic = {{ leader = \"nobody\" }}\n"),
            "'nobody' is not defined in this scene",
        ),
        (
            format!("{joint}max_velocity = 0\n"),
            "joint 'j': max_velocity must be > 0",
        ),
        (
            format!("{joint}{dummy}[[dummy_link]]\ndummies = [\"d\", \"j\"]\n"),
            "dummy_link: 'j' is not a dummy",
        ),
        (
            format!("{dummy}[[dummy_link]]\ndummies = [\"d\", \"d\"]\n"),
            "dummy_link: a dummy cannot be linked to itself",
        ),
    ] {
        let err = load_text(&text).expect_err(&text);
        assert!(err.starts_with("keys.toml:") && err.contains(want), "{err}\n---\n{text}");
    }
    // Unknown keys inside parts and mimic tables are warned about, with a hint.
    let model = load_text(&format!(
        "{joint}[[object]]\nname = \"k\"\nkind = \"joint\"\njoint = \"revolute\"\nmimic = {{ leader = \"j\", multiplyer = 2 }}\n\
         [[object]]\nname = \"s\"\nkind = \"shape\"\n[[object.part]]\nshape = \"sphere\"\nradius = 1.0\ncolour = [1, 0, 0]\n"
    ))
    .expect("loads");
    assert_eq!(
        model.warnings,
        [
            "unknown key 'object[1] ('k').mimic.multiplyer' (did you mean 'multiplier'?)",
            "unknown key 'object[2] ('s').part[0].colour' (did you mean 'color'?)",
        ]
    );
}
