//! gantry-coppelia-file's integration tests, one module per file beside this one, built as one
//! test binary: each binary links rapier, parry and Lua, so one link instead of one per
//! file keeps the test build short. Run one file's tests with its module name as the
//! filter: `cargo test -p gantry-coppelia-file --test integration <file>::`.

mod pyrep_test_scene;
mod shared_files;
