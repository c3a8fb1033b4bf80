//! The debugger's state and its two entry points from the Lua hook: a new line
//! ([`DebugHost::on_line`]) and an uncaught error ([`DebugHost::on_error`]).
//!
//! Borrowing rule: the state sits in a `RefCell` and no borrow is held across a call
//! into Lua, because Lua code run for the debugger (an expression, a condition) fires
//! the hook again.

use std::cell::{Cell, RefCell};
use std::collections::{HashMap, HashSet};
use std::path::{Component, Path, PathBuf};
use std::sync::atomic::Ordering;
use std::sync::mpsc::RecvTimeoutError;
use std::time::{Duration, Instant};

use mlua::{AppDataRef, Lua, Table, Thread, Value as LuaValue, VmState};

use super::inspect::{Inspector, RawFrame};
use super::link::{
    BreakpointSpec, BreakpointStatus, DebugCommand, DebugEvent, DebugLink, DebugReply, DebugRequest, DebuggerError,
    FrameInfo, ScopeInfo, StopReason, VariableInfo,
};
use crate::app_state::state;
use crate::directory::Directory;
use crate::lua_error::error_text;
use crate::running::Running;
use crate::sandbox::HostLibs;
use crate::threads::Threads;

/// How often a stopped script looks at the shutdown flag.
const HOLD_POLL: Duration = Duration::from_millis(50);

/// What the debugger reads and adjusts of the host while it holds a script: who runs
/// (its budget is suspended while stopped), the script directory (globals of a frame)
/// and the running thread's time slice.
struct Host<'a> {
    running: AppDataRef<'a, Running>,
    directory: AppDataRef<'a, Directory>,
    threads: AppDataRef<'a, Threads>,
}

impl<'a> Host<'a> {
    fn of(lua: &'a Lua) -> Self {
        Self {
            running: state(lua),
            directory: state(lua),
            threads: state(lua),
        }
    }
}

/// The debugger of one simulation (see the module docs of `debugger`).
pub(crate) struct DebugHost {
    state: RefCell<State>,
    inspect: Inspector,
    /// Set while a script is stopped or the debugger runs Lua of its own: line events
    /// then return at once.
    busy: Cell<bool>,
    /// Whether a line event has anything to check (breakpoints, a step, a pause): the
    /// one test every line pays while nothing is armed.
    armed: Cell<bool>,
}

struct State {
    link: Option<DebugLink>,
    attached: bool,
    /// Breakpoints by file key (see [`file_key`]).
    breakpoints: HashMap<PathBuf, Vec<Breakpoint>>,
    /// Every line that holds a breakpoint in some file: most lines are rejected here.
    lines: HashSet<u32>,
    break_on_error: bool,
    step: Option<Step>,
    pause: bool,
    /// Script chunks by chunk name (`@path`).
    files: HashMap<String, ScriptFile>,
    /// While stopped: what the requests inspect.
    session: Option<Session>,
}

struct Breakpoint {
    spec: BreakpointSpec,
    hits: u64,
}

#[derive(Clone)]
struct ScriptFile {
    key: PathBuf,
    /// Shown to the editor: absolute where the file exists.
    path: PathBuf,
    /// Script indices using this file, and their object paths.
    scripts: Vec<(usize, String)>,
    /// Lines in the file, to verify breakpoints.
    line_count: u32,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum StepMode {
    Over,
    In,
    Out,
}

#[derive(Debug, Clone, Copy)]
struct Step {
    mode: StepMode,
    /// The thread and stack depth stopped at, and which entry into a script it was.
    thread: *const std::ffi::c_void,
    depth: usize,
    entry: u64,
}

struct Session {
    co: Thread,
    frames: Vec<RawFrame>,
    refs: Vec<VarRef>,
}

#[derive(Clone)]
enum VarRef {
    Locals(usize),
    Upvalues(usize),
    Globals(Table),
    Table(Table),
}

/// What a request asks of a stopped script.
enum Resume {
    Continue,
    Step(StepMode),
}

impl DebugHost {
    pub(crate) fn new(lua: &Lua, libs: HostLibs, link: DebugLink) -> mlua::Result<Self> {
        Ok(Self {
            state: RefCell::new(State {
                link: Some(link),
                attached: false,
                breakpoints: HashMap::new(),
                lines: HashSet::new(),
                break_on_error: true,
                step: None,
                pause: false,
                files: HashMap::new(),
                session: None,
            }),
            inspect: Inspector::new(lua, libs)?,
            busy: Cell::new(false),
            armed: Cell::new(false),
        })
    }

