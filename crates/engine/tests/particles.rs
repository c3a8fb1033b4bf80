//! Particle objects as V-REP's jet, spray and propeller scripts use them
//! (`sim.addParticleObject`, `sim.addParticleObjectItem`, `sim.removeParticleObject`):
//! respondable particles are bodies that push what they hit, the others fly through;
//! item limits, lifetimes, removal and bad arguments behave as in CoppeliaSim.

use crate::util;
use util::Drive;

use gantry_lua::ScriptLimits;
use gantry_sim_core::Value;
use gantry_sim_core::drawing::DrawingKind;
use gantry_test_support::{assert_contains, int, text};
use util::{Scene, assert_running, world_position};

/// A 2 kg box resting on the floor at the origin, and a nozzle 0.6 m behind it (-x)
/// whose script fires a jet along +x.
const JET_SCENE: &str = r#"
[simulation]
dt = 0.05

[floor]
size = [20, 20]

[[object]]
name = "box"
kind = "shape"
shape = "box"
size = [0.2, 0.2, 0.2]
mass = 2
friction = 0.5
dynamic = true
position = [0, 0, 0.1]

[[object]]
name = "nozzle"
kind = "dummy"
position = [-0.6, 0, 0.1]
script = "jet.lua"
"#;

/// A non-threaded script emitting two dense 4 cm particles a step at 5 m/s along +x
/// (the end point is the start point plus the velocity), with `FLAGS` added to the
/// type.
const JET: &str = r#"
function sysCall_init()
    nozzle = sim.getObject('/nozzle')
    local t = sim.particle_spheres + sim.particle_ignoresgravity + sim.particle_cyclic + FLAGS
    jet = sim.addParticleObject(t, 0.04, 5000, {1, 0, 0.3}, 0.5, 40, {0.3, 0.7, 1})
end
function sysCall_actuation()
    local p = sim.getObjectPosition(nozzle, -1)
    for _, dz in ipairs({-0.03, 0.03}) do
        sim.addParticleObjectItem(jet, {p[1], p[2], p[3] + dz, p[1] + 5, p[2], p[3] + dz})
    end
end
function jetHandle()
    return jet
end
"#;

/// Runs the jet scene for 1 s with `flags` on the particle type; returns the scene
/// (still running) and how far the box moved along x and y, m. The box stays upright
/// on the floor.
fn run_jet(tag: &str, flags: &str) -> (Scene, f64, f64) {
    let script = JET.replace("FLAGS", flags);
    let mut sc = Scene::new(tag, JET_SCENE, &[("jet.lua", &script)], ScriptLimits::default());
    let b = sc.find("/box");
    let start = world_position(&sc.sim, b);
    sc.sim.start();
    for _ in 0..20 {
        sc.sim.step();
    }
    assert_running(&sc.sim, "jet.lua");
    let end = world_position(&sc.sim, b);
    assert!((end[2] - start[2]).abs() < 0.01, "the box left the floor: {end:?}");
    (sc, end[0] - start[0], end[1] - start[1])
}

#[test]
fn a_jet_of_respondable_particles_pushes_a_box() {
    let (sc, dx, dy) = run_jet("particles-jet", "sim.particle_respondable1to4");
    assert!(dx > 0.05, "the box moved {dx} m along the jet");
    assert!(dy.abs() < 0.2 * dx, "and stayed on its line: {dy} m sideways");
    // The jet is cyclic with 40 particles at most and a 0.5 s lifetime: 20 steps of 2
    // particles, the oldest of which expired.
    let core = sc.sim.core();
    let (h, o) = core.particles.iter().next().expect("the jet exists");
    assert!(
        o.item_count() <= 40 && o.item_count() >= 18,
        "{} particles",
        o.item_count()
    );
    // Those in front of the box are stopped by it: none got through.
    let through = core
        .particles
        .positions(&core.world, h)
        .expect("jet")
        .iter()
        .filter(|p| p.x > 0.2 + dx)
        .count();
    assert_eq!(through, 0, "respondable particles passed through the box");
}

#[test]
fn non_respondable_particles_fly_through_the_box() {
    let (sc, dx, dy) = run_jet("particles-ghost", "0");
    assert!(dx.abs() < 1e-3 && dy.abs() < 1e-3, "the box moved ({dx}, {dy}) m");
    let core = sc.sim.core();
    let (h, _) = core.particles.iter().next().expect("the jet exists");
    let positions = core.particles.positions(&core.world, h).expect("jet");
    assert!(
        positions.iter().any(|p| p.x > 0.5),
        "particles should have flown through the box: {positions:?}"
    );
    // Ballistic at 5 m/s along x, and weightless: the oldest particle, 0.5 s old at
    // most, is within 2.5 m of the nozzle at the nozzle's height.
    let v = core.particles.velocities(&core.world, h).expect("jet");
    assert!(v.iter().all(|v| (v.x - 5.0).abs() < 1e-3 && v.z.abs() < 1e-3), "{v:?}");
}

