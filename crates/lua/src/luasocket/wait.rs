//! Waiting the way LuaSocket's blocking calls wait, without blocking gantry's exit.
//!
//! Every socket is non-blocking; a call that must wait (an `accept` with no client
//! yet, a `receive` whose line has not arrived) retries in short slices until it
//! succeeds, its timeout passes, or the process or the simulation is stopping (the
//! flags of [`crate::limits::NetworkParams`]). A non-threaded script then waits as it
//! does in CoppeliaSim (the simulation stops there until a client comes), while Ctrl-C
//! or a stop request still ends the wait within one slice.
//!
//! Time spent waiting is given back to the running hook's time budget (see
//! [`crate::budget`]): the budget is there to catch runaway Lua code, and a script
//! waiting for a client is not one. Without this, the first instructions after an
//! `accept` that waited more than the budget would interrupt the script.

use std::io;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use mlua::Lua;

use super::sockets::Sockets;
use crate::app_state::state;
use crate::running::Running;
use crate::waiting::Waiting;

/// How long one wait lasts before the call retries and looks at the stop flag: short
/// enough that a client is served within it and Ctrl-C is felt at once, long enough
/// that a script blocked for minutes costs no CPU to speak of (100 wake-ups a second).
pub(crate) const SLICE: Duration = Duration::from_millis(10);

/// How a wait ended.
#[derive(Debug)]
pub(crate) enum Waited<T> {
    /// The operation succeeded.
    Ready(T),
    /// The timeout passed first.
    TimedOut,
    /// The process or the simulation is stopping (which one); the call gives up.
    Stopping(&'static str),
}

/// Calls `attempt` until it returns `Some`, an error, `timeout` passes (`None`: never)
/// or the process is stopping. `attempt` returns `Ok(None)` when it would block. It is
/// always called at least once, so a zero timeout is a non-blocking try.
///
/// # Errors
/// The error `attempt` returned.
pub(crate) fn wait_for<T>(
    lua: &Lua,
    timeout: Option<Duration>,
    mut attempt: impl FnMut() -> io::Result<Option<T>>,
) -> io::Result<Waited<T>> {
    let start = Instant::now();
    let until = timeout.map(|t| start + t);
    let (stop, interrupt) = {
        let params = &state::<Sockets>(lua).params;
        (params.stop.clone(), params.interrupt.clone())
    };
    let mut slept = false;
    let result = loop {
        match attempt() {
            Ok(Some(v)) => break Ok(Waited::Ready(v)),
            Ok(None) => {}
            Err(e) => break Err(e),
        }
        let now = Instant::now();
        if until.is_some_and(|u| now >= u) {
            break Ok(Waited::TimedOut);
        }
        if stop.as_ref().is_some_and(|s| s.load(Ordering::SeqCst)) {
            break Ok(Waited::Stopping("gantry is stopping"));
        }
        if interrupt.as_ref().is_some_and(|s| s.load(Ordering::SeqCst)) {
            break Ok(Waited::Stopping("the simulation is stopping"));
        }
        let slice = until.map_or(SLICE, |u| u.saturating_duration_since(now).min(SLICE));
        // The front end is served meanwhile (see `crate::waiting`).
        state::<Waiting>(lua).pause(slice);
        slept = true;
    };
    if slept {
        let running = state::<Running>(lua);
        running.deadline.set(running.deadline.get() + start.elapsed());
    }
    result
}

/// `Ok(None)` for the errors that mean "not yet" on a non-blocking socket.
pub(crate) fn not_yet<T>(r: io::Result<T>) -> io::Result<Option<T>> {
    match r {
        Ok(v) => Ok(Some(v)),
        Err(e) if matches!(e.kind(), io::ErrorKind::WouldBlock | io::ErrorKind::Interrupted) => Ok(None),
        Err(e) => Err(e),
    }
}
