//! Remote clients' stepping levels and locks: when the simulation may take its next step.
//!
//! This is CoppeliaSim's ZMQ remote API stepping model (reference notes §2.6), kept as
//! plain data so it can be tested without a world or a socket:
//!
//! * `sim.setStepping(true)` raises a client's level, `false` lowers it; the call returns
//!   the previous level. Enabling sets the client's desired step to the current one, so
//!   a running simulation halts until that client calls `sim.step()`.
//! * `sim.step()` lets the simulation advance one step past the current one and parks
//!   the caller until the step counter gets there. With several stepping clients the
//!   simulation advances only when *every* one of them has asked for the next step.
//! * `sim.acquireLock()`/`sim.releaseLock()` form a per-client hold count; while any
//!   client holds a lock the simulation does not advance.
//! * A step asked for while the simulation is stopped or paused returns at once, and
//!   pausing or stopping releases every parked client: nobody waits for a step that
//!   cannot come. Stopping also resets every level to 0, as the real add-on does.
//!
//! Non-goal: time. This module counts steps; the simulation thread decides when to take
//! them (real-time pacing, `--fast`).

use std::collections::BTreeMap;

use tokio::sync::oneshot;

/// A remote client, as the simulation thread knows it. The ZMQ transport assigns one
/// per client uuid; ids are never reused within a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ClientId(pub u64);

/// Most nested `setStepping(true)` calls or held locks per client. The counters are
/// bounded so that a runaway client gets an error instead of a wrapped counter.
pub const MAX_LEVEL: u32 = 1 << 16;

/// Who is parked in `sim.step()`: answered once the step counter reaches `target`.
struct Waiter {
    target: u64,
    done: oneshot::Sender<()>,
}

/// One client's stepping state.
#[derive(Default)]
struct ClientStepping {
    /// Nesting level of `setStepping(true)`; the client gates the simulation while > 0.
    level: u32,
    /// The simulation may advance up to this step count while `level > 0`.
    desired: u64,
    /// Locks held (`acquireLock` minus `releaseLock`).
    locks: u32,
    /// The client's parked `sim.step()`, if any (a REQ client has one request at most).
    waiter: Option<Waiter>,
}

impl ClientStepping {
    fn is_idle(&self) -> bool {
        self.level == 0 && self.locks == 0 && self.waiter.is_none()
    }
}

/// Why a stepping request was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum SteppingError {
    /// The client nested `setStepping(true)` or `acquireLock()` too deep.
    #[error("nesting is too deep ({MAX_LEVEL} levels); pair every enable with a disable")]
    TooDeep,
}

/// Every remote client's stepping state. Owned by the simulation thread.
#[derive(Default)]
pub struct Stepping {
    /// Only clients with non-default state are kept: a client that never stepped costs
    /// nothing here.
    clients: BTreeMap<ClientId, ClientStepping>,
}

impl Stepping {
    /// `sim.setStepping(enable)` at step count `current`; returns the previous level.
    ///
    /// # Errors
    /// [`SteppingError::TooDeep`] past [`MAX_LEVEL`].
    pub fn set_stepping(&mut self, client: ClientId, enable: bool, current: u64) -> Result<u32, SteppingError> {
        let c = self.clients.entry(client).or_default();
        let previous = c.level;
        if enable {
            if c.level >= MAX_LEVEL {
                return Err(SteppingError::TooDeep);
            }
            c.level += 1;
            if previous == 0 {
                // Hold the simulation where it is until this client asks for a step.
                c.desired = current;
            }
        } else {
            c.level = c.level.saturating_sub(1);
        }
        self.forget_if_idle(client);
        Ok(previous)
    }

    /// `sim.acquireLock()` (`acquire`) or `sim.releaseLock()`. Releasing a lock that is
    /// not held is accepted and does nothing, as in CoppeliaSim.
    ///
    /// # Errors
    /// [`SteppingError::TooDeep`] past [`MAX_LEVEL`] locks.
    pub fn lock(&mut self, client: ClientId, acquire: bool) -> Result<(), SteppingError> {
        let c = self.clients.entry(client).or_default();
        if acquire {
            if c.locks >= MAX_LEVEL {
                return Err(SteppingError::TooDeep);
            }
            c.locks += 1;
        } else {
            c.locks = c.locks.saturating_sub(1);
        }
        self.forget_if_idle(client);
        Ok(())
    }

