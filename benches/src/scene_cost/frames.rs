//! Frames timed: ns per frame of anything that advances by whole frames.

use lagrange_benches::timing::{interleaved, median_of_runs, Budget};

/// Frames per timed run: enough that a run of a nearly empty scene is not all clock reading.
pub const FRAMES_PER_RUN: usize = 120;

/// Median ns per frame of `frame` (called [`FRAMES_PER_RUN`] times per timed run).
pub fn ns_per_frame(budget: Budget, mut frame: impl FnMut()) -> f64 {
    let (timing, _) = median_of_runs(budget, || {
        for _ in 0..FRAMES_PER_RUN {
            frame();
        }
    });
    timing.median * 1e9 / FRAMES_PER_RUN as f64
}

/// The median of per-pair ratios of the frame costs of `a` and `b`, timed alternately
/// (robust to a load that changes while measuring), with each side's median ns per frame.
pub fn ratio(budget: Budget, mut a: impl FnMut(), mut b: impl FnMut()) -> (f64, f64, f64) {
    let pairs = budget.min_runs.max(15) | 1;
    let (ta, tb, r) = interleaved(
        pairs,
        || {
            for _ in 0..FRAMES_PER_RUN {
                a();
            }
        },
        || {
            for _ in 0..FRAMES_PER_RUN {
                b();
            }
        },
    );
    let per_frame = 1e9 / FRAMES_PER_RUN as f64;
    (r, ta.median * per_frame, tb.median * per_frame)
}