    /// Gives the link back (to move the debugger to a newly loaded scene).
    pub(crate) fn take_link(&self) -> Option<DebugLink> {
        self.state.borrow_mut().link.take()
    }

    /// Forgets the scene's scripts (before they are loaded again).
    pub(crate) fn clear_scripts(&self) {
        let mut s = self.state.borrow_mut();
        for name in s.files.keys() {
            let _ = self.inspect.scripts.raw_set(name.as_str(), LuaValue::Nil);
        }
        s.files.clear();
    }

    /// Registers script `index` (file `path`, on object `object_path`), compiled with
    /// the chunk name `@path`. Breakpoints set for its file apply to it from now on,
    /// also after a reload.
    pub(crate) fn register_script(&self, index: usize, path: &Path, object_path: String, source: &str) {
        let chunk = format!("@{}", path.display());
        let _ = self.inspect.scripts.raw_set(chunk.as_str(), true);
        let line_count = u32::try_from(source.lines().count()).unwrap_or(u32::MAX);
        let mut s = self.state.borrow_mut();
        let entry = s.files.entry(chunk).or_insert_with(|| ScriptFile {
            key: file_key(path),
            path: shown_path(path),
            scripts: Vec::new(),
            line_count,
        });
        entry.line_count = line_count;
        entry.scripts.retain(|(i, _)| *i != index);
        entry.scripts.push((index, object_path));
    }

    /// A line event of the hook. `Continue` unless a stop ended in an error to raise.
    pub(crate) fn on_line(&self, lua: &Lua, debug: &mlua::debug::Debug) -> mlua::Result<VmState> {
        if !self.armed.get() || self.busy.get() {
            return Ok(VmState::Continue);
        }
        let Some(line) = debug.current_line().and_then(|l| u32::try_from(l).ok()) else {
            return Ok(VmState::Continue);
        };
        let (has_line, stepping) = {
            let s = self.state.borrow();
            (s.lines.contains(&line), s.step.is_some() || s.pause)
        };
        if !has_line && !stepping {
            return Ok(VmState::Continue);
        }
        let source = debug.source();
        let Some(chunk) = source.source.as_deref() else {
            return Ok(VmState::Continue);
        };
        let Some(file) = self.state.borrow().files.get(chunk).cloned() else {
            // Not a script: the API's own Lua, an evaluated expression. `sim.*` calls
            // are stepped over as one line this way.
            return Ok(VmState::Continue);
        };
        let depth = stack_depth(lua);
        let co = lua.current_thread();
        let host = &Host::of(lua);
        if stepping && self.step_done(&co, depth, host) {
            let reason = if self.state.borrow().pause {
                StopReason::Pause
            } else {
                StopReason::Step
            };
            self.hold(lua, &co, depth, reason, None, host);
            return Ok(VmState::Continue);
        }
        if has_line && let Some(reason) = self.breakpoint_hit(&co, &file, line, host) {
            self.hold(lua, &co, depth, reason, None, host);
        }
        Ok(VmState::Continue)
    }

    /// An error no script caught, seen from the message handler of the protected call
    /// that runs a hook (the failing frame is still on the stack).
    pub(crate) fn on_error(&self, lua: &Lua, message: &LuaValue) {
        let host = &Host::of(lua);
        if self.busy.get() || host.running.interrupted.get() {
            return;
        }
        {
            let s = self.state.borrow();
            if !s.attached || !s.break_on_error {
                return;
            }
        }
        let text = match message {
            LuaValue::String(s) => s.to_string_lossy(),
            LuaValue::Error(e) => error_text(e),
            other => self.inspect.describe(other).0,
        };
        let co = lua.current_thread();
        self.hold(lua, &co, stack_depth(lua), StopReason::Exception, Some(text), host);
    }

    /// Serves the requests that arrived while no script is stopped.
    pub(crate) fn poll(&self, lua: &Lua) {
        let host = &Host::of(lua);
        loop {
            let cmd = {
                let s = self.state.borrow();
                let Some(link) = &s.link else { return };
                match link.commands.try_recv() {
                    Ok(c) => c,
                    Err(_) => return,
                }
            };
            let (reply, _) = self.serve(lua, cmd.request, host);
            (cmd.reply)(reply);
        }
    }

