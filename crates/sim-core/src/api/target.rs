//! A function name turned, once, into what serves it.
//!
//! A front end (the ZMQ and legacy transports, the in-process Python client, the Lua
//! host's table) receives names: `sim.getObjectPosition`, `getObject`,
//! `simIK.handleGroup`, `sim.step`. It resolves each into a [`Target`] at the edge and
//! hands that typed value on; nothing downstream compares the name again. How a call
//! is scheduled (inside a step or only between steps) is decided from the target's
//! type, by what the function touches, never from its spelling.

use super::host::{FrontEndFn, HOST_FUNCTIONS, Remote, ScriptHostFn};
use super::{ApiFn, ApiFunction, CallError, MODULES, Module};

/// What serves a remote client's call.
#[derive(Clone, Copy)]
pub enum Target {
    /// A function of the core registry, in `module`.
    Core {
        /// Its module (`sim`, `simIK`, `simUI`, `simVision`).
        module: &'static Module,
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
    /// Resolves a name as remote clients spell it: `getObject` or `sim.getObject` in
    /// `sim` (host functions included), `simIK.handleGroup` in another module, and the
    /// older names a module keeps as aliases.
    pub fn resolve(name: &str) -> Option<Target> {
        let index = INDEX.get_or_init(build_index);
        match index.get(name) {
            Some(t) => Some(*t),
            None if !name.contains('.') => index.get(format!("sim.{name}").as_str()).copied(),
            None => None,
        }
    }

    /// [`Target::resolve`], or CoppeliaSim's "No such function" error.
    ///
    /// # Errors
    /// No function of that name is served to remote clients.
    pub fn resolve_or_error(name: &str) -> Result<Target, CallError> {
        Self::resolve(name).ok_or_else(|| {
            let qualified = if name.contains('.') {
                name.to_owned()
            } else {
                format!("sim.{name}")
            };
            CallError::NoSuchFunction(qualified)
        })
    }

    /// The qualified name, for error messages: `sim.getObjectPosition`.
    pub fn qualified(&self) -> String {
        match self {
            Target::Core { module, name, .. } => format!("{}.{name}", module.name),
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
}

/// Every qualified name a remote client may call, with its target: built once, on
/// first use, so that resolving a name is one hash look-up.
static INDEX: std::sync::OnceLock<std::collections::HashMap<String, Target>> = std::sync::OnceLock::new();

fn build_index() -> std::collections::HashMap<String, Target> {
    let mut index = std::collections::HashMap::new();
    for module in MODULES {
        for (name, function) in module.callable() {
            index.insert(
                format!("{}.{name}", module.name),
                Target::Core { module, function, name },
            );
        }
    }
    for h in HOST_FUNCTIONS {
        let target = match h.remote {
            Remote::ByScriptHost(f) => Target::ScriptHost(f),
            Remote::ByFrontEnd(f) => Target::FrontEnd(f),
            Remote::No => continue,
        };
        index.insert(format!("sim.{}", h.name), target);
    }
    index
}

/// Every name a remote client may call, qualified (`sim.getObject`, `simIK.solve`),
/// with the older aliases of each module: what the front ends accept.
pub fn accepted_names() -> Vec<String> {
    let mut names = Vec::new();
    for m in MODULES {
        names.extend(m.iter().map(|f| format!("{}.{}", m.name, f.name)));
        names.extend(m.aliases.iter().map(|(old, _)| format!("{}.{old}", m.name)));
    }
    names.extend(super::host::remote_names().map(|n| format!("sim.{n}")));
    names
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_accepted_name_resolves_to_exactly_one_target() {
        let names = accepted_names();
        assert!(names.len() > 300, "{} names", names.len());
        for name in &names {
            let t = Target::resolve(name).unwrap_or_else(|| panic!("{name} does not resolve"));
            // The unqualified `sim` spelling reaches the same target.
            if let Some(bare) = name.strip_prefix("sim.") {
                assert_eq!(Target::resolve(bare), Some(t), "{name}");
            }
            // Exactly one: no other target answers to the same qualified name.
            let same: Vec<_> = names.iter().filter(|n| *n == name).collect();
            assert_eq!(same.len(), 1, "{name} is listed twice");
        }
        assert!(Target::resolve("sim.noSuchThing").is_none());
        assert!(Target::resolve("simNope.getObject").is_none());
        // Host functions that only scripts may call are not remote targets.
        assert!(Target::resolve("sim.wait").is_none());
        assert!(matches!(
            Target::resolve_or_error("noSuchThing"),
            Err(CallError::NoSuchFunction(n)) if n == "sim.noSuchThing"
        ));
    }

    #[test]
    fn scheduling_follows_what_a_function_touches() {
        let t = |n: &str| Target::resolve(n).unwrap().step_safety();
        assert_eq!(t("sim.getObjectPosition"), StepSafety::AnyBoundary);
        assert_eq!(t("sim.getVisionSensorImg"), StepSafety::PhaseBoundary);
        assert_eq!(t("simVision.sensorImgToWorkImg"), StepSafety::PhaseBoundary);
        assert_eq!(t("sim.callScriptFunction"), StepSafety::BetweenSteps);
        assert_eq!(t("sim.step"), StepSafety::BetweenSteps);
        assert_eq!(t("getScript"), StepSafety::BetweenSteps);
        assert_eq!(
            Target::resolve("sim.getObjectPosition").unwrap().qualified(),
            "sim.getObjectPosition"
        );
    }
}
