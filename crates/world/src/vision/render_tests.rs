//! The renderer's contracts that span its files: culling (per visual and per mesh
//! chunk, against the sampled frustum) never changes a bit of an image, sensors
//! drawn on several threads, whole or in bands of rows, give the bits they give one
//! after the other, and pixels that see nothing show the sensor's or the scene's
//! background.

use std::path::PathBuf;

use nalgebra::{Translation3, UnitQuaternion, Vector3};

use super::{SensorImage, VisionStates, handle_vision_sensor};
use crate::math::Pose;
use crate::scene::{LoadOptions, MapFiles, load_scene};
use crate::{Handle, Sim};

/// xorshift64: repeatable pseudo-random numbers without a dependency.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// Uniform in `lo..hi`.
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// An OBJ of a bumpy UV sphere of radius about 0.3 m: 2,400 triangles, so about ten
/// chunks of 256, with vertices shared between triangles as in a vendor's mesh.
fn bumpy_sphere_obj() -> String {
    uv_sphere_obj(30, 40)
}

/// A bumpy UV sphere of radius about 0.3 m with `rings` x `around` quads.
fn uv_sphere_obj(rings: u32, around: u32) -> String {
    let mut s = String::new();
    for i in 0..=rings {
        let phi = std::f64::consts::PI * f64::from(i) / f64::from(rings);
        for j in 0..around {
            let th = std::f64::consts::TAU * f64::from(j) / f64::from(around);
            let r = 0.3 + 0.03 * (5.0 * th).sin() * (3.0 * phi).sin();
            s += &format!(
                "v {} {} {}\n",
                r * phi.sin() * th.cos(),
                r * phi.sin() * th.sin(),
                r * phi.cos()
            );
        }
    }
    let at = |i: u32, j: u32| i * around + j % around + 1;
    for i in 0..rings {
        for j in 0..around {
            s += &format!("f {} {} {}\n", at(i, j), at(i + 1, j), at(i + 1, j + 1));
            s += &format!("f {} {} {}\n", at(i, j), at(i + 1, j + 1), at(i, j + 1));
        }
    }
    s
}

/// A test sensor: name, `[width, height]` (px), projection, view angle (degrees) or
/// ortho size (m), near and far (m).
type SensorSpec = (&'static str, [u32; 2], &'static str, f64, f64, f64);

/// Sensors of the scene below: name, resolution, projection, view angle (degrees) or
/// ortho size (m), near and far (m). Sizes 1 x 1 (the sampled frustum is one ray) to
/// 97 x 61; near planes far enough out that shapes straddle them.
const SENSORS: [SensorSpec; 6] = [
    ("one", [1, 1], "perspective", 60.0, 0.01, 6.0),
    ("tiny", [3, 2], "perspective", 90.0, 0.2, 5.0),
    ("wide", [97, 61], "perspective", 120.0, 0.05, 8.0),
    ("narrow", [64, 48], "perspective", 20.0, 0.5, 8.0),
    ("tall", [33, 80], "perspective", 60.0, 0.4, 2.5),
    ("ortho", [48, 40], "orthographic", 1.5, 0.3, 6.0),
];

