//! Reading a group's chains out of their trees into a [`KinematicModel`], the pure
//! snapshot the solver iterates on (`gantry-ik`): every rigid part of a base→tip path
//! (links, dummies, fixed joints) folds into one constant transform per movable joint.

use gantry_ik::{ElementChain, ElementModel, ElementTarget, IkElement, IkError, JointSlot, KinematicModel};

use super::trees::{JointView, Trees};
use crate::handle::Handle;
use crate::math::Pose;

/// Snapshots the chains and targets of `elements` from their trees (the scene, or the
/// environment's own objects), reading the joints' current values: a scene solve
/// starts from the scene as it is now, an own-object solve from the environment's
/// joints.
///
/// # Errors
/// Unknown base, tip or target, a tip not below its base, a path without a movable
/// joint, or a tip whose target is its linked dummy and that has none.
pub fn build_model(trees: &Trees<'_>, elements: &[IkElement]) -> Result<KinematicModel, IkError> {
    let mut model = KinematicModel {
        slots: Vec::new(),
        start: Vec::new(),
        elements: Vec::with_capacity(elements.len()),
    };
    for e in elements {
        let chain = add_chain(&mut model, trees, e.base, e.tip)?;
        let target = match e.target {
            ElementTarget::Object(t) => t,
            ElementTarget::LinkedDummy => trees.linked_dummy(e.tip)?.ok_or(IkError::NoTarget { tip: e.tip })?,
        };
        let target = trees.world(target, "target")?;
        model.elements.push(ElementModel {
            chain,
            target,
            constraints: e.constraints,
            precision: e.precision,
            weights: e.weights,
        });
    }
    Ok(model)
}

/// The chain from `base` to `tip`, its movable joints added to `model`'s slots.
fn add_chain(
    model: &mut KinematicModel,
    trees: &Trees<'_>,
    base: Handle,
    tip: Handle,
) -> Result<ElementChain, IkError> {
    let path = chain_path(trees, base, tip)?;
    let top = path.first().copied().unwrap_or(tip);
    let mut acc = trees.parent_frame(top)?;
    let mut links = Vec::new();
    for &h in &path {
        let node = trees.node(h, "chain")?;
        acc *= node.local;
        if h == tip {
            break;
        }
        match node.joint {
            Some(j) if j.movable => {
                let slot = slot_of(model, h, &j);
                links.push((acc, slot));
                acc = Pose::identity();
            }
            // A joint the solver may not move is a rigid link at its position.
            Some(j) => acc *= j.motion(),
            None => {}
        }
    }
    if links.is_empty() {
        return Err(IkError::NoJoints { tip, base });
    }
    let base_frame = if base == -1 {
        Pose::identity()
    } else {
        trees.world(base, "base")?
    };
    Ok(ElementChain::new(links, acc, base_frame))
}

/// The slot of joint `handle` in `model`, added (with its current value) on first use.
fn slot_of(model: &mut KinematicModel, handle: Handle, j: &JointView) -> usize {
    if let Some(i) = model.slots.iter().position(|s| s.handle == handle) {
        return i;
    }
    model.slots.push(JointSlot {
        handle,
        joint_type: j.joint_type,
        cyclic: j.cyclic,
        limits: j.limits,
    });
    model.start.push(j.position);
    model.slots.len() - 1
}

/// The objects from just below `base` down to `tip` (inclusive), top first. Both live in
/// the same tree: the scene's, or the environment's own.
///
/// # Errors
/// Unknown base or tip, `tip == base`, or a tip not below the base.
pub fn chain_path(trees: &Trees<'_>, base: Handle, tip: Handle) -> Result<Vec<Handle>, IkError> {
    trees.node(tip, "tip")?;
    if base != -1 {
        trees.node(base, "base")?;
    }
    let mut path = vec![tip];
    let mut cur = tip;
    // No tree has more levels than objects; the bound guards against a corrupt cycle.
    for _ in 0..=trees.depth_bound() {
        match trees.node(cur, "chain")?.parent {
            Some(p) if p == base => {
                path.reverse();
                return Ok(path);
            }
            Some(p) => {
                path.push(p);
                cur = p;
            }
            None if base == -1 => {
                path.reverse();
                return Ok(path);
            }
            None => break,
        }
    }
    Err(IkError::TipNotBelowBase { tip, base })
}
