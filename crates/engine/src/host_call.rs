//! The loop's functions as requests: what a front end hands the engine once it has
//! resolved a name to an [`api::FrontEndFn`] and read its arguments.

use gantry_sim_core::SimError;
use std::path::PathBuf;

use gantry_sim_core::Value;
use gantry_sim_core::api::{Args, CallError, FrontEndFn};
use gantry_sim_core::sim::Control;

/// A remote client's simulation control or stepping call, carried out by
/// [`crate::Input::Remote`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RemoteOp {
    /// `sim.setStepping(enable)`: returns the client's previous stepping level.
    SetStepping(bool),
    /// `sim.startSimulation()` (start, or resume from pause; `sysCall_init` runs on
    /// start), `sim.pauseSimulation()`, `sim.stopSimulation()` (cleanup, initial scene
    /// restored, stepping levels reset).
    Control(Control),
    /// `sim.acquireLock()` (`true`) or `sim.releaseLock()` (`false`).
    Lock(bool),
}

/// What the viewer's buttons and the command line ask of the simulation loop.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoopControl {
    /// Start or resume, pause, or stop (cleanup hooks run and the scene returns to its
    /// initial state).
    Control(Control),
    /// One step, whatever the state (a stopped simulation starts, then pauses).
    Step,
}

/// A call of a loop function with its arguments read: what each front end then
/// carries out (the engine does all but the waiting of `sim.step`, which is the front
/// end's: a socket parks the client, the in-process client steps at once).
#[derive(Debug, Clone, PartialEq)]
pub enum HostCall {
    /// A simulation-loop operation, `sim.setStepping(enable)` included.
    Remote(RemoteOp),
    /// `sim.step(wait=true)`; `wait` false (`client.step(wait=False)`) lets the
    /// simulation go on without waiting for the step.
    Step {
        /// Whether the caller waits for the step to be done.
        wait: bool,
    },
    /// `sim.loadScene(path)` (`Some`) or `sim.closeScene()` (`None`).
    LoadScene(Option<PathBuf>),
}

impl HostCall {
    /// Reads the arguments of the loop function `f`.
    ///
    /// # Errors
    /// A bad argument, in CoppeliaSim's words with the function's name.
    pub fn parse(f: FrontEndFn, args: &[Value]) -> Result<Self, CallError> {
        let a = Args::new(args);
        let in_function = |e: SimError| CallError::failed(format!("sim.{}", f.name()), e);
        Ok(match f {
            FrontEndFn::AcquireLock => HostCall::Remote(RemoteOp::Lock(true)),
            FrontEndFn::ReleaseLock => HostCall::Remote(RemoteOp::Lock(false)),
            FrontEndFn::StartSimulation => HostCall::Remote(RemoteOp::Control(Control::Start)),
            FrontEndFn::PauseSimulation => HostCall::Remote(RemoteOp::Control(Control::Pause)),
            FrontEndFn::StopSimulation => HostCall::Remote(RemoteOp::Control(Control::Stop)),
            FrontEndFn::SetStepping => HostCall::Remote(RemoteOp::SetStepping(a.bool(0).map_err(in_function)?)),
            FrontEndFn::Step => HostCall::Step {
                wait: args.first() != Some(&Value::Bool(false)),
            },
            FrontEndFn::LoadScene => HostCall::LoadScene(Some(a.str(0).map_err(in_function)?.into())),
            FrontEndFn::CloseScene => HostCall::LoadScene(None),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_loop_function_parses() {
        for (name, f) in gantry_sim_core::api::host::front_end_functions() {
            let args = match f {
                FrontEndFn::SetStepping => vec![Value::Bool(true)],
                FrontEndFn::LoadScene => vec![Value::from("scene.toml")],
                _ => Vec::new(),
            };
            assert!(HostCall::parse(f, &args).is_ok(), "{name}");
        }
        let e = HostCall::parse(FrontEndFn::SetStepping, &[]).unwrap_err();
        assert!(e.to_string().ends_with("(in function 'sim.setStepping')"), "{e}");
        assert_eq!(
            HostCall::parse(FrontEndFn::Step, &[Value::Bool(false)]).unwrap(),
            HostCall::Step { wait: false }
        );
    }
}
