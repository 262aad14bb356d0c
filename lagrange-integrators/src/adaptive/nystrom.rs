//! The position half of the Runge-Kutta-Nyström pairs ([`Nystrom`]): their tableau's extra
//! rows, a stage's position, and the rows of their dense output.

use super::sums::{real, stage_sum, Hermite};
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Real, State};

#[cfg(doc)]
use lagrange_core::Mechanism;

/// The position half of a Runge-Kutta-Nyström pair, which steps laws `q'' = f(t, q)` that do
/// not read `q'` ([`Mechanism::reads_velocities`] `false`) with fewer stages than a pair of
/// the first-order system needs for the same order.
///
/// ```text
/// stage i:  q_i = q0 + h (c_i q0' + h sum_j ABAR[i][j] kv_j),   q_i' = q0'
/// stage FSAL: (t0 + h, q1, q1'),   q1 = its row of ABAR,   q1' = q0' + h sum_j A[FSAL][j] kv_j
/// error:    e_q = h^2 sum_j E[j] kv_j,   e_q' = h sum_j EmbeddedPair::E[j] kv_j
/// ```
///
/// `A`'s row `FSAL` holds the velocity weights `b'` and may use the stage `FSAL` itself
/// (evaluated at `q1`, before `q1'` is formed); its other rows are zero: a stage's velocity is
/// `q0'`, which the law does not read. The dense output is the quintic Hermite interpolant of
/// `q` through `(q, q', q'')` at both ends, and its derivative for `q'` (orders 5 and 4, no
/// evaluation), in two rows (`R = 2`; `DENSE` is unused).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nystrom<const S: usize> {
    /// The position coefficients `abar_ij`, lower triangular (row `FSAL` is `b`).
    pub abar: [[f64; S]; S],
    /// The weights of the position error estimate.
    pub e: [f64; S],
}

/// The square matrix whose row `i` starts with `rows[i]` (zeros after): a strictly lower
/// triangular tableau written row by row, without its zeros.
///
/// # Panics
/// When a row `i` has more than `i` entries (in a constant, a compile error).
#[must_use]
pub const fn lower_triangular<const S: usize>(rows: [&[f64]; S]) -> [[f64; S]; S] {
    let mut m = [[0.0; S]; S];
    let mut i = 0;
    while i < S {
        assert!(
            rows[i].len() <= i,
            "a row of a strictly lower triangular tableau"
        );
        let mut j = 0;
        while j < rows[i].len() {
            m[i][j] = rows[i][j];
            j += 1;
        }
        i += 1;
    }
    m
}

/// `out = q0 + (q0' c + (sum_j w_j kv_j) h) h`: a stage's position ([`Nystrom`]).
#[inline(always)]
pub(super) fn position<T: Real, const N: usize>(
    out: &mut SVector<T, N>,
    y0: &State<T, N>,
    w: &[f64],
    c: f64,
    kv: &[SVector<T, N>],
    h: T,
) {
    let c = real::<T>(c);
    for (i, o) in out.as_mut_slice().iter_mut().enumerate() {
        let v = y0.qd.as_slice()[i];
        *o = y0.q.as_slice()[i] + (v * c + stage_sum(w, kv, i) * h) * h;
    }
}

/// The two rows of a Nyström pair's dense output beyond the cubic Hermite parts
/// ([`Nystrom`]), written to `[q4, q5, v4, v5]`:
///
/// - for `q`, the quintic Hermite interpolant: `d4` and `d5` add `s^2 (1-s)^2 (d4 + s d5)`,
///   which leaves the values and slopes at both ends alone and sets the second derivatives
///   to `h^2 q0''` and `h^2 q1''`;
/// - for `q'`, its derivative: the quartic through `q0', q0'', q1', q1''` whose mean over the
///   step is `(q1 - q0) / h`, the cubic plus `s^2 (1-s)^2 e4` (whose mean is `e4 / 30`).
pub(super) fn dense_rows<T: Real, const N: usize>(
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
