//! The position half of the Runge-Kutta-Nyström pairs ([`Nystrom`]): their tableau's extra
//! rows and a stage's position.

use super::sums::{real, stage_sum};
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
/// `q0'`, which the law does not read. The dense output is the quintic Hermite interpolant
/// ([`EmbeddedPair::HERMITE_DENSE`](super::EmbeddedPair::HERMITE_DENSE)).
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
