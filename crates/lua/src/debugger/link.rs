//! What a transport and the debugger exchange: the link (requests in, events out), the
//! requests and replies, and what they describe (breakpoints, frames, scopes,
//! variables). Plain data; the debugger itself is in `state.rs`.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::sync::mpsc::Receiver;

/// The two ends a transport gives the simulation: its requests, and where to report.
pub struct DebugLink {
    /// Requests, served between steps and while a script is stopped.
    pub commands: Receiver<DebugCommand>,
    /// Called on the simulation thread for each event; must not block.
    pub events: Box<dyn FnMut(DebugEvent) + Send>,
    /// Set when the process shuts down: a stopped script resumes and nothing stops again.
    pub release: Arc<AtomicBool>,
}

/// A request and where its answer goes.
pub struct DebugCommand {
    /// What to do.
    pub request: DebugRequest,
    /// Called once with the answer (on the simulation thread; must not block).
    pub reply: Box<dyn FnOnce(Result<DebugReply, DebuggerError>) + Send>,
}

/// Why the debugger refused a request. The text is what an editor shows the user.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DebuggerError {
    /// The request needs a stopped script (scopes, variables, evaluate), and none is.
    #[error("no script is stopped (set a breakpoint or pause first)")]
    NotStopped,
    /// A step request while no script is stopped.
    #[error("no script is stopped: nothing to step")]
    NothingToStep,
    /// A frame id beyond the stopped script's stack.
    #[error("no such frame")]
    NoSuchFrame,
    /// A variables reference this stop never handed out.
    #[error("unknown variables reference {0}")]
    UnknownReference(i64),
    /// An expression for a frame that belongs to no script of the scene.
    #[error("no script frame to evaluate in")]
    NoScriptFrame,
    /// setVariable on a name the scope does not have.
    #[error("no variable '{0}' in this scope")]
    NoSuchVariable(String),
    /// The Lua code run for the request (an expression, a new value) failed: Lua's message.
    #[error("{0}")]
    Lua(String),
}

/// What a debugger client can ask.
#[derive(Debug, Clone, PartialEq)]
pub enum DebugRequest {
    /// A client connected: start from no breakpoints.
    Attach,
    /// The client left: breakpoints are dropped and a stopped script resumes.
    Detach,
    /// Replaces the breakpoints of one script file (a path as the scene names it, or
    /// absolute). Answers [`DebugReply::Breakpoints`], one status per spec.
    SetBreakpoints {
        /// The script file.
        path: PathBuf,
        /// The breakpoints, one per line.
        breakpoints: Vec<BreakpointSpec>,
    },
    /// Whether an error no script catches stops the script (on by default).
    BreakOnError(bool),
    /// Resumes.
    Continue,
    /// Runs to the next line of the same function or a caller (or of the next hook).
    StepOver,
    /// Runs to the next line of any script code.
    StepIn,
    /// Runs until the function returns (or into the next hook, from a hook).
    StepOut,
    /// Stops at the next script line that runs.
    Pause,
    /// The stopped script's frames, top first ([`DebugReply::Frames`]).
    StackTrace,
    /// The scopes of a frame ([`DebugReply::Scopes`]); frames count from 1.
    Scopes {
        /// Frame id from [`FrameInfo::id`].
        frame: usize,
    },
    /// The variables behind a reference ([`DebugReply::Variables`]).
    Variables {
        /// From a scope or a table variable.
        reference: i64,
    },
    /// Evaluates an expression (or runs statements) in a frame of the stopped script,
    /// inside the script's sandbox ([`DebugReply::Value`]).
    Evaluate {
        /// Frame id; `None` for the top frame.
        frame: Option<usize>,
        /// Lua source.
        expression: String,
    },
    /// Assigns the value of `value` (a Lua expression) to `name` in a scope or table.
    SetVariable {
        /// The scope or table.
        reference: i64,
        /// Variable or key name as listed.
        name: String,
        /// A Lua expression, evaluated in the frame.
        value: String,
    },
    /// The script files of the scene ([`DebugReply::Sources`]).
    Sources,
}

/// One breakpoint as the client sets it.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BreakpointSpec {
    /// Line, from 1.
    pub line: u32,
    /// Stops only when this Lua expression is true in the frame.
    pub condition: Option<String>,
    /// Stops by hit count: `N` or `==N` (the Nth hit), `>N`, `>=N`, `<N`, `<=N`, `%N`.
    pub hit_condition: Option<String>,
    /// Logs this text instead of stopping; `{expr}` parts are evaluated.
    pub log_message: Option<String>,
}

/// Answers.
#[derive(Debug, Clone, PartialEq)]
pub enum DebugReply {
    /// Done, nothing to report.
    Done,
    /// One status per breakpoint asked for.
    Breakpoints(Vec<BreakpointStatus>),
    /// Stack frames, top first.
    Frames(Vec<FrameInfo>),
    /// Scopes of a frame.
    Scopes(Vec<ScopeInfo>),
    /// Variables of a scope or table.
    Variables(Vec<VariableInfo>),
    /// A value (evaluate, setVariable).
    Value(VariableInfo),
    /// Script files.
    Sources(Vec<PathBuf>),
}

/// Whether a breakpoint will be hit.
#[derive(Debug, Clone, PartialEq)]
pub struct BreakpointStatus {
    /// A script of the scene has this file and the line exists.
    pub verified: bool,
    /// The line.
    pub line: u32,
    /// Why not verified.
    pub message: Option<String>,
}

/// A stack frame of a stopped script.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameInfo {
    /// Id for [`DebugRequest::Scopes`] and [`DebugRequest::Evaluate`] (1 = top).
    pub id: usize,
    /// The function (for a hook: its name) and the script's object path.
    pub name: String,
    /// The script file, absolute where it exists on disk.
    pub path: PathBuf,
    /// Current line, from 1.
    pub line: u32,
}

/// A scope of a frame.
#[derive(Debug, Clone, PartialEq)]
pub struct ScopeInfo {
    /// "Locals", "Upvalues" or "Globals".
    pub name: &'static str,
    /// For [`DebugRequest::Variables`].
    pub reference: i64,
}

/// A variable (or an evaluated value) as an editor shows it.
#[derive(Debug, Clone, PartialEq)]
pub struct VariableInfo {
    /// Name (table keys: `[1]` for integers, the key for strings).
    pub name: String,
    /// The value as text (strings quoted).
    pub value: String,
    /// Lua's type name.
    pub type_name: String,
    /// Above 0 for a table: its entries, listed on request.
    pub reference: i64,
}

/// Why a script stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopReason {
    /// A breakpoint.
    Breakpoint,
    /// A step finished.
    Step,
    /// A pause request.
    Pause,
    /// An error no script caught.
    Exception,
}

impl StopReason {
    /// DAP's name for it.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Breakpoint => "breakpoint",
            Self::Step => "step",
            Self::Pause => "pause",
            Self::Exception => "exception",
        }
    }
}

/// What the debugger reports.
#[derive(Debug, Clone, PartialEq)]
pub enum DebugEvent {
    /// A script stopped: the simulation waits.
    Stopped {
        /// Why.
        reason: StopReason,
        /// The script file.
        path: PathBuf,
        /// Its line.
        line: u32,
        /// The error message, for [`StopReason::Exception`].
        text: Option<String>,
    },
    /// The script resumed.
    Continued,
    /// A logpoint's text.
    Output {
        /// The text, without a trailing newline.
        text: String,
        /// Where the logpoint is.
        path: PathBuf,
        /// Its line.
        line: u32,
    },
}
