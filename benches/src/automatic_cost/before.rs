//! The automatic path as it was before issue 16, frozen here so that every run of this bench
//! measures it beside the current one: `M` from one evaluation of `T` over
//! `Dual<Dual<S, N>, N>` (both directions on `q'`), `f` from a second such evaluation (outer
//! on `q`, inner on `q'`) and one `Dual<S, N>` evaluation of `V`, then a Cholesky solve.

use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{solve_spd, Dual, Error, Lagrangian, Real, State};

/// Second derivatives: an outer direction over an inner one.
type D2<T, const N: usize> = Dual<Dual<T, N>, N>;

/// `x` as a second-order dual constant.
fn d2_constant<T: Real, const N: usize>(x: T) -> D2<T, N> {
    D2::constant(Dual::constant(x))
}

/// `M = d2T/dq'dq'`.
fn mass_matrix<T: Real, L: Lagrangian<T, N>, const N: usize>(
    l: &L,
    s: &State<T, N>,
) -> SMatrix<T, N, N> {
    let q = s.q.map(d2_constant);
    let qd = SVector::<D2<T, N>, N>::from_fn(|k, _| D2::variable(Dual::variable(s.qd[k], k), k));
    let r = l.kinetic(d2_constant(s.t), &q, &qd);
    SMatrix::from_fn(|i, k| r.eps[k].eps[i])
}

/// `f = dT/dq - dV/dq - (d2T/dq'dq) q'` (no explicit time: no fixture here has one).
fn rhs<T: Real, L: Lagrangian<T, N>, const N: usize>(l: &L, s: &State<T, N>) -> SVector<T, N> {
    let v = l.potential(
        Dual::constant(s.t),
        &SVector::<Dual<T, N>, N>::from_fn(|k, _| Dual::variable(s.q[k], k)),
    );
    let inner_qd = SVector::<D2<T, N>, N>::from_fn(|i, _| D2::constant(Dual::variable(s.qd[i], i)));
    let outer_q = SVector::<D2<T, N>, N>::from_fn(|k, _| D2::variable(Dual::constant(s.q[k]), k));
    let r = l.kinetic(d2_constant(s.t), &outer_q, &inner_qd);
    SVector::<T, N>::from_fn(|i, _| {
        let mut fi = r.eps[i].re - v.eps[i];
        for k in 0..N {
            fi -= r.eps[k].eps[i] * s.qd[k];
        }
        fi
    })
}

/// `q''` by the old automatic path: `M^-1 (f + Q)`.
///
/// # Errors
/// As [`solve_spd`].
pub fn acceleration<T: Real, L: Lagrangian<T, N>, const N: usize>(
    l: &L,
    s: &State<T, N>,
) -> Result<SVector<T, N>, Error> {
    solve_spd(
        &mass_matrix(l, s),
        &(rhs(l, s) + l.non_conservative_force(s)),
    )
}
