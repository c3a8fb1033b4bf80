//! `cargo bench -p gantry-engine --bench editing`: the editor's edits on a large scene,
//! on the simulation thread (issue 48's bar: a 1,000-object paste and its undo each
//! under 100 ms with 5,000 objects in the scene).
//!
//! The scene: 5,000 cuboids made by one edit. Each figure is the median (and minimum)
//! of 9 runs, milliseconds: pasting 1,000 of them (`sim.copyPasteObjects`, one edit,
//! which also copies the scene for its undo), undoing that paste, redoing it, and
//! moving one object (one `sim.setObjectPosition` edit), the cost of a drag's step.

use std::time::Instant;

use gantry_engine::{Engine, EngineConfig, Input};
use gantry_sim_core::Value;
use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene_text};

fn edit(engine: &mut Engine, label: &str, calls: &[(String, Vec<Value>)]) -> Vec<Value> {
    engine
        .serve(Input::Edit { label, calls })
        .into_values()
        .unwrap_or_else(|e| panic!("{label}: {e}"))
}

fn undo(engine: &mut Engine, undo: bool) {
    let out = engine.serve(Input::Undo(undo)).into_values().expect("undo");
    assert!(!out.is_empty(), "nothing to undo or redo");
}

/// Median and minimum of `times` (ms), as "median (min)".
fn summary(mut times: Vec<f64>) -> String {
    times.sort_by(f64::total_cmp);
    format!("{:.1} ({:.1})", times[times.len() / 2], times[0])
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

fn main() {
    let path = std::env::temp_dir().join("gantry-bench-editing.toml");
    let model = load_scene_text(&DiskFiles, "[simulation]\ndt = 0.05\n", &path, &LoadOptions::default())
        .expect("an empty scene");
    let mut engine = Engine::new(model, EngineConfig::default(), None).expect("engine");
    let cuboid = |k: i64| {
        (
            "sim.createPrimitiveShape".to_owned(),
            vec![Value::Int(3), Value::floats(&[0.05, 0.05, 0.05 + 1e-4 * k as f64])],
        )
    };
    let made = edit(&mut engine, "Add 5000", &(0..5000).map(cuboid).collect::<Vec<_>>());
    let handles: Vec<Value> = made
        .iter()
        .map(|r| match r {
            Value::Array(v) => v[0].clone(),
            other => panic!("{other:?}"),
        })
        .collect();
    let paste = vec![(
        "sim.copyPasteObjects".to_owned(),
        vec![Value::Array(handles[..1000].to_vec())],
    )];
    let mv = |x: f64| {
        vec![(
            "sim.setObjectPosition".to_owned(),
            vec![handles[0].clone(), Value::Int(-1), Value::floats(&[x, 0.0, 0.1])],
        )]
    };
    let (mut pastes, mut undos, mut redos, mut moves) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for run in 0..9 {
        let t = Instant::now();
        edit(&mut engine, "Paste", &paste);
        pastes.push(ms(t));
        let t = Instant::now();
        undo(&mut engine, true);
        undos.push(ms(t));
        let t = Instant::now();
        undo(&mut engine, false);
        redos.push(ms(t));
        undo(&mut engine, true);
        let t = Instant::now();
        edit(&mut engine, "Move", &mv(f64::from(run) * 0.01));
        moves.push(ms(t));
    }
    println!("| editing, 5,000 cuboids in the scene | ms, median (min) of 9 |");
    println!("|---|---|");
    println!("| paste 1,000 objects (one edit) | {} |", summary(pastes));
    println!("| undo that paste | {} |", summary(undos));
    println!("| redo it | {} |", summary(redos));
    println!("| move one object (one edit) | {} |", summary(moves));
}
