//! The floor gantry adds under what has none of its own: a bare URDF robot, a
//! CoppeliaSim model (`.ttm`), and a scene file's `[floor]` section.

use super::model::{GeomModel, Geometry, MassModel, ObjectModel, ObjectModelKind, SceneModel, ShapeModel, VisualModel};
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
        extension: String::new(),
        layer: 1,
        kind: ObjectModelKind::Shape(ShapeModel {
            geoms: vec![GeomModel {
                geometry: geometry.clone(),
                local,
            }],
            visuals: vec![VisualModel {
                geometry,
                local,
                color,
                texture: None,
            }],
            dynamic: false,
            mass: MassModel::Density(1000.0),
            friction,
            restitution: 0.0,
            collision_group: u32::MAX,
            collision_mask: u32::MAX,
            respondable: true,
            detectable: false,
            measurable: false,
            collidable: true,
            self_collision: true,
        }),
    }
}

/// Puts a robot or model on a 5 x 5 m floor, which becomes object 0 (every index of
/// the model moves up by one).
pub(super) fn put_on_floor(model: &mut SceneModel) {
    model.offset_indices(1);
    model
        .objects
        .insert(0, floor_object([DEFAULT_SIDE, DEFAULT_SIDE], 1.0, [0.55, 0.55, 0.5]));
}
