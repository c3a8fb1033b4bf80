//! `sim.startSimulation`, `sim.pauseSimulation` and `sim.stopSimulation` from scripts:
//! a request kept here and carried out by the simulation once no script runs (a script
//! cannot stop the simulation it is running in from inside its own hook).

use std::cell::Cell;

use gantry_sim_core::sim::{Advancing, Control, SimulationState};
use mlua::{Lua, Table};

use crate::app_state::state;
use crate::sim_cell::SimCell;

/// A start, pause or stop asked for by a script, carried out once no script runs.
#[derive(Default)]
pub(crate) struct PendingControl(Cell<Option<Control>>);

impl PendingControl {
    /// The request, if any, now to be carried out.
    pub(crate) fn take(&self) -> Option<Control> {
        self.0.take()
    }

    /// Drops any request (a stop asked for by the host wins over its cleanup hooks').
    pub(crate) fn clear(&self) {
        self.0.set(None);
    }
}

/// Installs the three functions into `sim`.
pub(crate) fn install(lua: &Lua, sim: &Table) -> mlua::Result<()> {
    for (name, control) in [
        ("startSimulation", Control::Start),
        ("pauseSimulation", Control::Pause),
        ("stopSimulation", Control::Stop),
    ] {
        sim.set(
            name,
            lua.create_function(move |lua, ()| {
                state::<PendingControl>(lua).0.set(Some(control));
                // Scripts see the request in `sim.getSimulationState` for the rest of
                // the step, as CoppeliaSim's "last before pause" / "about to stop".
                if let Ok(mut w) = state::<SimCell>(lua).try_borrow_mut()
                    && w.state == SimulationState::Running
                {
                    match control {
                        Control::Pause => w.advancing = Advancing::LastBeforePause,
                        Control::Stop => w.advancing = Advancing::AboutToStop,
                        Control::Start => {}
                    }
                }
                Ok(())
            })?,
        )?;
    }
    Ok(())
}
