//! How long a script may run and how much memory Lua may use.

use std::time::Duration;

/// Limits that keep a script from stalling or exhausting the simulator.
#[derive(Debug, Clone, Copy)]
pub struct ScriptLimits {
    /// Longest a single hook call may run before it is interrupted.
    pub time_budget: Duration,
    /// Memory of the shared Lua state, bytes.
    pub memory: usize,
}

impl Default for ScriptLimits {
    fn default() -> Self {
        Self {
            time_budget: Duration::from_secs(1),
            memory: 512 << 20,
        }
    }
}
