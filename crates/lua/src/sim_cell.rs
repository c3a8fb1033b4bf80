//! The simulation (the world and its subsystems) as the Lua host's functions reach it.
//!
//! The engine owns the [`Sim`] and lends it to the Lua host through this cell: one
//! `Rc<RefCell<..>>` on the simulation thread only (the `Lua` value is not `Send` and
//! never leaves it). The engine borrows it between hooks; a `sim.*` function borrows it
//! while it runs, and one finding it borrowed reports "the world is busy" instead of
//! panicking. Nothing else holds a clone.

use std::cell::RefCell;
use std::ops::Deref;
use std::rc::Rc;

use gantry_sim_core::Sim;

/// The simulation, shared between its owner (the engine) and the Lua host.
#[derive(Clone)]
pub struct SimCell(pub(crate) Rc<RefCell<Sim>>);

impl SimCell {
    /// A cell holding `sim`.
    pub fn new(sim: Sim) -> Self {
        Self(Rc::new(RefCell::new(sim)))
    }

    /// Appends a line to the world's log at the current simulation time.
    pub fn log(&self, verbosity: i64, source: &str, msg: &str) {
        let w = &mut self.borrow_mut().world;
        let t = w.time();
        w.log.push(t, verbosity, source, msg);
    }
}

impl Deref for SimCell {
    type Target = RefCell<Sim>;

    fn deref(&self) -> &RefCell<Sim> {
        &self.0
    }
}