    /// `sim.step()` at step count `current`. When `advancing` is false (stopped or
    /// paused) the client is answered at once; otherwise it is parked until the
    /// counter reaches `current + 1`. A new step request replaces an older parked one
    /// of the same client (which is answered, so its sender is never left hanging).
    pub fn request_step(&mut self, client: ClientId, current: u64, advancing: bool, done: oneshot::Sender<()>) {
        if !advancing {
            let _ = done.send(());
            return;
        }
        let c = self.clients.entry(client).or_default();
        let target = current.saturating_add(1);
        if c.level > 0 {
            c.desired = c.desired.max(target);
        }
        if let Some(old) = c.waiter.replace(Waiter { target, done }) {
            let _ = old.done.send(());
        }
    }

    /// `client`'s blocking call needs the step after `current`: a stepping client's
    /// desired step moves there, as its own `sim.step()` would move it (nothing to do
    /// for a client that is not stepping).
    pub fn want_step(&mut self, client: ClientId, current: u64) {
        if let Some(c) = self.clients.get_mut(&client)
            && c.level > 0
        {
            c.desired = c.desired.max(current.saturating_add(1));
        }
    }

    /// Whether `client` holds a lock (`sim.acquireLock`).
    pub fn holds_lock(&self, client: ClientId) -> bool {
        self.clients.get(&client).is_some_and(|c| c.locks > 0)
    }

    /// Whether the simulation may go from step count `current` to `current + 1`.
    pub fn may_advance(&self, current: u64) -> bool {
        self.clients
            .values()
            .all(|c| c.locks == 0 && (c.level == 0 || c.desired > current))
    }

    /// Whether any client is stepping (the simulation thread then steps on demand
    /// instead of in real time).
    pub fn any_stepping(&self) -> bool {
        self.clients.values().any(|c| c.level > 0)
    }

    /// The step counter reached `current`: answers every client parked for it.
    pub fn stepped(&mut self, current: u64) {
        let mut emptied = Vec::new();
        for (id, c) in &mut self.clients {
            if c.waiter.as_ref().is_some_and(|w| w.target <= current) {
                if let Some(w) = c.waiter.take() {
                    let _ = w.done.send(());
                }
                if c.is_idle() {
                    emptied.push(*id);
                }
            }
        }
        for id in emptied {
            self.clients.remove(&id);
        }
    }

    /// The simulation paused or stopped: answers every parked client, since the step
    /// they wait for will not come until someone starts the simulation again.
    pub fn release_waiters(&mut self) {
        for c in self.clients.values_mut() {
            if let Some(w) = c.waiter.take() {
                let _ = w.done.send(());
            }
        }
        self.clients.retain(|_, c| !c.is_idle());
    }

    /// The simulation stopped: every level goes back to 0 and parked clients are
    /// answered. Locks stay with their holders.
    pub fn stopped(&mut self) {
        for c in self.clients.values_mut() {
            c.level = 0;
        }
        self.release_waiters();
    }

    /// Forgets a client that left (`_*end*_`) or went idle past its timeout, so it can
    /// no longer hold the simulation. A parked step of it is answered.
    pub fn drop_client(&mut self, client: ClientId) {
        if let Some(c) = self.clients.remove(&client)
            && let Some(w) = c.waiter
        {
            let _ = w.done.send(());
        }
    }

    /// Forgets every client (the transports are gone): parked clients are answered.
    pub fn clear(&mut self) {
        for (_, c) in std::mem::take(&mut self.clients) {
            if let Some(w) = c.waiter {
                let _ = w.done.send(());
            }
        }
    }

    /// Number of clients with any stepping state (for tests and logs).
    pub fn len(&self) -> usize {
        self.clients.len()
    }

    /// Whether no client has stepping state.
    pub fn is_empty(&self) -> bool {
        self.clients.is_empty()
    }

