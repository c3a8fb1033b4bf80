//! Forward kinematics of the arm6 robot against an independent hand-written model, joint
//! clamping and wrapping, and that the scene-format documentation's example loads.

use crate::util;

use std::f64::consts::{FRAC_PI_2, PI};

use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene_text};
use gantry_sim_core::world::ObjectKind;
use gantry_sim_core::{Handle, Sim};
use gantry_test_support::repo;
use util::{asset, find};

// ---------------------------------------------------------------------------------------
// The independent model: plain f64 rotation matrices, no gantry or nalgebra math.
// ---------------------------------------------------------------------------------------

type Mat3 = [[f64; 3]; 3];
type Vec3 = [f64; 3];

/// A rigid transform `x -> r x + p`.
#[derive(Debug, Clone, Copy)]
struct Frame {
    r: Mat3,
    p: Vec3,
}

const IDENTITY: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut m = [[0.0; 3]; 3];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    m
}

fn mat_vec(a: &Mat3, v: &Vec3) -> Vec3 {
    [0, 1, 2].map(|i| (0..3).map(|k| a[i][k] * v[k]).sum())
}

fn transpose(a: &Mat3) -> Mat3 {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| a[j][i]))
}

/// Rotation by `angle` about the unit vector `k` (Rodrigues' formula).
fn axis_angle(k: Vec3, angle: f64) -> Mat3 {
    let (s, c) = angle.sin_cos();
    let skew = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]];
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| IDENTITY[i][j] * c + s * skew[i][j] + (1.0 - c) * k[i] * k[j]))
}

impl Frame {
    const IDENTITY: Frame = Frame {
        r: IDENTITY,
        p: [0.0; 3],
    };

    /// `self * other`: `other` expressed in `self`'s frame.
    fn then(&self, other: &Frame) -> Frame {
        let q = mat_vec(&self.r, &other.p);
        Frame {
            r: mat_mul(&self.r, &other.r),
            p: [0, 1, 2].map(|i| self.p[i] + q[i]),
        }
    }

    fn translation(p: Vec3) -> Frame {
        Frame { r: IDENTITY, p }
    }

    fn rotation(axis: Vec3, angle: f64) -> Frame {
        Frame {
            r: axis_angle(axis, angle),
            p: [0.0; 3],
        }
    }
}

/// The arm's kinematic chain, transcribed from the comment at the top of arm6.urdf:
/// for each joint, the offset of its origin from the previous link frame and its axis in
/// that frame. Every link frame is the joint frame rotated by the joint angle, so at all
/// joints zero the link frames are parallel to the base frame.
const CHAIN: [(Vec3, Vec3); 6] = [
    ([0.0, 0.0, 0.100], [0.0, 0.0, 1.0]), // joint1, base yaw: z = 0.100 above the base
    ([0.070, 0.0, 0.252], [0.0, -1.0, 0.0]), // joint2, shoulder: a1 = 0.070, d1 = 0.352 above the floor
    ([0.0, 0.0, 0.360], [0.0, -1.0, 0.0]), // joint3, elbow: upper arm a2 = 0.360 along Z
    ([0.226, 0.0, 0.0], [1.0, 0.0, 0.0]), // joint4, forearm roll
    ([0.154, 0.0, 0.0], [0.0, -1.0, 0.0]), // joint5, wrist bend (forearm 0.380 in total)
    ([0.046, 0.0, 0.0], [1.0, 0.0, 0.0]), // joint6, flange roll
];
/// The fixed tool frame after link6 (wrist centre to tip: 0.046 + 0.014 = 0.060).
const TIP_OFFSET: Vec3 = [0.014, 0.0, 0.0];

/// World frames of link1..link6 and the tip for joint angles `q` (rad); the robot base is
/// the world origin, as in fk_arm.toml.
fn model_fk(q: &[f64; 6]) -> [Frame; 7] {
    let mut frames = [Frame::IDENTITY; 7];
    let mut cur = Frame::IDENTITY;
    for (i, ((offset, axis), qi)) in CHAIN.iter().zip(q).enumerate() {
        cur = cur
            .then(&Frame::translation(*offset))
            .then(&Frame::rotation(*axis, *qi));
        frames[i] = cur;
    }
    frames[6] = cur.then(&Frame::translation(TIP_OFFSET));
    frames
}

