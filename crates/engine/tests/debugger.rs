//! The script debugger's engine, driven as a transport drives it: a client thread sends
//! requests through the link while the test thread steps the simulation, which stops
//! (blocks) inside a script wherever the client asked.

use crate::util;

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, Sender};
use std::time::Duration;

use gantry_lua::debugger::{BreakpointSpec, StopReason, VariableInfo};
use gantry_lua::{DebugCommand, DebugEvent, DebugLink, DebugReply, DebugRequest, ScriptLimits};
use gantry_test_support::{TempDir, load};

/// `a.lua`: line numbers matter to the tests below.
const A: &str = "count = 0
function helper(x)
  local y = x * 2
  return y
end
function sysCall_actuation()
  count = count + 1
  local v = helper(count)
  local w = v + 1
end
function sysCall_sensing()
  local s = count
end
";

const ONE: &str = r#"
[simulation]
dt = 0.05

[[object]]
name = "a"
kind = "dummy"
script = "a.lua"
"#;

/// The client's side of the link.
struct Client {
    tx: Sender<DebugCommand>,
    events: Receiver<DebugEvent>,
    script: PathBuf,
}

impl Client {
    fn ask(&self, request: DebugRequest) -> Result<DebugReply, String> {
        let (reply, rx) = mpsc::channel();
        self.tx
            .send(DebugCommand {
                request,
                reply: Box::new(move |r| {
                    let _ = reply.send(r);
                }),
            })
            .expect("the simulation listens");
        rx.recv_timeout(Duration::from_secs(20))
            .expect("an answer")
            .map_err(|e| e.to_string())
    }

    fn ok(&self, request: DebugRequest) -> DebugReply {
        let what = format!("{request:?}");
        self.ask(request).unwrap_or_else(|e| panic!("{what} failed: {e}"))
    }

    fn breakpoints(&self, specs: Vec<BreakpointSpec>) {
        self.ok(DebugRequest::SetBreakpoints {
            path: self.script.clone(),
            breakpoints: specs,
        });
    }

    /// The next stop, skipping other events; panics after 20 s.
    fn stopped(&self) -> (StopReason, u32, Option<String>) {
        loop {
            match self.events.recv_timeout(Duration::from_secs(20)).expect("a stop") {
                DebugEvent::Stopped { reason, line, text, .. } => return (reason, line, text),
                _ => continue,
            }
        }
    }

    fn eval(&self, expression: &str) -> Result<VariableInfo, String> {
        match self.ask(DebugRequest::Evaluate {
            frame: None,
            expression: expression.into(),
        })? {
            DebugReply::Value(v) => Ok(v),
            other => panic!("evaluate answered {other:?}"),
        }
    }

    fn value(&self, expression: &str) -> String {
        self.eval(expression)
            .unwrap_or_else(|e| panic!("{expression}: {e}"))
            .value
    }

    fn frames(&self) -> Vec<gantry_lua::debugger::FrameInfo> {
        match self.ok(DebugRequest::StackTrace) {
            DebugReply::Frames(f) => f,
            other => panic!("stackTrace answered {other:?}"),
        }
    }

    fn variables(&self, reference: i64) -> Vec<VariableInfo> {
        match self.ok(DebugRequest::Variables { reference }) {
            DebugReply::Variables(v) => v,
            other => panic!("variables answered {other:?}"),
        }
    }

    fn scope(&self, frame: usize, name: &str) -> i64 {
        match self.ok(DebugRequest::Scopes { frame }) {
            DebugReply::Scopes(s) => s.iter().find(|s| s.name == name).expect("the scope").reference,
            other => panic!("scopes answered {other:?}"),
        }
    }
}

fn bp(line: u32) -> BreakpointSpec {
    BreakpointSpec {
        line,
        ..BreakpointSpec::default()
    }
}

/// Runs `client` on its own thread against a debugged simulation of `files`, stepping
/// on this thread until the client is done (at most `max_steps`).
fn debug_session(files: &[(&str, &str)], limits: ScriptLimits, client: impl FnOnce(Client) + Send + 'static) {
    let dir = TempDir::new("debugger");
    let scene = dir.write("scene.toml", ONE);
    for (name, text) in files {
        dir.write(name, text);
    }
    let (tx, commands) = mpsc::channel();
    let (etx, events) = mpsc::channel();
    let release = Arc::new(AtomicBool::new(false));
    let link = DebugLink {
        commands,
        events: Box::new(move |e| {
            let _ = etx.send(e);
        }),
        release: release.clone(),
    };
    let mut sim = util::engine_debugged(load(&scene), limits, link).expect("the simulation starts");
    let script = dir.path().join("a.lua");
    let done = Arc::new(AtomicBool::new(false));
    let flag = done.clone();
    // The client attaches before the first step, as a DAP client does before
    // configurationDone.
    let c = Client { tx, events, script };
    let (ready_tx, ready_rx) = mpsc::channel();
    let worker = std::thread::spawn(move || {
        c.ok(DebugRequest::Attach);
        let _ = ready_tx.send(());
        let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| client(c)));
        flag.store(true, Ordering::SeqCst);
        r
    });
    while ready_rx.try_recv().is_err() {
        sim.debug_poll();
        std::thread::sleep(Duration::from_millis(1));
    }
    let mut steps = 0;
    while !done.load(Ordering::SeqCst) {
        sim.debug_poll();
        sim.step();
        steps += 1;
        assert!(steps < 20_000, "the client did not finish");
        std::thread::sleep(Duration::from_millis(1));
    }
    release.store(true, Ordering::SeqCst);
    if let Err(p) = worker.join().expect("the client thread") {
        std::panic::resume_unwind(p);
    }
}

