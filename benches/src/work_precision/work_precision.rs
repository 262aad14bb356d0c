//! Reading the work-precision curves: the time a method needs for a given final error (by
//! log-log interpolation between the sweep's points) and least-squares slopes.

use super::sweep::Row;

/// The cost of reaching an error level on one method's curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reach {
    /// Interpolated (log-log) between the two sweep points around the level: s per simulated s.
    Interpolated(f64),
    /// The cheapest point of the sweep is already below the level: at most this, s per
    /// simulated s (the curve does not extend to coarser errors).
    AtMost(f64),
    /// No point reaches the level; the best error the curve has.
    NotReached {
        /// Smallest final error of the sweep.
        best: f64,
    },
}

impl Reach {
    /// The time, when the level was reached.
    pub fn time(self) -> Option<f64> {
        match self {
            Self::Interpolated(t) | Self::AtMost(t) => Some(t),
            Self::NotReached { .. } => None,
        }
    }
}

/// The wall time per simulated second at which `curve` (one method on one problem in one
/// precision, in sweep order: coarse to fine) first reaches final error `level`.
///
/// Walking from the coarsest successful point, the first point at or below `level` and the
/// point before it bracket the level; the time is interpolated linearly in
/// `(log error, log time)` between them. Failed points are skipped.
pub fn time_at(curve: &[&Row], level: f64) -> Reach {
    let ok: Vec<&&Row> = curve
        .iter()
        .filter(|r| r.ok() && r.final_error.is_finite() && r.seconds > 0.0)
        .collect();
    let Some(i) = ok.iter().position(|r| r.final_error <= level) else {
        let best = ok
            .iter()
            .map(|r| r.final_error)
            .fold(f64::INFINITY, f64::min);
        return Reach::NotReached { best };
    };
    let hit = ok[i];
    if i == 0 {
        return Reach::AtMost(hit.per_simulated_second());
    }
    let prev = ok[i - 1];
    let (e0, e1) = (prev.final_error.ln(), hit.final_error.max(1e-300).ln());
    let (t0, t1) = (
        prev.per_simulated_second().ln(),
        hit.per_simulated_second().ln(),
    );
    if (e0 - e1).abs() < 1e-300 {
        return Reach::Interpolated(hit.per_simulated_second());
    }
    let f = (e0 - level.ln()) / (e0 - e1);
    Reach::Interpolated((t0 + f * (t1 - t0)).exp())
}

/// Least-squares slope of `ln y` against `ln x`.
pub fn log_log_slope(points: &[(f64, f64)]) -> f64 {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0)
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxy: f64 = pts.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = pts.iter().map(|(x, _)| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

/// The rows grouped into curves: one per (problem, precision, method), in first-seen order,
/// each in sweep order.
pub fn curves(rows: &[Row]) -> Vec<Vec<&Row>> {
    let mut out: Vec<Vec<&Row>> = Vec::new();
    for r in rows {
        match out.iter_mut().find(|c| {
            c.first().is_some_and(|f| {
                f.problem == r.problem && f.precision == r.precision && f.method == r.method
            })
        }) {
            Some(c) => c.push(r),
            None => out.push(vec![r]),
        }
    }
    out
}