/// Joint ranges from the URDF comment (IRB 140 limits); `None` for continuous joints.
const LIMITS_DEG: [Option<(f64, f64)>; 6] = [
    None,
    Some((-110.0, 90.0)),
    Some((-50.0, 230.0)),
    None,
    Some((-120.0, 120.0)),
    None,
];

/// xorshift64*: a tiny deterministic PRNG, so every run tests the same configurations.
struct XorShift(u64);

impl XorShift {
    /// Uniform in [0, 1).
    fn next_f64(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D);
        (x >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A configuration within the joint limits; continuous joints in (-pi, pi].
    fn configuration(&mut self) -> [f64; 6] {
        LIMITS_DEG.map(|limits| {
            let u = self.next_f64();
            match limits {
                Some((lo, hi)) => (lo + u * (hi - lo)).to_radians(),
                None => PI - u * 2.0 * PI,
            }
        })
    }
}

// ---------------------------------------------------------------------------------------
// Reading gantry's world.
// ---------------------------------------------------------------------------------------

const JOINTS: [&str; 6] = [
    "/arm6/joint1",
    "/arm6/joint2",
    "/arm6/joint3",
    "/arm6/joint4",
    "/arm6/joint5",
    "/arm6/joint6",
];
/// The link objects compared with the model, in `model_fk` order. `/arm6/tip` finds the
/// URDF link `tip` before the scene's dummy of the same alias, which hangs below it.
const LINKS: [&str; 7] = [
    "/arm6/link1",
    "/arm6/link2",
    "/arm6/link3",
    "/arm6/link4",
    "/arm6/link5",
    "/arm6/link6",
    "/arm6/tip",
];

/// Absolute tolerances: the object tree is f64, so errors should be ~1e-15.
const POSITION_TOL: f64 = 1e-6;
const ANGLE_TOL: f64 = 1e-6;

fn fk_arm() -> Sim {
    util::asset_scene("scenes/fk_arm.toml")
}

/// The world frame of an object, converted to the model's plain arrays.
fn world_frame(w: &Sim, h: Handle) -> Frame {
    let pose = w.world.object(h).expect("object exists").world;
    let m = pose.rotation.to_rotation_matrix().into_inner();
    let t = pose.translation.vector;
    Frame {
        r: [0, 1, 2].map(|i| [0, 1, 2].map(|j| m[(i, j)])),
        p: [t.x, t.y, t.z],
    }
}

fn distance(a: &Vec3, b: &Vec3) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt()
}

/// The angle of the rotation taking `a` to `b`. atan2 of the sine (from the skew part) and
/// cosine (from the trace) stays accurate near zero, where acos of the trace would not.
fn rotation_angle(a: &Mat3, b: &Mat3) -> f64 {
    let d = mat_mul(&transpose(a), b);
    let sin2 = [d[2][1] - d[1][2], d[0][2] - d[2][0], d[1][0] - d[0][1]];
    let sin = (sin2.iter().map(|v| v * v).sum::<f64>()).sqrt() / 2.0;
    let cos = (d[0][0] + d[1][1] + d[2][2] - 1.0) / 2.0;
    sin.atan2(cos)
}

/// Largest position and orientation errors of the seven link frames against the model.
fn fk_errors(w: &Sim, links: &[Handle; 7], q: &[f64; 6]) -> (f64, f64) {
    let expected = model_fk(q);
    let mut worst = (0.0f64, 0.0f64);
    for (h, e) in links.iter().zip(&expected) {
        let actual = world_frame(w, *h);
        worst.0 = worst.0.max(distance(&actual.p, &e.p));
        worst.1 = worst.1.max(rotation_angle(&e.r, &actual.r));
    }
    worst
}

fn set_joints(w: &mut Sim, joints: &[Handle; 6], q: &[f64; 6]) {
    for (h, qi) in joints.iter().zip(q) {
        w.world.set_joint_position(*h, *qi).expect("joint");
    }
}

fn handles<const N: usize>(w: &Sim, paths: [&str; N]) -> [Handle; N] {
    paths.map(|p| find(w, p))
}

// ---------------------------------------------------------------------------------------
// Tests.
// ---------------------------------------------------------------------------------------

