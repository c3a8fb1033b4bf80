//! Inverse kinematics (`simIK`): environments, groups of base/tip/target elements, and a
//! damped-least-squares solver over the joints of their chains.
//!
//! CoppeliaSim's `simIK` keeps a separate *IK world* that mirrors the scene and must be
//! synchronised by hand (`syncFromSim`/`syncToSim`, or `handleGroup{syncWorlds=true}`).
//! gantry's elements come in two kinds:
//!
//! * elements made from the scene (`addElementFromScene`) have no copy: their chain is the
//!   scene's own tree path from the tip up to the base, and every solve starts from the
//!   joint values the scene holds *now*. This deliberately fixes the quirk of the paper's
//!   script (reference §1.5), whose IK world was never resynchronised, so an IK command
//!   after FK commands started from a stale configuration. What remains of the IK world
//!   is [`IkEnvironment::pending`]: a solution computed with `syncWorlds=false` waits
//!   there until `syncToSim` writes it to the scene;
//! * elements on the environment's own objects (built one by one with `createDummy`,
//!   `createJoint`, `setObjectParent`, ..., then `addElement`; CoppeliaSim 4.2-4.5 scripts)
//!   live in that tree (`objects`), which is the IK world: solves read and write its
//!   joints, and a script copies values to the scene itself.
//!
//! Layout: the environments, their own objects, the chain snapshot (forward kinematics,
//! analytic Jacobian, errors) and the solver that iterates on it need no scene, and are
//! the crate `gantry-ik`, re-exported here. This module is what reads the scene: `trees`
//! reads either tree, `snapshot` folds a base→tip path of one into the solver's pure
//! data, and this file ties environments, groups and solves to the scene (solving,
//! writing solutions back, syncing). `crate::ik_groups` keeps the scene's own IK groups
//! (the built-in kinematics of V-REP 3 and CoppeliaSim 4.0-4.2) on this machinery.
//! Non-goals: spherical joints, joint dependencies, joint IK weights and the
//! `generatePath` family.

mod snapshot;
mod trees;

use std::collections::BTreeMap;

pub use gantry_ik::*;
pub use snapshot::{build_model, chain_path};
pub use trees::{JointView, NodeView, Trees};

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
    let environment = envs.get(env)?;
    environment.group(group)?;
    // Scene objects only: the environment's own objects are added with `add_element`.
    for (role, h) in [("base", base), ("tip", tip), ("target", target)] {
        if is_own_object(h) {
            return Err(IkError::BadArgument(format!(
                "{role} {h} is an object of the IK environment, not of the scene (use simIK.addElement for those)"
            )));
        }
    }
    let trees = Trees::new(world, &environment.objects);
    trees.world(target, "target")?;
    let probe = IkElement {
        handle: 0,
        base,
        tip,
        target: ElementTarget::Object(target),
        constraints,
        precision: [0.0; 2],
        weights: [1.0; 3],
    };
    // Building the model runs every check the solver relies on.
    build_model(&trees, std::slice::from_ref(&probe))?;
    let mut objects = chain_path(&trees, base, tip)?;
    if base != -1 {
        objects.insert(0, base);
    }
    if !objects.contains(&target) {
        objects.push(target);
    }
    let handle = envs
        .get_mut(env)?
        .add_element(group, base, tip, ElementTarget::Object(target), constraints)?;
    Ok((handle, objects))
}