/// Many shapes of every kind around the origin (boxes, spheres, cylinders, capsules,
/// meshes, some rotated, some huge: a 60 m slab whose corners are all outside any
/// view it covers, and a 3 m bumpy sphere around everything, nearer than some far planes), and the sensors of [`SENSORS`].
fn scene() -> Sim {
    let mut rng = Rng(0x5eed_cafe);
    let mut text = String::from("[simulation]\ndt = 0.05\n\n");
    let kinds = ["box", "sphere", "cylinder", "capsule", "mesh"];
    for k in 0..40 {
        let kind = kinds[k % kinds.len()];
        let (x, y, z) = (rng.range(-2.5, 2.5), rng.range(-2.5, 2.5), rng.range(0.0, 1.5));
        let (a, b, c) = (
            rng.range(-180.0, 180.0),
            rng.range(-90.0, 90.0),
            rng.range(-180.0, 180.0),
        );
        let colour = [rng.range(0.1, 1.0), rng.range(0.1, 1.0), rng.range(0.1, 1.0)];
        let geometry = match kind {
            "box" => format!(
                "size = [{}, {}, {}]",
                rng.range(0.05, 0.8),
                rng.range(0.05, 0.8),
                rng.range(0.05, 0.8)
            ),
            "sphere" => format!("radius = {}", rng.range(0.05, 0.4)),
            "mesh" => format!("mesh = \"bumpy.obj\"\nscale = [{0}, {0}, {0}]", rng.range(0.5, 2.0)),
            _ => format!("radius = {}\nlength = {}", rng.range(0.03, 0.3), rng.range(0.1, 1.0)),
        };
        text += &format!(
            "[[object]]\nname = \"s{k}\"\nkind = \"shape\"\nshape = \"{kind}\"\n{geometry}\n\
             position = [{x}, {y}, {z}]\norientation_deg = [{a}, {b}, {c}]\ncolor = {colour:?}\n\n"
        );
    }
    text += "[[object]]\nname = \"slab\"\nkind = \"shape\"\nshape = \"box\"\nsize = [60, 60, 0.02]\n\
             position = [0, 0, -0.01]\ncolor = [0.5, 0.6, 0.7]\n\n";
    text += "[[object]]\nname = \"dome\"\nkind = \"shape\"\nshape = \"mesh\"\nmesh = \"bumpy.obj\"\n\
             scale = [10, 10, 10]\nposition = [0, 0, 0]\ncolor = [0.9, 0.8, 0.2]\n\n";
    // A vendor-dense mesh (28,800 triangles of about 1.5 cm), which small views draw
    // at a coarser level.
    text += "[[object]]\nname = \"dense\"\nkind = \"shape\"\nshape = \"mesh\"\nmesh = \"dense.obj\"\n\
             scale = [2, 2, 2]\nposition = [0.5, -0.5, 0.8]\ncolor = [0.3, 0.7, 0.9]\n\n";
    for (name, [w, h], projection, angle, near, far) in SENSORS {
        let extent = if projection == "orthographic" {
            format!("ortho_size = {angle}")
        } else {
            format!("fov_deg = {angle}")
        };
        text += &format!(
            "[[object]]\nname = \"{name}\"\nkind = \"vision_sensor\"\nresolution = [{w}, {h}]\n\
             projection = \"{projection}\"\n{extent}\nnear = {near}\nfar = {far}\n\n"
        );
    }
    let dir = PathBuf::from("/cull-test");
    let files = MapFiles::new([
        (dir.join("scene.toml"), text.into_bytes()),
        (dir.join("bumpy.obj"), bumpy_sphere_obj().into_bytes()),
        (dir.join("dense.obj"), uv_sphere_obj(120, 120).into_bytes()),
    ]);
    let model = load_scene(&files, &dir.join("scene.toml"), &LoadOptions::default()).expect("test scene loads");
    Sim::new(&model)
}

fn sensor(w: &Sim, name: &str) -> Handle {
    w.world.find(&format!("/{name}"), None, 0).expect(name)
}

/// RGB bytes and depth bits of sensor `h`'s last image.
fn image(states: &VisionStates, h: Handle) -> (Vec<u8>, Vec<u32>) {
    let img = states.image(h).expect("rendered");
    (img.rgb().to_vec(), img.depth().iter().map(|d| d.to_bits()).collect())
}

/// A random sensor pose: anywhere over the scene (some inside the big shapes, most
/// outside them, some below the slab), looking anywhere; a third of them aimed at a
/// random shape so that views are full of geometry, partly in view and partly not.
fn random_pose(rng: &mut Rng, targets: &[Pose]) -> Pose {
    let eye = Vector3::new(rng.range(-3.5, 3.5), rng.range(-3.5, 3.5), rng.range(-0.3, 2.5));
    let rotation = if rng.next().is_multiple_of(3) {
        let t = targets[(rng.next() % targets.len() as u64) as usize].translation.vector;
        // +Z (the viewing axis) onto the direction to the target, rolled at random.
        let dir = t - eye;
        let aim = UnitQuaternion::rotation_between(&Vector3::z(), &dir).unwrap_or_else(UnitQuaternion::identity);
        aim * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), rng.range(-3.2, 3.2))
    } else {
        UnitQuaternion::from_euler_angles(rng.range(-3.2, 3.2), rng.range(-1.6, 1.6), rng.range(-3.2, 3.2))
    };
    Pose::from_parts(Translation3::from(eye), rotation)
}

