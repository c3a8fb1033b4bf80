//! Names to [`Target`]s: the one look-up a front end does at its edge.
//!
//! Kept apart from [`super::target`] because it reads the registry ([`MODULES`],
//! defined in `api/mod.rs`), which re-exports [`Target`]: the type stays below the
//! registry and the look-up above it, so no file imports in a circle.

use super::host::{HOST_FUNCTIONS, Remote};
use super::target::Target;
use super::{CallError, MODULES};

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
                Target::Core {
                    module: module.name,
                    function,
                    name,
                },
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::api::StepSafety;

    #[test]
    fn every_accepted_name_resolves_to_exactly_one_target() {
        let names = Target::accepted_names();
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
        assert!(Target::resolve("sim.switchThread").is_none());
        // Blocking ones are, served by the engine over several steps.
        assert!(matches!(Target::resolve("sim.wait"), Some(Target::ScriptHost(f)) if f.blocks()));
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