/// A dummy with a script that drives particle objects from calls.
const PROBE_SCENE: &str = r#"
[simulation]
dt = 0.05

[[object]]
name = "probe"
kind = "dummy"
script = "probe.lua"
"#;

fn probe(tag: &str, body: &str) -> Scene {
    Scene::probe(tag, PROBE_SCENE, body)
}

#[test]
fn full_objects_ignore_or_recycle_and_particles_expire() {
    let body = r#"
function sysCall_init()
    local t = sim.particle_roughspheres + sim.particle_ignoresgravity
    plain = sim.addParticleObject(t, 0.01, 1000, nil, 0.2, 3)
    cyclic = sim.addParticleObject(t + sim.particle_cyclic, 0.01, 1000, nil, 0, 3)
    hidden = sim.addParticleObject(t + sim.particle_invisible, 0.01, 1000, nil, 0, 3)
    for i = 1, 5 do
        sim.addParticleObjectItem(plain, {i, 0, 0, i, 0, 0})
        sim.addParticleObjectItem(cyclic, {i, 0, 0, i, 0, 0})
    end
    sim.addParticleObjectItem(hidden, {0, 0, 0, 0, 0, 0})
end
function handles()
    return plain, cyclic, hidden
end
function empty(h)
    sim.addParticleObjectItem(h, nil)
end
function remove(h)
    sim.removeParticleObject(h)
    return err(sim.addParticleObjectItem, h, {0, 0, 0, 0, 0, 0})
end
function redraw()
    sim.removeDrawingObject(sim.handle_all)
    local mine = sim.addDrawingObject(sim.drawing_lines, 2, 0, -1, 10, {1, 0, 0})
    sim.addDrawingObjectItem(mine, {0, 0, 0, 1, 1, 1})
end
"#;
    let mut sc = probe("particles-limits", body);
    let hs: Vec<i64> = sc.call("handles", &[]).iter().map(int).collect();
    let (plain, cyclic, hidden) = (hs[0], hs[1], hs[2]);
    let xs = |sc: &Scene, h: i64| -> Vec<f64> {
        let core = sc.sim.core();
        core.particles
            .positions(&core.world, h)
            .expect("exists")
            .iter()
            .map(|p| p.x)
            .collect()
    };
    assert_eq!(xs(&sc, plain), [1.0, 2.0, 3.0], "a full object ignores new items");
    assert_eq!(
        xs(&sc, cyclic),
        [3.0, 4.0, 5.0],
        "a full cyclic one replaces its oldest"
    );
    // Drawn from the first step on: one sphere-point drawing object per visible object.
    sc.sim.step();
    {
        let core = sc.sim.core();
        let drawn: Vec<(DrawingKind, usize)> = core.drawings.iter().map(|(_, d)| (d.kind(), d.item_count())).collect();
        assert_eq!(drawn, [(DrawingKind::SpherePoints, 3), (DrawingKind::SpherePoints, 3)]);
    }
    // The plain object's 0.2 s lifetime is over after 5 steps of 0.05 s; the others
    // have none.
    for _ in 0..4 {
        sc.sim.step();
    }
    assert!(xs(&sc, plain).is_empty(), "expired: {:?}", xs(&sc, plain));
    assert_eq!(xs(&sc, cyclic).len(), 3);
    sc.call("empty", &[Value::Int(cyclic)]);
    assert!(xs(&sc, cyclic).is_empty(), "nil item data empties the object");
    let e = sc.call("remove", &[Value::Int(hidden)]);
    assert_contains(
        text(&e[0]),
        &["particle object does not exist", "sim.addParticleObjectItem"],
    );
    assert_eq!(sc.sim.core().particles.len(), 2);
    // A script that removes every drawing object and draws its own: its drawing keeps
    // what it drew (it may have the handle a particle drawing had), and the particles
    // get new drawing objects.
    sc.call("redraw", &[]);
    sc.sim.step();
    {
        let core = sc.sim.core();
        let drawn: Vec<(DrawingKind, usize)> = core.drawings.iter().map(|(_, d)| (d.kind(), d.item_count())).collect();
        assert_eq!(
            drawn,
            [
                (DrawingKind::Lines, 1),
                (DrawingKind::SpherePoints, 0),
                (DrawingKind::SpherePoints, 0)
            ]
        );
    }
    // At stop the particle objects go with the simulation, and their bodies too.
    sc.sim.stop();
    assert!(sc.sim.core().particles.is_empty());
    assert!(sc.sim.core().drawings.is_empty(), "their drawing objects too");
}