#[test]
fn culling_drops_nothing_visible() {
    let mut w = scene();
    let shapes: Vec<Pose> = (0..40)
        .map(|k| w.world.object(sensor(&w, &format!("s{k}"))).expect("shape").world)
        .collect();
    let mut rng = Rng(0x0dd_ba11);
    let mut tessellated = VisionStates::default();
    tessellated.shapes.refresh(&w.world);
    let (mut culled, mut drawn, mut nonempty) = (0, 0, 0);
    for round in 0..60 {
        for (name, ..) in SENSORS {
            let h = sensor(&w, name);
            let pose = random_pose(&mut rng, &shapes);
            w.world.set_world_pose(h, pose).expect("pose");
            // Fresh image states, over the tessellations made once above.
            let mut culling = VisionStates {
                shapes: tessellated.shapes.clone(),
                ..VisionStates::default()
            };
            let mut everything = VisionStates {
                no_cull: true,
                shapes: tessellated.shapes.clone(),
                ..VisionStates::default()
            };
            // Every other round with masks, which must not change a bit either.
            let with_mask = round % 2 == 1;
            for states in [&mut culling, &mut everything] {
                if with_mask {
                    super::read_mask(&w.world, states, h).expect("render");
                } else {
                    handle_vision_sensor(&w.world, states, h).expect("render");
                }
            }
            let (a, b) = (image(&culling, h), image(&everything, h));
            if with_mask {
                let (ma, mb) = (
                    culling.image(h).and_then(SensorImage::mask),
                    everything.image(h).and_then(SensorImage::mask),
                );
                assert!(
                    ma.is_some() && ma == mb,
                    "round {round}, sensor {name} at {pose:?}: mask differs with culling"
                );
                // Where nothing is seen the depth is 1 (and where the depth is less,
                // something is; a surface at the far plane may also read 1).
                for (&id, &d) in ma.unwrap_or_default().iter().zip(&a.1) {
                    assert!(
                        id != -1 || d == 1f32.to_bits(),
                        "round {round}, sensor {name}: nothing seen at depth {}",
                        f32::from_bits(d)
                    );
                }
            }
            assert!(
                a.0 == b.0,
                "round {round}, sensor {name} at {pose:?}: RGB differs with culling"
            );
            assert!(
                a.1 == b.1,
                "round {round}, sensor {name} at {pose:?}: depth differs with culling"
            );
            culled += culling.scratch.stats.culled_chunks;
            drawn += culling.scratch.stats.drawn_chunks;
            assert_eq!(everything.scratch.stats.culled_chunks, 0);
            nonempty += usize::from(a.0.iter().any(|&c| c != 0));
        }
    }
    // The comparison covered both: views with something drawn, and chunks culled.
    assert!(nonempty > 200, "{nonempty} of 360 images show something");
    assert!(culled > 10 * drawn / 100, "culled {culled} chunks, drew {drawn}");
    assert!(drawn > 1000, "drew {drawn} chunks");
}

