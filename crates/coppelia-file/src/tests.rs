//! Whole-file tests on small files the tests build themselves, so the format code is
//! covered on any clone (the public files are checked by `tests/shared_files.rs`).

use crate::testutil::{Payload, Stream, file, light_encode, pack_indices};
use crate::*;

/// Precision of the generated file: f32 tags (`Cfq`, `Mas`, ...) or f64 (`_fq`, `_as`).
#[derive(Clone, Copy)]
pub(crate) enum Precision {
    Single,
    Double,
}

/// `tag` in the right variant with `values` in the right width.
fn reals(s: Stream, p: Precision, f32_tag: &str, f64_tag: &str, lead: &[u8], values: &[f64]) -> Stream {
    match p {
        Precision::Single => {
            let v: Vec<f32> = values.iter().map(|&v| v as f32).collect();
            s.chunk(f32_tag, &Payload::new().raw(lead).f32s(&v).done())
        }
        Precision::Double => s.chunk(f64_tag, &Payload::new().raw(lead).f64s(values).done()),
    }
}

/// The common part of an object, up to and including `NXT`.
fn common(p: Precision, handle: i32, parent: i32, name: &str, pose: [f64; 7], omp: i32, var: u8) -> Stream {
    let s = Stream::new().chunk("3do", b"9:;");
    let s = reals(s, p, "Cfq", "_fq", &[], &pose);
    s.chunk("Ids", &Payload::new().i32(handle).i32(parent).done())
        .chunk("Ali", &Payload::new().str(&format!("{name}Alias")).done())
        .chunk("Nme", &Payload::new().str(name).done())
        .chunk("Omp", &Payload::new().i32(omp).done())
        .chunk("Rst", &Payload::new().str(&format!("open_{name}();linear")).done())
        .chunk("Va3", &[var])
        .chunk(
            "Cr2",
            &Payload::new().str("self.parent").i32(2).i32(handle).i32(parent).done(),
        )
        .chunk("Zzz", b"an unknown chunk is skipped")
        .marker("NXT")
}