#[test]
fn independent_model_reproduces_the_documented_start_pose() {
    // Guards the model itself: the URDF comment says that with joint5 = -90 deg the tip is
    // at (0.450, 0, 0.652) and the tool points down (tip X axis along world -Z).
    let tip = model_fk(&[0.0, 0.0, 0.0, 0.0, -FRAC_PI_2, 0.0])[6];
    assert!(distance(&tip.p, &[0.450, 0.0, 0.652]) < 1e-12, "{:?}", tip.p);
    let tool_x = [tip.r[0][0], tip.r[1][0], tip.r[2][0]];
    assert!(distance(&tool_x, &[0.0, 0.0, -1.0]) < 1e-12, "{tool_x:?}");
}

#[test]
fn scene_starts_in_the_documented_pose() {
    let w = fk_arm();
    let joints = handles(&w, JOINTS);
    let links = handles(&w, LINKS);
    assert!(
        matches!(w.world.object(links[6]).expect("tip").kind, ObjectKind::Shape(_)),
        "/arm6/tip should be the URDF link"
    );
    // `initial = { joint5 = -90 }` is in degrees; the world reads radians.
    let q: [f64; 6] = joints.map(|h| w.world.joint(h).expect("joint").position);
    assert_eq!(q[..4], [0.0; 4]);
    assert!((q[4] + FRAC_PI_2).abs() < 1e-15, "joint5 starts at {}", q[4]);
    let (dp, da) = fk_errors(&w, &links, &q);
    assert!(dp < 1e-12 && da < 1e-12, "start pose off by {dp} m, {da} rad");
}

#[test]
fn forward_kinematics_matches_independent_model() {
    let mut w = fk_arm();
    let joints = handles(&w, JOINTS);
    let links = handles(&w, LINKS);
    let mut rng = XorShift(0x9E37_79B9_7F4A_7C15);
    let (mut max_dp, mut max_da) = (0.0f64, 0.0f64);
    for i in 0..50 {
        let q = rng.configuration();
        set_joints(&mut w, &joints, &q);
        // Every sample is inside the limits, so the joints must read back what was set
        // (wrapping of a continuous joint may move it by an ulp, not more).
        for (h, qi) in joints.iter().zip(&q) {
            let read = w.world.joint(*h).expect("joint").position;
            assert!(
                (read - qi).abs() < 1e-12,
                "config {i}: joint {h} set to {qi}, reads {read}"
            );
        }
        let (dp, da) = fk_errors(&w, &links, &q);
        assert!(
            dp < POSITION_TOL,
            "config {i} q = {q:?}: a link is {dp} m from the model"
        );
        assert!(da < ANGLE_TOL, "config {i} q = {q:?}: a link is {da} rad off the model");
        max_dp = max_dp.max(dp);
        max_da = max_da.max(da);
    }
    eprintln!("max FK error over 50 configurations: {max_dp:.3e} m, {max_da:.3e} rad");
}

#[test]
fn joint_position_is_clamped_to_its_limits() {
    let mut w = fk_arm();
    let joints = handles(&w, JOINTS);
    let links = handles(&w, LINKS);
    // joint2's URDF limits are [-110, 90] deg, given in the file as radians.
    w.world.set_joint_position(joints[1], 3.0).expect("joint");
    let upper = w.world.joint(joints[1]).expect("joint").position;
    assert_eq!(upper, FRAC_PI_2, "joint2 set to 3.0 rad reads {upper}");
    w.world.set_joint_position(joints[1], -3.0).expect("joint");
    let lower = w.world.joint(joints[1]).expect("joint").position;
    assert_eq!(lower, -1.9198621771937625, "joint2 set to -3.0 rad reads {lower}");
    // The links follow the clamped value, not the requested one.
    let (dp, da) = fk_errors(&w, &links, &[0.0, lower, 0.0, 0.0, -FRAC_PI_2, 0.0]);
    assert!(
        dp < POSITION_TOL && da < ANGLE_TOL,
        "links off the clamped pose by {dp} m, {da} rad"
    );
}

