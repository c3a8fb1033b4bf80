//! One `sim.*` function as the registry holds it: its implementation typed by what it may
//! touch ([`ApiFn`]), the caller's context, and how it is invoked. Every function file
//! and the registry build on it.

use super::args::Args;
use crate::Value;
use crate::error::SimError;
use crate::sim::Sim;
use crate::world::Handle;
use crate::world::World;

/// Who is calling: scripts have an object ("emitting object" for `.` in paths),
/// remote clients do not.
#[derive(Debug, Clone, Copy, Default)]
pub struct CallContext<'a> {
    /// The object the calling script is attached to.
    pub script_object: Option<Handle>,
    /// A name for log lines (a script file, or "remote").
    pub source: &'a str,
}

/// What a function returns: CoppeliaSim's multiple return values.
pub type Ret = Vec<Value>;

/// A `sim.*` function that touches only the world: objects and physics.
pub type WorldFn = fn(&mut World, &CallContext<'_>, &Args<'_>) -> Result<Ret, SimError>;

/// A `sim.*` function that touches the floors above the world too: the simulation
/// state, signals, drawings, graphs, UIs, IK environments, vision images, generators.
pub type SimFn = fn(&mut Sim, &CallContext<'_>, &Args<'_>) -> Result<Ret, SimError>;

/// An implementation, typed by what it may touch.
#[derive(Clone, Copy)]
pub enum ApiFn {
    /// The world only.
    World(WorldFn),
    /// Anything in the simulation.
    Sim(SimFn),
}

/// How long a function may take, for front ends that must decide whether to let other
/// work run meanwhile (the in-process Python client releases the GIL for the long
/// ones; for the quick ones releasing and retaking it costs more than the call).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cost {
    /// Microseconds: reads and writes of poses, parameters, signals.
    Quick,
    /// May render, solve, plan or query geometry: up to milliseconds and more.
    Long,
}

/// One entry of the registry.
#[derive(Clone, Copy)]
pub struct ApiFunction {
    /// Name without the `sim.` prefix.
    pub name: &'static str,
    /// The implementation.
    pub call: ApiFn,
    /// How long it may take.
    pub cost: Cost,
}

impl ApiFunction {
    /// Runs the function on `sim`.
    ///
    /// # Errors
    /// The function's own error, without its name (see [`SimError::in_function`]).
    pub fn invoke(&self, sim: &mut Sim, ctx: &CallContext<'_>, args: &Args<'_>) -> Result<Ret, SimError> {
        match self.call {
            ApiFn::World(f) => f(&mut sim.world, ctx, args),
            ApiFn::Sim(f) => f(sim, ctx, args),
        }
    }
}
