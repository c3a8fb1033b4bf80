//! gantry's integration tests, one module per file beside this one, built as one
//! test binary: each binary links rapier, parry and Lua, so one link instead of one per
//! file keeps the test build short. Run one file's tests with its module name as the
//! filter: `cargo test -p gantry --test integration <file>::`.

mod common;

mod api_doc;
mod blue_robot_cli;
mod cli;
mod record_cli;
mod security;
mod showroom_roams;
mod shutdown;
mod text_channel;
