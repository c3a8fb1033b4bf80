//! Real-time pacing: when the next step of a free-running simulation is due.
//!
//! Steps are scheduled from a fixed origin (step k is due at `origin + k dt`, the
//! first at once) rather than from the end of the previous step, so that jitter in
//! one step does not accumulate into drift. The origin is re-anchored whenever the
//! simulation stops being free running (paused, held by a stepping client, stopped),
//! so that the time spent there is not caught up afterwards, and when the simulation
//! falls more than [`MAX_LAG`] behind: a scene slower than real time then runs as fast
//! as it can instead of owing ever more steps.
//!
//! Pure bookkeeping over [`Instant`]s given by the caller: no clock is read here, so
//! the rules are tested with made-up times.

use std::time::{Duration, Instant};

/// How far a free-running simulation may fall behind the wall clock before pacing
/// gives up on the missed steps: one simulated second.
pub const MAX_LAG: Duration = Duration::from_secs(1);

/// The real-time schedule.
#[derive(Debug, Clone, Copy)]
pub struct Pacing {
    /// When step 0 of the current schedule was due.
    origin: Instant,
    /// Steps taken on this schedule.
    taken: u64,
}

impl Pacing {
    /// A schedule whose first step is due at `now`.
    pub fn new(now: Instant) -> Self {
        Self { origin: now, taken: 0 }
    }

    /// Starts the schedule afresh: the next step is due at `now`.
    pub fn restart(&mut self, now: Instant) {
        *self = Self::new(now);
    }

    /// When the next step is due, for steps of `dt` seconds.
    pub fn next_due(&self, dt: f64) -> Instant {
        self.origin + Duration::from_secs_f64(self.taken as f64 * dt.max(0.0))
    }

    /// How many steps are due at `now` and not yet taken (at least one once the next
    /// is due), at most [`MAX_LAG`]'s worth.
    pub fn due_steps(&self, now: Instant, dt: f64) -> u64 {
        if dt <= 0.0 || now < self.next_due(dt) {
            return 0;
        }
        let elapsed = now.saturating_duration_since(self.origin).as_secs_f64();
        let due = (elapsed / dt) as u64 + 1;
        due.saturating_sub(self.taken).min(Self::max_lag_steps(dt))
    }

    /// One step taken at `now` on this schedule. When the schedule is more than
    /// [`MAX_LAG`] behind `now`, it restarts from `now`.
    pub fn taken(&mut self, now: Instant, dt: f64) {
        self.taken += 1;
        let next = self.next_due(dt);
        if now.saturating_duration_since(next) > MAX_LAG {
            self.restart(now);
        }
    }

    fn max_lag_steps(dt: f64) -> u64 {
        ((MAX_LAG.as_secs_f64() / dt).ceil() as u64).max(1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DT: f64 = 0.05;

    fn ms(n: u64) -> Duration {
        Duration::from_millis(n)
    }

    #[test]
    fn steps_fall_due_on_a_fixed_grid_the_first_at_once() {
        let t0 = Instant::now();
        let mut p = Pacing::new(t0);
        assert_eq!(p.due_steps(t0, DT), 1);
        p.taken(t0, DT);
        assert_eq!(p.next_due(DT), t0 + ms(50));
        assert_eq!(p.due_steps(t0 + ms(49), DT), 0);
        // A late step does not move the grid: the next is still due at 100 ms.
        p.taken(t0 + ms(70), DT);
        assert_eq!(p.next_due(DT), t0 + ms(100));
        assert_eq!(p.due_steps(t0 + ms(260), DT), 4);
    }

    #[test]
    fn a_slow_simulation_owes_at_most_a_second_and_then_restarts() {
        let t0 = Instant::now();
        let mut p = Pacing::new(t0);
        assert_eq!(p.due_steps(t0 + Duration::from_secs(10), DT), 20);
        p.taken(t0 + Duration::from_secs(10), DT);
        // More than a second behind: the schedule starts again from that step.
        assert_eq!(p.next_due(DT), t0 + Duration::from_secs(10));
        assert_eq!(p.due_steps(t0 + Duration::from_secs(10), DT), 1);
    }

    #[test]
    fn restarting_forgets_the_time_spent_held() {
        let t0 = Instant::now();
        let mut p = Pacing::new(t0);
        p.taken(t0, DT);
        p.restart(t0 + Duration::from_secs(5));
        assert_eq!(p.due_steps(t0 + Duration::from_secs(5), DT), 1);
        assert_eq!(p.next_due(DT), t0 + Duration::from_secs(5));
    }
}
