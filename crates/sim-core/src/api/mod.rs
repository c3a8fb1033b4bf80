//! The one implementation of each `sim.*` function, over [`Value`].
//!
//! The Lua host and the ZMQ remote API are thin converters around [`FUNCTIONS`]: they
//! turn their values into [`Value`]s, call the function with the world and the caller's
//! context, and turn the results back. Return shapes follow CoppeliaSim (positions as 3
//! numbers, `readProximitySensor` always 5 values, ...), and errors carry a message to
//! which the front end appends `(in function 'sim.name')`.

mod application;
mod args;
mod configuration;
mod contacts;
mod create_joint;
mod create_sensors;
mod custom_data;
mod drawing;
mod engine_params;
mod error;
mod extension;
mod function;
mod graph_curves;
pub mod host;
mod ik;
mod ik_groups;
mod ik_legacy;
mod ik_objects;
mod image;
mod image_file;
mod joints;
pub mod legacy;
mod lights;
mod links;
mod log;
mod matrix;
mod objects;
mod octree;
mod ompl;
mod packing;
mod params;
mod particles;
mod paths;
mod point_cloud;
mod properties;
mod proximity_check;
mod referenced;
mod resolve;
pub(crate) mod ruckig;
mod scan;
mod scene;
mod scene_file;
mod sensing;
mod shape_group;
mod shape_info;
mod shape_mesh;
mod signals;
mod simulation;
mod simulator_messages;
mod target;
mod textures;
mod tubes;
mod ui;
mod views;
mod vision;
mod vision_buffers;
mod vision_spherical;

pub use args::Args;
pub use error::CallError;
pub use function::{ApiFn, ApiFunction, CallContext, Cost, Ret, SimFn, WorldFn};
pub use host::{
    FrontEndFn, HOST_FUNCTIONS, HOST_MODULES, HostFunction, HostModule, InScripts, Remote, ScriptHostFn, Touches,
    host_function,
};
pub use target::{StepSafety, Target};

use crate::Value;
use crate::sim::Sim;

/// Every `sim.*` function implemented in the core, in alphabetical order.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "addItemToCollection",
        call: ApiFn::World(sensing::add_item_to_collection),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "addLog",
        call: ApiFn::World(log::add_log),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "checkCollision",
        call: ApiFn::World(sensing::check_collision),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "checkDistance",
        call: ApiFn::World(sensing::check_distance),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "clearDoubleSignal",
        call: ApiFn::Sim(signals::clear_double_signal),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "clearFloatSignal",
        call: ApiFn::Sim(signals::clear_float_signal),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "clearInt32Signal",
        call: ApiFn::Sim(signals::clear_int32_signal),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "clearStringSignal",
        call: ApiFn::Sim(signals::clear_string_signal),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "createCollection",
        call: ApiFn::World(sensing::create_collection),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "destroyCollection",
        call: ApiFn::World(sensing::destroy_collection),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getCollectionHandle",
        call: ApiFn::World(sensing::get_collection_handle),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getCollectionName",
        call: ApiFn::World(sensing::get_collection_name),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getCollectionObjects",
        call: ApiFn::World(sensing::get_collection_objects),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getDoubleSignal",
        call: ApiFn::Sim(signals::get_double_signal),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getFloatSignal",
        call: ApiFn::Sim(signals::get_float_signal),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getInt32Signal",
        call: ApiFn::Sim(signals::get_int32_signal),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getJointForce",
        call: ApiFn::World(joints::get_joint_force),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getJointInterval",
        call: ApiFn::World(joints::get_joint_interval),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getJointPosition",
        call: ApiFn::World(joints::get_joint_position),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getJointTargetPosition",
        call: ApiFn::World(joints::get_joint_target_position),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getJointTargetVelocity",
        call: ApiFn::World(joints::get_joint_target_velocity),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getJointType",
        call: ApiFn::World(joints::get_joint_type),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getJointVelocity",
        call: ApiFn::World(joints::get_joint_velocity),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObject",
        call: ApiFn::World(objects::get_object),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectAlias",
        call: ApiFn::World(objects::get_object_alias),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectMatrix",
        call: ApiFn::World(objects::get_object_matrix),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectOrientation",
        call: ApiFn::World(objects::get_object_orientation),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectParent",
        call: ApiFn::World(objects::get_object_parent),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectPose",
        call: ApiFn::World(objects::get_object_pose),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectPosition",
        call: ApiFn::World(objects::get_object_position),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectQuaternion",
        call: ApiFn::World(objects::get_object_quaternion),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectType",
        call: ApiFn::World(objects::get_object_type),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectVelocity",
        call: ApiFn::World(objects::get_object_velocity),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectsInTree",
        call: ApiFn::World(objects::get_objects_in_tree),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getSimulationState",
        call: ApiFn::Sim(simulation::get_simulation_state),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getSimulationTime",
        call: ApiFn::World(simulation::get_simulation_time),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getSimulationTimeStep",
        call: ApiFn::World(simulation::get_simulation_time_step),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getSimulatorMessage",
        call: ApiFn::Sim(simulator_messages::get_simulator_message),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getStringSignal",
        call: ApiFn::Sim(signals::get_string_signal),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getSystemTime",
        call: ApiFn::World(simulation::get_system_time),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "handleProximitySensor",
        call: ApiFn::World(sensing::handle_proximity_sensor),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "readForceSensor",
        call: ApiFn::World(sensing::read_force_sensor),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "readProximitySensor",
        call: ApiFn::World(sensing::read_proximity_sensor),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setDoubleSignal",
        call: ApiFn::Sim(signals::set_double_signal),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setFloatSignal",
        call: ApiFn::Sim(signals::set_float_signal),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setInt32Signal",
        call: ApiFn::Sim(signals::set_int32_signal),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setJointInterval",
        call: ApiFn::World(joints::set_joint_interval),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setJointPosition",
        call: ApiFn::World(joints::set_joint_position),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setJointTargetForce",
        call: ApiFn::World(joints::set_joint_target_force),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setJointTargetPosition",
        call: ApiFn::World(joints::set_joint_target_position),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setJointTargetVelocity",
        call: ApiFn::World(joints::set_joint_target_velocity),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setObjectMatrix",
        call: ApiFn::World(objects::set_object_matrix),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setObjectOrientation",
        call: ApiFn::World(objects::set_object_orientation),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setObjectPose",
        call: ApiFn::World(objects::set_object_pose),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setObjectPosition",
        call: ApiFn::World(objects::set_object_position),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setObjectQuaternion",
        call: ApiFn::World(objects::set_object_quaternion),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setStringSignal",
        call: ApiFn::Sim(signals::set_string_signal),
        cost: Cost::Quick,
    },
];