/// Adds an element whose tip is dummy `tip` (`simIK.addElement`, 4.2 `addIkElement`): its
/// base is the world until `setElementBase`, its target is whatever dummy the tip is
/// linked to when the group is solved, and it constrains the full pose. The tip is one of
/// the environment's own dummies or a scene dummy.
///
/// # Errors
/// Unknown environment, group or tip, or a tip that is not a dummy.
pub fn add_element(
    world: &World,
    envs: &mut IkEnvironments,
    env: Handle,
    group: Handle,
    tip: Handle,
) -> Result<Handle, IkError> {
    let environment = envs.get(env)?;
    environment.group(group)?;
    let is_dummy = if is_own_object(tip) {
        matches!(environment.objects.get(tip)?.kind, IkObjectKind::Dummy { .. })
    } else {
        let o = world.object(tip).map_err(|_| IkError::NoSuchObject {
            role: "tip",
            handle: tip,
        })?;
        matches!(o.kind, crate::world::ObjectKind::Dummy)
    };
    if !is_dummy {
        return Err(IkError::WrongKind {
            handle: tip,
            expected: "dummy",
        });
    }
    envs.get_mut(env)?
        .add_element(group, -1, tip, ElementTarget::LinkedDummy, Constraints::POSE)
}

/// The joints of a group's chains (`simIK.getGroupJoints`): every joint between each
/// element's base and tip, top first, element by element, each once. They are scene
/// handles for elements built from the scene, the environment's own otherwise.
///
/// # Errors
/// Unknown environment or group, or an element whose objects no longer form a chain.
pub fn chain_joints(world: &World, envs: &IkEnvironments, env: Handle, group: Handle) -> Result<Vec<Handle>, IkError> {
    let environment = envs.get(env)?;
    let g = environment.group(group)?;
    let trees = Trees::new(world, &environment.objects);
    let mut joints = Vec::new();
    for e in &g.elements {
        for h in chain_path(&trees, e.base, e.tip)? {
            if trees.node(h, "chain")?.joint.is_some() && !joints.contains(&h) {
                joints.push(h);
            }
        }
    }
    Ok(joints)
}

/// Checks that `base` (`-1`: the world) can be the base of an element tipped at `tip`:
/// both exist in the same tree, the tip hangs below the base, and a joint the solver may
/// move lies between.
///
/// # Errors
/// As [`chain_path`], or [`IkError::NoJoints`].
pub fn check_chain(trees: &Trees<'_>, base: Handle, tip: Handle) -> Result<(), IkError> {
    let path = chain_path(trees, base, tip)?;
    for &h in &path[..path.len().saturating_sub(1)] {
        if trees.node(h, "chain")?.joint.is_some_and(|j| j.movable) {
            return Ok(());
        }
    }
    Err(IkError::NoJoints { tip, base })
}