    /// Whether a pending step (or pause) ends at this line.
    fn step_done(&self, co: &Thread, depth: usize, host: &Host<'_>) -> bool {
        let s = self.state.borrow();
        if s.pause {
            return true;
        }
        let Some(step) = s.step else { return false };
        let elsewhere = step.thread != co.to_pointer() || step.entry != host.running.entries.get();
        match step.mode {
            StepMode::In => true,
            // From another thread or a later hook call: the stepped function is gone,
            // so stop in whatever script code runs next.
            StepMode::Over => elsewhere || depth <= step.depth,
            StepMode::Out => elsewhere || depth < step.depth,
        }
    }

    /// Counts a hit of the breakpoint at `line` of `file` and decides: stop, log, or
    /// go on.
    fn breakpoint_hit(&self, co: &Thread, file: &ScriptFile, line: u32, host: &Host<'_>) -> Option<StopReason> {
        let spec = {
            let s = self.state.borrow();
            s.breakpoints
                .get(&file.key)?
                .iter()
                .find(|b| b.spec.line == line)?
                .spec
                .clone()
        };
        if let Some(cond) = &spec.condition
            && !cond.trim().is_empty()
        {
            match self.evaluate_at(co, 1, cond, host) {
                Ok(v) => {
                    if matches!(v, LuaValue::Nil | LuaValue::Boolean(false)) {
                        return None;
                    }
                }
                // A condition that fails stops, with the reason in the log: silently
                // never stopping would hide the mistake.
                Err(e) => self.emit(DebugEvent::Output {
                    text: format!("breakpoint condition `{cond}` failed: {e}"),
                    path: file.path.clone(),
                    line,
                }),
            }
        }
        let hits = {
            let mut s = self.state.borrow_mut();
            let b = s
                .breakpoints
                .get_mut(&file.key)
                .and_then(|v| v.iter_mut().find(|b| b.spec.line == line))?;
            b.hits += 1;
            b.hits
        };
        if let Some(h) = &spec.hit_condition
            && !hit_condition_met(h, hits)
        {
            return None;
        }
        if let Some(msg) = &spec.log_message {
            let text = self.interpolate(co, msg, host);
            self.emit(DebugEvent::Output {
                text,
                path: file.path.clone(),
                line,
            });
            return None;
        }
        Some(StopReason::Breakpoint)
    }

    /// A logpoint's message with each `{expr}` replaced by its value.
    fn interpolate(&self, co: &Thread, msg: &str, host: &Host<'_>) -> String {
        let mut out = String::new();
        let mut rest = msg;
        while let Some(open) = rest.find('{') {
            out.push_str(&rest[..open]);
            let after = &rest[open + 1..];
            let Some(close) = after.find('}') else {
                out.push_str(&rest[open..]);
                return out;
            };
            let expr = &after[..close];
            match self.evaluate_at(co, 1, expr, host) {
                Ok(LuaValue::String(s)) => out.push_str(&s.to_string_lossy()),
                Ok(v) => out.push_str(&self.inspect.describe(&v).0),
                Err(e) => out.push_str(&format!("<{e}>")),
            }
            rest = &after[close + 1..];
        }
        out.push_str(rest);
        out
    }

    /// Stops the simulation here until the client resumes it.
    fn hold(&self, lua: &Lua, co: &Thread, depth: usize, reason: StopReason, text: Option<String>, host: &Host<'_>) {
        let started = Instant::now();
        // The stopped time is not the script's: no budget, no pre-emption meanwhile.
        let deadline = host.running.deadline.replace(started + Duration::from_secs(3600 * 24));
        let slice_end = host.threads.take_slice_end();
        let interrupted = host.running.interrupted.get();
        self.busy.set(true);
        let frames = self.inspect.frames(co).unwrap_or_default();
        let (path, line) = match frames.first() {
            Some(f) => (self.file_of(&f.source).map(|f| f.path).unwrap_or_default(), f.line),
            None => (PathBuf::new(), 0),
        };
        {
            let mut s = self.state.borrow_mut();
            s.step = None;
            s.pause = false;
            s.session = Some(Session {
                co: co.clone(),
                frames,
                refs: Vec::new(),
            });
        }
        self.emit(DebugEvent::Stopped {
            reason,
            path,
            line,
            text,
        });
        let resume = loop {
            let next = {
                let s = self.state.borrow();
                let Some(link) = &s.link else { break Resume::Continue };
                if link.release.load(Ordering::SeqCst) {
                    break Resume::Continue;
                }
                link.commands.recv_timeout(HOLD_POLL)
            };
            let cmd: DebugCommand = match next {
                Ok(c) => c,
                Err(RecvTimeoutError::Timeout) => continue,
                Err(RecvTimeoutError::Disconnected) => break Resume::Continue,
            };
            let (reply, resume) = self.serve(lua, cmd.request, host);
            (cmd.reply)(reply);
            if let Some(r) = resume {
                break r;
            }
        };
        let entry = host.running.entries.get();
        {
            let mut s = self.state.borrow_mut();
            s.session = None;
            if let Resume::Step(mode) = resume {
                // After an error the failing function is about to unwind: any next
                // script line is the next step.
                let mode = if reason == StopReason::Exception {
                    StepMode::In
                } else {
                    mode
                };
                s.step = Some(Step {
                    mode,
                    thread: co.to_pointer(),
                    depth,
                    entry,
                });
            }
        }
        self.busy.set(false);
        self.update_armed();
        self.emit(DebugEvent::Continued);
        let paused = started.elapsed();
        host.running.deadline.set(deadline + paused);
        host.threads.set_slice_end(slice_end.map(|t| t + paused));
        host.running.interrupted.set(interrupted);
    }

