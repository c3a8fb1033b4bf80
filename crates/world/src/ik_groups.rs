//! The scene's own IK groups: V-REP 3 / CoppeliaSim 4.0-4.2's built-in kinematics, set up
//! in the scene (`[[ik_group]]` in gantry's scene files) and reached by handle
//! (`sim.getIkGroupHandle`, `sim.handleIkGroup`, ...).
//!
//! Each group is backed by a group of one private `simIK` environment whose elements are
//! made from the scene, as `simIK.addElementFromScene` makes them: handling one solves
//! with the same solver and writes the joints back, as `applyIkEnvironmentToScene` does.
//! Groups not flagged explicit are handled by the main script every step
//! ([`SceneIkGroups::handle_automatic`]). Handles start at [`FIRST_GROUP`], CoppeliaSim's
//! range for IK groups, so that they never name a scene object.

use std::collections::BTreeMap;

use nalgebra::DMatrix;

use crate::handle::Handle;
use crate::ik::{
    Apply, ConfigSearch, Constraints, ElementTarget, IkElement, IkEnvironments, IkError, IkGroup, IkMethod, IkResult,
    KinematicModel, SolveParams, Trees, build_model, find_config, handle_groups, solve,
};
use crate::math::Pose;
use crate::scene::{IkGroupModel, IkMethodModel};
use crate::world::World;

/// The handle of a scene's first IK group; the others follow in file order.
pub const FIRST_GROUP: Handle = 2_030_000;

/// The fewest solver iterations a scene group gets per handling, whatever it asks for.
/// CoppeliaSim's arms ask for 3 to 6, enough for its full Newton steps; gantry's solver
/// caps each step (the error it aims at, and 10° per joint: see the solver), so from a
/// singular pose (PyRep's UR10 saved stretched straight up at all zeros) 6 iterations
/// leave the tip where it was while 20 reach a target a few centimetres away. Iterations
/// stop as soon as the tips are on their targets, so the floor costs nothing then. A
/// script's `sim.setIkGroupProperties` sets the number exactly.
pub const MIN_ITERATIONS: u32 = 20;

/// Most solves [`SceneIkGroups::linear_path`] runs for one point of the path.
pub const PATH_SOLVES_PER_POINT: usize = 5;

/// A path of configurations ([`SceneIkGroups::linear_path`]).
#[derive(Debug, Clone, PartialEq)]
pub struct IkPath {
    /// The joints of the group's chains, base to tip.
    pub joints: Vec<Handle>,
    /// One configuration per point: a value per joint of `joints`.
    pub configs: Vec<Vec<f64>>,
}

/// The pose a fraction `s` of the way from `a` to `b`: positions on the straight line,
/// orientations by slerp (half-turn apart, where slerp has no single path, `a`'s until
/// halfway then `b`'s).
fn interpolate(a: &Pose, b: &Pose, s: f64) -> Pose {
    let t = a.translation.vector.lerp(&b.translation.vector, s);
    let r = a
        .rotation
        .try_slerp(&b.rotation, s, 1e-9)
        .unwrap_or(if s < 0.5 { a.rotation } else { b.rotation });
    Pose::from_parts(t.into(), r)
}

/// One IK group of the scene.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneIkGroup {
    /// Its handle.
    pub handle: Handle,
    /// Its name (`sim.getIkGroupHandle`).
    pub name: String,
    /// Whether only `sim.handleIkGroup` on this group solves it.
    pub explicit: bool,
    /// The backing group in [`SceneIkGroups`]' environment.
    group: Handle,
}

/// Every IK group of the scene.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SceneIkGroups {
    envs: IkEnvironments,
    env: Handle,
    groups: Vec<SceneIkGroup>,
}

impl SceneIkGroups {
    /// The scene's groups, with their elements made from the scene's objects. A chain that
    /// cannot be solved (a tip not below its base, no joint between) is kept as written:
    /// handling its group fails with the reason, as in CoppeliaSim.
    pub fn build(models: &[IkGroupModel]) -> Self {
        let mut envs = IkEnvironments::default();
        let env = envs.create();
        let mut groups = Self {
            envs,
            env,
            groups: Vec::new(),
        };
        // At load, an object's handle is its index in the model.
        groups.add(models, |i| Some(i as Handle));
        groups
    }