    fn forget_if_idle(&mut self, client: ClientId) {
        if self.clients.get(&client).is_some_and(ClientStepping::is_idle) {
            self.clients.remove(&client);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const A: ClientId = ClientId(1);
    const B: ClientId = ClientId(2);

    fn step(s: &mut Stepping, c: ClientId, current: u64) -> oneshot::Receiver<()> {
        let (tx, rx) = oneshot::channel();
        s.request_step(c, current, true, tx);
        rx
    }

    #[test]
    fn levels_nest_and_return_the_previous_value() {
        let mut s = Stepping::default();
        assert_eq!(s.set_stepping(A, true, 5), Ok(0));
        assert_eq!(s.set_stepping(A, true, 5), Ok(1));
        assert_eq!(s.set_stepping(A, false, 5), Ok(2));
        assert_eq!(s.set_stepping(A, false, 5), Ok(1));
        assert_eq!(s.set_stepping(A, false, 5), Ok(0));
        assert!(s.is_empty(), "a client back at level 0 is forgotten");
    }

    #[test]
    fn one_stepping_client_gates_the_simulation() {
        let mut s = Stepping::default();
        assert!(s.may_advance(10));
        s.set_stepping(A, true, 10).unwrap();
        assert!(!s.may_advance(10), "enabling holds the simulation at the current step");
        let mut rx = step(&mut s, A, 10);
        assert!(s.may_advance(10));
        assert!(rx.try_recv().is_err(), "parked until the step happens");
        s.stepped(11);
        assert!(rx.try_recv().is_ok());
        assert!(!s.may_advance(11), "one step per request");
    }

    #[test]
    fn every_stepping_client_must_ask() {
        let mut s = Stepping::default();
        s.set_stepping(A, true, 0).unwrap();
        s.set_stepping(B, true, 0).unwrap();
        let _a = step(&mut s, A, 0);
        assert!(!s.may_advance(0), "B has not asked yet");
        let _b = step(&mut s, B, 0);
        assert!(s.may_advance(0));
    }

    #[test]
    fn a_non_stepping_client_waits_for_the_next_step_without_gating() {
        let mut s = Stepping::default();
        let mut rx = step(&mut s, A, 3);
        assert!(s.may_advance(3));
        assert!(!s.any_stepping());
        s.stepped(4);
        assert!(rx.try_recv().is_ok());
        assert!(s.is_empty());
    }

    #[test]
    fn stopped_or_paused_answers_at_once_and_stop_resets_levels() {
        let mut s = Stepping::default();
        let (tx, mut rx) = oneshot::channel();
        s.request_step(A, 0, false, tx);
        assert!(rx.try_recv().is_ok());

        s.set_stepping(A, true, 0).unwrap();
        s.set_stepping(A, true, 0).unwrap();
        let mut parked = step(&mut s, A, 0);
        s.stopped();
        assert!(parked.try_recv().is_ok());
        assert_eq!(s.set_stepping(A, true, 0), Ok(0), "stop reset the level");
    }

    #[test]
    fn locks_hold_the_simulation_and_dropping_a_client_frees_it() {
        let mut s = Stepping::default();
        s.lock(A, true).unwrap();
        assert!(!s.may_advance(0));
        s.lock(A, false).unwrap();
        assert!(s.may_advance(0));
        s.lock(A, false).unwrap();
        assert!(s.is_empty(), "an unmatched release is harmless");

        s.set_stepping(B, true, 0).unwrap();
        let mut parked = step(&mut s, B, 0);
        s.set_stepping(A, true, 0).unwrap();
        assert!(!s.may_advance(0));
        s.drop_client(A);
        assert!(s.may_advance(0));
        s.drop_client(B);
        assert!(parked.try_recv().is_ok());
    }

    #[test]
    fn a_repeated_step_request_answers_the_older_one() {
        let mut s = Stepping::default();
        let mut first = step(&mut s, A, 0);
        let _second = step(&mut s, A, 0);
        assert!(first.try_recv().is_ok());
    }

    #[test]
    fn nesting_is_bounded() {
        let mut s = Stepping::default();
        for _ in 0..MAX_LEVEL {
            s.set_stepping(A, true, 0).unwrap();
        }
        assert_eq!(s.set_stepping(A, true, 0), Err(SteppingError::TooDeep));
    }
}
