//! What each legacy remote API command does: a thin converter from the `simx*` command
//! codes and their binary arguments to the registry's `sim.*` functions, and from their
//! results to the binary replies the client library reads. Nothing here acts on the
//! world itself: every command is one or more [`SimHandle`] requests.
//!
//! `table::COMMANDS` lists every command served, by code; a command that is one
//! registry call is written there as data, the others are `table::Simx` variants
//! implemented by family: `objects`, `sensors`, `signals`, `script_call`, and
//! the session's own commands (stepping, errors, closing) below.
//!
//! Layouts follow the client library (`layout`): integers and floats are little-endian
//! 32-bit, strings NUL-terminated; a reply repeats the command's identifying data (the
//! transport does that) and carries the results as its pure data. A command that fails
//! on the server side replies with status bit 0 set, which the client reports as
//! `simx_return_remote_error_flag`; the reason is kept for `simxGetLastErrors`.
//! Commands gantry does not serve (the old 2D UIs, file transfer, dialogs' results)
//! fail that way, with a message naming them.

mod layout;
mod objects;
mod script_call;
mod sensors;
mod session;
mod signals;
mod table;

use gantry_protocol::legacy_remote_api::Command;

use session::Ctx;
pub use session::{Outcome, Session};

use crate::sim_thread::SimHandle;

/// Runs one command for the session's client.
pub async fn execute(sim: &SimHandle, session: &mut Session, cmd: &Command) -> Outcome {
    let Some(entry) = table::find(cmd.code) else {
        let why = format!(
            "command 0x{:04x} is not served by gantry's legacy remote API (see docs/legacy-remote-api.md)",
            cmd.code
        );
        return session.fail(cmd, why);
    };
    tracing::trace!("legacy remote API {}", entry.name);
    let mut cx = Ctx { sim, session, cmd };
    let result = entry.command.run(&mut cx).await;
    match result {
        Ok(o) => o,
        Err(why) => session.fail(cmd, why.to_string()),
    }
}

#[cfg(test)]
mod tests;
