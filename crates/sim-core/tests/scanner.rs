//! Laser scanners against geometry worked out by hand: the bundled scene
//! `assets/scenes/scanners.toml` scanned through `simVision` (as its scanners' scripts
//! do, but called from here) and through `sim.castRays`, with every range compared with
//! the distance from the scanner to the scene's boxes, cylinder and floor along the
//! same ray. Bad input to the three functions gives clear errors.

use crate::util;

use gantry_sim_core::math::{Pose, Vec3};
use gantry_sim_core::{Handle, Sim, Value};
use gantry_test_support::{floats, int};
use util::{asset_scene, err, find, ok};

/// `sim.handleflag_abscoords`.
const ABSCOORDS: i64 = 0x0080_0000;
/// The Hokuyo's and Velodyne's ranges: their sensors' far clipping distances, m.
const HOKUYO_FAR: f64 = 5.0;
const VELODYNE_FAR: f64 = 10.0;
/// The pillar is drawn as a prism of 32 sides inside the true cylinder (what rapier
/// collides with), at most r (1 - cos(pi / 32)) = 0.96 mm inside it.
const PILLAR_SAGITTA: f64 = 0.2 * (1.0 - 0.995_184_726_672_196_9);

/// A primitive of the scene, in the world frame, as scanners.toml places it.
#[derive(Debug, Clone, Copy)]
enum Solid {
    /// A box turned by `yaw` about the vertical through its centre.
    Box { centre: [f64; 3], half: [f64; 3], yaw: f64 },
    /// A cylinder along the vertical.
    Cylinder {
        centre: [f64; 3],
        radius: f64,
        half_length: f64,
    },
}

/// The scene's primitives by object path: the floor (a slab 0.1 m thick whose top is
/// z = 0), four boxes and the pillar. The Hokuyo's housing is left out: both scans
/// exclude it (the sensors' near plane, the ray cast's ignored tree).
fn solids() -> Vec<(&'static str, Solid)> {
    let cuboid = |centre, half, yaw_deg: f64| Solid::Box {
        centre,
        half,
        yaw: yaw_deg.to_radians(),
    };
    vec![
        ("/Floor", cuboid([0.0, 0.0, -0.05], [5.0, 5.0, 0.05], 0.0)),
        ("/wallFront", cuboid([3.0, 0.0, 0.5], [0.1, 2.0, 0.5], 0.0)),
        ("/wallLeft", cuboid([0.5, 2.5, 0.5], [2.0, 0.1, 0.5], 0.0)),
        ("/block", cuboid([1.5, -1.2, 0.5], [0.2, 0.2, 0.5], 30.0)),
        ("/crate", cuboid([-0.6, 1.6, 0.3], [0.3, 0.3, 0.3], 0.0)),
        (
            "/pillar",
            Solid::Cylinder {
                centre: [-0.8, -1.6, 0.6],
                radius: 0.2,
                half_length: 0.6,
            },
        ),
    ]
}

impl Solid {
    /// Where a ray from `o` along unit `d` (both world frame) enters the solid, m, if it does.
    fn entry(&self, o: Vec3, d: Vec3) -> Option<f64> {
        match *self {
            Solid::Box { centre, half, yaw } => {
                // Into the box's frame, then the slab method.
                let (s, c) = yaw.sin_cos();
                let to_box = |v: Vec3| Vec3::new(c * v.x + s * v.y, -s * v.x + c * v.y, v.z);
                let (o, d) = (to_box(o - Vec3::from(centre)), to_box(d));
                let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
                for k in 0..3 {
                    if d[k].abs() < 1e-15 {
                        if o[k].abs() > half[k] {
                            return None;
                        }
                        continue;
                    }
                    let (a, b) = ((-half[k] - o[k]) / d[k], (half[k] - o[k]) / d[k]);
                    t0 = t0.max(a.min(b));
                    t1 = t1.min(a.max(b));
                }
                (t0 <= t1 && t0 >= 0.0).then_some(t0)
            }
            Solid::Cylinder {
                centre,
                radius,
                half_length,
            } => {
                let o = o - Vec3::from(centre);
                let mut best: Option<f64> = None;
                let mut keep = |t: f64| {
                    if t >= 0.0 && best.is_none_or(|b| t < b) {
                        best = Some(t);
                    }
                };
                // The side: |o_xy + t d_xy| = r, within the length.
                let (a, b, c) = (
                    d.x * d.x + d.y * d.y,
                    2.0 * (o.x * d.x + o.y * d.y),
                    o.x * o.x + o.y * o.y - radius * radius,
                );
                let disc = b * b - 4.0 * a * c;
                if a > 1e-15 && disc >= 0.0 {
                    let t = (-b - disc.sqrt()) / (2.0 * a);
                    if (o.z + t * d.z).abs() <= half_length {
                        keep(t);
                    }
                }
                // The caps.
                if d.z.abs() > 1e-15 {
                    for z in [-half_length, half_length] {
                        let t = (z - o.z) / d.z;
                        let (x, y) = (o.x + t * d.x, o.y + t * d.y);
                        if x * x + y * y <= radius * radius {
                            keep(t);
                        }
                    }
                }
                best
            }
        }
    }

