//! What the simulation thread does while a script waits in a blocking call.
//!
//! A non-threaded script that waits in LuaSocket's `accept` or `receive` holds the
//! simulation there, as in CoppeliaSim (the paper's `Blue Robot.ttt` waits in
//! `accept` inside `sysCall_actuation` until its GUI connects). The simulation thread
//! is then inside the step, but much of what front ends ask needs no step to finish:
//! the scene to draw, the poses, the log. So instead of sleeping between its retries,
//! a wait hands its slice of time to the front end's [`WaitService`], which serves
//! such requests and returns when the slice is over.

use std::cell::RefCell;
use std::rc::Rc;
use std::time::Duration;

/// Serves the front end for about the given slice of time while a script waits. It
/// must not run Lua or step the simulation, and must return within the slice (give or
/// take one request served).
pub type WaitService = Rc<dyn Fn(Duration)>;

/// The front end's wait service, if it gave one (see the module docs).
#[derive(Default)]
pub(crate) struct Waiting(RefCell<Option<WaitService>>);

impl Waiting {
    /// Installs (or removes) the service.
    pub(crate) fn set(&self, service: Option<WaitService>) {
        *self.0.borrow_mut() = service;
    }

    /// Spends `slice` serving the front end, or sleeping without a service.
    pub(crate) fn pause(&self, slice: Duration) {
        // Out of the cell first: the service may take its time, and nothing it does
        // may find the cell borrowed.
        let service = self.0.borrow().clone();
        match service {
            Some(serve) => serve(slice),
            None => std::thread::sleep(slice),
        }
    }
}