#[test]
fn coarser_levels_stay_within_half_a_pixel() {
    // Random views drawn with the meshes' coarser levels where the pixels allow, and in
    // full: where the shape seen differs, the full image has a silhouette within a
    // pixel; elsewhere (the pixel and its eight neighbours see one shape) depths agree
    // within 1 %.
    let mut w = scene();
    let shapes: Vec<Pose> = (0..40)
        .map(|k| w.world.object(sensor(&w, &format!("s{k}"))).expect("shape").world)
        .collect();
    let mut rng = Rng(0xc0a2_5e11);
    let mut tessellated = VisionStates::default();
    tessellated.shapes.refresh(&w.world);
    let (mut coarse, mut compared, mut differing) = (0, 0, 0);
    for round in 0..40 {
        for (name, [width, height], _, _, near, far) in SENSORS {
            let h = sensor(&w, name);
            let pose = random_pose(&mut rng, &shapes);
            w.world.set_world_pose(h, pose).expect("pose");
            let mut images = Vec::new();
            for full_detail in [false, true] {
                let mut states = VisionStates {
                    shapes: tessellated.shapes.clone(),
                    full_detail,
                    ..VisionStates::default()
                };
                super::read_mask(&w.world, &mut states, h).expect("render");
                if !full_detail {
                    coarse += states.scratch.stats.coarse_visuals;
                }
                let img = states.image(h).expect("rendered");
                images.push((img.mask().expect("a mask").to_vec(), img.depth().to_vec()));
            }
            let [(mask, depth), (full_mask, full_depth)] = [&images[0], &images[1]];
            let (w_px, h_px) = (width as usize, height as usize);
            let uniform = |x: usize, y: usize| {
                let id = full_mask[y * w_px + x];
                (y.saturating_sub(1)..(y + 2).min(h_px))
                    .all(|yy| (x.saturating_sub(1)..(x + 2).min(w_px)).all(|xx| full_mask[yy * w_px + xx] == id))
            };
            for y in 0..h_px {
                for x in 0..w_px {
                    let i = y * w_px + x;
                    if uniform(x, y) {
                        compared += 1;
                        assert_eq!(
                            mask[i], full_mask[i],
                            "round {round}, {name}, pixel ({x}, {y}): another shape"
                        );
                        if full_mask[i] != -1 {
                            let metres = |d: f32| near + f64::from(d) * (far - near);
                            let (a, b) = (metres(depth[i]), metres(full_depth[i]));
                            assert!(
                                (a - b).abs() <= 0.01 * b,
                                "round {round}, {name}, pixel ({x}, {y}): {a} m against {b} m"
                            );
                        }
                    }
                    differing += usize::from(depth[i].to_bits() != full_depth[i].to_bits());
                }
            }
        }
    }
    // Coarse levels were drawn, and changed some depths, so the comparison is not empty.
    assert!(coarse > 20, "{coarse} coarse visuals drawn");
    assert!(compared > 10_000, "{compared} pixels compared");
    assert!(differing > 0, "no pixel changed: were coarse levels drawn?");
}

#[test]
fn sensors_drawn_in_parallel_give_the_same_images() {
    let mut w = scene();
    let shapes: Vec<Pose> = (0..40)
        .map(|k| w.world.object(sensor(&w, &format!("s{k}"))).expect("shape").world)
        .collect();
    let mut rng = Rng(0xfee1_900d);
    let handles: Vec<Handle> = SENSORS.iter().map(|s| sensor(&w, s.0)).collect();
    for &h in &handles {
        w.world.set_world_pose(h, random_pose(&mut rng, &shapes)).expect("pose");
    }
    let run = |threads: usize| {
        let mut states = VisionStates::default();
        let outcomes = states.render_many(&w.world, &handles, threads);
        assert!(outcomes.iter().all(Result::is_ok));
        // Frame buffers follow the threads, not the sensors: one set per thread, and
        // one per sensor drawn in bands (fewer than the threads).
        assert!(states.extra_scratch.len() < threads && states.frames.len() < threads.max(2));
        handles.iter().map(|&h| image(&states, h)).collect::<Vec<_>>()
    };
    let one_by_one = run(1);
    // Two runs of each thread count: the images are the same bits every time.
    for threads in [2, 2, 3, 6, 6] {
        assert!(run(threads) == one_by_one, "{threads} threads");
    }
    // The public entry point takes the parallel path on a multi-core machine.
    let mut states = VisionStates::default();
    let rendered = super::handle_all_vision_sensors(&w.world, &mut states, false).expect("render");
    assert_eq!(rendered, handles.len());
    let all: Vec<_> = handles.iter().map(|&h| image(&states, h)).collect();
    assert!(all == one_by_one);
    assert!(one_by_one.iter().filter(|(rgb, _)| rgb.iter().any(|&c| c != 0)).count() >= 3);
}