#[test]
fn continuous_joint_wraps_into_half_open_interval() {
    let mut w = fk_arm();
    let joint1 = find(&w, "/arm6/joint1");
    let links = handles(&w, LINKS);
    w.world.set_joint_position(joint1, 1.5 * PI).expect("joint");
    let q = w.world.joint(joint1).expect("joint").position;
    assert!(
        (q + FRAC_PI_2).abs() < 1e-12,
        "joint1 set to 3pi/2 reads {q}, expected -pi/2"
    );
    let (dp, da) = fk_errors(&w, &links, &[-FRAC_PI_2, 0.0, 0.0, 0.0, -FRAC_PI_2, 0.0]);
    assert!(
        dp < POSITION_TOL && da < ANGLE_TOL,
        "links off the wrapped pose by {dp} m, {da} rad"
    );
    // The range is (-pi, pi]: -pi itself is reported as +pi, and +pi stays +pi.
    w.world.set_joint_position(joint1, -PI).expect("joint");
    assert_eq!(
        w.world.joint(joint1).expect("joint").position,
        PI,
        "-pi must wrap to +pi"
    );
    w.world.set_joint_position(joint1, PI).expect("joint");
    assert_eq!(w.world.joint(joint1).expect("joint").position, PI, "+pi must stay +pi");
}

#[test]
fn set_joint_position_moves_descendants_before_any_step() {
    let mut w = fk_arm();
    let joint1 = find(&w, "/arm6/joint1");
    let tip = find(&w, "/arm6/tip");
    let before = world_frame(&w, tip).p;
    w.world.set_joint_position(joint1, 0.5).expect("joint");
    let after = world_frame(&w, tip).p;
    assert_eq!(w.world.steps(), 0, "no step may have run");
    // Yawing the base by 0.5 rad swings the tip about world Z at radius 0.45 m.
    let expected = [0.45 * 0.5f64.cos(), 0.45 * 0.5f64.sin(), 0.652];
    assert!(
        distance(&before, &after) > 0.2,
        "tip did not move: {before:?} -> {after:?}"
    );
    assert!(
        distance(&after, &expected) < 1e-12,
        "tip at {after:?}, expected {expected:?}"
    );
    // The scene's dummy below the tip link moves along with it.
    let dummy = w.world.find("/arm6/tip/tip", None, 0).expect("tip_frame dummy");
    assert!(distance(&world_frame(&w, dummy).p, &expected) < 1e-12);
}

// ---------------------------------------------------------------------------------------
// docs/scene-format.md stays loadable.
// ---------------------------------------------------------------------------------------

/// The first ```toml block after the "## Complete example" heading.
fn doc_example(doc: &str) -> String {
    let mut lines = doc.lines().skip_while(|l| l.trim() != "## Complete example");
    assert!(
        lines.next().is_some(),
        "docs/scene-format.md has no '## Complete example' heading"
    );
    let mut lines = lines.skip_while(|l| l.trim() != "```toml");
    assert!(lines.next().is_some(), "no ```toml block after '## Complete example'");
    let block: Vec<&str> = lines.take_while(|l| l.trim() != "```").collect();
    assert!(!block.is_empty(), "the example block is empty");
    block.join("\n") + "\n"
}

#[test]
fn scene_format_doc_example_loads() {
    let doc_path = repo("docs/scene-format.md");
    let doc = std::fs::read_to_string(&doc_path).expect("docs/scene-format.md is readable");
    let text = doc_example(&doc);
    // The document says the example is meant to be saved in assets/scenes/, so its relative
    // paths are resolved from there. load_scene_text only uses the path to anchor relative
    // paths and to name the file in messages: nothing is written to disk.
    let path = asset("scenes/doc_example.toml");
    let model = load_scene_text(&DiskFiles, &text, &path, &LoadOptions::default())
        .unwrap_or_else(|e| panic!("the documented example does not load: {e}"));
    // A misspelt key would only warn; the documented example must be clean.
    assert!(
        model.warnings.is_empty(),
        "the documented example warns: {:?}",
        model.warnings
    );
    assert!(!model.scripts.is_empty(), "the example should attach a script");
    let mut w = Sim::new(&model);
    assert!(
        w.world.warnings().is_empty(),
        "building the example warns: {:?}",
        w.world.warnings()
    );
    for _ in 0..10 {
        w.step();
    }
    for &h in w.world.handles() {
        let p = w.world.object(h).expect("exists").world.translation.vector;
        assert!(
            p.iter().all(|v| v.is_finite()),
            "object {h} has a non-finite pose after 10 steps"
        );
    }
}
