//! The simulation core (the world and its subsystems) as the host functions reach it.
//!
//! [`crate::simulation::Simulation`] owns it and lends it out by `RefCell` borrows on the
//! simulation thread only (the `Lua` value is not `Send` and never leaves it). The same
//! cell sits in the Lua state's app data for the `sim.*` functions; a function finding
//! it borrowed reports "the world is busy" instead of panicking.

use std::cell::RefCell;
use std::ops::Deref;
use std::rc::Rc;

use gantry_sim_core::Sim;

/// The core, shared between the simulation and the host functions.
#[derive(Clone)]
pub(crate) struct CoreCell(pub(crate) Rc<RefCell<Sim>>);

impl Deref for CoreCell {
    type Target = RefCell<Sim>;

    fn deref(&self) -> &RefCell<Sim> {
        &self.0
    }
}

impl CoreCell {
    /// Appends a line to the world's log at the current simulation time.
    pub(crate) fn log(&self, verbosity: i64, source: &str, msg: &str) {
        let w = &mut self.borrow_mut().world;
        let t = w.time();
        w.log.push(t, verbosity, source, msg);
    }
}
