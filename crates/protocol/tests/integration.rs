//! gantry-protocol's integration tests, one module per file beside this one, built as one
//! test binary: each binary links rapier, parry and Lua, so one link instead of one per
//! file keeps the test build short. Run one file's tests with its module name as the
//! filter: `cargo test -p gantry-protocol --test integration <file>::`.

mod ros_cdr;
mod ros_typed;
