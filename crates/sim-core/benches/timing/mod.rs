//! The figure every sim-core bench prints: the median and the minimum of many runs.

use std::time::Instant;

/// Median and minimum milliseconds of `f` over `n` runs (after one unmeasured warm-up
/// run), as "median (min)" with `decimals` digits: on a busy machine the minimum is the
/// steadier figure for comparing two versions.
pub fn median_ms(n: usize, decimals: usize, mut f: impl FnMut()) -> String {
    f();
    let mut times: Vec<f64> = (0..n.max(1))
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    format!("{:.decimals$} ({:.decimals$})", times[times.len() / 2], times[0])
}