    /// Distance from `p` (world frame) to the solid's surface, m.
    fn surface_distance(&self, p: Vec3) -> f64 {
        match *self {
            Solid::Box { centre, half, yaw } => {
                let (s, c) = yaw.sin_cos();
                let q = p - Vec3::from(centre);
                let q = Vec3::new(c * q.x + s * q.y, -s * q.x + c * q.y, q.z);
                let out = Vec3::from_fn(|k, _| (q[k].abs() - half[k]).max(0.0));
                let inside = (0..3).map(|k| q[k].abs() - half[k]).fold(f64::NEG_INFINITY, f64::max);
                if out.norm() > 0.0 { out.norm() } else { -inside }
            }
            Solid::Cylinder {
                centre,
                radius,
                half_length,
            } => {
                let q = p - Vec3::from(centre);
                let (r, z) = ((q.x * q.x + q.y * q.y).sqrt() - radius, q.z.abs() - half_length);
                if r > 0.0 || z > 0.0 {
                    (r.max(0.0).powi(2) + z.max(0.0).powi(2)).sqrt()
                } else {
                    -r.max(z)
                }
            }
        }
    }
}

/// The first solid a ray from `o` along unit `d` enters, and where (m).
fn first_hit(o: Vec3, d: Vec3) -> Option<(&'static str, f64)> {
    solids()
        .into_iter()
        .filter_map(|(name, s)| s.entry(o, d).map(|t| (name, t)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

/// The nearest solid's surface to `p`: its name and distance (m).
fn nearest_surface(p: Vec3) -> (&'static str, f64) {
    solids()
        .into_iter()
        .map(|(name, s)| (name, s.surface_distance(p)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("the scene has solids")
}

/// Half the angle between pixel centres of the 3-D scanner's sensors, at most (90
/// degrees over 512 pixels, 0.39 of that height over 200), rad.
const HALF_PIXEL: f64 = 0.5 * 2.0 / 512.0;

/// Eight beams around unit `d`, `angle` (rad) away from it.
fn near_beams(d: Vec3, angle: f64) -> Vec<Vec3> {
    let a = if d.z.abs() < 0.9 { Vec3::z() } else { Vec3::x() };
    let (u, v) = (d.cross(&a).normalize(), d.cross(&d.cross(&a)).normalize());
    (0..8)
        .map(|k| {
            let phi = std::f64::consts::TAU * f64::from(k) / 8.0;
            (d + angle.tan() * (phi.cos() * u + phi.sin() * v)).normalize()
        })
        .collect()
}

fn world_pose(w: &Sim, h: Handle) -> Pose {
    w.world.object(h).expect("object").world
}

/// A `simVision` packet's floats.
fn unpack(v: &Value) -> Vec<f64> {
    let Value::Bytes(b) = v else {
        panic!("expected packed floats, got {v:?}");
    };
    b.chunks_exact(4)
        .map(|c| f64::from(f32::from_le_bytes([c[0], c[1], c[2], c[3]])))
        .collect()
}

/// One point of a packet: `(x, y, z)` and the distance.
fn points(packet: &[f64]) -> Vec<(Vec3, f64)> {
    let n = (packet[0] * packet[1]) as usize;
    assert_eq!(packet.len(), 2 + 4 * n, "packet length");
    packet[2..]
        .chunks_exact(4)
        .map(|c| (Vec3::new(c[0], c[1], c[2]), c[3]))
        .collect()
}

/// What each of the scanner's sensor filters does (scripts/hokuyo_sensor.lua,
/// velodyne_sensor.lua), called from here: render, depth to the work image, points
/// (`flags` OR-ed onto the handle of the last call).
fn scan_with(w: &mut Sim, sensor: Handle, flags: i64, function: &str, args: &[Value]) -> Vec<f64> {
    ok(w, "sim.handleVisionSensor", &[Value::Int(sensor)]);
    ok(w, "simVision.sensorDepthMapToWorkImg", &[Value::Int(sensor)]);
    let mut call = vec![Value::Int(sensor | flags)];
    call.extend_from_slice(args);
    let reply = ok(w, function, &call);
    assert_eq!(reply[0], Value::Bool(false), "never a trigger");
    unpack(&reply[1])
}

fn scan(w: &mut Sim, sensor: Handle, function: &str, args: &[Value]) -> Vec<f64> {
    scan_with(w, sensor, 0, function, args)
}

fn flat(dirs: &[Vec3]) -> Value {
    Value::Array(dirs.iter().flat_map(|d| [d.x, d.y, d.z]).map(Value::Float).collect())
}

fn cast(w: &mut Sim, frame: Handle, dirs: &[Vec3], max: f64, ignored: i64, options: i64) -> Vec<(f64, Handle)> {
    let reply = ok(
        w,
        "sim.castRays",
        &[
            Value::Int(frame),
            flat(dirs),
            Value::Float(max),
            Value::Int(ignored),
            Value::Int(options),
        ],
    );
    let (d, h) = (floats(&reply[0]), &reply[1]);
    let Value::Array(h) = h else { panic!("handles: {h:?}") };
    assert_eq!(d.len(), dirs.len());
    d.into_iter().zip(h.iter().map(int)).collect()
}

#[test]
fn the_2d_scanner_ranges_are_the_analytic_distances_and_the_ray_casts() {
    let mut w = asset_scene("scenes/scanners.toml");
    let hokuyo = find(&w, "/hokuyo");
    let pillar = find(&w, "/pillar");
    let mut returns = 0;
    let mut misses = 0;
    for path in ["/hokuyo/sensor1", "/hokuyo/sensor2"] {
        let sensor = find(&w, path);
        let pose = world_pose(&w, sensor);
        let o = pose.translation.vector;
        let packet = scan(
            &mut w,
            sensor,
            "simVision.coordinatesFromWorkImg",
            &[Value::Array(vec![Value::Int(342), Value::Int(1)]), Value::Bool(false)],
        );
        assert_eq!(packet[..2], [342.0, 1.0]);
        let pts = points(&packet);
        let dirs: Vec<Vec3> = pts.iter().map(|(p, _)| p.normalize()).collect();
        // The same beams as rays from the sensor, through the housing it sits in.
        let rays = cast(&mut w, sensor, &dirs, HOKUYO_FAR, hokuyo, 0);
        for (k, ((p, dist), (ray_dist, ray_handle))) in pts.iter().zip(&rays).enumerate() {
            let d = pose.rotation * dirs[k];
            let expected = first_hit(o, d);
            // The point is on its own ray, at the distance reported.
            assert!((p.norm() - dist).abs() < 1e-5, "point {k}: |p| {} vs {dist}", p.norm());
            if *dist >= HOKUYO_FAR * 0.9999 {
                misses += 1;
                assert!(
                    expected.is_none_or(|(_, t)| t > HOKUYO_FAR - 1e-3),
                    "{path} point {k}: a miss where {expected:?} is in range"
                );
                assert!(
                    *ray_dist == -1.0 || *ray_dist > HOKUYO_FAR - 1e-3,
                    "ray {k}: {ray_dist}"
                );
                continue;
            }
            returns += 1;
            let (name, t) = expected.unwrap_or_else(|| panic!("{path} point {k} at {dist} m where nothing is"));
            let hit = pose * nalgebra::Point3::from(*p);
            if name == "/pillar" {
                // The drawn prism lies up to the sagitta inside the true cylinder.
                let radial = Solid::Cylinder {
                    centre: [-0.8, -1.6, 0.6],
                    radius: 0.2,
                    half_length: 0.6,
                }
                .surface_distance(hit.coords);
                assert!(
                    radial.abs() <= PILLAR_SAGITTA + 1e-4,
                    "pillar point {k}: {radial} m off"
                );
                assert_eq!(*ray_handle, pillar);
                assert!((ray_dist - t).abs() < 1e-3, "ray {k} to the pillar: {ray_dist} vs {t}");
            } else {
                assert!(
                    (dist - t).abs() < 1e-3,
                    "{path} point {k} on {name}: {dist} m, analytic {t} m"
                );
                assert!(
                    (ray_dist - t).abs() < 1e-3,
                    "ray {k} on {name}: {ray_dist} m, analytic {t} m"
                );
                assert!(
                    (ray_dist - dist).abs() < 1e-3,
                    "point {k}: scanner {dist}, ray {ray_dist}"
                );
                assert_eq!(*ray_handle, find(&w, name), "ray {k} hits {name}");
            }
        }
    }
    // Walls, block, crate and pillar fill most of the 240 degrees; the open corner to
    // the back right is beyond range.
    assert!(returns > 500 && misses > 20, "{returns} returns, {misses} misses");
}

#[test]
fn the_3d_scanner_points_lie_on_the_primitives() {
    let mut w = asset_scene("scenes/scanners.toml");
    let velodyne = world_pose(&w, find(&w, "/velodyne")).translation.vector;
    let half_span = (1.0f64 - 1.0 / 512.0).atan();
    let (mut on_surface, mut near_edge, mut misses) = (0, 0, 0);
    for i in 1..=4 {
        let sensor = find(&w, &format!("/velodyne/sensor{i}"));
        let pose = world_pose(&w, sensor);
        let packet = scan_with(
            &mut w,
            sensor,
            ABSCOORDS,
            "simVision.velodyneDataFromWorkImg",
            &[
                Value::Array(vec![Value::Int(450), Value::Int(16)]),
                Value::Float(30f64.to_radians()),
            ],
        );
        // The world-frame packet is the sensor-frame one moved.
        let local = scan(
            &mut w,
            sensor,
            "simVision.velodyneDataFromWorkImg",
            &[
                Value::Array(vec![Value::Int(450), Value::Int(16)]),
                Value::Float(30f64.to_radians()),
            ],
        );
        for (k, ((p, dist), (q, _))) in points(&packet).into_iter().zip(points(&local)).enumerate() {
            assert!((pose * nalgebra::Point3::from(q) - nalgebra::Point3::from(p)).norm() < 1e-5);
            // Beam k: azimuth k / 16, elevation k % 16, both evenly spread.
            let (az, el) = (q.x.atan2(q.z), (q.y / q.norm()).asin());
            let want_az = -half_span + 2.0 * half_span * (k / 16) as f64 / 449.0;
            let want_el = (-15.0 + 30.0 * (k % 16) as f64 / 15.0).to_radians();
            assert!(
                (az - want_az).abs() < 1e-5 && (el - want_el).abs() < 1e-5,
                "beam {k}: {az} {el}"
            );
            if dist >= VELODYNE_FAR * 0.9999 {
                misses += 1;
                let beam = (p - velodyne).normalize();
                let far_or_none = |d: Vec3| first_hit(velodyne, d).is_none_or(|(_, t)| t > VELODYNE_FAR - 0.05);
                // A beam within half a pixel of a silhouette reads the nearest pixel,
                // which may be the background's.
                assert!(
                    far_or_none(beam) || near_beams(beam, HALF_PIXEL).into_iter().any(far_or_none),
                    "sensor {i} beam {k}: a miss where {:?} is",
                    first_hit(velodyne, beam)
                );
                continue;
            }
            let (name, off) = nearest_surface(p);
            let tolerance = if name == "/pillar" { PILLAR_SAGITTA + 1e-4 } else { 1e-3 };
            if off.abs() <= tolerance {
                on_surface += 1;
                continue;
            }
            // Where the four pixels around a beam do not see one surface (a silhouette,
            // or the floor at a grazing angle), the nearest pixel's depth is taken: the
            // range is then one the scene shows within a pixel of the beam.
            near_edge += 1;
            let beam = (p - velodyne).normalize();
            let ranges: Vec<f64> = std::iter::once(beam)
                .chain(near_beams(beam, 1.5 * HALF_PIXEL))
                .map(|d| first_hit(velodyne, d).map_or(f64::INFINITY, |(_, t)| t))
                .collect();
            let (lo, hi) = ranges
                .iter()
                .fold((f64::INFINITY, 0.0f64), |(lo, hi), &t| (lo.min(t), hi.max(t)));
            assert!(
                lo - 1e-3 <= dist && dist <= hi + 1e-3,
                "sensor {i} beam {k}: {dist} m, {off} m off {name}, the ranges around are {ranges:?}"
            );
        }
    }
    let total = on_surface + near_edge;
    assert!(
        near_edge * 100 <= total,
        "{on_surface} points on a surface within 1 mm, {near_edge} at edges, {misses} misses"
    );
    // The upper beams pass over the 1 m walls, and the flatter lower ones reach the
    // floor beyond its edge, 5 m out.
    assert!(total > 10_000 && misses > 10_000, "{total} returns, {misses} misses");
}

#[test]
fn cast_rays_give_analytic_distances_and_the_shapes_hit() {
    let mut w = asset_scene("scenes/scanners.toml");
    let hokuyo = find(&w, "/hokuyo");
    let o = world_pose(&w, hokuyo).translation.vector;
    // 360 beams around in the scan plane, and 360 more 20 degrees down (to the floor
    // and the foot of the walls), in the scanner's frame (= the world's axes here).
    let mut dirs = Vec::new();
    for down in [0.0f64, 20.0] {
        for k in 0..360 {
            let (az, el) = ((k as f64).to_radians(), -down.to_radians());
            dirs.push(Vec3::new(az.cos() * el.cos(), az.sin() * el.cos(), el.sin()));
        }
    }
    let rays = cast(&mut w, hokuyo, &dirs, 4.0, hokuyo, 0);
    let mut hits = 0;
    for (k, (&(dist, handle), d)) in rays.iter().zip(&dirs).enumerate() {
        match first_hit(o, *d) {
            Some((name, t)) if t <= 4.0 => {
                hits += 1;
                assert!((dist - t).abs() < 1e-4, "ray {k} on {name}: {dist} vs {t}");
                assert_eq!(handle, find(&w, name), "ray {k}");
            }
            other => assert_eq!((dist, handle), (-1.0, -1), "ray {k}: expected {other:?}"),
        }
    }
    assert!(hits > 400, "{hits} hits");

    // The scanner's own housing: without ignoring it, every ray starts inside it.
    let housing = find(&w, "/hokuyo/hokuyoBody");
    for (dist, handle) in cast(&mut w, hokuyo, &dirs[..10], 4.0, -1, 0) {
        assert_eq!((dist, handle), (0.0, housing));
    }
    // Detectable shapes only: the floor is not one, so the rays down pass through it.
    let floor = find(&w, "/Floor");
    let all = cast(&mut w, hokuyo, &dirs, 4.0, hokuyo, 0);
    let detectable = cast(&mut w, hokuyo, &dirs, 4.0, hokuyo, 1);
    let on_floor = all.iter().filter(|r| r.1 == floor).count();
    assert!(on_floor > 50, "{on_floor} rays on the floor");
    for (a, b) in all.iter().zip(&detectable) {
        if a.1 == floor {
            assert_ne!(b.1, floor);
        } else {
            assert_eq!(a, b);
        }
    }
    // Deterministic: the same rays again give the same bits.
    assert_eq!(cast(&mut w, hokuyo, &dirs, 4.0, hokuyo, 0), all);
    // Rays follow the frame: moved 1 m back, the front wall is 1 m farther.
    let ahead = cast(&mut w, hokuyo, &[Vec3::x()], 4.0, hokuyo, 0)[0];
    ok(
        &mut w,
        "sim.setObjectPosition",
        &[
            Value::Int(hokuyo),
            Value::Array(vec![Value::Float(-1.0), Value::Float(0.0), Value::Float(0.3)]),
            Value::Int(-1),
        ],
    );
    let back = cast(&mut w, hokuyo, &[Vec3::x()], 4.0, hokuyo, 0)[0];
    assert!(
        (back.0 - ahead.0 - 1.0).abs() < 1e-5 && back.1 == ahead.1,
        "{ahead:?} then {back:?}"
    );
}

#[test]
fn bad_input_gives_clear_errors() {
    let mut w = asset_scene("scenes/scanners.toml");
    let hokuyo = find(&w, "/hokuyo");
    let sensor = find(&w, "/hokuyo/sensor1");
    let cast = |w: &mut Sim, args: Vec<Value>| err(w, "sim.castRays", &args);
    let x = || Value::Array(vec![Value::Float(1.0), Value::Float(0.0), Value::Float(0.0)]);
    let nums = |v: &[f64]| Value::Array(v.iter().map(|&f| Value::Float(f)).collect());

    let e = cast(&mut w, vec![Value::Int(hokuyo), nums(&[1.0, 0.0]), Value::Float(1.0)]);
    assert!(e.contains("argument 2") && e.contains("3 per ray"), "{e}");
    let e = cast(
        &mut w,
        vec![
            Value::Int(hokuyo),
            nums(&[1.0, 0.0, 0.0, f64::NAN, 0.0, 1.0]),
            Value::Float(1.0),
        ],
    );
    assert!(e.contains("argument 2") && e.contains("direction 2"), "{e}");
    let e = cast(
        &mut w,
        vec![Value::Int(hokuyo), nums(&[0.0, 0.0, 0.0]), Value::Float(1.0)],
    );
    assert!(e.contains("direction 1") && e.contains("not zero"), "{e}");
    let e = cast(
        &mut w,
        vec![Value::Int(hokuyo), Value::Str("abc".into()), Value::Float(1.0)],
    );
    assert!(e.contains("argument 2") && e.contains("whole directions"), "{e}");
    for max in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = cast(&mut w, vec![Value::Int(hokuyo), x(), Value::Float(max)]);
        assert!(e.contains("argument 3") && e.contains("> 0"), "{max}: {e}");
    }
    let e = cast(&mut w, vec![Value::Int(9999), x(), Value::Float(1.0)]);
    assert!(e.contains("does not exist") && e.contains("9999"), "{e}");
    let e = cast(
        &mut w,
        vec![Value::Int(hokuyo), x(), Value::Float(1.0), Value::Int(9999)],
    );
    assert!(e.contains("does not exist") && e.contains("9999"), "{e}");
    let e = cast(
        &mut w,
        vec![
            Value::Int(hokuyo),
            x(),
            Value::Float(1.0),
            Value::Int(-1),
            Value::Int(6),
        ],
    );
    assert!(e.contains("argument 5") && e.contains("unknown bits"), "{e}");
    // Packed floats work as a table does.
    let packed: Vec<u8> = [1.0f32, 0.0, 0.0].iter().flat_map(|v| v.to_le_bytes()).collect();
    let a = ok(
        &mut w,
        "sim.castRays",
        &[
            Value::Int(hokuyo),
            Value::Bytes(packed),
            Value::Float(4.0),
            Value::Int(hokuyo),
        ],
    );
    let b = ok(
        &mut w,
        "sim.castRays",
        &[Value::Int(hokuyo), x(), Value::Float(4.0), Value::Int(hokuyo)],
    );
    assert_eq!(a, b);

    let counts = |x: i64, y: i64| Value::Array(vec![Value::Int(x), Value::Int(y)]);
    let coords = |w: &mut Sim, h: Handle, c: Value| {
        err(
            w,
            "simVision.coordinatesFromWorkImg",
            &[Value::Int(h), c, Value::Bool(false)],
        )
    };
    // Not a vision sensor.
    let e = coords(&mut w, hokuyo, counts(10, 1));
    assert!(e.contains("not a vision sensor"), "{e}");
    // No work image yet, then a colour one, then a uniform colour that is no depth.
    let e = coords(&mut w, sensor, counts(10, 1));
    assert!(e.contains("sensorDepthMapToWorkImg"), "{e}");
    ok(&mut w, "simVision.sensorImgToWorkImg", &[Value::Int(sensor)]);
    let e = coords(&mut w, sensor, counts(10, 1));
    assert!(e.contains("not a depth map"), "{e}");
    ok(
        &mut w,
        "simVision.uniformImgToWorkImg",
        &[Value::Int(sensor), nums(&[0.5, 0.2, 0.1])],
    );
    let e = coords(&mut w, sensor, counts(10, 1));
    assert!(e.contains("not a depth"), "{e}");
    // A depth map, with bad counts.
    ok(&mut w, "simVision.sensorDepthMapToWorkImg", &[Value::Int(sensor)]);
    for bad in [
        counts(0, 1),
        counts(10, -1),
        Value::Array(vec![Value::Int(3)]),
        Value::Int(3),
    ] {
        let e = coords(&mut w, sensor, bad);
        assert!(e.contains("argument 2") && e.contains("positive integers"), "{e}");
    }
    let e = coords(&mut w, sensor, counts(5000, 5000));
    assert!(e.contains("at most"), "{e}");
    // Velodyne beams higher than the image reaches at its sides.
    let velo = find(&w, "/velodyne/sensor1");
    ok(&mut w, "simVision.sensorDepthMapToWorkImg", &[Value::Int(velo)]);
    let e = err(
        &mut w,
        "simVision.velodyneDataFromWorkImg",
        &[Value::Int(velo), counts(450, 16), Value::Float(60f64.to_radians())],
    );
    assert!(e.contains("beyond") && e.contains("image"), "{e}");
    for angle in [f64::NAN, -0.1, 4.0] {
        let e = err(
            &mut w,
            "simVision.velodyneDataFromWorkImg",
            &[Value::Int(velo), counts(450, 16), Value::Float(angle)],
        );
        assert!(e.contains("argument 3") || e.contains("vertical angle"), "{angle}: {e}");
    }
}
