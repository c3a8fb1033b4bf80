//! gantry-engine's integration tests, one module per file beside this one, built as one
//! test binary: each binary links rapier, parry and Lua, so one link instead of one per
//! file keeps the test build short. Run one file's tests with its module name as the
//! filter: `cargo test -p gantry-engine --test integration <file>::`.

mod util;

mod api;
mod bad_scripts;
mod blue_robot;
mod coppelia_scenes;
mod debugger;
mod files;
mod hooks;
mod ik_groups;
mod ik_objects;
mod legacy;
mod listeners;
mod luasocket;
mod messages;
mod modules;
mod old_scene_functions;
mod ompl;
mod particles;
mod paths;
mod point_cloud;
mod pyrep_scene;
mod random_seed;
mod ros;
mod ros_action;
mod rover;
mod runtime_models;
mod sandbox;
mod scanner;
mod scene_editing;
mod seed;
mod threads;
