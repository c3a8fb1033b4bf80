//! The world's scene-editing state, beside the object table: removed handles, the scene
//! revision and edit counters, layers, colours gantry does not render, one-step forces,
//! and the settings scripts change. `edit.rs` edits through it; the object table and
//! its lookups (in `world.rs`) only ask which handles are removed.

use std::collections::HashMap;

use rapier3d::prelude::RigidBodyHandle;

use super::object::Handle;

/// A colour component of a shape (`sim.colorcomponent_*`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ColorComponent {
    /// Ambient and diffuse (0): the colour the viewer and vision sensors draw.
    AmbientDiffuse,
    /// Diffuse (1); for shapes the same as ambient-diffuse.
    Diffuse,
    /// Specular (2).
    Specular,
    /// Emission (3).
    Emission,
    /// Transparency (4): one value, 0 opaque.
    Transparency,
    /// Auxiliary (5).
    Auxiliary,
}

impl ColorComponent {
    /// The component for CoppeliaSim's number, `None` when out of range.
    pub fn from_code(code: i64) -> Option<Self> {
        Some(match code {
            0 => Self::AmbientDiffuse,
            1 => Self::Diffuse,
            2 => Self::Specular,
            3 => Self::Emission,
            4 => Self::Transparency,
            5 => Self::Auxiliary,
            _ => return None,
        })
    }

    /// How many values the component has: 1 for transparency, else 3 (RGB).
    pub fn value_count(self) -> usize {
        if self == Self::Transparency { 1 } else { 3 }
    }

    /// CoppeliaSim's value for a component gantry does not render.
    pub(super) fn default_value(self) -> Vec<f64> {
        match self {
            Self::Specular => vec![0.25; 3],
            Self::Transparency => vec![0.0],
            Self::Auxiliary => vec![0.5, 0.0, 0.0],
            _ => vec![0.0; 3],
        }
    }
}

/// Counters of structural edits (`sim.intparam_objectcreationcounter` and friends).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct EditCounters {
    /// Objects created (including copies) since the world was built.
    pub created: u64,
    /// Objects removed.
    pub destroyed: u64,
    /// Hierarchy changes (re-parenting, removal).
    pub hierarchy: u64,
}

/// The world's scene-editing state, beside the object table.
#[derive(Debug, Clone, Default)]
pub(crate) struct EditState {
    /// `removed[h]`: handle `h` belonged to an object that was removed.
    pub(super) removed: Vec<bool>,
    /// See [`World::scene_revision`].
    pub(super) revision: u64,
    /// See [`World::geometry_revision`].
    pub(super) geometry_revision: u64,
    pub(super) counters: EditCounters,
    /// Visibility layers that differ from the default (1).
    pub(super) layers: HashMap<Handle, i64>,
    /// Model properties of model bases (`sim.setModelProperty`), without the
    /// `sim.modelproperty_not_model` bits (those are the object's `model_base`).
    pub(super) model_props: HashMap<Handle, i64>,
    /// Object properties (`sim.setObjectProperty`) that differ from 0.
    pub(super) object_props: HashMap<Handle, i64>,
    /// Object special properties (`sim.setObjectSpecialProperty`) that differ from the
    /// object type's default.
    pub(super) special_props: HashMap<Handle, i64>,
    /// Object parameters CoppeliaSim has that change nothing in gantry's simulation (a
    /// vision sensor's window size: gantry renders off-screen; the OpenGL version it
    /// renders with), by (object, parameter id), kept so that what a client sets reads
    /// back.
    pub(super) stored_params: HashMap<(Handle, i64), i64>,
    /// Shape colour components gantry does not render, as set by `sim.setShapeColor`.
    pub(super) colors: HashMap<(Handle, ColorComponent), Vec<f64>>,
    /// Bodies given a force or torque for the coming step (`sim.addForce`).
    pub(super) forced: Vec<RigidBodyHandle>,
    /// `sim.boolparam_realtime_simulation` as scripts set it.
    pub(super) realtime: bool,
    /// State of `sim.floatparam_rand`'s generator (xorshift64*, deterministic per run).
    pub(super) rand: u64,
}

impl EditState {
    /// The state of a world built with `n` objects, its random numbers from `seed`.
    pub(crate) fn new(n: usize, seed: i64) -> Self {
        // Seed 0 keeps the sequence gantry always had. xorshift must not start at 0,
        // which the odd multiplier's product with a seed never gives but for seed 0.
        let seed = u64::from_ne_bytes(seed.to_ne_bytes());
        let rand = 0x9E37_79B9_7F4A_7C15 ^ seed.wrapping_mul(0xBF58_476D_1CE4_E5B9);
        Self {
            removed: vec![false; n],
            rand: if rand == 0 { 0x9E37_79B9_7F4A_7C15 } else { rand },
            ..Self::default()
        }
    }

    /// Whether `h` names a removed object.
    pub(crate) fn is_removed(&self, h: Handle) -> bool {
        gone(&self.removed, h)
    }
}

/// Whether `removed` marks `h`.
pub(super) fn gone(removed: &[bool], h: Handle) -> bool {
    usize::try_from(h)
        .ok()
        .and_then(|i| removed.get(i))
        .copied()
        .unwrap_or(false)
}
