//! `sim.addLog`: a line in the simulation log, with the calling script (or "remote") as
//! its source.

use super::{Args, CallContext, Ret};
use crate::error::SimError;
use crate::world::World;

/// `sim.addLog(verbosity, message)`.
pub(super) fn add_log(w: &mut World, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let verbosity = a.int(0)?;
    let msg = a.str(1)?;
    let t = w.time();
    w.log.push(t, verbosity, ctx.source, msg);
    Ok(Vec::new())
}
