//! Closed-form mass solves shared by the two-coordinate systems: a symmetric 2x2 inverse, and a
//! diagonal solve that reports the configuration where a diagonal entry vanishes.

use lagrange_core::nalgebra::{Matrix2, SVector, Vector2};
use lagrange_core::{Error, Real, State};

/// Solves the symmetric positive definite 2x2 system `m x = b` by its closed-form inverse.
///
/// # Errors
/// [`Error::NonFiniteState`] when `m`, `b` or the result holds NaN or infinity;
/// [`Error::SingularMassMatrix`] when `det m <= 0`.
pub(crate) fn solve_sym2<T: Real>(m: &Matrix2<T>, b: &Vector2<T>) -> Result<Vector2<T>, Error> {
    let det = m[(0, 0)] * m[(1, 1)] - m[(0, 1)] * m[(1, 0)];
    solve_sym2_det(m, det, b)
}

/// As [`solve_sym2`] with `det m` given, for a mechanism that knows a form of it free of
/// cancellation. One division: the inverse determinant scales both components.
///
/// # Errors
/// As [`solve_sym2`].
pub(crate) fn solve_sym2_det<T: Real>(
    m: &Matrix2<T>,
    det: T,
    b: &Vector2<T>,
) -> Result<Vector2<T>, Error> {
    if !det.is_finite() {
        return Err(Error::NonFiniteState);
    }
    if det <= T::zero() {
        return Err(Error::SingularMassMatrix { pivot: 1 });
    }
    let inv = T::one() / det;
    let x = Vector2::new(
        (m[(1, 1)] * b[0] - m[(0, 1)] * b[1]) * inv,
        (m[(0, 0)] * b[1] - m[(1, 0)] * b[0]) * inv,
    );
    finite(x, Error::NonFiniteState)
}

/// Solves `diag(d) x = b` at state `s` for a diagonal mass matrix whose entries vanish only at
/// a singular configuration of the mechanism, named by `what`.
///
/// # Errors
/// [`Error::NonFiniteState`] when `s` holds NaN or infinity; else [`Error::Singularity`] `what`
/// when an entry of `d` is not positive (the state is at the singular configuration) or a
/// quotient is not finite (the state is so close to it, or so fast, that `q''` overflows).
#[inline]
pub(crate) fn solve_diagonal2<T: Real>(
    s: &State<T, 2>,
    d: [T; 2],
    b: &Vector2<T>,
    what: &'static str,
) -> Result<Vector2<T>, Error> {
    s.check_finite()?;
    if !(d[0] > T::zero() && d[1] > T::zero()) {
        return Err(Error::Singularity { what });
    }
    finite(
        Vector2::new(b[0] / d[0], b[1] / d[1]),
        Error::Singularity { what },
    )
}

/// `Ok` when the radial coordinate `r = s.q[0]` is positive: [`Error::NonFiniteState`] when `s`
/// holds NaN or infinity, [`Error::Singularity`] `what` at `r <= 0`.
#[inline]
pub(crate) fn positive_radius<T: Real>(s: &State<T, 2>, what: &'static str) -> Result<(), Error> {
    s.check_finite()?;
    if s.q[0] > T::zero() {
        Ok(())
    } else {
        Err(Error::Singularity { what })
    }
}

/// `x` when every entry is finite, else `error`.
#[inline]
pub(crate) fn finite<T: Real, const N: usize>(
    x: SVector<T, N>,
    error: Error,
) -> Result<SVector<T, N>, Error> {
    // Every entry tested, without a branch per entry (as `Mechanism::acceleration`'s test).
    if x.iter().fold(true, |all, v| all & v.is_finite()) {
        Ok(x)
    } else {
        Err(error)
    }
}