/// Solves `groups` of environment `env` in order, each from the current joint values (of
/// the scene for scene chains, of the environment's own joints for its own chains), with
/// the solutions of the groups before it in effect. A disabled group is skipped.
///
/// A group's solution is dropped, and its joints keep the values they had before it, when
/// it could not be computed, or when its flags ask for it (`group_restoreonbadlintol`,
/// `group_restoreonbadangtol`) and it ended outside its precision, as in CoppeliaSim.
/// Otherwise the environment's own joints take it at once (they are the IK world), and
/// scene joints according to `apply`; when not written, the scene is left exactly as it
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
    // Resolve everything before touching a tree, so an error leaves them unchanged.
    let environment = envs.get_mut(env)?;
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
    let enabled: Vec<&IkGroup> = configs
        .iter()
        .filter(|g| g.flags.contains(GroupFlags::ENABLED))
        .collect();
    if enabled.is_empty() {
        outcome.flags = CALC_NOT_PERFORMED | CALC_NOT_WITHIN_TOLERANCE;
        return Ok(outcome);
    }
    // Scene values overwritten while later groups are solved, restored if not applied.
    let mut original: BTreeMap<Handle, f64> = BTreeMap::new();
    // The environment's own joints as they were, restored if a group fails to build.
    let own_before = environment.objects.clone();
    let mut failure = None;
    for (i, g) in enabled.iter().enumerate() {
        let model = match build_model(&Trees::new(world, &environment.objects), &g.elements) {
            Ok(m) => m,
            Err(e) => {
                failure = Some(e);
                break;
            }
        };
        let mut sol = solve(
            &model,
            &SolveParams {
                method: g.method,
                damping: g.damping,
                max_iterations: g.max_iterations,
            },
        );
        if restores(g.flags, &model, &sol) {
            sol.q.clone_from(&model.start);
        }
        outcome.result = worse(outcome.result, sol.result);
        outcome.flags |= sol.flags;
        outcome.precision = [
            outcome.precision[0].max(sol.precision[0]),
            outcome.precision[1].max(sol.precision[1]),
        ];
        outcome.iterations += sol.iterations;
        for (slot, &q) in model.slots.iter().zip(&sol.q) {
            outcome.joints.insert(slot.handle, q);
            if is_own_object(slot.handle) {
                // The IK world takes every computed solution; values come from the
                // solver, finite and within limits, for joints the model just read.
                let _ = environment.objects.set_joint_position(slot.handle, q);
            } else if i + 1 < enabled.len() {
                // A later group may hang below, or share joints with, this one: let it
                // start from this group's solution.
                if let Ok(j) = world.joint(slot.handle) {
                    original.entry(slot.handle).or_insert(j.position);
                }
                let _ = world.set_joint_position(slot.handle, q);
            }
        }
    }
    let scene_joints = || outcome.joints.iter().filter(|(h, _)| !is_own_object(**h));
    let write = failure.is_none()
        && match apply {
            Apply::Never => false,
            Apply::OnSuccess => outcome.flags & CALC_NOT_WITHIN_TOLERANCE == 0,
            Apply::Always => scene_joints().all(|(_, q)| q.is_finite()),
        };
    if write {
        for (&h, &q) in scene_joints() {
            let _ = world.set_joint_position(h, q);
        }
    } else {
        for (&h, &q) in &original {
            let _ = world.set_joint_position(h, q);
        }
    }
    if let Some(e) = failure {
        environment.objects = own_before;
        return Err(e);
    }
    outcome.applied = write;
    for (&h, &q) in scene_joints() {
        if write {
            environment.pending.remove(&h);
        } else {
            environment.pending.insert(h, q);
        }
    }
    Ok(outcome)
}

/// Whether a group's solution is dropped for the start configuration: it could not be
/// computed, or its flags ask for it and some element ended outside its linear (angular)
/// precision.
fn restores(flags: GroupFlags, model: &KinematicModel, sol: &Solution) -> bool {
    if sol.flags & CALC_CANNOT_INVERT != 0 {
        return true;
    }
    if sol.flags & CALC_NOT_WITHIN_TOLERANCE == 0 {
        return false;
    }
    let (mut bad_linear, mut bad_angular) = (false, false);
    for e in &model.elements {
        let d = e.linearize(&sol.q, &model.slots).distance;
        bad_linear |= d.linear > e.precision[0];
        bad_angular |= d.angular > e.precision[1];
    }
    (flags.contains(GroupFlags::RESTORE_ON_BAD_LINEAR) && bad_linear)
        || (flags.contains(GroupFlags::RESTORE_ON_BAD_ANGULAR) && bad_angular)
}

/// How [`find_config`] searches: a deterministic stand-in for CoppeliaSim's "sample
/// random configurations for so many milliseconds".
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConfigSearch {
    /// Random configurations drawn at most, after the current one.
    pub samples: u32,
    /// Solves run at most (the current configuration's included).
    pub solves: u32,
    /// Only configurations whose tips are within this distance of their targets (summed
    /// over the elements, see `metric`) are solved from; `None`: every one.
    pub threshold: Option<f64>,
    /// Weights of x, y, z (m, in each element's base frame) and of the angle (rad) in the
    /// distance: `sqrt((wx dx)² + (wy dy)² + (wz dz)² + (wa angle)²)`.
    pub metric: [f64; 4],
    /// Iterations each solve gets at least, whatever the group says. gantry's solver caps
    /// the error one step aims at (the solver's `MAX_ERROR`), so it needs more iterations
    /// than CoppeliaSim's full Newton steps to cover the same distance: a group set up
    /// for CoppeliaSim with 3 iterations would otherwise almost never converge from a
    /// sampled configuration.
    pub min_iterations: u32,
}

