//! The scripts' part of a step: the hooks the engine calls between the phases of its
//! step (`gantry_engine`'s `step.rs` holds CoppeliaSim's order), and the points inside
//! the vision phase where the engine may serve requests.
//!
//! The engine's step: [`LuaHost::begin_step`] (UI callbacks, ROS messages, every script
//! thread resumed), [`LuaHost::actuation`] (children's scripts before their parents'),
//! the physics substeps and proximity sensors, [`LuaHost::vision`] (vision sensors with
//! their `sysCall_vision`), [`LuaHost::sensing`], then simulation time advances and
//! what scripts asked for is carried out. Scripts see the step's start time throughout
//! the step, as in CoppeliaSim.

use std::borrow::Cow;

use gantry_sim_core::world::ObjectKind;
use gantry_sim_core::{Handle, Value, vision};
use mlua::{Function, Table};

use crate::convert::to_multi;
use crate::hooks::Hook;
use crate::host::LuaHost;
use crate::scripts::ScriptState;

/// A point inside a step where the engine lets its caller serve requests, and what
/// may be observed there.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepBoundary {
    /// Between two phases: anything may be read or called.
    Phase,
    /// A vision sensor has rendered and its `sysCall_vision` has not processed the
    /// image yet. A reader of vision sensors, or a script (which might read one),
    /// would see an image CoppeliaSim never shows, so such requests must wait; other
    /// world calls are fine.
    VisionUnprocessed,
}

impl LuaHost {
    /// The start of a step, before actuation: the callbacks of UI events and ROS 2
    /// messages that arrived since the last step, then every script thread resumed
    /// (CoppeliaSim resumes threads at the start of actuation).
    pub fn begin_step(&mut self) {
        self.dispatch_ui_events();
        self.dispatch_ros();
        self.scripts.resume_threads();
    }

    /// Every script's `sysCall_actuation`, children's before their parents'.
    pub fn actuation(&mut self) {
        for k in 0..self.scripts.order.len() {
            let i = self.scripts.order[k];
            if self.scripts.list[i].actuation.is_some() {
                self.scripts.call_hook(i, Hook::Actuation);
            }
        }
    }

    /// Every script's `sysCall_sensing`, children's before their parents'.
    pub fn sensing(&mut self) {
        for k in 0..self.scripts.order.len() {
            let i = self.scripts.order[k];
            if self.scripts.list[i].sensing.is_some() {
                self.scripts.call_hook(i, Hook::Sensing);
            }
        }
    }

    /// Runs the callbacks of UI events (a slider moved in the viewer, `simUI.interact`)
    /// in the scripts that created the UIs: `callback(ui, id, value)`, on the script's
    /// next turn, before actuation.
    fn dispatch_ui_events(&mut self) {
        let events = self.core.borrow_mut().uis.take_events();
        for ev in events {
            let scripts = &mut self.scripts;
            let Some(i) = scripts
                .list
                .iter()
                .position(|s| Some(s.object) == ev.script_object && s.state == ScriptState::Running)
            else {
                continue;
            };
            let name = scripts.list[i].name.clone();
            let Ok(Some(f)) = scripts.list[i].env.get::<Option<Function>>(ev.callback.as_str()) else {
                let msg = format!("UI callback '{}' is not a function of this script", ev.callback);
                self.core.log(300, &name, &msg);
                continue;
            };
            let args = match to_multi(&self.lua, &[Value::Int(ev.ui), Value::Int(ev.widget), ev.value.clone()]) {
                Ok(a) => a,
                Err(e) => {
                    self.core.log(200, &name, &format!("UI event dropped: {e}"));
                    continue;
                }
            };
            scripts.enter(i, Cow::Owned(ev.callback.clone()));
            let r = scripts.call_script::<()>(&f, args);
            scripts.leave();
            if let Err(e) = r {
                scripts.fail(i, e);
            }
        }
    }

    /// Renders the vision sensors whose scripts define `sysCall_vision`, then calls it
    /// with `inData.handle` (CoppeliaSim handles vision sensors after proximity sensors,
    /// before `sysCall_sensing`). Sensors without such a script render only when read.
    /// `between` is called after each render ([`StepBoundary::VisionUnprocessed`]) and
    /// after each callback ([`StepBoundary::Phase`]); no script runs then.
    pub fn vision(&mut self, between: &mut dyn FnMut(&mut LuaHost, StepBoundary)) {
        for k in 0..self.scripts.order.len() {
            let i = self.scripts.order[k];
            let Some(f) = self.scripts.list[i].vision.clone() else {
                continue;
            };
            let h = self.scripts.list[i].object;
            let rendered = {
                let sim = &mut *self.core.borrow_mut();
                vision::handle_vision_sensor(&sim.world, &mut sim.vision, h)
            };
            if let Err(e) = rendered {
                let msg = format!("sysCall_vision needs the script on a vision sensor: {e}");
                self.core.log(300, &self.scripts.list[i].name.clone(), &msg);
                self.scripts.list[i].vision = None;
                continue;
            }
            between(self, StepBoundary::VisionUnprocessed);
            let in_data = match self.vision_in_data(h) {
                Ok(t) => t,
                Err(e) => {
                    self.scripts.fail(i, e);
                    continue;
                }
            };
            self.scripts.enter(i, Cow::Borrowed("sysCall_vision"));
            let r = self.scripts.call_script::<Option<Table>>(&f, in_data);
            self.scripts.leave();
            match r {
                // `return {trigger = true, packedPackets = {sim.packFloatTable(...)}}`
                // makes readVisionSensor report a detection, as in CoppeliaSim.
                Ok(Some(out)) => {
                    let trigger = out.get::<Option<bool>>("trigger").ok().flatten().unwrap_or(false);
                    let packets: Vec<Vec<f64>> = out
                        .get::<Option<Vec<mlua::LuaString>>>("packedPackets")
                        .ok()
                        .flatten()
                        .unwrap_or_default()
                        .iter()
                        .map(|p| vision::unpack_floats(&p.as_bytes()))
                        .collect();
                    let _ = self.core.borrow_mut().vision.set_callback_result(h, trigger, packets);
                }
                Ok(None) => {}
                Err(e) => {
                    self.scripts.fail(i, e);
                }
            }
            between(self, StepBoundary::Phase);
        }
    }

    /// CoppeliaSim's `inData` for `sysCall_vision`: handle, resolution, clipping planes,
    /// view angle (rad) and the perspective flag.
    fn vision_in_data(&self, h: Handle) -> mlua::Result<Table> {
        let t = self.lua.create_table()?;
        t.set("handle", h)?;
        if let Ok(ObjectKind::VisionSensor(v)) = self.core.borrow().world.object(h).map(|o| &o.kind) {
            t.set(
                "resolution",
                vec![i64::from(v.resolution[0]), i64::from(v.resolution[1])],
            )?;
            t.set("clippingPlanes", vec![v.near, v.far])?;
            t.set("viewAngle", v.fov)?;
            t.set("orthoSize", v.ortho_size)?;
            t.set(
                "perspectiveOperation",
                v.projection == gantry_sim_core::scene::Projection::Perspective,
            )?;
        }
        Ok(t)
    }
}
