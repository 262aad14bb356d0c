//! The dense output of a pair without a continuous extension of its own: the quintic
//! Hermite interpolant through `q`, `q'` and `q''` at the step's two ends, at no evaluation.

use super::sums::{real, Hermite};
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Real, State};

#[cfg(doc)]
use super::EmbeddedPair;

/// The two rows beyond the cubic Hermite parts of a dense output that uses no stage of its
/// own ([`EmbeddedPair::HERMITE_DENSE`]: the Nyström and Verner pairs), written to
/// `[q4, q5, v4, v5]`:
///
/// - for `q`, the quintic Hermite interpolant: `d4` and `d5` add `s^2 (1-s)^2 (d4 + s d5)`,
///   which leaves the values and slopes at both ends alone and sets the second derivatives
///   to `h^2 q0''` and `h^2 q1''`;
/// - for `q'`, its derivative: the quartic through `q0', q0'', q1', q1''` whose mean over the
///   step is `(q1 - q0) / h`, the cubic plus `s^2 (1-s)^2 e4` (whose mean is `e4 / 30`).
pub(super) fn quintic_rows<T: Real, const N: usize>(
    [q4, q5, v4, v5]: [&mut SVector<T, N>; 4],
    hermite: &Option<(Hermite<T, N>, Hermite<T, N>)>,
    kv: &[SVector<T, N>],
    (y0, y1): (&State<T, N>, &State<T, N>),
    h: T,
    fsal: usize,
) {
    let Some(([_, d2, d3], [e1, e2, e3])) = hermite else {
        return;
    };
    // (h / 2) h, not h^2 / 2: a step long enough for h^2 to overflow is finite here.
    let half_h = h * real::<T>(0.5);
    *q4 = kv[0] * half_h * h + d2 - d3;
    *q5 = kv[fsal] * half_h * h + d2 + d3 * real::<T>(2.0) - *q4;
    let cubic_mean = y0.qd + e1 * real::<T>(0.5) + e2 / real::<T>(6.0) + e3 / real::<T>(12.0);
    *v4 = ((y1.q - y0.q) / h - cubic_mean) * real::<T>(30.0);
    *v5 = SVector::zeros();
}