#[test]
fn bad_arguments_are_clear_errors() {
    let body = r#"
function sysCall_init()
    jet = sim.addParticleObject(sim.particle_spheres + sim.particle_itemcolors, 0.01, 1000, nil, 0, 10)
end
function errors()
    local box = sim.getObject('/probe')
    return {
        err(sim.addParticleObject, 7, 0.01, 1000, nil, 0, 10),
        err(sim.addParticleObject, sim.particle_spheres, 0, 1000, nil, 0, 10),
        err(sim.addParticleObject, sim.particle_spheres, 0.01, -1, nil, 0, 10),
        err(sim.addParticleObject, sim.particle_spheres, 0.01, 1000, {2, 1, 0.2}, 0, 10),
        err(sim.addParticleObject, sim.particle_spheres, 0.01, 1000, nil, -1, 10),
        err(sim.addParticleObjectItem, jet, {0, 0, 0, 1, 0, 0}),
        err(sim.addParticleObjectItem, jet, {0, 0, 0, 1, 0, 0, 1, 'red', 0}),
        err(sim.addParticleObjectItem, box, {0, 0, 0, 1, 0, 0}),
        err(sim.removeParticleObject, jet + 1),
    }
end
"#;
    let mut sc = probe("particles-bad", body);
    let r = sc.call("errors", &[]);
    let Value::Array(errors) = &r[0] else { panic!("{r:?}") };
    let expected: [&[&str]; 9] = [
        &["unknown particle object type 7", "sim.addParticleObject"],
        &["argument 2", "size"],
        &["argument 3", "density"],
        &["argument 4", "2 (id, value) pairs"],
        &["argument 5", "lifetime"],
        &["take 9 numbers", "r, g, b", "sim.addParticleObjectItem"],
        &["element 8", "number"],
        &["particle object does not exist"],
        &["particle object does not exist", "sim.removeParticleObject"],
    ];
    assert_eq!(errors.len(), expected.len(), "{errors:?}");
    for (e, parts) in errors.iter().zip(expected) {
        assert_contains(text(e), parts);
    }
    assert_running(&sc.sim, "probe.lua");
    // Particle objects exist only while the simulation runs.
    sc.sim.stop();
    let stopped = sc
        .sim
        .call(
            "addParticleObject",
            &[
                Value::Int(4),
                Value::Float(0.01),
                Value::Float(1000.0),
                Value::Nil,
                Value::Float(0.0),
                Value::Int(10),
            ],
        )
        .expect_err("refused while stopped");
    assert_contains(stopped, &["simulation is not running"]);
}

/// The quadcopter and propeller models' calls, with V-REP 3's global names: a cyclic,
/// weightless down-wash of 50 particles at most, with `params` setting restitution
/// (id 1) and ODE's soft ERP (id 3, ignored).
#[test]
fn the_propeller_models_calls_run_unmodified() {
    let body = r#"
function sysCall_init()
    local t = sim_particle_roughspheres + sim_particle_cyclic + sim_particle_respondable1to4
        + sim_particle_respondable5to8 + sim_particle_ignoresgravity
    wash = simAddParticleObject(t, 0.005, 8500, {2, 1, 0.2, 3, 0.4}, 0.5, 50, {0.3, 0.7, 1})
end
function sysCall_actuation()
    for i = 1, 20 do
        local x = (i - 10) * 0.01
        simAddParticleObjectItem(wash, {x, 0, 1, x, 0, 0.5})
    end
end
"#;
    let mut sc = probe("particles-propeller", body);
    for _ in 0..5 {
        sc.sim.step();
    }
    assert_running(&sc.sim, "probe.lua");
    let core = sc.sim.core();
    let (h, o) = core.particles.iter().next().expect("the down-wash exists");
    assert_eq!(o.material().restitution, 0.2);
    assert_eq!(o.item_count(), 50, "cyclic: the newest 50 of 100 emitted");
    // Weightless and touching nothing: every particle still falls at 0.5 m/s.
    let v = core.particles.velocities(&core.world, h).expect("wash");
    assert!(v.iter().all(|v| (v.z + 0.5).abs() < 1e-3), "{v:?}");
}