#[test]
fn images_drawn_in_bands_of_rows_are_the_same_bits() {
    let mut w = scene();
    let shapes: Vec<Pose> = (0..40)
        .map(|k| w.world.object(sensor(&w, &format!("s{k}"))).expect("shape").world)
        .collect();
    let handles: Vec<Handle> = SENSORS.iter().map(|s| sensor(&w, s.0)).collect();
    let mut rng = Rng(0x0ba2_d5ee);
    // RGB, depth and mask of each sensor rendered alone on `threads` threads: one
    // sensor on several threads is cut into bands (`threads` of them, or one per row).
    // One renderer per thread count, kept from round to round.
    let mut renderers: Vec<VisionStates> = (0..4)
        .map(|_| VisionStates {
            band_every_size: true,
            ..VisionStates::default()
        })
        .collect();
    let draw = |w: &Sim, states: &mut VisionStates, threads: usize| {
        handles
            .iter()
            .map(|&h| {
                super::read_mask(&w.world, states, h).expect("mask on");
                assert!(states.render_many(&w.world, &[h], threads)[0].is_ok());
                let img = states.image(h).expect("rendered");
                let mask = img.mask().expect("a mask").to_vec();
                (image(states, h), mask)
            })
            .collect::<Vec<_>>()
    };
    let mut seen = 0;
    for _ in 0..12 {
        for &h in &handles {
            w.world.set_world_pose(h, random_pose(&mut rng, &shapes)).expect("pose");
        }
        let [one, more @ ..] = &mut renderers[..] else {
            unreachable!("four renderers")
        };
        let whole = draw(&w, one, 1);
        seen += whole.iter().filter(|((rgb, _), _)| rgb.iter().any(|&c| c != 0)).count();
        // 2 and 3 bands; 64 is more than any sensor's rows (one band per row).
        for (states, threads) in more.iter_mut().zip([2, 3, 64]) {
            assert!(draw(&w, states, threads) == whole, "{threads} bands");
        }
    }
    assert!(seen >= 20, "only {seen} images saw anything");
}

#[test]
fn culling_the_back_faces_of_closed_meshes_changes_only_silhouette_pixels() {
    let mut w = scene();
    let shapes: Vec<Pose> = (0..40)
        .map(|k| w.world.object(sensor(&w, &format!("s{k}"))).expect("shape").world)
        .collect();
    let handles: Vec<Handle> = SENSORS.iter().map(|s| sensor(&w, s.0)).collect();
    // One renderer culling them, one drawing every face; masks on in both.
    let mut culling = VisionStates::default();
    let mut two_sided = VisionStates {
        two_sided_meshes: true,
        ..VisionStates::default()
    };
    let mut rng = Rng(0xbacf_ace5);
    let (mut compared, mut differing, mut back_faces) = (0usize, 0usize, 0usize);
    for round in 0..40 {
        for &h in &handles {
            w.world.set_world_pose(h, random_pose(&mut rng, &shapes)).expect("pose");
        }
        for (&h, spec) in handles.iter().zip(SENSORS) {
            let [width, height] = spec.1.map(|v| v as usize);
            let draw = |states: &mut VisionStates| {
                super::read_mask(&w.world, states, h).expect("mask on");
                handle_vision_sensor(&w.world, states, h).expect("render");
                let mask = states.image(h).and_then(SensorImage::mask).expect("a mask").to_vec();
                (image(states, h), mask, states.scratch.stats.back_faces)
            };
            let ((rgb, depth), mask, culled) = draw(&mut culling);
            let ((rgb2, depth2), mask2, _) = draw(&mut two_sided);
            back_faces += culled;
            for i in 0..width * height {
                compared += 1;
                if rgb[3 * i..3 * i + 3] == rgb2[3 * i..3 * i + 3] && depth[i] == depth2[i] && mask[i] == mask2[i] {
                    continue;
                }
                differing += 1;
                // Only where a front and a back face meet: a silhouette of the shape
                // seen (two-sided), so a neighbour shows something else.
                let (x, y) = (i % width, i / width);
                let edge = [(0, 1), (2, 1), (1, 0), (1, 2)].iter().any(|&(dx, dy)| {
                    let (nx, ny) = ((x + dx).wrapping_sub(1), (y + dy).wrapping_sub(1));
                    nx < width && ny < height && mask2[ny * width + nx] != mask2[i]
                });
                assert!(
                    edge,
                    "round {round}, {}, pixel ({x}, {y}) differs away from a silhouette",
                    spec.0
                );
            }
        }
    }
    assert!(back_faces > 10_000, "only {back_faces} back faces culled");
    assert!(compared > 100_000, "{compared} pixels compared");
    // Ties at silhouettes are rare.
    assert!(differing * 1000 <= compared, "{differing} of {compared} pixels differ");
}