/// A namespace of the API as scripts see it (`sim`, `simIK`, `simUI`, `simVision`):
/// its functions, gathered from the files that implement them, and its constants.
pub struct Module {
    /// The Lua global / remote-API name, e.g. `simIK`.
    pub name: &'static str,
    /// Function tables, each owned by one implementation file.
    pub functions: &'static [&'static [ApiFunction]],
    /// Constants, e.g. `simIK.constraint_pose`, gathered like the functions.
    pub constants: Constants,
    /// Older names of functions that were only renamed: `(old, current)`.
    pub aliases: &'static [(&'static str, &'static str)],
}

/// A module's constants: the tables of the files that define them, read as one list
/// (`for (name, value) in module.constants`).
#[derive(Clone, Copy)]
pub struct Constants(pub &'static [&'static [(&'static str, i64)]]);

impl Constants {
    /// Every constant, table by table.
    pub fn iter(self) -> <Self as IntoIterator>::IntoIter {
        self.into_iter()
    }
}

impl IntoIterator for Constants {
    type Item = &'static (&'static str, i64);
    type IntoIter = std::iter::Flatten<std::iter::Copied<std::slice::Iter<'static, &'static [(&'static str, i64)]>>>;

    fn into_iter(self) -> Self::IntoIter {
        self.0.iter().copied().flatten()
    }
}

impl Module {
    /// Every function of the module.
    pub fn iter(&self) -> impl Iterator<Item = &'static ApiFunction> + use<> {
        self.functions.iter().flat_map(|t| t.iter())
    }

    /// Looks a function up by its unqualified name, or by an older name of it.
    pub fn function(&self, name: &str) -> Option<&'static ApiFunction> {
        self.iter().find(|f| f.name == name).or_else(|| {
            let (_, current) = self.aliases.iter().find(|(old, _)| *old == name)?;
            self.iter().find(|f| f.name == *current)
        })
    }

    /// Every name a script or client may call: the functions, then the aliases, each
    /// with the function it runs.
    pub fn callable(&self) -> impl Iterator<Item = (&'static str, &'static ApiFunction)> + use<> {
        let functions = self.iter().map(|f| (f.name, f));
        let module: &'static [&'static [ApiFunction]] = self.functions;
        let aliases = self.aliases.iter().filter_map(move |(old, current)| {
            module
                .iter()
                .flat_map(|t| t.iter())
                .find(|f| f.name == *current)
                .map(|f| (*old, f))
        });
        functions.chain(aliases)
    }
}

/// Every namespace of the API. New capabilities add their function tables here.
pub const MODULES: &[Module] = &[
    Module {
        name: "sim",
        functions: &[
            FUNCTIONS,
            drawing::FUNCTIONS,
            vision::FUNCTIONS,
            matrix::FUNCTIONS,
            packing::FUNCTIONS,
            ruckig::FUNCTIONS,
            scene::FUNCTIONS,
            params::FUNCTIONS,
            legacy::FUNCTIONS,
            links::FUNCTIONS,
            proximity_check::FUNCTIONS,
            custom_data::FUNCTIONS,
            referenced::FUNCTIONS,
            views::FUNCTIONS,
            point_cloud::FUNCTIONS,
            octree::FUNCTIONS,
            scan::FUNCTIONS,
            image::FUNCTIONS,
            image_file::FUNCTIONS,
            application::FUNCTIONS,
            tubes::FUNCTIONS,
            properties::FUNCTIONS,
            paths::FUNCTIONS,
            particles::FUNCTIONS,
            ik_groups::FUNCTIONS,
            shape_group::FUNCTIONS,
            shape_info::FUNCTIONS,
            shape_mesh::FUNCTIONS,
            textures::FUNCTIONS,
            lights::FUNCTIONS,
            graph_curves::FUNCTIONS,
            contacts::FUNCTIONS,
            extension::FUNCTIONS,
            configuration::FUNCTIONS,
            create_joint::FUNCTIONS,
            create_sensors::FUNCTIONS,
            engine_params::FUNCTIONS,
            scene_file::FUNCTIONS,
        ],
        constants: Constants(&[
            CONSTANTS,
            scene::CONSTANTS,
            textures::CONSTANTS,
            params::CONSTANTS,
            ruckig::CONSTANTS,
            legacy::CONSTANTS,
            scan::CONSTANTS,
            crate::world::model_property::CONSTANTS,
            crate::world::object_special_property::CONSTANTS,
            paths::CONSTANTS,
            particles::CONSTANTS,
            ik_groups::CONSTANTS,
            engine_params::CONSTANTS,
        ]),
        aliases: legacy::ALIASES,
    },
    Module {
        name: "simIK",
        functions: &[ik::FUNCTIONS, ik_objects::FUNCTIONS, ik_legacy::FUNCTIONS],
        constants: Constants(&[ik::CONSTANTS, ik_objects::CONSTANTS]),
        aliases: ik_legacy::ALIASES,
    },
    Module {
        name: "simOMPL",
        functions: &[ompl::FUNCTIONS],
        constants: Constants(&[ompl::CONSTANTS]),
        aliases: &[],
    },
    Module {
        name: "simUI",
        functions: &[ui::FUNCTIONS],
        constants: Constants(&[ui::CONSTANTS]),
        aliases: &[],
    },
    Module {
        name: "simVision",
        functions: &[
            vision::SIM_VISION_FUNCTIONS,
            scan::SIM_VISION_FUNCTIONS,
            vision_buffers::SIM_VISION_FUNCTIONS,
        ],
        constants: Constants(&[]),
        aliases: &[],
    },
];

/// The module named `name`.
pub fn module(name: &str) -> Option<&'static Module> {
    MODULES.iter().find(|m| m.name == name)
}