    /// Answers one request; `Some` when it resumes a stopped script.
    fn serve(
        &self,
        lua: &Lua,
        request: DebugRequest,
        host: &Host<'_>,
    ) -> (Result<DebugReply, DebuggerError>, Option<Resume>) {
        let stopped = self.state.borrow().session.is_some();
        let resume = |r: Resume| {
            if stopped {
                (Ok(DebugReply::Done), Some(r))
            } else {
                (Ok(DebugReply::Done), None)
            }
        };
        match request {
            DebugRequest::Attach => {
                let mut s = self.state.borrow_mut();
                s.attached = true;
                s.breakpoints.clear();
                s.lines.clear();
                s.break_on_error = true;
                drop(s);
                self.update_armed();
                (Ok(DebugReply::Done), None)
            }
            DebugRequest::Detach => {
                let mut s = self.state.borrow_mut();
                s.attached = false;
                s.breakpoints.clear();
                s.lines.clear();
                s.step = None;
                s.pause = false;
                drop(s);
                self.update_armed();
                resume(Resume::Continue)
            }
            DebugRequest::SetBreakpoints { path, breakpoints } => {
                let statuses = self.set_breakpoints(&path, breakpoints);
                (Ok(DebugReply::Breakpoints(statuses)), None)
            }
            DebugRequest::BreakOnError(on) => {
                self.state.borrow_mut().break_on_error = on;
                (Ok(DebugReply::Done), None)
            }
            DebugRequest::Continue => resume(Resume::Continue),
            DebugRequest::StepOver => self.step_or_refuse(stopped, StepMode::Over),
            DebugRequest::StepIn => self.step_or_refuse(stopped, StepMode::In),
            DebugRequest::StepOut => self.step_or_refuse(stopped, StepMode::Out),
            DebugRequest::Pause => {
                if !stopped {
                    self.state.borrow_mut().pause = true;
                    self.update_armed();
                }
                (Ok(DebugReply::Done), None)
            }
            DebugRequest::StackTrace => (Ok(DebugReply::Frames(self.stack(host))), None),
            DebugRequest::Scopes { frame } => (self.scopes(frame, host), None),
            DebugRequest::Variables { reference } => (self.variables(lua, reference), None),
            DebugRequest::Evaluate { frame, expression } => (self.evaluate(frame, &expression, host), None),
            DebugRequest::SetVariable { reference, name, value } => {
                (self.set_variable(reference, &name, &value, host), None)
            }
            DebugRequest::Sources => {
                let s = self.state.borrow();
                let mut paths: Vec<PathBuf> = s.files.values().map(|f| f.path.clone()).collect();
                paths.sort();
                paths.dedup();
                (Ok(DebugReply::Sources(paths)), None)
            }
        }
    }

    fn step_or_refuse(&self, stopped: bool, mode: StepMode) -> (Result<DebugReply, DebuggerError>, Option<Resume>) {
        if stopped {
            (Ok(DebugReply::Done), Some(Resume::Step(mode)))
        } else {
            (Err(DebuggerError::NothingToStep), None)
        }
    }

