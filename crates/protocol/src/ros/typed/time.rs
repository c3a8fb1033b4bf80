//! `builtin_interfaces/msg/Time`, the stamp of every typed message, and simulation
//! seconds as the nanoseconds it is made from.

use super::cdr_writer::CdrWriter;

/// `builtin_interfaces/msg/Time`: a simulation time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Time {
    /// Whole seconds.
    pub sec: i32,
    /// Nanoseconds past `sec`, below 1e9.
    pub nanosec: u32,
}

impl Time {
    /// The time `ns` nanoseconds after zero (saturating at `i32::MAX` seconds, 68 years).
    pub fn from_nanos(ns: u64) -> Self {
        Self {
            sec: i32::try_from(ns / 1_000_000_000).unwrap_or(i32::MAX),
            // Below 1e9, so it fits.
            nanosec: (ns % 1_000_000_000) as u32,
        }
    }

    /// Its two fields, in order.
    pub(super) fn encode(self, w: &mut CdrWriter) {
        w.i32(self.sec);
        w.u32(self.nanosec);
    }
}

/// Simulation seconds as nanoseconds (negative and non-finite times become 0).
pub fn nanos_from_secs(t: f64) -> u64 {
    if t.is_finite() && t > 0.0 {
        // Saturating float-to-int cast; 584 years of simulation fit.
        (t * 1e9).round() as u64
    } else {
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_splits_nanoseconds() {
        assert_eq!(
            Time::from_nanos(2_500_000_001),
            Time {
                sec: 2,
                nanosec: 500_000_001
            }
        );
        assert_eq!(nanos_from_secs(0.05), 50_000_000);
        assert_eq!(nanos_from_secs(-1.0), 0);
        assert_eq!(nanos_from_secs(f64::NAN), 0);
    }
}