/// A scene with one object of every decoded kind, in the given precision.
pub(crate) fn sample_body(p: Precision) -> Vec<u8> {
    let h = std::f64::consts::FRAC_1_SQRT_2;
    // Mesh buffers: a unit triangle (packed indices), a quad (raw indices).
    let tri = Payload::new()
        .f32s(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0])
        .done();
    let quad = Payload::new()
        .f32s(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0])
        .done();
    let quad_ind = Payload::new().i32(0).i32(1).i32(2).i32(0).i32(2).i32(3).done();
    let vin = Stream::new()
        .chunk("Ver", &tri)
        .chunk("Ver", &quad)
        .chunk("In2", &pack_indices(&[0, 1, 2]))
        .chunk("Ind", &quad_ind);

    // A simple shape: one mesh, a cylinder primitive, its vertex frame turned 90° about z.
    let colour = Stream::new().chunk("Cl3", &Payload::new().f32s(&[0.5, 0.25, 1.0]).f32s(&[0.0; 12]).done());
    let wrapper = Stream::new().chunk("Nme", &Payload::new().str("sub__0").done());
    let wrapper = reals(wrapper, p, "Mas", "_as", &[], &[2.0]);
    // Principal frame at (0, 0, 0.1), turned 90° about z; moments per kg.
    let wrapper = reals(
        wrapper,
        p,
        "Ine",
        "_ne",
        &[],
        &[0.0, 0.0, 0.1, h, 0.0, 0.0, h, 1.0, 2.0, 3.0],
    );
    let mesh = wrapper
        .marker("EOO")
        .nested("Cl0", colour)
        .chunk("Vev", &0i32.to_le_bytes())
        .chunk("Inv", &0i32.to_le_bytes())
        .chunk("Nov", &(-1i32).to_le_bytes());
    let mesh = reals(mesh, p, "Ppr", "_pr", &5i32.to_le_bytes(), &[0.2, 0.2, 0.5]);
    let mesh = reals(mesh, p, "Ppf", "_pf", &[], &[0.0, 0.0, 0.25, h, 0.0, 0.0, h]);
    let material = reals(
        Stream::new(),
        p,
        "BuN",
        "_uN",
        &Payload::new().i32(3).i32(0).done(),
        &[0.3, 0.9, 0.7],
    );
    let shape = common(p, 10, -1, "base", [1.0, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0], 0x1f3, 1)
        .nested("Ge2", Stream::new().nested("Gst", mesh))
        .nested("Mat", material)
        .chunk("Dc2", &0xff00u16.to_le_bytes())
        .chunk("Sss", &[0x80])
        .chunk("Ss3", &[0x01]);

    // A compound: a mesh leaf and a nested compound with another leaf.
    let leaf = |name: &str, vev: i32, inv: i32| {
        let w = Stream::new().chunk("Nme", &Payload::new().str(name).done());
        let w = reals(w, p, "Mas", "_as", &[], &[0.5]).marker("EOO");
        let w = w.chunk("Vev", &vev.to_le_bytes()).chunk("Inv", &inv.to_le_bytes());
        reals(w, p, "Ppf", "_pf", &[], &[1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
    };
    let inner = reals(Stream::new(), p, "Mas", "_as", &[], &[0.5]).nested("Geo", leaf("quad", 1, 1));
    let root = reals(Stream::new(), p, "Mas", "_as", &[], &[1.0])
        .chunk("Com", &Payload::new().f64s(&[0.1, 0.2, 0.3]).done())
        .chunk(
            "Imx",
            &Payload::new()
                .f64s(&[1.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 3.0])
                .done(),
        )
        .nested("Geo", leaf("tri", 0, 0))
        .nested("Wrp", inner);
    let compound = common(p, 11, 10, "link", [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0], 0, 0)
        .nested("Ge2", Stream::new().nested("Gsg", root));

    // A revolute joint at 90°, dynamic in position control, depending on nothing.
    let joint = common(p, 12, 10, "joint", [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.2], 0, 0)
        .chunk("Jtt", &10i32.to_le_bytes())
        .chunk("Va9", &[0x01])
        .chunk("Jmd", &5i32.to_le_bytes())
        .chunk("Dcm", &8i32.to_le_bytes())
        .chunk("_uc", &Payload::new().f64s(&[3.0, 10.0, 100.0]).done());
    let joint = reals(joint, p, "Pmr", "_mr", &[], &[-1.5, 3.0]);
    let joint = reals(joint, p, "Prt", "_rt", &[], &[std::f64::consts::FRAC_PI_2]);
    let joint = reals(joint, p, "Dmp", "_mp", &[], &[0.5, 20.0]);
    let joint = reals(joint, p, "Dtp", "_tp", &[], &[0.25]);
    let joint = reals(joint, p, "Jdt", "_dt", &(-1i32).to_le_bytes(), &[1.0, 0.0]);

    // Tip and target dummies, the tip under the joint.
    let tip = common(p, 13, 12, "arm_tip", [1.0, 0.0, 0.0, 0.0, 0.3, 0.0, 0.0], 0, 0)
        .chunk("Lli", &14i32.to_le_bytes())
        .chunk("Dl2", &5i32.to_le_bytes());
    let target = common(p, 14, -1, "arm_target", [1.0, 0.0, 0.0, 0.0, 0.0, 0.3, 0.7], 0, 0)
        .chunk("Lli", &13i32.to_le_bytes())
        .chunk("Dl2", &5i32.to_le_bytes());

    // Sensors.
    let volume = Stream::new().chunk("Snt", &3i32.to_le_bytes());
    let volume = reals(
        volume,
        p,
        "Ss3",
        "_s3",
        &[],
        &[0.01, 0.5, 9.0, 9.0, 9.0, 9.0, 0.02, 9.0, 1.0],
    );
    let proximity = common(p, 15, 10, "sonar", [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 0, 0)
        .chunk("Snt", &20i32.to_le_bytes())
        .nested("Vod", volume);
    let vision = common(p, 16, 10, "camera", [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 0, 0)
        .chunk("Res", &Payload::new().i32(64).i32(48).done())
        .chunk("Va3", &[0x01]);
    let vision = reals(vision, p, "Ccp", "_cp", &[], &[0.1, 1.0, 0.01, 10.0]);
    let camera = common(p, 20, -1, "view", [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 3.0], 0, 0)
        .chunk("Cp4", &Payload::new().i32(-1).f32s(&[0.1]).done());
    let camera = reals(camera, p, "Cp3", "_p3", &[], &[2.5, 0.75]);
    let camera = reals(camera, p, "Ccp", "_cp", &[], &[0.05, 30.0]);
    let force = common(p, 17, 10, "force", [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 0, 0)
        .chunk("Fil", &Payload::new().i32(5).i32(1).done());
    let force = match p {
        Precision::Single => force.chunk("Tre", &Payload::new().f32s(&[100.0, 10.0]).i32(3).done()),
        Precision::Double => force.chunk("_ri", &Payload::new().f64s(&[100.0, 10.0]).i32(3).done()),
    };

    // Scripts: a script object with a child script, and a default main script in LST.
    let child_text = b"function sysCall_init()\n    sim.addLog(sim.verbosity_msgs, 'hello')\nend\n";
    let soo = Stream::new()
        .chunk("Si2", &Payload::new().i32(0).i32(18).i32(1).done())
        .chunk("Va2", &[0xc9])
        .chunk("Ste", &light_encode(child_text))
        .chunk("Lne", &Payload::new().str("lua").done());
    let script_object = common(p, 18, 11, "Script", [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 0, 0).nested("Soo", soo);
    let main = Stream::new()
        .chunk("Si2", &Payload::new().i32(1).i32(-1).i32(0).done())
        .chunk("Va2", &[0xc0])
        .chunk("Ste", &light_encode(b"require('defaultMainScript')"));

    let sim = Stream::new().chunk("Sts", &0.05f32.to_le_bytes());
    let sim = match p {
        Precision::Single => sim,
        Precision::Double => sim
            .chunk("St2", &50_000u64.to_le_bytes())
            .chunk("_t3", &0.025f64.to_le_bytes()),
    };
    let dynamics = Stream::new().chunk("Ver", &0i32.to_le_bytes());
    let dynamics = reals(dynamics, p, "En3", "_n3", &1i32.to_le_bytes(), &[0.0, 0.0, -9.81]);
    // The f32 sample has no step chunk: the step is the first Bullet/ODE parameter.
    let dynamics = match p {
        Precision::Single => dynamics
            .chunk("BuN", &Payload::new().i32(1).i32(0).f32s(&[0.002]).done())
            .chunk("OdN", &Payload::new().i32(1).i32(0).f32s(&[0.005]).done()),
        Precision::Double => reals(dynamics, p, "Stp", "_tp", &[], &[0.005]),
    };

    // A spot light, off, with its colours in a colour object as 4.x writes it.
    let light = common(p, 19, -1, "light", [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 2.0], 0, 0);
    let light = reals(light, p, "Cp2", "_p2", &Payload::new().i32(2).i32(7).done(), &[0.1]);
    let light = reals(light, p, "Cp3", "_p3", &[], &[0.75]);
    let light = reals(light, p, "Caf", "_af", &[], &[0.5, 0.125, 0.25]);
    let colours = |ambient: f32| {
        Payload::new()
            .f32s(&[ambient, ambient, ambient, 0.25, 0.5, 0.75, 0.125, 0.375, 0.625])
            .f32s(&[0.0; 6])
            .done()
    };
    let light = light
        .chunk("Cas", &[0x02])
        .nested(
            "Cl1",
            Stream::new().chunk("Cl3", &Payload::new().f32s(&[0.9; 15]).done()),
        )
        .nested(
            "Cl2",
            Stream::new().chunk("Cl2", &colours(0.2)).chunk("Cl3", &colours(0.0)),
        );
    // An old path: two control points, closed.
    let point = |x: f64, q: [f64; 4]| {
        let s = Stream::new();
        let v = [x, 0.5, 0.0, q[0], q[1], q[2], q[3], 0.25, 0.75];
        let s = match p {
            Precision::Single => {
                let v: Vec<f32> = v.iter().map(|&v| v as f32).collect();
                s.chunk("At2", &Payload::new().f32s(&v).i32(9).f32s(&[0.5]).done())
            }
            Precision::Double => s.chunk("_t2", &Payload::new().f64s(&v).i32(9).f64s(&[0.5]).done()),
        };
        reals(s, p, "At3", "_t3", &[], &[0.0])
    };
    let ntp = Stream::new()
        .nested("Pat", point(0.0, [1.0, 0.0, 0.0, 0.0]))
        .nested("Pat", point(1.0, [h, 0.0, 0.0, h]))
        .chunk("Si2", &Payload::new().i32(1).f32s(&[0.01]).done())
        .chunk("At2", &Payload::new().i32(4 | 1).done());
    let path = common(p, 21, -1, "path", [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 0, 0)
        .chunk("Var", &[4])
        .nested("Ntp", ntp);

    Stream::new()
        .nested("MTC", Stream::new().chunk("Tm2", &[0; 16]))
        .nested("VIN", vin)
        .nested("SHP", shape)
        .nested("SHP", compound)
        .nested("JNT", joint)
        .nested("DMY", tip)
        .nested("DMY", target)
        .nested("SNR", proximity)
        .nested("RSN", vision)
        .nested("FSE", force)
        .nested("SCT", script_object)
        .nested("CMA", camera)
        .nested("LGT", light)
        .nested("PAT", path)
        .nested("SIM", sim)
        .nested("DYN", dynamics)
        .nested("LST", main)
        .nested("GRP", collection())
        .nested(
            "IKO",
            Stream::new()
                .chunk("Oid", &Payload::new().i32(2_031_029).done())
                .chunk("Nme", &Payload::new().str("base_ik").done())
                .chunk("Mit", &Payload::new().i32(6).done())
                .chunk("Dpg", &Payload::new().f32s(&[0.25]).done())
                .chunk("Cmt", &Payload::new().i32(1).done())
                .chunk("Var", &[0x59])
                .nested(
                    "Ike",
                    Stream::new()
                        .chunk("Ik2", &Payload::new().i32(12).i32(10).done())
                        .chunk("Ctr", &Payload::new().i32(7).done())
                        .chunk("Var", &[1]),
                ),
        )
        .marker("EOF")
        .bytes()
}

/// A collection as PyRep's arms have: the tree from the base, less one loose object.
fn collection() -> Stream {
    let item = |object: i32, kind: u8, var: u8| {
        Stream::new()
            .chunk("Obj", &Payload::new().i32(object).i32(0).done())
            .chunk("Gty", &[kind])
            .chunk("Var", &[var])
    };
    Stream::new()
        .chunk("Grn", &Payload::new().str("base_arm").done())
        .chunk("Gix", &Payload::new().i32(2_000_002).done())
        .chunk("Par", &[0])
        .chunk("Uis", &Payload::new().str("A5401EBDDE1E2F77").done())
        .nested("Asg", item(10, 1, 1))
        .nested("Asg", item(11, 0, 0))
}

pub(crate) fn sample_file(p: Precision) -> Vec<u8> {
    let (ser, version) = match p {
        Precision::Single => (22, 40100),
        Precision::Double => (25, 40700),
    };
    file(ser, version, 1, &sample_body(p))
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-6
}

#[test]
fn reads_every_kind_in_both_precisions() {
    for p in [Precision::Single, Precision::Double] {
        let f = read(&sample_file(p)).unwrap();
        assert_eq!(f.header.file_type, FileType::Scene);
        assert_eq!(f.objects.len(), 12);
        let by_name = |n: &str| f.objects.iter().find(|o| o.name == n).unwrap();

        let base = by_name("base");
        assert_eq!((base.handle, base.parent), (10, None));
        assert_eq!(base.alias.as_deref(), Some("baseAlias"));
        assert_eq!(base.referenced, [("self.parent".to_owned(), vec![10, -1])]);
        assert_eq!(base.extension, "open_base();linear");
        assert_eq!(
            f.ik_groups,
            [IkGroup {
                handle: 2_031_029,
                name: "base_ik".into(),
                max_iterations: 6,
                method: 1,
                damping: 0.25,
                flags: 0x59,
                elements: vec![IkElement {
                    tip: 12,
                    base: 10,
                    constraints: 7,
                    active: true,
                }],
            }]
        );
        assert_eq!(
            f.collections,
            [Collection {
                handle: 2_000_002,
                name: "base_arm".into(),
                items: vec![
                    CollectionItem {
                        object: 10,
                        kind: CollectionItemKind::Tree { include_base: true },
                        additive: true,
                    },
                    CollectionItem {
                        object: 11,
                        kind: CollectionItemKind::Object,
                        additive: false,
                    },
                ],
            }]
        );
        assert!(base.collidable && base.measurable && base.detectable && base.model_base);
        assert_eq!(base.local_pose.position, [0.5, 0.0, 0.0]);
        let ObjectKind::Shape(s) = &base.kind else {
            panic!("base is a shape")
        };
        assert!(s.dynamic && s.respondable && !s.compound);
        assert_eq!(s.respondable_mask, 0xff00);
        assert!(close(s.mass, 2.0));
        assert!(close(s.friction.unwrap(), 0.7) && close(s.restitution.unwrap(), 0.3));
        // Principal moments 1, 2, 3 about axes turned 90° about z: x and y swap.
        assert!(close(s.inertia_per_kg[0][0], 2.0) && close(s.inertia_per_kg[1][1], 1.0));
        assert!(close(s.inertia_per_kg[2][2], 3.0) && close(s.centre_of_mass[2], 0.1));
        let leaf = &s.leaves[0];
        assert_eq!(leaf.primitive, PrimitiveKind::Cylinder);
        assert!(close(leaf.size[2], 0.5) && close(leaf.frame.position[2], 0.25));
        assert_eq!(leaf.colour, Some([0.5, 0.25, 1.0]));
        assert_eq!(&leaf.indices[..], &[0, 1, 2]);
        assert_eq!(leaf.vertices.len(), 3);
        assert_eq!(leaf.normals, None);

        let ObjectKind::Shape(c) = &by_name("link").kind else {
            panic!("link is a shape")
        };
        assert!(c.compound && !c.dynamic);
        assert_eq!(
            c.leaves.iter().map(|l| l.name.as_str()).collect::<Vec<_>>(),
            ["tri", "quad"]
        );
        assert_eq!(c.leaves[1].indices.len(), 6);
        assert_eq!(c.centre_of_mass, [0.1, 0.2, 0.3]);
        assert_eq!(c.inertia_per_kg[1][1], 2.0);
        assert_eq!(c.leaves[0].frame.position, [1.0, 0.0, 0.0]);

        let ObjectKind::Joint(j) = &by_name("joint").kind else {
            panic!("joint")
        };
        assert_eq!(
            (j.joint_type, j.mode, j.dynamic_control),
            (JointType::Revolute, JointMode::Dynamic, DynamicControl::Position)
        );
        assert!(j.cyclic && close(j.min, -1.5) && close(j.range, 3.0));
        assert!(close(j.target_velocity, 0.5) && close(j.max_force, 20.0) && close(j.target_position, 0.25));
        assert_eq!((j.dependency, j.max_velocity), (None, Some(3.0)));

        let ObjectKind::Dummy(d) = &by_name("arm_tip").kind else {
            panic!("dummy")
        };
        assert_eq!((d.linked, d.link), (Some(14), DummyLink::IkTipTarget));
        // The tip hangs 0.3 m along x from a joint turned 90° about z, 0.2 m up: it
        // ends at (0.5, 0.3, 0.2)... plus the base's 0.5 m; the target was put there.
        let world = f.world_poses();
        let tip = world[f.objects.iter().position(|o| o.name == "arm_tip").unwrap()].unwrap();
        let target = world[f.objects.iter().position(|o| o.name == "arm_target").unwrap()].unwrap();
        for k in 0..3 {
            assert!(close(tip.position[k], [0.5, 0.3, 0.2][k]), "{:?}", tip.position);
        }
        assert!(close(target.position[1], 0.3));

        let ObjectKind::ProximitySensor(ps) = &by_name("sonar").kind else {
            panic!("sensor")
        };
        let ProximityVolume::Cone {
            offset,
            range,
            radius,
            angle,
        } = ps.volume
        else {
            panic!("cone")
        };
        assert!(close(offset, 0.01) && close(range, 0.5) && close(radius, 0.02) && close(angle, 1.0));
        let ObjectKind::VisionSensor(vs) = &by_name("camera").kind else {
            panic!("vision")
        };
        assert!(vs.perspective && vs.resolution == [64, 48] && close(vs.view_angle, 1.0) && close(vs.far, 10.0));
        assert!(close(vs.ortho_size, 0.1) && close(vs.near, 0.01));
        let ObjectKind::ForceSensor(fs) = &by_name("force").kind else {
            panic!("force")
        };
        assert!(close(fs.force_threshold, 100.0) && fs.consecutive_violations == 3);
        assert!(fs.filter_samples == 5 && fs.filter_type == 1);
        let ObjectKind::Light(light) = &by_name("light").kind else {
            panic!("light")
        };
        assert_eq!((light.light_type, light.spot_exponent), (LightType::Spot, 7));
        assert!(!light.on && light.local);
        assert!(close(light.spot_cutoff, 0.75) && close(light.size, 0.1));
        assert_eq!(light.attenuation, [0.5, 0.125, 0.25]);
        // The last colour chunk wins; diffuse and specular are the second and third RGB.
        assert_eq!(
            (light.diffuse, light.specular),
            ([0.25, 0.5, 0.75], [0.125, 0.375, 0.625])
        );
        let ObjectKind::Path(path) = &by_name("path").kind else {
            panic!("path")
        };
        assert!(path.closed() && path.attributes == 5 && path.points.len() == 2);
        let b = path.points[1];
        assert!(close(b.position[0], 1.0) && close(b.position[1], 0.5));
        let h = std::f64::consts::FRAC_1_SQRT_2;
        assert!(close(b.rotation[0], h) && close(b.rotation[3], h));
        assert!(close(b.bezier_factors[0], 0.25) && close(b.bezier_factors[1], 0.75));
        assert!(b.bezier_points == 9 && close(b.max_relative_velocity, 0.5));
        let ObjectKind::Camera(cam) = &by_name("view").kind else {
            panic!("camera")
        };
        assert!(close(cam.ortho_size, 2.5) && close(cam.view_angle, 0.75));
        assert!(close(cam.near, 0.05) && close(cam.far, 30.0));

        assert_eq!(f.scripts.len(), 2);
        let main = &f.scripts[0];
        assert_eq!(
            (main.script_type, main.origin, main.object),
            (ScriptType::Main, ScriptOrigin::List, None)
        );
        assert!(main.default_main && !main.threaded);
        let child = &f.scripts[1];
        assert_eq!(
            (child.script_type, child.origin, child.object),
            (ScriptType::Child, ScriptOrigin::Object(18), Some(11))
        );
        assert!(child.threaded && !child.disabled && !child.default_main);
        assert_eq!(child.language, ScriptLanguage::Lua);
        assert!(child.text.starts_with("function sysCall_init()"));

        let st = f.settings;
        let dt = match p {
            Precision::Single => 0.05,
            Precision::Double => 0.025,
        };
        assert!(close(st.time_step.unwrap(), dt));
        assert_eq!(
            (st.engine, st.gravity.map(|g| g[2] as f32)),
            (Some(Engine::Ode), Some(-9.81))
        );
        assert!(close(st.engine_step.unwrap(), 0.005));
    }
}

#[test]
fn header_problems_are_named() {
    let good = sample_file(Precision::Double);
    assert!(matches!(read(b"VRE"), Err(ReadError::Header(_))));
    assert!(matches!(read(&good[..500]), Err(ReadError::Header(_))));
    let mut bad = good.clone();
    bad[0] = b'X';
    assert!(matches!(read(&bad), Err(ReadError::Header(_))));
    let old = file(16, 30000, 1, b"EOF");
    let err = read(&old).unwrap_err();
    assert_eq!(err, ReadError::UnsupportedVersion { version: 16, min: 18 });
    assert!(err.to_string().contains("serialization version 16"));
    let mut raw = good.clone();
    raw[12] = 0;
    assert_eq!(read(&raw).unwrap_err(), ReadError::UnsupportedCompression(0));
    let mut negative = good.clone();
    negative[13..17].copy_from_slice(&(-1i32).to_le_bytes());
    assert!(matches!(read(&negative), Err(ReadError::BodyLength { .. })));
    let mut huge = good.clone();
    huge[13..17].copy_from_slice(&i32::MAX.to_le_bytes());
    assert!(matches!(read(&huge), Err(ReadError::BodyLength { .. })));
    let h = Header::parse(&good).unwrap();
    assert_eq!(
        (h.serialization_version, h.program_version_text()),
        (25, "4.7.0".to_owned())
    );
}

#[test]
fn truncated_and_corrupt_bodies_are_errors() {
    let good = sample_file(Precision::Single);
    // Cut anywhere in the coded body: the data runs out.
    for cut in [
        header::HEADER_LEN,
        header::HEADER_LEN + 1,
        header::HEADER_LEN + 40,
        good.len() - 1,
    ] {
        assert!(read(&good[..cut]).is_err(), "cut at {cut}");
    }
    // Damaged chunk streams, coded correctly.
    let cases: Vec<(Vec<u8>, &str)> = vec![
        // A chunk longer than the body.
        (Stream::new().chunk("SHP", &[0; 4]).bytes()[..9].to_vec(), "claims"),
        // An object without NXT.
        (
            Stream::new()
                .nested("JNT", Stream::new().chunk("Ids", &[0; 8]))
                .marker("EOF")
                .bytes(),
            "NXT",
        ),
        // An object without Ids.
        (
            Stream::new().nested("DMY", Stream::new().marker("NXT")).bytes(),
            "no Ids",
        ),
        // Referenced handles: a count beyond the chunk, and a negative one.
        (
            Stream::new()
                .nested(
                    "DMY",
                    Stream::new()
                        .chunk("Cr2", &Payload::new().str("t").i32(1_000_000).i32(1).done())
                        .marker("NXT"),
                )
                .bytes(),
            "referenced handles",
        ),
        (
            Stream::new()
                .nested(
                    "DMY",
                    Stream::new()
                        .chunk("Cr2", &Payload::new().str("t").i32(-3).done())
                        .marker("NXT"),
                )
                .bytes(),
            "-3 referenced handles",
        ),
        // An extension string longer than its chunk.
        (
            Stream::new()
                .nested(
                    "DMY",
                    Stream::new()
                        .chunk("Rst", &Payload::new().i32(50).raw(b"short").done())
                        .marker("NXT"),
                )
                .bytes(),
            "too short",
        ),
        // A collection item without its object, and one whose object is cut short.
        (
            Stream::new()
                .nested("GRP", Stream::new().nested("Asg", Stream::new().chunk("Gty", &[1])))
                .bytes(),
            "names no object",
        ),
        (
            Stream::new()
                .nested("GRP", Stream::new().nested("Asg", Stream::new().chunk("Obj", &[1, 0])))
                .bytes(),
            "GRP/Asg/Obj",
        ),
        // An IK element without its tip.
        (
            Stream::new()
                .nested(
                    "IKO",
                    Stream::new().nested("Ike", Stream::new().chunk("Ctr", &[7, 0, 0, 0])),
                )
                .bytes(),
            "names no tip",
        ),
        // A short pose.
        (
            Stream::new()
                .nested("DMY", Stream::new().chunk("_fq", &[0; 20]).marker("NXT"))
                .bytes(),
            "too short",
        ),
        // A mesh naming a vertex buffer that does not exist.
        (bad_mesh(7, 0, pack_indices(&[0, 1, 2])), "vertex buffer 7"),
        // Indices beyond the vertices.
        (bad_mesh(0, 0, pack_indices(&[0, 1, 3])), "beyond"),
        // Not whole triangles.
        (bad_mesh(0, 0, pack_indices(&[0, 1])), "whole triangles"),
        // An absurd packed count.
        (
            bad_mesh(0, 0, Payload::new().i32(i32::MAX).raw(&[31; 3]).done()),
            "does not fit",
        ),
        // Nesting deeper than the cap.
        (deep_compound(chunk::MAX_DEPTH + 5), "deeper"),
    ];
    for (body, expect) in cases {
        let err = read(&file(25, 40700, 1, &body)).unwrap_err();
        assert!(err.to_string().contains(expect), "{err} (expected {expect:?})");
    }
    // Nesting at the cap is fine.
    assert!(read(&file(25, 40700, 1, &deep_compound(chunk::MAX_DEPTH - 4))).is_ok());
}

/// A file with one shape whose mesh uses vertex buffer `vev` and index buffer `inv`,
/// the VIN holding one triangle's vertices and `in2` as packed indices.
fn bad_mesh(vev: i32, inv: i32, in2: Vec<u8>) -> Vec<u8> {
    let vin = Stream::new()
        .chunk("Ver", &Payload::new().f32s(&[0.0; 9]).done())
        .chunk("In2", &in2);
    let mesh = Stream::new()
        .marker("EOO")
        .chunk("Vev", &vev.to_le_bytes())
        .chunk("Inv", &inv.to_le_bytes());
    let shape = common(Precision::Double, 1, -1, "s", [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 0, 0)
        .nested("Ge2", Stream::new().nested("Gst", mesh));
    Stream::new()
        .nested("VIN", vin)
        .nested("SHP", shape)
        .marker("EOF")
        .bytes()
}

/// A shape whose compound nests `depth` wrappers.
fn deep_compound(depth: usize) -> Vec<u8> {
    let vin = Stream::new()
        .chunk("Ver", &Payload::new().f32s(&[0.0; 9]).done())
        .chunk("In2", &pack_indices(&[0, 1, 2]));
    let leaf = Stream::new()
        .marker("EOO")
        .chunk("Vev", &0i32.to_le_bytes())
        .chunk("Inv", &0i32.to_le_bytes());
    let mut node = Stream::new().nested("Geo", leaf);
    for _ in 0..depth {
        node = Stream::new().nested("Wrp", node);
    }
    let shape = common(Precision::Double, 1, -1, "s", [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 0, 0)
        .nested("Ge2", Stream::new().nested("Gsg", node));
    Stream::new()
        .nested("VIN", vin)
        .nested("SHP", shape)
        .marker("EOF")
        .bytes()
}

#[test]
fn mutated_files_never_panic() {
    // A small deterministic fuzz: flip, overwrite and cut bytes of the samples, both in
    // the coded file and in the decoded body (re-coded, so the chunk reader sees them).
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for p in [Precision::Single, Precision::Double] {
        let coded = sample_file(p);
        let body = sample_body(p);
        for _ in 0..400 {
            let mut b = coded.clone();
            let i = header::HEADER_LEN + (next() as usize) % (b.len() - header::HEADER_LEN);
            b[i] ^= 1 << (next() % 8);
            if let Ok(f) = read(&b) {
                f.check_guarantees().unwrap();
            }

            let mut d = body.clone();
            for _ in 0..1 + next() % 4 {
                let i = (next() as usize) % d.len();
                d[i] = match next() % 3 {
                    0 => d[i] ^ (1 << (next() % 8)),
                    1 => 0xff,
                    _ => next() as u8,
                };
            }
            if next() % 4 == 0 {
                d.truncate((next() as usize) % d.len());
            }
            if let Ok(f) = read(&file(25, 40700, 1, &d)) {
                f.check_guarantees().unwrap();
            }
        }
    }
}

#[test]
fn world_poses_survive_broken_and_cyclic_trees() {
    let mut f = read(&sample_file(Precision::Double)).unwrap();
    f.check_guarantees().unwrap();
    // Children listed before parents still compose.
    f.objects.reverse();
    let world = f.world_poses();
    assert!(world.iter().all(Option::is_some));
    // A cycle and a missing parent leave only the affected objects unplaced.
    let n = f.objects.len();
    let (a, b) = (f.objects[0].handle, f.objects[1].handle);
    f.objects[0].parent = Some(b);
    f.objects[1].parent = Some(a);
    f.objects[2].parent = Some(9999);
    let world = f.world_poses();
    assert_eq!(world.len(), n);
    assert!(world[0].is_none() && world[1].is_none() && world[2].is_none());
}

/// Writes the fuzz seeds (`fuzz/seeds/coppelia_file/`) from this file's samples:
/// `cargo test -p gantry-coppelia-file -- --ignored write_fuzz_seeds`.
#[test]
#[ignore = "writes files into the repository; run by hand when the samples change"]
fn write_fuzz_seeds() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/seeds/coppelia_file");
    std::fs::create_dir_all(&dir).unwrap();
    let seeds = [
        ("scene_f32.ttt", sample_file(Precision::Single)),
        ("scene_f64.ttt", sample_file(Precision::Double)),
        (
            "index_out_of_range.ttt",
            file(25, 40700, 1, &bad_mesh(0, 0, pack_indices(&[0, 1, 3]))),
        ),
        ("deep_compound.ttt", file(25, 40700, 2, &deep_compound(6))),
        ("old_version.ttt", file(17, 30005, 1, b"EOF")),
    ];
    for (name, bytes) in seeds {
        // Small seeds keep the fuzzer fast (libFuzzer sizes its inputs from the largest seed).
        assert!(bytes.len() < 8192, "{name} is {} bytes", bytes.len());
        std::fs::write(dir.join(name), bytes).unwrap();
    }
}
