//! gantry-server's integration tests, one module per file beside this one, built as one
//! test binary: each binary links rapier, parry and Lua, so one link instead of one per
//! file keeps the test build short. Run one file's tests with its module name as the
//! filter: `cargo test -p gantry-server --test integration <file>::`.

mod util;

mod blocking_accept;
mod call_share;
mod http;
mod mid_step;
mod quit_when_stopped;
mod record;
mod replay;
mod token;
mod zmq;
