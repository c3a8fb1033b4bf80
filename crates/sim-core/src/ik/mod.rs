//! Inverse kinematics (`simIK`): environments, groups of base/tip/target elements, and a
//! damped-least-squares solver over the scene's joints.
//!
//! CoppeliaSim's `simIK` keeps a separate *IK world* that mirrors the scene and must be
//! synchronised by hand (`syncFromSim`/`syncToSim`, or `handleGroup{syncWorlds=true}`).
//! gantry has no such copy: an element's chain is the scene's own tree path from the tip up
//! to the base, and every solve starts from the joint values the scene holds *now*. This
//! deliberately fixes the quirk of the paper's script (reference §1.5), whose IK world was
//! never resynchronised, so an IK command after FK commands started from a stale
//! configuration. What remains of the IK world is [`IkEnvironment::pending`]: a solution
//! computed with `syncWorlds=false` waits there until `syncToSim` writes it to the scene.
//!
//! Layout: `environment` holds the handles and settings, `chain` snapshots a base→tip path
//! into pure data (forward kinematics, analytic Jacobian, errors), `solver` iterates on that
//! snapshot, and this file ties them to the [`World`]. Non-goals: spherical joints, joint
//! dependencies, joint IK weights and the `getConfigForTipPose`/`generatePath` family.

mod chain;
mod environment;
mod solver;

use std::collections::BTreeMap;

pub use chain::{
    ChainPose, Distance, ElementChain, ElementModel, JointSlot, KinematicModel, Linearization, chain_path,
};
pub use environment::{Constraints, IkElement, IkEnvironment, IkEnvironments, IkError, IkGroup, IkMethod};
pub use solver::{
    CALC_CANNOT_INVERT, CALC_LIMIT_HIT, CALC_NOT_PERFORMED, CALC_NOT_WITHIN_TOLERANCE, IkResult, STOP_TOLERANCE,
    Solution, SolveParams, solve,
};

use crate::world::{Handle, World};

/// When a solve writes its joint values into the scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Apply {
    /// Never: the solution is kept in the environment ([`IkEnvironment::pending`]).
    Never,
    /// Only when every element ended within its precision (`handleGroup` with
    /// `syncWorlds=true`, CoppeliaSim's rule: no write-back on `calc_notwithintolerance`).
    OnSuccess,
    /// Whatever the outcome, as long as the values are finite (`allowError=true`, the
    /// legacy `handleIkGroup`, and `applyIkEnvironmentToScene` by default).
    Always,
}

/// The outcome of handling one or more groups.
#[derive(Debug, Clone, PartialEq)]
pub struct GroupsOutcome {
    /// The worst result over the groups (not performed < success < fail).
    pub result: IkResult,
    /// `simIK.calc_*` bits of every group, or-ed.
    pub flags: i64,
    /// Largest remaining linear (m) and angular (rad) distance over all elements.
    pub precision: [f64; 2],
    /// Solver steps summed over the groups.
    pub iterations: u32,
    /// Whether the solution was written into the scene.
    pub applied: bool,
    /// The solved joint values (rad or m) by joint handle.
    pub joints: BTreeMap<Handle, f64>,
}

/// Adds an element to `group` after checking it against the scene: base, tip and target
/// exist, the tip hangs below the base (`-1` = world), and at least one revolute or
/// prismatic joint lies between. Returns the element handle and the scene objects of the
/// path (base, the objects down to the tip, and the target), which `addElementFromScene`
/// reports as its identity "sim-to-IK" map.
///
/// # Errors
/// Unknown environment, group or object, a tip not below its base, or no joint between.
pub fn add_element_from_scene(
    world: &World,
    envs: &mut IkEnvironments,
    env: Handle,
    group: Handle,
    [base, tip, target]: [Handle; 3],
    constraints: Constraints,
) -> Result<(Handle, Vec<Handle>), IkError> {
    envs.get(env)?.group(group)?;
    world.object(target).map_err(|_| IkError::NoSuchObject {
        role: "target",
        handle: target,
    })?;
    let probe = IkElement {
        handle: 0,
        base,
        tip,
        target,
        constraints,
        precision: [0.0; 2],
        weights: [1.0; 3],
    };
    // Building the model runs every check the solver relies on.
    KinematicModel::from_world(world, std::slice::from_ref(&probe))?;
    let mut objects = chain_path(world, base, tip)?;
    if base != -1 {
        objects.insert(0, base);
    }
    if !objects.contains(&target) {
        objects.push(target);
    }
    let handle = envs.get_mut(env)?.add_element(group, base, tip, target, constraints)?;
    Ok((handle, objects))
}

