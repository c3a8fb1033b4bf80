//! A function name turned, once, into what serves it.
//!
//! A front end (the ZMQ and legacy transports, the in-process Python client, the Lua
//! host's table) receives names: `sim.getObjectPosition`, `getObject`,
//! `simIK.handleGroup`, `sim.step`. It resolves each into a [`Target`] at the edge and
//! hands that typed value on; nothing downstream compares the name again. How a call
//! is scheduled (inside a step or only between steps) is decided from the target's
//! type, by what the function touches, never from its spelling.

use super::function::{ApiFn, ApiFunction, Cost};
use super::host::{FrontEndFn, ScriptHostFn};

/// What serves a remote client's call.
#[derive(Clone, Copy)]
pub enum Target {
    /// A function of the core registry, in `module`.
    Core {
        /// Its module's name (`sim`, `simIK`, `simUI`, `simVision`).
        module: &'static str,
        /// The function.
        function: &'static ApiFunction,
        /// The name it was called by: the function's, or an older alias of it (errors
        /// name the function as the caller spelled it, as CoppeliaSim's do).
        name: &'static str,
    },
    /// A function the Lua host serves for clients too (it needs the scripts).
    ScriptHost(ScriptHostFn),
    /// A function of the client's session or the simulation loop (stepping, start,
    /// pause, stop, locks, scenes): the engine serves it.
    FrontEnd(FrontEndFn),
}

impl std::fmt::Debug for Target {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Target({})", self.qualified())
    }
}

impl PartialEq for Target {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (
                Self::Core {
                    function: a, name: x, ..
                },
                Self::Core {
                    function: b, name: y, ..
                },
            ) => std::ptr::eq(*a, *b) && x == y,
            (Self::ScriptHost(a), Self::ScriptHost(b)) => a == b,
            (Self::FrontEnd(a), Self::FrontEnd(b)) => a == b,
            _ => false,
        }
    }
}

/// Where a call may be served relative to a step in progress.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepSafety {
    /// Between any two phases of a step, even while a vision sensor's image waits for
    /// its `sysCall_vision`: the function touches only the world, which holds no image.
    AnyBoundary,
    /// Between phases of a step, but not while an image is unprocessed: the function
    /// may read the floors above the world (images among them).
    PhaseBoundary,
    /// Only between steps: it runs script code or acts on the loop, either of which may
    /// start, stop or pause the simulation.
    BetweenSteps,
}

impl Target {
    /// The qualified name, for error messages: `sim.getObjectPosition`.
    pub fn qualified(&self) -> String {
        match self {
            Target::Core { module, name, .. } => format!("{module}.{name}"),
            Target::ScriptHost(f) => format!("sim.{}", f.name()),
            Target::FrontEnd(f) => format!("sim.{}", f.name()),
        }
    }

    /// Where a call of this target may be served relative to a step in progress.
    pub fn step_safety(&self) -> StepSafety {
        match self {
            Target::Core { function, .. } => match function.call {
                ApiFn::World(_) => StepSafety::AnyBoundary,
                ApiFn::Sim(_) => StepSafety::PhaseBoundary,
            },
            Target::ScriptHost(_) | Target::FrontEnd(_) => StepSafety::BetweenSteps,
        }
    }

    /// How long a call of this target may take: the registry's [`Cost`] for a core
    /// function; script code (a function of the Lua host) may run long; the loop's
    /// functions are quick (a front end that waits for a step does so itself).
    pub fn cost(&self) -> Cost {
        match self {
            Target::Core { function, .. } => function.cost,
            Target::ScriptHost(_) => Cost::Long,
            Target::FrontEnd(_) => Cost::Quick,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn what_may_run_long_comes_from_the_registry() {
        let cost = |name: &str| Target::resolve(name).expect(name).cost();
        for name in Target::accepted_names() {
            let c = cost(&name);
            // Every IK solve and image operation may run long.
            if name.starts_with("simIK.") || name.starts_with("simVision.") {
                assert_eq!(c, Cost::Long, "{name}");
            }
        }
        for long in [
            "sim.getVisionSensorImg",
            "sim.handleVisionSensor",
            "sim.checkDistance",
            "sim.castRays",
            "simOMPL.compute",
            "sim.callScriptFunction",
        ] {
            assert_eq!(cost(long), Cost::Long, "{long}");
        }
        for quick in [
            "sim.getObjectPosition",
            "sim.setJointTargetPosition",
            "sim.getInt32Signal",
            "simOMPL.createStateSpace",
            "sim.step",
        ] {
            assert_eq!(cost(quick), Cost::Quick, "{quick}");
        }
    }
}