    /// Adds the groups of a model imported into the scene (`sim.loadModel`), its objects
    /// at the handles `handle_of` gives for their model indices. A name the scene has
    /// already gets CoppeliaSim's copy suffix (`Panda_ik#0`, `#1`, ...), as the copied
    /// objects' names do. An element whose object did not make it into the scene is
    /// left out.
    pub fn add(&mut self, models: &[IkGroupModel], handle_of: impl Fn(usize) -> Option<Handle>) {
        for m in models {
            let name = self.free_name(&m.name);
            let Ok(environment) = self.envs.get_mut(self.env) else {
                break;
            };
            let group = environment.create_group(&name);
            if let Ok(g) = environment.group_mut(group) {
                g.method = match m.method {
                    IkMethodModel::PseudoInverse => IkMethod::PseudoInverse,
                    IkMethodModel::DampedLeastSquares => IkMethod::DampedLeastSquares,
                };
                g.damping = m.damping;
                g.max_iterations = m.max_iterations.max(MIN_ITERATIONS);
            }
            for e in &m.elements {
                let (Some(tip), Some(target)) = (handle_of(e.tip), handle_of(e.target)) else {
                    continue;
                };
                let base = match e.base {
                    Some(b) => match handle_of(b) {
                        Some(h) => h,
                        None => continue,
                    },
                    None => -1,
                };
                let constraints = Constraints::from_code(i64::from(e.constraints)).unwrap_or(Constraints::POSE);
                // The group was just created.
                let _ = environment.add_element(group, base, tip, ElementTarget::Object(target), constraints);
            }
            let handle = FIRST_GROUP + self.groups.len() as Handle;
            self.groups.push(SceneIkGroup {
                handle,
                name,
                explicit: m.explicit,
                group,
            });
        }
    }

    /// `name`, or the first of `name#0`, `name#1`, ... no group has.
    fn free_name(&self, name: &str) -> String {
        if self.by_name(name).is_none() {
            return name.to_owned();
        }
        (0..)
            .map(|k| format!("{name}#{k}"))
            .find(|n| self.by_name(n).is_none())
            .unwrap_or_else(|| name.to_owned())
    }

    /// Every group, in handle order.
    pub fn iter(&self) -> impl Iterator<Item = &SceneIkGroup> {
        self.groups.iter()
    }

    /// The group named `name`.
    pub fn by_name(&self, name: &str) -> Option<&SceneIkGroup> {
        self.groups.iter().find(|g| g.name == name)
    }

    /// The group behind a handle.
    pub fn get(&self, handle: Handle) -> Option<&SceneIkGroup> {
        self.groups.iter().find(|g| g.handle == handle)
    }

    /// Sets whether only `sim.handleIkGroup` on the group solves it. Returns `false` when
    /// `handle` names no group.
    pub fn set_explicit(&mut self, handle: Handle, explicit: bool) -> bool {
        match self.groups.iter_mut().find(|g| g.handle == handle) {
            Some(g) => {
                g.explicit = explicit;
                true
            }
            None => false,
        }
    }

    /// The group's calculation settings and elements. `None` when `handle` names no group.
    pub fn settings_mut(&mut self, handle: Handle) -> Option<&mut IkGroup> {
        let group = self.get(handle)?.group;
        self.envs.get_mut(self.env).ok()?.group_mut(group).ok()
    }

    /// The group's calculation settings and elements. `None` when `handle` names no group.
    pub fn settings(&self, handle: Handle) -> Option<&IkGroup> {
        let group = self.get(handle)?.group;
        self.envs.get(self.env).ok()?.group(group).ok()
    }

    /// The element of the group whose tip is `tip`.
    pub fn element_mut(&mut self, handle: Handle, tip: Handle) -> Option<&mut IkElement> {
        self.settings_mut(handle)?.elements.iter_mut().find(|e| e.tip == tip)
    }

    /// Solves the group from the scene's joint values and writes the solution into the
    /// scene whatever the result (finite values within the joints' limits), as
    /// CoppeliaSim's built-in IK does.
    ///
    /// # Errors
    /// No such group ([`IkError::NoSuchGroup`]), or a chain that does not exist any more.
    pub fn handle(&mut self, world: &mut World, handle: Handle) -> Result<IkResult, IkError> {
        let group = self.get(handle).ok_or(IkError::NoSuchGroup(handle))?.group;
        let outcome = handle_groups(world, &mut self.envs, self.env, &[group], Apply::Always)?;
        Ok(outcome.result)
    }

    /// Solves the group from the scene's joint values as [`Self::handle`] does, without
    /// writing anything into the scene (`sim.checkIkGroup`): the result and the solved
    /// values of the chains' joints, by handle.
    ///
    /// # Errors
    /// No such group, or a chain that does not exist any more.
    pub fn check(&mut self, world: &mut World, handle: Handle) -> Result<(IkResult, BTreeMap<Handle, f64>), IkError> {
        let group = self.get(handle).ok_or(IkError::NoSuchGroup(handle))?.group;
        // One group: `handle_groups` writes no scene joint when told not to apply.
        let outcome = handle_groups(world, &mut self.envs, self.env, &[group], Apply::Never)?;
        // The solution is not waiting for a sync: this environment has none.
        self.envs.get_mut(self.env)?.pending.clear();
        Ok((outcome.result, outcome.joints))
    }

