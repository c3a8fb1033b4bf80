//! `sim.checkDistance` searches outwards through rapier's broad-phase tree instead of
//! measuring every pair; these tests hold it to the brute-force answer on scattered
//! spheres, whose exact distance is known in closed form (|c1 − c2| − r1 − r2).

use std::path::Path;

use gantry_sim_core::api::{CallContext, call};
use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene_text};
use gantry_sim_core::{Sim, Value};

const HANDLE_ALL: i64 = -2;

/// A small deterministic generator (no dependency, same numbers on every machine).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

struct Ball {
    centre: [f64; 3],
    radius: f64,
}

/// `n` static spheres scattered over a `spread` × `spread` m square, some in tight
/// clusters and some far apart, so the search box must grow several times.
fn scatter(seed: u64, n: usize, spread: f64) -> (Sim, Vec<Ball>) {
    let mut rng = Lcg(seed);
    let mut text = String::from("[simulation]\ndt = 0.05\n");
    let mut balls = Vec::new();
    for i in 0..n {
        let scale = if i % 3 == 0 { 0.2 } else { spread };
        let centre = [
            (rng.next() - 0.5) * scale,
            (rng.next() - 0.5) * scale,
            0.5 + rng.next() * 2.0,
        ];
        let radius = 0.02 + rng.next() * 0.2;
        text.push_str(&format!(
            "\n[[object]]\nname = \"b{i}\"\nkind = \"shape\"\nshape = \"sphere\"\nradius = {radius}\nposition = [{}, {}, {}]\n",
            centre[0], centre[1], centre[2]
        ));
        balls.push(Ball { centre, radius });
    }
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scattered.toml");
    let model = load_scene_text(&DiskFiles, &text, &path, &LoadOptions::default()).expect("scene loads");
    (Sim::new(&model), balls)
}

fn gap(a: &Ball, b: &Ball) -> f64 {
    let d: f64 = (0..3).map(|i| (a.centre[i] - b.centre[i]).powi(2)).sum::<f64>().sqrt();
    d - a.radius - b.radius
}

/// checkDistance(ball i, everything, threshold) → (distance, other ball index) or None.
fn check(w: &mut Sim, i: usize, threshold: f64) -> Option<(f64, usize)> {
    let h = w.world.find(&format!("/b{i}"), None, 0).expect("ball");
    let r = call(
        w,
        &CallContext::default(),
        "checkDistance",
        &[Value::Int(h), Value::Int(HANDLE_ALL), Value::Float(threshold)],
    )
    .expect("checkDistance");
    if r[0].as_i64() != Some(1) {
        return None;
    }
    let Value::Array(data) = &r[1] else {
        panic!("distData is an array: {r:?}")
    };
    let d = data[6].as_f64().expect("distance");
    let Value::Array(pair) = &r[2] else {
        panic!("objectPair is an array: {r:?}")
    };
    let other = pair[1].as_i64().expect("handle");
    let name = w.world.object(other).expect("object").alias.clone();
    Some((d, name.trim_start_matches('b').parse().expect("ball index")))
}

fn brute_force(balls: &[Ball], i: usize, threshold: f64) -> Option<(f64, usize)> {
    let limit = if threshold > 0.0 { threshold } else { f64::INFINITY };
    (0..balls.len())
        .filter(|&k| k != i)
        .map(|k| (gap(&balls[i], &balls[k]).max(0.0), k))
        .filter(|&(d, _)| d < limit)
        .min_by(|x, y| x.0.total_cmp(&y.0))
}

#[test]
fn nearest_shape_matches_brute_force_at_every_range() {
    for (seed, spread) in [(1, 3.0), (2, 20.0), (3, 200.0)] {
        let (mut w, balls) = scatter(seed, 60, spread);
        for i in 0..balls.len() {
            for threshold in [0.0, 0.05, 1.0, 50.0] {
                let want = brute_force(&balls, i, threshold);
                let got = check(&mut w, i, threshold);
                match (want, got) {
                    (None, None) => {}
                    (Some((dw, kw)), Some((dg, kg))) => {
                        // f32 physics shapes: agreement to a few micrometres.
                        assert!(
                            (dw - dg).abs() < 2e-5,
                            "seed {seed}, ball {i}, threshold {threshold}: {dg} vs {dw}"
                        );
                        // Another ball at the same distance (within rounding) is an equal answer.
                        assert!(
                            kw == kg || (gap(&balls[i], &balls[kg]).max(0.0) - dw).abs() < 2e-5,
                            "seed {seed}, ball {i}: nearest is b{kw}, got b{kg}"
                        );
                    }
                    (w, g) => panic!("seed {seed}, ball {i}, threshold {threshold}: want {w:?}, got {g:?}"),
                }
            }
        }
    }
}

#[test]
fn nothing_else_in_the_scene_means_no_distance() {
    let (mut w, _) = scatter(4, 1, 1.0);
    assert_eq!(check(&mut w, 0, 0.0), None);
}