/// Solves `groups` of environment `env` in order, each from the scene's current joint
/// values (with the solutions of the groups before it in effect), and writes the result to
/// the scene according to `apply`. When it is not written, the scene is left exactly as it
/// was and the solution is stored in the environment's [`IkEnvironment::pending`].
///
/// # Errors
/// Unknown environment or group, or an element whose objects no longer form a chain.
pub fn handle_groups(
    world: &mut World,
    envs: &mut IkEnvironments,
    env: Handle,
    groups: &[Handle],
    apply: Apply,
) -> Result<GroupsOutcome, IkError> {
    // Resolve everything before touching the scene, so an error leaves it unchanged.
    let environment = envs.get(env)?;
    let configs: Vec<IkGroup> = groups
        .iter()
        .map(|&g| environment.group(g).cloned())
        .collect::<Result<_, _>>()?;
    let mut outcome = GroupsOutcome {
        result: IkResult::NotPerformed,
        flags: 0,
        precision: [0.0; 2],
        iterations: 0,
        applied: false,
        joints: BTreeMap::new(),
    };
    if configs.is_empty() {
        outcome.flags = CALC_NOT_PERFORMED | CALC_NOT_WITHIN_TOLERANCE;
        return Ok(outcome);
    }
    // Scene values overwritten while later groups are solved, restored if not applied.
    let mut original: BTreeMap<Handle, f64> = BTreeMap::new();
    let mut failure = None;
    for (i, g) in configs.iter().enumerate() {
        let model = match KinematicModel::from_world(world, &g.elements) {
            Ok(m) => m,
            Err(e) => {
                failure = Some(e);
                break;
            }
        };
        let sol = solve(
            &model,
            &SolveParams {
                method: g.method,
                damping: g.damping,
                max_iterations: g.max_iterations,
            },
        );
        outcome.result = worse(outcome.result, sol.result);
        outcome.flags |= sol.flags;
        outcome.precision = [
            outcome.precision[0].max(sol.precision[0]),
            outcome.precision[1].max(sol.precision[1]),
        ];
        outcome.iterations += sol.iterations;
        for (slot, &q) in model.slots.iter().zip(&sol.q) {
            outcome.joints.insert(slot.handle, q);
        }
        if i + 1 < configs.len() {
            // A later group may hang below, or share joints with, this one: let it start
            // from this group's solution.
            for (slot, &q) in model.slots.iter().zip(&sol.q) {
                if let Ok(j) = world.joint(slot.handle) {
                    original.entry(slot.handle).or_insert(j.position);
                }
                // Values come from the solver, finite and within limits: cannot fail.
                let _ = world.set_joint_position(slot.handle, q);
            }
        }
    }
    let write = failure.is_none()
        && match apply {
            Apply::Never => false,
            Apply::OnSuccess => outcome.flags & CALC_NOT_WITHIN_TOLERANCE == 0,
            Apply::Always => outcome.joints.values().all(|q| q.is_finite()),
        };
    if write {
        for (&h, &q) in &outcome.joints {
            let _ = world.set_joint_position(h, q);
        }
    } else {
        for (&h, &q) in &original {
            let _ = world.set_joint_position(h, q);
        }
    }
    if let Some(e) = failure {
        return Err(e);
    }
    outcome.applied = write;
    let pending = &mut envs.get_mut(env)?.pending;
    for (&h, &q) in &outcome.joints {
        if write {
            pending.remove(&h);
        } else {
            pending.insert(h, q);
        }
    }
    Ok(outcome)
}

