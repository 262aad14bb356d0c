//! Wall-clock timing: the median of repeated whole runs, and interleaved pairs for ratios.

use std::hint::black_box;
use std::time::Instant;

/// How much timing to spend per measured point.
#[derive(Debug, Clone, Copy)]
pub struct Budget {
    /// Aim for about this many seconds of timed runs per point.
    pub seconds: f64,
    /// At least this many timed runs.
    pub min_runs: usize,
    /// At most this many timed runs.
    pub max_runs: usize,
}

/// The result of timing one function.
#[derive(Debug, Clone, Copy)]
pub struct Timing {
    /// Median wall time of one run, s.
    pub median: f64,
    /// Fastest run, s.
    pub min: f64,
    /// Number of timed runs.
    pub runs: usize,
}

/// Seconds one call of `f` takes, and what it returned.
pub fn timed<R>(f: &mut impl FnMut() -> R) -> (f64, R) {
    let clock = Instant::now();
    let out = black_box(f());
    (clock.elapsed().as_secs_f64(), out)
}

/// Seconds one call of `f` takes.
pub fn once<R>(f: &mut impl FnMut() -> R) -> f64 {
    timed(f).0
}

/// The median of an odd number of runs of `f`, as many as fit the budget (the first, a
/// warm-up, sizes the rest and is not counted), and what each timed run returned, in order.
pub fn median_of_runs<R>(budget: Budget, mut f: impl FnMut() -> R) -> (Timing, Vec<R>) {
    let first = once(&mut f);
    let fit = (budget.seconds / first.max(1e-9)).floor() as usize;
    let runs = (fit.clamp(budget.min_runs, budget.max_runs.max(budget.min_runs))) | 1;
    let (mut times, outputs): (Vec<f64>, Vec<R>) = (0..runs).map(|_| timed(&mut f)).unzip();
    times.sort_by(f64::total_cmp);
    let timing = Timing {
        median: times[runs / 2],
        min: times[0],
        runs,
    };
    (timing, outputs)
}

/// Times `a` and `b` alternately, `pairs` times after one warm-up of each, and returns their
/// timings and the median of the per-pair ratios `a / b` (robust to a load that changes
/// during the measurement, as on a shared machine).
pub fn interleaved<RA, RB>(
    pairs: usize,
    mut a: impl FnMut() -> RA,
    mut b: impl FnMut() -> RB,
) -> (Timing, Timing, f64) {
    once(&mut a);
    once(&mut b);
    let mut ta = Vec::with_capacity(pairs);
    let mut tb = Vec::with_capacity(pairs);
    let mut ratios = Vec::with_capacity(pairs);
    for _ in 0..pairs.max(1) {
        let x = once(&mut a);
        let y = once(&mut b);
        ta.push(x);
        tb.push(y);
        ratios.push(x / y);
    }
    (summary(ta), summary(tb), median(ratios))
}

/// Median and minimum of `times`.
fn summary(times: Vec<f64>) -> Timing {
    let runs = times.len();
    let min = times.iter().copied().fold(f64::INFINITY, f64::min);
    Timing {
        median: median(times),
        min,
        runs,
    }
}

/// The median of `xs` (the mean of the middle two for an even count; NaN when empty).
pub fn median(mut xs: Vec<f64>) -> f64 {
    xs.sort_by(f64::total_cmp);
    let n = xs.len();
    match n {
        0 => f64::NAN,
        _ if n % 2 == 1 => xs[n / 2],
        _ => 0.5 * (xs[n / 2 - 1] + xs[n / 2]),
    }
}