fn session(client: impl FnOnce(Client) + Send + 'static) {
    debug_session(&[("a.lua", A)], ScriptLimits::default(), client);
}

#[test]
fn a_breakpoint_stops_the_script_with_its_frames_and_the_simulation_stands_still() {
    session(|c| {
        c.breakpoints(vec![bp(9)]);
        let (reason, line, _) = c.stopped();
        assert_eq!((reason, line), (StopReason::Breakpoint, 9));
        let frames = c.frames();
        assert_eq!(frames.len(), 1);
        assert_eq!(frames[0].line, 9);
        assert!(
            frames[0].name.starts_with("sysCall_actuation @ /a"),
            "{}",
            frames[0].name
        );
        assert!(frames[0].path.ends_with("a.lua"));
        assert_eq!(c.value("count"), "1");
        assert_eq!(c.value("v * 10"), "20");
        let t0 = c.value("sim.getSimulationTime()");
        std::thread::sleep(Duration::from_millis(300));
        assert_eq!(c.value("sim.getSimulationTime()"), t0, "time stood still while stopped");
        // Locals and the script's own globals (without the API tables).
        let locals = c.variables(c.scope(1, "Locals"));
        let names: Vec<&str> = locals.iter().map(|v| v.name.as_str()).collect();
        assert_eq!(names, ["v"]);
        let globals = c.variables(c.scope(1, "Globals"));
        let names: Vec<&str> = globals.iter().map(|v| v.name.as_str()).collect();
        assert!(names.contains(&"count") && names.contains(&"helper"), "{names:?}");
        assert!(!names.contains(&"sim") && !names.contains(&"math"), "{names:?}");
        c.ok(DebugRequest::Continue);
        let (_, line, _) = c.stopped();
        assert_eq!(line, 9);
        assert_eq!(c.value("count"), "2", "the next step's hit");
        let t1: f64 = c.value("sim.getSimulationTime()").parse().unwrap();
        assert!(t1 > t0.parse::<f64>().unwrap());
        c.ok(DebugRequest::Detach);
    });
}

#[test]
fn steps_go_over_into_and_out_across_hooks() {
    session(|c| {
        c.breakpoints(vec![bp(8)]);
        assert_eq!(c.stopped().1, 8);
        c.ok(DebugRequest::StepIn);
        assert_eq!(c.stopped(), (StopReason::Step, 3, None), "into helper");
        assert_eq!(c.frames().len(), 2);
        assert!(c.frames()[0].name.starts_with("helper"));
        c.ok(DebugRequest::StepOver);
        assert_eq!(c.stopped().1, 4, "over, within helper");
        c.ok(DebugRequest::StepOut);
        // Back in the caller. Lua reports no new line for the rest of line 8 (the
        // assignment), so the first line the caller starts is 9.
        let (_, line, _) = c.stopped();
        assert_eq!(line, 9);
        assert_eq!(c.frames().len(), 1);
        c.breakpoints(vec![]);
        // Out of the hook: the next hook that runs is sysCall_sensing.
        c.ok(DebugRequest::StepOut);
        let (reason, line, _) = c.stopped();
        assert_eq!((reason, line), (StopReason::Step, 12));
        assert!(c.frames()[0].name.starts_with("sysCall_sensing"));
        c.ok(DebugRequest::Detach);
    });
}