/// Searches for a configuration that puts every element of `group` within its precision,
/// for targets a local solve cannot reach from the current configuration (another branch
/// of the arm, or a path blocked by joint limits). The first attempt starts from the scene;
/// the others from pseudo-random configurations within the limits, drawn from a fixed seed
/// so the search is deterministic. Each attempt is a full solve with the group's settings.
/// The scene is not modified. Returns the joint values by handle, or `None` when no attempt
/// succeeded.
///
/// # Errors
/// Unknown environment or group, or an element that no longer forms a chain.
pub fn find_config(
    world: &World,
    envs: &IkEnvironments,
    env: Handle,
    group: Handle,
    attempts: u32,
) -> Result<Option<BTreeMap<Handle, f64>>, IkError> {
    let g = envs.get(env)?.group(group)?;
    let mut model = KinematicModel::from_world(world, &g.elements)?;
    let params = SolveParams {
        method: g.method,
        damping: g.damping,
        max_iterations: g.max_iterations,
    };
    let mut rng = SplitMix64(0x6a09_e667_f3bc_c908);
    let current = model.start.clone();
    for k in 0..attempts {
        if k > 0 {
            for ((s, slot), &q0) in model.start.iter_mut().zip(&model.slots).zip(&current) {
                let (lo, hi) = match (slot.cyclic, slot.limits) {
                    (true, _) => (-std::f64::consts::PI, std::f64::consts::PI),
                    (false, Some(l)) => l,
                    // Unlimited: a turn (rad) or a metre (m) either side of the current value.
                    (false, None) => (q0 - std::f64::consts::PI, q0 + std::f64::consts::PI),
                };
                *s = slot.constrain(lo + (hi - lo) * rng.next_unit());
            }
        }
        let sol = solve(&model, &params);
        if sol.result == IkResult::Success {
            return Ok(Some(model.slots.iter().map(|s| s.handle).zip(sol.q).collect()));
        }
    }
    Ok(None)
}

/// A tiny deterministic generator for [`find_config`]'s restarts (splitmix64): gantry's
/// runs must be reproducible, so no OS randomness.
struct SplitMix64(u64);

impl SplitMix64 {
    /// A uniform number in [0, 1).
    fn next_unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        // The top 53 bits make an exactly representable fraction.
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Writes the pending solutions of `groups`' joints into the scene (`simIK.syncToSim`).
///
/// # Errors
/// Unknown environment or group.
pub fn sync_to_scene(
    world: &mut World,
    envs: &mut IkEnvironments,
    env: Handle,
    groups: &[Handle],
) -> Result<(), IkError> {
    let joints = group_joints(world, envs, env, groups)?;
    let environment = envs.get_mut(env)?;
    let values: Vec<(Handle, f64)> = joints
        .into_iter()
        .filter_map(|h| environment.pending.remove(&h).map(|q| (h, q)))
        .collect();
    for (h, q) in values {
        let _ = world.set_joint_position(h, q);
    }
    Ok(())
}

/// Forgets the pending solutions of `groups`' joints, so the IK world equals the scene
/// again (`simIK.syncFromSim`).
///
/// # Errors
/// Unknown environment or group.
pub fn sync_from_scene(
    world: &World,
    envs: &mut IkEnvironments,
    env: Handle,
    groups: &[Handle],
) -> Result<(), IkError> {
    let joints = group_joints(world, envs, env, groups)?;
    let environment = envs.get_mut(env)?;
    for h in joints {
        environment.pending.remove(&h);
    }
    Ok(())
}

/// The movable joints of every element of `groups` (duplicates removed, scene order kept).
fn group_joints(world: &World, envs: &IkEnvironments, env: Handle, groups: &[Handle]) -> Result<Vec<Handle>, IkError> {
    let environment = envs.get(env)?;
    let mut out = Vec::new();
    for &g in groups {
        let elements = &environment.group(g)?.elements;
        // A chain broken since (impossible today: the tree is fixed) just contributes nothing.
        if let Ok(model) = KinematicModel::from_world(world, elements) {
            for s in model.slots {
                if !out.contains(&s.handle) {
                    out.push(s.handle);
                }
            }
        }
    }
    Ok(out)
}

/// The result that wins when several groups are handled together.
fn worse(a: IkResult, b: IkResult) -> IkResult {
    let rank = |r| match r {
        IkResult::NotPerformed => 0,
        IkResult::Success => 1,
        IkResult::Fail => 2,
    };
    if rank(b) > rank(a) { b } else { a }
}
