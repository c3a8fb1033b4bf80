//! gantry-sim-core's integration tests, one module per file beside this one, built as one
//! test binary: each binary links rapier, parry and Lua, so one link instead of one per
//! file keeps the test build short. Run one file's tests with its module name as the
//! filter: `cargo test -p gantry-sim-core --test integration <file>::`.

mod util;

mod api_errors;
mod api_math;
mod api_ruckig;
mod bad_scenes;
mod containment;
mod convert;
mod coppelia_import;
mod coppelia_vision;
mod custom_data;
mod determinism;
mod distance;
mod drawing;
mod floating_views;
mod ik;
mod ik_legacy;
mod ik_objects;
mod joint_force;
mod kinematic_motion;
mod kinematics;
mod legacy;
mod lights_and_old_paths;
mod links;
mod octrees;
mod paths;
mod point_cloud;
mod pyrep_ik_groups;
mod pyrep_objects;
mod scanner;
mod scene_building;
mod scene_edit;
mod selection;
mod sensing_more;
mod shape_meshes;
mod simulator_messages;
mod spherical_vision;
mod textures_from_files;
mod ui;
mod urdf_dynamics;
mod urdf_robots;
mod vision;
mod vision_buffers;
mod vision_mask;
mod vision_projection;
mod world;