#[test]
fn conditions_hit_counts_and_logpoints() {
    session(|c| {
        c.breakpoints(vec![BreakpointSpec {
            line: 9,
            condition: Some("count >= 3".into()),
            ..BreakpointSpec::default()
        }]);
        c.stopped();
        assert_eq!(c.value("count"), "3");
        c.breakpoints(vec![BreakpointSpec {
            line: 12,
            hit_condition: Some("2".into()),
            ..BreakpointSpec::default()
        }]);
        c.ok(DebugRequest::Continue);
        c.stopped();
        // Sensing of the step stopped in (hit 1) and of the next one (hit 2).
        assert_eq!(c.value("count"), "4");
        c.breakpoints(vec![BreakpointSpec {
            line: 9,
            log_message: Some("v is {v}".into()),
            ..BreakpointSpec::default()
        }]);
        c.ok(DebugRequest::Continue);
        let text = loop {
            match c.events.recv_timeout(Duration::from_secs(20)).expect("output") {
                DebugEvent::Output { text, .. } => break text,
                DebugEvent::Stopped { .. } => panic!("a logpoint does not stop"),
                DebugEvent::Continued => {}
            }
        };
        assert!(text.starts_with("v is "), "{text}");
        c.ok(DebugRequest::Detach);
    });
}

#[test]
fn an_uncaught_error_stops_at_its_line_and_the_script_then_fails() {
    let script = "function sysCall_actuation()\n  local t = nil\n  if sim.getSimulationTime() > 0.1 then\n    return t.x\n  end\nend\n";
    debug_session(&[("a.lua", script)], ScriptLimits::default(), |c| {
        let (reason, line, text) = c.stopped();
        assert_eq!((reason, line), (StopReason::Exception, 4));
        assert!(text.unwrap_or_default().contains("attempt to index"));
        assert_eq!(c.value("t"), "nil", "the failing frame's locals are there");
        c.ok(DebugRequest::Continue);
        c.ok(DebugRequest::Detach);
    });
}

#[test]
fn set_variable_changes_a_local_and_evaluate_stays_in_the_sandbox() {
    session(|c| {
        c.breakpoints(vec![bp(9)]);
        c.stopped();
        let locals = c.scope(1, "Locals");
        c.ok(DebugRequest::SetVariable {
            reference: locals,
            name: "v".into(),
            value: "40 + 2".into(),
        });
        assert_eq!(c.value("v"), "42");
        for escape in [
            "os.exit()",
            // Files outside the scene's folder and the --allow-files folders.
            "io.open('/etc/hostname')",
            "debug.getinfo(1)",
            "load('return 1')",
            "require('os')",
        ] {
            assert!(c.eval(escape).is_err(), "{escape} must fail inside the sandbox");
        }
        // A runaway expression is interrupted by the time budget, not the simulator.
        let err = c.eval("(function() while true do end end)()").unwrap_err();
        assert!(err.contains("time budget"), "{err}");
        assert_eq!(c.value("count"), "1", "the script is still there");
        c.ok(DebugRequest::Detach);
    });
}

#[test]
fn stopped_time_does_not_count_against_the_hook_budget() {
    let limits = ScriptLimits {
        time_budget: Duration::from_millis(300),
        ..ScriptLimits::default()
    };
    debug_session(&[("a.lua", A)], limits, |c| {
        c.breakpoints(vec![bp(9)]);
        c.stopped();
        std::thread::sleep(Duration::from_millis(800));
        c.breakpoints(vec![bp(12)]);
        c.ok(DebugRequest::Continue);
        assert_eq!(c.stopped().1, 12, "the script ran on, not interrupted");
        c.ok(DebugRequest::Detach);
    });
}

#[test]
fn a_threaded_script_stops_inside_its_coroutine() {
    let script =
        "function sysCall_thread()\n  local n = 0\n  while true do\n    n = n + 1\n    sim.step()\n  end\nend\n";
    debug_session(&[("a.lua", script)], ScriptLimits::default(), |c| {
        c.breakpoints(vec![BreakpointSpec {
            line: 4,
            condition: Some("n == 2".into()),
            ..BreakpointSpec::default()
        }]);
        c.stopped();
        assert_eq!(c.value("n"), "2");
        assert!(c.frames()[0].name.starts_with("sysCall_thread"));
        c.ok(DebugRequest::StepOver);
        assert_eq!(c.stopped().1, 5);
        c.ok(DebugRequest::Detach);
    });
}

#[test]
fn detaching_resumes_and_a_new_client_starts_clean() {
    session(|c| {
        c.breakpoints(vec![bp(9)]);
        c.stopped();
        c.ok(DebugRequest::Detach);
        // Detached: nothing stops any more.
        assert!(
            c.events
                .recv_timeout(Duration::from_millis(300))
                .is_ok_and(|e| e == DebugEvent::Continued)
        );
        assert!(
            !matches!(
                c.events.recv_timeout(Duration::from_millis(300)),
                Ok(DebugEvent::Stopped { .. })
            ),
            "no stop after detach"
        );
        c.ok(DebugRequest::Attach);
        c.breakpoints(vec![bp(7)]);
        assert_eq!(c.stopped().1, 7);
        c.ok(DebugRequest::Detach);
    });
}