    fn set_breakpoints(&self, path: &Path, specs: Vec<BreakpointSpec>) -> Vec<BreakpointStatus> {
        let key = file_key(path);
        let mut s = self.state.borrow_mut();
        let file = s.files.values().find(|f| f.key == key).cloned();
        let statuses = specs
            .iter()
            .map(|b| match &file {
                None => BreakpointStatus {
                    verified: false,
                    line: b.line,
                    message: Some(format!(
                        "no script of this scene is {} (the breakpoint applies if one is loaded)",
                        path.display()
                    )),
                },
                Some(f) if b.line == 0 || b.line > f.line_count => BreakpointStatus {
                    verified: false,
                    line: b.line,
                    message: Some(format!("{} has {} lines", f.path.display(), f.line_count)),
                },
                Some(_) => BreakpointStatus {
                    verified: true,
                    line: b.line,
                    message: None,
                },
            })
            .collect();
        if specs.is_empty() {
            s.breakpoints.remove(&key);
        } else {
            let list = specs.into_iter().map(|spec| Breakpoint { spec, hits: 0 }).collect();
            s.breakpoints.insert(key, list);
        }
        s.lines = s.breakpoints.values().flatten().map(|b| b.spec.line).collect();
        drop(s);
        self.update_armed();
        statuses
    }

    fn update_armed(&self) {
        let s = self.state.borrow();
        self.armed
            .set(s.attached && (!s.lines.is_empty() || s.step.is_some() || s.pause));
    }

    fn file_of(&self, chunk: &str) -> Option<ScriptFile> {
        self.state.borrow().files.get(chunk).cloned()
    }

    fn stack(&self, host: &Host<'_>) -> Vec<FrameInfo> {
        let s = self.state.borrow();
        let Some(session) = &s.session else {
            return Vec::new();
        };
        let n = session.frames.len();
        session
            .frames
            .iter()
            .enumerate()
            .map(|(i, f)| {
                let file = s.files.get(&f.source);
                // The bottom frame was called by the host: it is the hook running now.
                let function = match &f.name {
                    Some(name) => name.clone(),
                    None if i + 1 == n => host.running.hook.borrow().to_string(),
                    None => "function".into(),
                };
                let object = file
                    .and_then(|file| {
                        let current = host.running.script.get();
                        file.scripts
                            .iter()
                            .find(|(idx, _)| Some(*idx) == current)
                            .or(file.scripts.first())
                            .map(|(_, p)| p.clone())
                    })
                    .unwrap_or_default();
                FrameInfo {
                    id: i + 1,
                    name: format!("{function} @ {object}"),
                    path: file.map(|f| f.path.clone()).unwrap_or_default(),
                    line: f.line,
                }
            })
            .collect()
    }

    fn scopes(&self, frame: usize, host: &Host<'_>) -> Result<DebugReply, DebuggerError> {
        let mut s = self.state.borrow_mut();
        let State { session, files, .. } = &mut *s;
        let session = session.as_mut().ok_or(DebuggerError::NotStopped)?;
        let f = session
            .frames
            .get(frame.wrapping_sub(1))
            .ok_or(DebuggerError::NoSuchFrame)?;
        let env = files
            .get(&f.source)
            .and_then(|file| file.scripts.first())
            .and_then(|(idx, _)| host.directory.entry(*idx).map(|e| e.env));
        let mut out = Vec::new();
        session.refs.push(VarRef::Locals(frame));
        out.push(ScopeInfo {
            name: "Locals",
            reference: session.refs.len() as i64,
        });
        session.refs.push(VarRef::Upvalues(frame));
        out.push(ScopeInfo {
            name: "Upvalues",
            reference: session.refs.len() as i64,
        });
        if let Some(env) = env {
            session.refs.push(VarRef::Globals(env));
            out.push(ScopeInfo {
                name: "Globals",
                reference: session.refs.len() as i64,
            });
        }
        Ok(DebugReply::Scopes(out))
    }

    fn variables(&self, lua: &Lua, reference: i64) -> Result<DebugReply, DebuggerError> {
        let (co, var) = self.lookup(reference)?;
        self.busy.set(true);
        let pairs: Result<Vec<(String, LuaValue)>, DebuggerError> = match &var {
            VarRef::Locals(k) => self.inspect.scope(&co, *k, false).map_err(lua_failed),
            VarRef::Upvalues(k) => self.inspect.scope(&co, *k, true).map_err(lua_failed),
            VarRef::Globals(env) => Ok(script_globals(lua, env)),
            VarRef::Table(t) => self
                .inspect
                .entries(t)
                .map(|v| v.into_iter().map(|(n, v, _)| (n, v)).collect())
                .map_err(lua_failed),
        };
        let out = pairs.map(|pairs| pairs.into_iter().map(|(n, v)| self.variable(n, &v)).collect());
        self.busy.set(false);
        out.map(DebugReply::Variables)
    }

