//! Closed-form mass solves shared by the two-coordinate systems: a symmetric 2x2 inverse, and a
//! diagonal solve that reports the configuration where a diagonal entry vanishes.

use lagrange_core::nalgebra::{Matrix2, SVector, Vector2};
use lagrange_core::{all_finite, check_finite, Error, Real, State};

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
///
/// Inlined, and its tests of `det` count no divergence across lanes (an error fails the lane
/// step, [`check_finite`]): called, it spilled every live float of a lane step around it.
#[inline(always)]
pub(crate) fn solve_sym2_det<T: Real>(
    m: &Matrix2<T>,
    det: T,
    b: &Vector2<T>,
) -> Result<Vector2<T>, Error> {
    if !T::every_lane_finite(&[det]) {
        return Err(Error::NonFiniteState);
    }
    if !T::every_lane_positive(&[det]) {
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

/// `qdd`, the accelerations of a mechanism in a radius `r = s.q[0]` (the elastic pendulum,
/// Kepler) at `s`, when they are finite, the time is, `r > 0`, and `M`'s angular entry
/// `m_r2 = m r^2` has not underflowed to zero (the split form's singular `M`: both forms refuse
/// the same states); else [`Error::NonFiniteState`] for a state that is not finite and
/// [`Error::Singularity`] `what` otherwise. Coordinates or rates that are not finite give
/// accelerations that are not, so this one test of the result passes every good state and the
/// error is told apart only on failure: a test of the whole state first was a fifth of an RK4
/// step of the elastic pendulum.
#[inline(always)]
pub(crate) fn radial_accelerations<T: Real>(
    s: &State<T, 2>,
    qdd: Vector2<T>,
    m_r2: T,
    what: &'static str,
) -> Result<Vector2<T>, Error> {
    let good = s.t.is_finite() & all_finite(qdd.as_slice());
    if good && s.q[0] > T::zero() && m_r2 > T::zero() {
        return Ok(qdd);
    }
    positive_radius(s, what)?;
    Err(Error::Singularity { what })
}

/// `x` when every entry is finite, else `error`: every entry tested, with one branch for all
/// ([`check_finite`]).
#[inline]
pub(crate) fn finite<T: Real, const N: usize>(
    x: SVector<T, N>,
    error: Error,
) -> Result<SVector<T, N>, Error> {
    check_finite(x.as_slice(), error).map(|()| x)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(q0: f64) -> State<f64, 2> {
        State::new(0.0, [q0, 0.2], [0.3, -0.4])
    }

    /// The symmetric solve leaves a residual of a few ulps of `|m| |x|` on positive definite
    /// systems with weak and strong coupling, and refuses a non-positive or non-finite
    /// determinant and a result that overflows.
    #[test]
    fn symmetric_solve() -> Result<(), Error> {
        for (a, c, d) in [
            (2.0, 0.3, 1.5),
            (1.0, -0.99, 1.0),
            (5e3, 2.0, 3e-3),
            (1.0, 0.0, 4.0),
        ] {
            let m = Matrix2::new(a, c, c, d);
            let b = Vector2::new(0.7, -1.9);
            for x in [solve_sym2(&m, &b), solve_sym2_det(&m, a * d - c * c, &b)] {
                let x = x?;
                let scale = m.abs().max() * x.abs().max();
                assert!(
                    (m * x - b).abs().max() <= 8.0 * f64::EPSILON * scale,
                    "{m:?}: {x:?}"
                );
            }
        }
        let b = Vector2::new(1.0, 1.0);
        let singular = Matrix2::new(1.0, 1.0, 1.0, 1.0);
        assert_eq!(
            solve_sym2(&singular, &b),
            Err(Error::SingularMassMatrix { pivot: 1 })
        );
        let indefinite = Matrix2::new(1.0, 2.0, 2.0, 1.0);
        assert_eq!(
            solve_sym2(&indefinite, &b),
            Err(Error::SingularMassMatrix { pivot: 1 })
        );
        let m = Matrix2::new(1.0, 0.0, 0.0, 1.0);
        assert_eq!(solve_sym2_det(&m, f64::NAN, &b), Err(Error::NonFiniteState));
        assert_eq!(
            solve_sym2_det(&m, f64::INFINITY, &b),
            Err(Error::NonFiniteState)
        );
        let tiny = Matrix2::new(1.0, 0.0, 0.0, 1e-300);
        assert_eq!(
            solve_sym2(&tiny, &Vector2::new(1.0, 1e10)),
            Err(Error::NonFiniteState)
        );
        Ok(())
    }

    /// The diagonal solve divides by positive entries; an entry that is zero or negative (the
    /// singular configuration), or a quotient that overflows, is the singularity named; a
    /// state that is not finite is `NonFiniteState`.
    #[test]
    fn diagonal_solve() {
        let b = Vector2::new(3.0, -2.0);
        assert_eq!(
            solve_diagonal2(&state(1.0), [2.0, 4.0], &b, "r = 0"),
            Ok(Vector2::new(1.5, -0.5))
        );
        let singular = Err(Error::Singularity { what: "r = 0" });
        for d in [
            [-1.0, 4.0],
            [2.0, -4.0],
            [0.0, 4.0],
            [2.0, 0.0],
            [-1.0, -1.0],
        ] {
            assert_eq!(
                solve_diagonal2(&state(1.0), d, &b, "r = 0"),
                singular,
                "{d:?}"
            );
        }
        assert_eq!(
            solve_diagonal2(
                &state(1.0),
                [1e-310, 1.0],
                &Vector2::new(1e10, 1.0),
                "r = 0"
            ),
            singular
        );
        assert_eq!(
            solve_diagonal2(&state(f64::NAN), [2.0, 4.0], &b, "r = 0"),
            Err(Error::NonFiniteState)
        );
    }

    /// A positive radius passes; zero and negative are the singularity; NaN is not finite.
    #[test]
    fn radius() {
        assert_eq!(positive_radius(&state(0.5), "r = 0"), Ok(()));
        for r in [0.0, -0.5] {
            assert_eq!(
                positive_radius(&state(r), "r = 0"),
                Err(Error::Singularity { what: "r = 0" })
            );
        }
        assert_eq!(
            positive_radius(&state(f64::NAN), "r = 0"),
            Err(Error::NonFiniteState)
        );
    }

    /// Every entry must be finite, not only one.
    #[test]
    fn finiteness() {
        let e = Error::NonFiniteState;
        assert_eq!(
            finite(Vector2::new(1.0, 2.0), e),
            Ok(Vector2::new(1.0, 2.0))
        );
        for bad in [
            [1.0, f64::NAN],
            [f64::INFINITY, 1.0],
            [f64::NAN, f64::NEG_INFINITY],
        ] {
            assert_eq!(finite(Vector2::from(bad), e), Err(e), "{bad:?}");
        }
    }
}