impl ConfigSearch {
    /// CoppeliaSim's default metric: metres count fully, radians a tenth.
    pub const DEFAULT_METRIC: [f64; 4] = [1.0, 1.0, 1.0, 0.1];

    /// A solve from the current configuration, then from up to `attempts - 1` random
    /// ones, with no distance filter (`simIK.findConfig`).
    pub fn attempts(attempts: u32) -> Self {
        Self {
            samples: attempts.saturating_sub(1),
            solves: attempts,
            threshold: None,
            metric: Self::DEFAULT_METRIC,
            min_iterations: 0,
        }
    }
}

/// Searches for a configuration that puts every element of `group` within its precision,
/// for targets a local solve cannot reach from the current configuration (another branch
/// of the arm, or a path blocked by joint limits). The first attempt starts from the
/// current joint values; the others from pseudo-random configurations within the limits,
/// drawn from a fixed seed so the search is deterministic, and (with a threshold) only
/// from those whose tips already lie near their targets, as CoppeliaSim's
/// `getConfigForTipPose` does. Each attempt is a full solve with the group's settings.
/// No joint is modified. Returns the joint values by handle, or `None` when no attempt
/// succeeded.
///
/// # Errors
/// Unknown environment or group, or an element that no longer forms a chain.
pub fn find_config(
    world: &World,
    envs: &IkEnvironments,
    env: Handle,
    group: Handle,
    search: &ConfigSearch,
) -> Result<Option<BTreeMap<Handle, f64>>, IkError> {
    let environment = envs.get(env)?;
    let g = environment.group(group)?;
    let mut model = build_model(&Trees::new(world, &environment.objects), &g.elements)?;
    let params = SolveParams {
        method: g.method,
        damping: g.damping,
        max_iterations: g.max_iterations.max(search.min_iterations),
    };
    let mut rng = SplitMix64(0x6a09_e667_f3bc_c908);
    let current = model.start.clone();
    let mut solves = 0;
    for k in 0..=search.samples {
        if solves >= search.solves {
            break;
        }
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
            if let Some(threshold) = search.threshold
                && metric_distance(&model, &search.metric) > threshold
            {
                continue;
            }
        }
        solves += 1;
        let sol = solve(&model, &params);
        if sol.result == IkResult::Success {
            return Ok(Some(model.slots.iter().map(|s| s.handle).zip(sol.q).collect()));
        }
    }
    Ok(None)
}

/// The distance of every tip from its target at the model's start configuration, summed
/// over the elements (see [`ConfigSearch::metric`]).
fn metric_distance(model: &KinematicModel, metric: &[f64; 4]) -> f64 {
    model
        .elements
        .iter()
        .map(|e| {
            let base = e.chain.base_frame().inverse();
            let tip = base * e.chain.forward(&model.start, &model.slots).tip;
            let target = base * e.target;
            let d = tip.translation.vector - target.translation.vector;
            let angle = tip.rotation.angle_to(&target.rotation);
            ((metric[0] * d.x).powi(2)
                + (metric[1] * d.y).powi(2)
                + (metric[2] * d.z).powi(2)
                + (metric[3] * angle).powi(2))
            .sqrt()
        })
        .sum()
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

/// The movable scene joints of every element of `groups` (duplicates removed, order of
/// first appearance kept); the environment's own joints have nothing pending.
fn group_joints(world: &World, envs: &IkEnvironments, env: Handle, groups: &[Handle]) -> Result<Vec<Handle>, IkError> {
    let environment = envs.get(env)?;
    let trees = Trees::new(world, &environment.objects);
    let mut out = Vec::new();
    for &g in groups {
        let elements = &environment.group(g)?.elements;
        // A chain broken since just contributes nothing.
        if let Ok(model) = build_model(&trees, elements) {
            for s in model.slots {
                if !is_own_object(s.handle) && !out.contains(&s.handle) {
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
