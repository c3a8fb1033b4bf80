//! The simulation's life, as the engine's own operations: start (or resume), pause
//! and stop, with their scripts' hooks, what follows for the stepping clients, and
//! what scripts asked for carried out once none runs.
//!
//! A stop runs every script's `sysCall_cleanup`, then puts back the scene as it was at
//! the start (`scene_copy`), as CoppeliaSim restores the scene when its simulation
//! stops: edits made while stopped stay, what the run moved goes back; the log
//! survives.

use std::time::Instant;

use gantry_lua::{LoadedModel, LuaHost};
use gantry_sim_core::Handle;
use gantry_sim_core::scene::SceneModel;
use gantry_sim_core::sim::{Advancing, Control, SimulationState};

use crate::engine::Engine;
use crate::scene::build_sim;
use crate::scene_copy::RestorePoint;

/// Appends a loaded model's objects and scripts to `scene` (indices moved past the
/// scene's), so that a stop rebuilds them.
fn merge_into(scene: &mut SceneModel, mut model: SceneModel) {
    let offset = scene.objects.len();
    model.offset_indices(offset);
    scene.objects.extend(model.objects);
    scene.scripts.extend(model.scripts);
    scene.dummy_links.extend(model.dummy_links);
    // A URDF model keeps its text and link names through a stop and restart too
    // (`/robot_description` and its TF frames on the ROS 2 graph).
    scene.urdf_robots.extend(model.urdf_robots);
}

impl Engine {
    /// Start (or resume), pause or stop, whoever asks: a remote client, the viewer,
    /// the command line, a script. A stop runs the cleanup hooks, restores the initial
    /// scene and resets every client's stepping level (as CoppeliaSim's add-on does,
    /// so a stopped client cannot hold the next run), even when the simulation was
    /// stopped already; blocking calls in progress end with an error. A pause answers
    /// the clients waiting for a step.
    pub(crate) fn control(&mut self, c: Control) {
        match c {
            Control::Start => {
                if self.state() != SimulationState::Running {
                    self.start();
                }
            }
            Control::Pause => self.pause(),
            Control::Stop => self.stop(),
        }
    }

    /// Starts (or resumes) the simulation: `sysCall_beforeSimulation` on a start,
    /// `sysCall_resume` on a resume, then `sysCall_init` of every script not yet
    /// initialised. Real-time pacing starts from now.
    fn start(&mut self) {
        // An interrupt left by a request that did not stop (a scene that failed to
        // load) must not cut the new run's first wait short.
        if let Some(host) = &self.host {
            host.clear_interrupt();
        }
        match self.state() {
            SimulationState::Stopped => {
                // The scene as it starts, edits made while stopped included.
                self.restore = Some(RestorePoint::capture(&self.sim.borrow(), &self.model));
                if let Some(host) = &mut self.host {
                    host.before_simulation();
                }
                self.sim.borrow_mut().advancing = Advancing::FirstAfterStop;
            }
            SimulationState::Paused => {
                {
                    let mut sim = self.sim.borrow_mut();
                    sim.state = SimulationState::Running;
                    sim.advancing = Advancing::FirstAfterPause;
                }
                if let Some(host) = &mut self.host {
                    host.resumed();
                }
            }
            SimulationState::Running => {}
        }
        self.sim.borrow_mut().state = SimulationState::Running;
        self.restart_pacing(Instant::now());
        if let Some(host) = &mut self.host {
            host.initialise();
        }
        self.carry_out_requests();
    }

    /// Pauses: steps are refused until a start; `sysCall_suspend` runs.
    fn pause(&mut self) {
        if self.state() == SimulationState::Running {
            self.sim.borrow_mut().state = SimulationState::Paused;
            if let Some(host) = &mut self.host {
                host.suspended();
            }
        }
        self.stepping.release_waiters();
    }

    /// Stops: every script's `sysCall_cleanup` runs, then the scene of the start comes
    /// back (or the scene model is rebuilt, see `scene_copy`) and the scripts are
    /// reloaded.
    fn stop(&mut self) {
        // The stop asked for is being served (even when already stopped).
        if let Some(host) = &self.host {
            host.clear_interrupt();
        }
        if self.state() != SimulationState::Stopped {
            self.sim.borrow_mut().advancing = Advancing::AboutToStop;
            self.cleanup();
            let loaded = self.host.as_mut().map(LuaHost::simulation_ended).unwrap_or_default();
            // A model a cleanup hook loaded joins the scene now being rebuilt.
            for LoadedModel { model, .. } in loaded {
                merge_into(&mut self.model, model);
            }
            let log = std::mem::take(&mut self.sim.borrow_mut().world.log);
            let restore = self.restore.take();
            let mut sim = match restore {
                Some(point) => point.restore(&self.model, &self.sim.borrow()),
                None => build_sim(&self.model),
            };
            sim.world.log = log;
            *self.sim.borrow_mut() = sim;
            if let Some(host) = &mut self.host {
                host.reload_all(&self.model.scripts);
            }
        }
        self.stepping.stopped();
        self.end_blocking();
    }

    /// Runs `sysCall_cleanup` of every initialised script (errored ones included, as in
    /// CoppeliaSim), then `sysCall_afterSimulation` if a run ended. Called by a stop and
    /// when the engine finishes.
    pub(crate) fn cleanup(&mut self) {
        let ended = self.state() != SimulationState::Stopped;
        if let Some(host) = &mut self.host {
            host.clean_up();
        }
        self.sim.borrow_mut().state = SimulationState::Stopped;
        if ended && let Some(host) = &mut self.host {
            host.after_simulation();
        }
    }

    /// Carries out what scripts asked for while they ran, now that none runs: models
    /// loaded (their scripts attach, and initialise if the simulation runs), and a
    /// start, pause or stop.
    pub(crate) fn carry_out_requests(&mut self) {
        let Some(host) = self.host.as_mut() else {
            return;
        };
        let requests = host.take_requests();
        let running = self.sim.borrow().state != SimulationState::Stopped;
        for LoadedModel { model, handles } in requests.models {
            // Each script runs on its object's live handle; the model's index is where
            // a stop will rebuild it. Script indices stay aligned with the model's.
            let objects: Vec<Handle> = model.scripts.iter().map(|s| handles[s.object]).collect();
            let first = self.model.scripts.len();
            merge_into(&mut self.model, model);
            host.attach_scripts(first, &self.model.scripts[first..], &objects, running);
        }
        if let Some(c) = requests.control {
            self.control(c);
        }
    }
}
