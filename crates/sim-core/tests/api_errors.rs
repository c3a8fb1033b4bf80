//! Errors stay structured until a front end formats them: each failure has a kind
//! (what went wrong) and the text CoppeliaSim prints, `msg (in function 'sim.x')`.

use std::path::Path;

use gantry_sim_core::api::{self, CallContext, CallError};
use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene_text};
use gantry_sim_core::sim::SimulationState;
use gantry_sim_core::{Sim, SimError, Value};

fn sim() -> Sim {
    let text = "[[object]]\nname = \"box\"\nkind = \"dummy\"\n";
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("errors.toml");
    Sim::new(&load_scene_text(&DiskFiles, text, &path, &LoadOptions::default()).expect("scene"))
}

fn fail(s: &mut Sim, name: &str, args: &[Value]) -> CallError {
    api::call(s, &CallContext::default(), name, args).expect_err(name)
}

#[test]
fn each_failure_has_its_kind_and_coppeliasims_text() {
    let mut s = sim();
    let e = fail(&mut s, "sim.getObject", &[Value::Str("/nothing".into())]);
    // The path stays with the error for the caller; the text is CoppeliaSim's.
    assert!(
        matches!(e.error(), Some(SimError::PathNotFound(p)) if p == "/nothing"),
        "{e:?}"
    );
    assert_eq!(
        e.to_string(),
        "object does not exist, or alias/path is ill formatted. (in function 'sim.getObject')"
    );

    let e = fail(&mut s, "sim.getJointPosition", &[Value::Int(0)]);
    assert!(matches!(e.error(), Some(SimError::WrongKind { handle: 0, .. })), "{e}");
    assert!(e.to_string().ends_with("(in function 'sim.getJointPosition')"), "{e}");

    let e = fail(&mut s, "sim.getObjectPosition", &[Value::Str("box".into())]);
    assert!(matches!(e.error(), Some(SimError::BadArgument(_))), "{e}");
    assert!(e.to_string().starts_with("argument 1: "), "{e}");

    let e = fail(&mut s, "sim.getObjectPosition", &[Value::Int(99)]);
    assert_eq!(e.error(), Some(&SimError::NoSuchObject(99)), "{e}");
    assert_eq!(
        e.to_string(),
        "object does not exist. (handle 99) (in function 'sim.getObjectPosition')"
    );

    // A well-formed call refused in this state: the time step while running.
    s.state = SimulationState::Running;
    let e = fail(&mut s, "sim.setFloatParam", &[Value::Int(1), Value::Float(0.01)]);
    assert!(matches!(e.error(), Some(SimError::Refused(_))), "{e}");
    assert!(
        e.to_string()
            .contains("only be changed while the simulation is stopped"),
        "{e}"
    );

    let e = fail(&mut s, "sim.noSuchThing", &[]);
    assert_eq!(e, CallError::NoSuchFunction("sim.noSuchThing".into()));
    assert_eq!(e.error(), None);
    assert_eq!(e.to_string(), "No such function: sim.noSuchThing");
}
