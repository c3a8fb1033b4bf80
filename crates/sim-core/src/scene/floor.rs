//! The floor gantry adds under what has none of its own: a bare URDF robot, a
//! CoppeliaSim model (`.ttm`), and a scene file's `[floor]` section.

use super::model::{
    GeomModel, Geometry, MassModel, ObjectModel, ObjectModelKind, ScriptModel, ShapeModel, VisualModel,
};
use crate::math::Pose;

/// Side of the floor under a bare robot or model, m.
const DEFAULT_SIDE: f64 = 5.0;

/// The floor: a static box whose top face is the plane z = 0. It is neither detectable
/// nor measurable, like CoppeliaSim's default floor, so sensors and distance queries see
/// obstacles rather than the ground.
pub(super) fn floor_object(size: [f64; 2], friction: f64, color: [f32; 3]) -> ObjectModel {
    let half = [size[0] / 2.0, size[1] / 2.0, 0.05];
    let geometry = Geometry::Box { half_extents: half };
    let local = Pose::translation(0.0, 0.0, -0.05);
    ObjectModel {
        alias: "Floor".into(),
        parent: None,
        local: Pose::identity(),
        model_base: true,
        kind: ObjectModelKind::Shape(ShapeModel {
            geoms: vec![GeomModel {
                geometry: geometry.clone(),
                local,
            }],
            visuals: vec![VisualModel { geometry, local, color }],
            dynamic: false,
            mass: MassModel::Density(1000.0),
            friction,
            restitution: 0.0,
            collision_group: u32::MAX,
            collision_mask: u32::MAX,
            respondable: true,
            detectable: false,
            measurable: false,
            self_collision: true,
        }),
    }
}

/// `objects` (a robot or model, in hierarchy order) on a 5 x 5 m floor. The floor
/// becomes object 0, so every index into `objects` moves up by one: parents, mimic
/// leaders, the objects `scripts` are attached to and the dummies of `links`.
pub(super) fn on_floor(
    objects: Vec<ObjectModel>,
    scripts: &mut [ScriptModel],
    links: &mut [[usize; 2]],
) -> Vec<ObjectModel> {
    let mut out = Vec::with_capacity(objects.len() + 1);
    out.push(floor_object([DEFAULT_SIDE, DEFAULT_SIDE], 1.0, [0.55, 0.55, 0.5]));
    out.extend(objects.into_iter().map(|mut o| {
        o.parent = o.parent.map(|p| p + 1);
        if let ObjectModelKind::Joint(j) = &mut o.kind
            && let Some(m) = &mut j.mimic
        {
            m.leader += 1;
        }
        o
    }));
    for s in scripts {
        s.object += 1;
    }
    for pair in links.iter_mut().flatten() {
        *pair += 1;
    }
    out
}