    fn lookup(&self, reference: i64) -> Result<(Thread, VarRef), DebuggerError> {
        let s = self.state.borrow();
        let session = s.session.as_ref().ok_or(DebuggerError::NotStopped)?;
        let var = usize::try_from(reference - 1)
            .ok()
            .and_then(|i| session.refs.get(i))
            .ok_or(DebuggerError::UnknownReference(reference))?;
        Ok((session.co.clone(), var.clone()))
    }

    /// The variable as shown, registering a reference when it is a table.
    fn variable(&self, name: String, v: &LuaValue) -> VariableInfo {
        let (value, type_name) = self.inspect.describe(v);
        let reference = match v {
            LuaValue::Table(t) => {
                let mut s = self.state.borrow_mut();
                match s.session.as_mut() {
                    Some(session) => {
                        session.refs.push(VarRef::Table(t.clone()));
                        session.refs.len() as i64
                    }
                    None => 0,
                }
            }
            _ => 0,
        };
        VariableInfo {
            name,
            value,
            type_name,
            reference,
        }
    }

    fn evaluate(&self, frame: Option<usize>, expression: &str, host: &Host<'_>) -> Result<DebugReply, DebuggerError> {
        let co = {
            let s = self.state.borrow();
            s.session
                .as_ref()
                .map(|x| x.co.clone())
                .ok_or(DebuggerError::NotStopped)?
        };
        let v = self.evaluate_at(&co, frame.unwrap_or(1), expression, host)?;
        Ok(DebugReply::Value(self.variable(expression.to_owned(), &v)))
    }

    /// Runs `code` in frame `k` of `co` under a fresh time budget; its first result.
    fn evaluate_at(&self, co: &Thread, k: usize, code: &str, host: &Host<'_>) -> Result<LuaValue, DebuggerError> {
        let env = self.env_of_frame(co, k, host).ok_or(DebuggerError::NoScriptFrame)?;
        let was_busy = self.busy.replace(true);
        let deadline = host.running.deadline.replace(Instant::now() + host.running.budget);
        let interrupted = host.running.interrupted.replace(false);
        let result = self
            .inspect
            .compile(Some((co, k)), &env, code)
            .and_then(|f| self.inspect.run(f));
        host.running.deadline.set(deadline);
        host.running.interrupted.set(interrupted);
        self.busy.set(was_busy);
        result.map(|values| values.into_iter().next().unwrap_or(LuaValue::Nil))
    }

    /// The globals of the script that frame `k` of `co` belongs to.
    fn env_of_frame(&self, co: &Thread, k: usize, host: &Host<'_>) -> Option<Table> {
        let source = {
            let s = self.state.borrow();
            match &s.session {
                Some(session) if session.co.to_pointer() == co.to_pointer() => {
                    session.frames.get(k.checked_sub(1)?)?.source.clone()
                }
                _ => self.inspect.frames(co).ok()?.get(k.checked_sub(1)?)?.source.clone(),
            }
        };
        let idx = self.file_of(&source)?.scripts.first()?.0;
        host.directory.entry(idx).map(|e| e.env)
    }

    fn set_variable(
        &self,
        reference: i64,
        name: &str,
        value: &str,
        host: &Host<'_>,
    ) -> Result<DebugReply, DebuggerError> {
        let (co, var) = self.lookup(reference)?;
        let frame = match &var {
            VarRef::Locals(k) | VarRef::Upvalues(k) => *k,
            _ => 1,
        };
        let v = self.evaluate_at(&co, frame, value, host)?;
        self.busy.set(true);
        let done = match &var {
            VarRef::Locals(k) => self.inspect.set(&co, *k, name, v.clone(), false),
            VarRef::Upvalues(k) => self.inspect.set(&co, *k, name, v.clone(), true),
            VarRef::Globals(t) => t.raw_set(name, v.clone()).map(|()| true),
            VarRef::Table(t) => {
                // Entries are listed as `[1]` for integer keys, by name otherwise.
                let key = match name.strip_prefix('[').and_then(|n| n.strip_suffix(']')) {
                    Some(n) => n.parse::<i64>().map_or(LuaValue::Nil, LuaValue::Integer),
                    None => LuaValue::Nil,
                };
                let r = if key.is_nil() {
                    t.raw_set(name, v.clone())
                } else {
                    t.raw_set(key, v.clone())
                };
                r.map(|()| true)
            }
        };
        self.busy.set(false);
        match done {
            Ok(true) => Ok(DebugReply::Value(self.variable(name.to_owned(), &v))),
            Ok(false) => Err(DebuggerError::NoSuchVariable(name.to_owned())),
            Err(e) => Err(lua_failed(e)),
        }
    }