/// Looks a `sim.*` function up by its name without the `sim.` prefix.
pub fn function(name: &str) -> Option<&'static ApiFunction> {
    module("sim").and_then(|m| m.function(name))
}

/// Calls `sim.<name>`, or `<module>.<name>` when `name` is qualified (`simIK.handleGroup`).
///
/// # Errors
/// Unknown function, or the function's own error with its qualified name.
pub fn call(sim: &mut Sim, ctx: &CallContext<'_>, name: &str, args: &[Value]) -> Result<Ret, CallError> {
    let (module_name, fname) = name.split_once('.').unwrap_or(("sim", name));
    let f = module(module_name)
        .and_then(|m| m.function(fname))
        .ok_or_else(|| CallError::NoSuchFunction(format!("{module_name}.{fname}")))?;
    f.invoke(sim, ctx, &Args::new(args))
        .map_err(|e| CallError::failed(format!("{module_name}.{fname}"), e))
}

/// The `sim.*` constants scripts and clients use, with CoppeliaSim's values.
pub const CONSTANTS: &[(&str, i64)] = &[
    ("handle_world", -1),
    ("message_keypress", crate::ui::MESSAGE_KEYPRESS),
    ("handle_all", -2),
    ("handle_all_except_explicit", -3),
    ("handle_self", -4),
    ("handle_main_script", -5),
    ("handle_tree", -6),
    ("handle_chain", -7),
    ("handle_single", -8),
    ("handle_default", -9),
    ("handle_all_except_self", -10),
    ("handle_parent", -11),
    ("handle_scene", -12),
    ("handle_app", -13),
    ("handle_inverse", -14),
    ("simulation_stopped", 0),
    ("simulation_paused", 8),
    ("simulation_advancing", 16),
    ("simulation_advancing_firstafterstop", 16),
    ("simulation_advancing_running", 17),
    ("simulation_advancing_lastbeforepause", 19),
    ("simulation_advancing_firstafterpause", 20),
    ("simulation_advancing_abouttostop", 21),
    ("simulation_advancing_lastbeforestop", 22),
    ("object_shape_type", 0),
    ("object_joint_type", 1),
    ("object_graph_type", 2),
    ("object_camera_type", 3),
    ("object_dummy_type", 4),
    ("object_proximitysensor_type", 5),
    ("object_path_type", 8),
    ("object_visionsensor_type", 9),
    ("object_forcesensor_type", 12),
    ("object_light_type", 13),
    ("light_omnidirectional_subtype", 1),
    ("light_spot_subtype", 2),
    ("light_directional_subtype", 3),
    ("object_octree_type", 15),
    ("object_pointcloud_type", 16),
    ("joint_revolute_subtype", 10),
    ("joint_prismatic_subtype", 11),
    ("joint_spherical_subtype", 12),
    // gantry extension: fixed joints have no CoppeliaSim subtype.
    ("joint_fixed_subtype", 13),
    ("jointmode_kinematic", 0),
    ("jointmode_passive", 0),
    ("jointmode_dependent", 4),
    ("jointmode_dynamic", 5),
    // CoppeliaSim 4.4's name for the dynamic mode.
    ("jointmode_force", 5),
    // CoppeliaSim 4.1's IK mode: kinematic, moved by IK groups (PyRep sets it).
    ("jointmode_ik", 2),
    ("proximitysensor_pyramid_subtype", 30),
    ("proximitysensor_cylinder_subtype", 31),
    ("proximitysensor_disc_subtype", 32),
    ("proximitysensor_cone_subtype", 33),
    ("proximitysensor_ray_subtype", 34),
    ("drawing_points", 0),
    ("drawing_lines", 1),
    ("drawing_triangles", 2),
    ("drawing_spherepts", 7),
    ("drawing_linestrip", 8),
    ("drawing_trianglepts", 9),
    ("drawing_cubepts", 12),
    // Flags, CoppeliaSim's values. Those the viewer has no use for (transparency,
    // overlay, back-face culling, ...) are accepted and change nothing.
    ("drawing_itemcolors", 0x20),
    ("drawing_vertexcolors", 0x40),
    ("drawing_itemsizes", 0x80),
    ("drawing_backfaceculling", 0x100),
    ("drawing_wireframe", 0x200),
    ("drawing_painttag", 0x400),
    ("drawing_followparentvisibility", 0x800),
    ("drawing_cyclic", 4096),
    ("drawing_50percenttransparency", 0x2000),
    ("drawing_25percenttransparency", 0x4000),
    ("drawing_12percenttransparency", 0x8000),
    ("drawing_emissioncolor", 0x1_0000),
    ("drawing_facingcamera", 0x2_0000),
    ("drawing_overlay", 0x4_0000),
    ("drawing_itemtransparency", 0x8_0000),
    ("drawing_persistent", 0x10_0000),
    ("drawing_local", 0x80_0000),
    ("handleflag_addmultiple", 0x0100_0000),
    ("handleflag_silenterror", scene::HANDLEFLAG_SILENT_ERROR),
    ("handleflag_reljointbaseframe", objects::HANDLEFLAG_REL_JOINT_BASE_FRAME),
    ("handleflag_depthbuffermeters", 0x0080_0000),
    ("verbosity_none", 100),
    ("verbosity_errors", 200),
    ("verbosity_warnings", 300),
    ("verbosity_loadinfos", 350),
    ("verbosity_scripterrors", 400),
    ("verbosity_scriptwarnings", 420),
    ("verbosity_scriptinfos", 450),
    // CoppeliaSim 4.5's name for the same level (its plugin examples log with it).
    ("verbosity_msgs", 450),
    ("verbosity_infos", 500),
    ("verbosity_debug", 600),
    ("scripttype_main", 0),
    ("scripttype_childscript", 1),
    ("scripttype_customization", 6),
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn registry_is_sorted_and_unique() {
        // Every implementation file's table is sorted, so a missing or doubled entry
        // shows in review; names are unique across the tables of a module.
        for m in MODULES {
            for table in m.functions {
                for w in table.windows(2) {
                    assert!(w[0].name < w[1].name, "{}: {} / {}", m.name, w[0].name, w[1].name);
                }
            }
        }
        assert!(function("getObject").is_some());
        assert!(function("nope").is_none());
        for m in MODULES {
            let mut names: Vec<&str> = m.iter().map(|f| f.name).collect();
            let n = names.len();
            names.sort_unstable();
            names.dedup();
            assert_eq!(names.len(), n, "a function of {} is registered twice", m.name);
            let mut constants: Vec<&str> = m.constants.iter().map(|(c, _)| *c).collect();
            let n = constants.len();
            constants.sort_unstable();
            constants.dedup();
            assert_eq!(constants.len(), n, "a constant of {} is defined twice", m.name);
        }
    }
}