    /// Configurations that move every tip of the group along a straight line (and a
    /// slerp of its orientation) from where it is to its target, in `points` evenly spaced
    /// poses, the first being the current configuration (`sim.generateIkPath`). Each point
    /// is solved from the previous one with the group's settings, up to
    /// [`PATH_SOLVES_PER_POINT`] times (gantry's solver steps are shorter than
    /// CoppeliaSim's, see the solver's `MAX_ERROR`). Returns `None` when a point cannot be
    /// reached within the elements' precision. The scene is not touched: the values are
    /// by model slot, with the slots' joint handles.
    ///
    /// # Errors
    /// No such group, or a chain that cannot be built.
    pub fn linear_path(&self, world: &World, handle: Handle, points: usize) -> Result<Option<IkPath>, IkError> {
        let mut model = self.model(world, handle)?;
        let g = self.settings(handle).ok_or(IkError::NoSuchGroup(handle))?;
        let params = SolveParams {
            method: g.method,
            damping: g.damping,
            max_iterations: g.max_iterations,
        };
        let starts: Vec<Pose> = model
            .elements
            .iter()
            .map(|e| e.chain.forward(&model.start, &model.slots).tip)
            .collect();
        let goals: Vec<Pose> = model.elements.iter().map(|e| e.target).collect();
        let mut configs = vec![model.start.clone()];
        for i in 1..points {
            let s = i as f64 / (points - 1) as f64;
            for ((e, a), b) in model.elements.iter_mut().zip(&starts).zip(&goals) {
                e.target = interpolate(a, b, s);
            }
            let mut reached = false;
            for _ in 0..PATH_SOLVES_PER_POINT {
                let sol = solve(&model, &params);
                model.start = sol.q;
                if sol.result == IkResult::Success {
                    reached = true;
                    break;
                }
            }
            if !reached {
                return Ok(None);
            }
            configs.push(model.start.clone());
        }
        Ok(Some(IkPath {
            joints: model.slots.iter().map(|s| s.handle).collect(),
            configs,
        }))
    }

    /// Handles every group not flagged explicit, in handle order, as the main script's
    /// `sim.handleIkGroup(sim.handle_all_except_explicit)` does each step. Returns how
    /// many were performed; a group whose chain cannot be solved is skipped.
    pub fn handle_automatic(&mut self, world: &mut World) -> usize {
        let automatic: Vec<Handle> = self.groups.iter().filter(|g| !g.explicit).map(|g| g.handle).collect();
        automatic
            .into_iter()
            .filter(|&h| matches!(self.handle(world, h), Ok(r) if r != IkResult::NotPerformed))
            .count()
    }

    /// The group's Jacobian at the scene's current joint values: one row per constrained
    /// component of each element (x, y, z in the base frame, then the angular rows), one
    /// column per joint of the chains, base to tip.
    ///
    /// # Errors
    /// No such group, or a chain that cannot be built.
    pub fn jacobian(&self, world: &World, handle: Handle) -> Result<DMatrix<f64>, IkError> {
        let model = self.model(world, handle)?;
        let blocks: Vec<DMatrix<f64>> = model
            .elements
            .iter()
            .map(|e| e.linearize(&model.start, &model.slots).jacobian)
            .collect();
        let rows = blocks.iter().map(DMatrix::nrows).sum();
        let mut j = DMatrix::zeros(rows, model.slots.len());
        let mut r = 0;
        for b in blocks {
            j.view_mut((r, 0), (b.nrows(), b.ncols())).copy_from(&b);
            r += b.nrows();
        }
        Ok(j)
    }

    /// Searches a configuration putting the group's tips on their targets without moving
    /// the scene (see [`find_config`]).
    ///
    /// # Errors
    /// No such group, or a chain that cannot be built.
    pub fn find_config(
        &self,
        world: &World,
        handle: Handle,
        search: &ConfigSearch,
    ) -> Result<Option<BTreeMap<Handle, f64>>, IkError> {
        let group = self.get(handle).ok_or(IkError::NoSuchGroup(handle))?.group;
        find_config(world, &self.envs, self.env, group, search)
    }

    /// The group's problem as the solver sees it now.
    fn model(&self, world: &World, handle: Handle) -> Result<KinematicModel, IkError> {
        let group = self.get(handle).ok_or(IkError::NoSuchGroup(handle))?.group;
        let environment = self.envs.get(self.env)?;
        let g = environment.group(group)?;
        build_model(&Trees::new(world, &environment.objects), &g.elements)
    }
}