/// A sensor at the origin looking up (+Z) at a small box 1 m above, so most of its
/// pixels see nothing; `simulation` and `sensor_keys` are extra lines for the scene's
/// `[simulation]` table and the sensor's object. The sensor's RGB bytes, depth bits and
/// colour-coded image (of a twin sensor), after one handling each.
fn looking_up(simulation: &str, sensor_keys: &str) -> (Vec<u8>, Vec<u32>, Vec<u8>) {
    let text = format!(
        "[simulation]\ndt = 0.05\n{simulation}\n\n\
         [[object]]\nname = \"box\"\nkind = \"shape\"\nshape = \"box\"\nsize = [0.2, 0.2, 0.2]\n\
         position = [0, 0, 1]\ncolor = [0.9, 0.1, 0.1]\n\n\
         [[object]]\nname = \"eye\"\nkind = \"vision_sensor\"\nresolution = [32, 24]\nfov_deg = 60\n\
         near = 0.01\nfar = 5\n{sensor_keys}\n\n\
         [[object]]\nname = \"coded\"\nkind = \"vision_sensor\"\nresolution = [32, 24]\nfov_deg = 60\n\
         near = 0.01\nfar = 5\nrender_mode = \"color_coded\"\n{sensor_keys}\n"
    );
    let path = PathBuf::from("/background-test/scene.toml");
    let files = MapFiles::new([(path.clone(), text.into_bytes())]);
    let model = load_scene(&files, &path, &LoadOptions::default()).expect("test scene loads");
    let w = Sim::new(&model);
    let mut states = VisionStates::default();
    let (eye, coded) = (sensor(&w, "eye"), sensor(&w, "coded"));
    handle_vision_sensor(&w.world, &mut states, eye).expect("renders");
    handle_vision_sensor(&w.world, &mut states, coded).expect("renders");
    let (rgb, depth) = image(&states, eye);
    (rgb, depth, image(&states, coded).0)
}

#[test]
fn pixels_that_see_nothing_show_the_background() {
    let pixels = |rgb: &[u8]| rgb.chunks(3).map(|p| [p[0], p[1], p[2]]).collect::<Vec<_>>();
    // No background anywhere: black where nothing is seen, as before.
    let (black_rgb, black_depth, black_coded) = looking_up("", "");
    let nothing: Vec<bool> = black_depth.iter().map(|&d| f32::from_bits(d) == 1.0).collect();
    let seen = nothing.iter().filter(|n| !**n).count();
    assert!(seen > 0 && seen < nothing.len() / 2, "the box covers {seen} pixels");
    for (p, n) in pixels(&black_rgb).iter().zip(&nothing) {
        assert_eq!(*p == [0, 0, 0], *n, "{p:?}");
    }

    // The scene's background fills exactly the pixels that see nothing; the box's
    // pixels, the depth image and the colour-coded image do not change.
    let (rgb, depth, coded) = looking_up("background = [0.2, 0.4, 0.6]", "");
    assert_eq!(depth, black_depth);
    assert_eq!(coded, black_coded);
    for ((p, b), n) in pixels(&rgb).iter().zip(pixels(&black_rgb)).zip(&nothing) {
        assert_eq!(*p, if *n { [51, 102, 153] } else { b });
    }
    // Colour-coded images stay white where nothing is seen.
    for (p, n) in pixels(&coded).iter().zip(&nothing) {
        assert_eq!(*p == [255, 255, 255], *n, "{p:?}");
    }

    // A sensor's own colour wins over the scene's.
    let (rgb, depth, _) = looking_up("background = [0.2, 0.4, 0.6]", "background = [1, 1, 0]");
    assert_eq!(depth, black_depth);
    for ((p, b), n) in pixels(&rgb).iter().zip(pixels(&black_rgb)).zip(&nothing) {
        assert_eq!(*p, if *n { [255, 255, 0] } else { b });
    }
}