    fn emit(&self, event: DebugEvent) {
        let mut s = self.state.borrow_mut();
        if let Some(link) = s.link.as_mut() {
            (link.events)(event);
        }
    }
}

/// A Lua error met while inspecting, as the editor shows it (mlua's full text).
fn lua_failed(e: mlua::Error) -> DebuggerError {
    DebuggerError::Lua(e.to_string())
}

/// The script's own globals: its environment without what every script gets (the
/// API and library tables, `print`, `require`).
fn script_globals(lua: &Lua, env: &Table) -> Vec<(String, LuaValue)> {
    let base = lua.globals();
    let mut out: Vec<(String, LuaValue)> = env
        .pairs::<LuaValue, LuaValue>()
        .filter_map(Result::ok)
        .filter_map(|(k, v)| {
            let name = k.as_string()?.to_str().ok()?.to_owned();
            let shared = matches!(name.as_str(), "_G" | "print" | "require")
                || !matches!(base.raw_get::<LuaValue>(name.as_str()), Ok(LuaValue::Nil));
            (!shared).then_some((name, v))
        })
        .take(super::inspect::MAX_ENTRIES as usize)
        .collect();
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

/// How many frames the running thread has (levels of `lua_getstack`).
fn stack_depth(lua: &Lua) -> usize {
    let mut n = 0;
    while lua.inspect_stack(n, |_| ()).is_some() {
        n += 1;
    }
    n
}

/// Whether a hit count meets a DAP hit condition: `N`/`==N` the Nth hit, `>N`, `>=N`,
/// `<N`, `<=N`, `%N` every Nth. An unreadable condition never stops.
pub(super) fn hit_condition_met(condition: &str, hits: u64) -> bool {
    let c = condition.trim();
    let (op, n) = ["==", ">=", "<=", ">", "<", "%", "="]
        .iter()
        .find_map(|op| c.strip_prefix(op).map(|rest| (*op, rest)))
        .unwrap_or(("==", c));
    let Ok(n) = n.trim().parse::<u64>() else {
        return false;
    };
    match op {
        ">=" => hits >= n,
        "<=" => hits <= n,
        ">" => hits > n,
        "<" => hits < n,
        "%" => n > 0 && hits.is_multiple_of(n),
        _ => hits == n,
    }
}

/// The path breakpoints are matched by: absolute and without `.`/`..`, through
/// symbolic links where the file exists.
fn file_key(path: &Path) -> PathBuf {
    std::fs::canonicalize(path).unwrap_or_else(|_| normalize(path))
}

/// The path shown to editors: absolute where the file exists, else as named.
fn shown_path(path: &Path) -> PathBuf {
    std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
}

fn normalize(path: &Path) -> PathBuf {
    let absolute = if path.is_absolute() {
        path.to_path_buf()
    } else {
        std::env::current_dir().unwrap_or_default().join(path)
    };
    let mut out = PathBuf::new();
    for c in absolute.components() {
        match c {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            other => out.push(other),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hit_conditions_follow_the_documented_forms() {
        assert!(hit_condition_met("3", 3));
        assert!(!hit_condition_met("3", 2));
        assert!(hit_condition_met("==3", 3));
        assert!(hit_condition_met(">= 2", 2));
        assert!(!hit_condition_met(">2", 2));
        assert!(hit_condition_met("<2", 1));
        assert!(hit_condition_met("%2", 4));
        assert!(!hit_condition_met("%2", 3));
        assert!(!hit_condition_met("%0", 3));
        assert!(!hit_condition_met("often", 3));
    }

    #[test]
    fn paths_normalise_without_the_file_existing() {
        assert_eq!(normalize(Path::new("/a/b/../c/./d.lua")), PathBuf::from("/a/c/d.lua"));
    }
}
