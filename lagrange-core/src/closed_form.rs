//! [`ClosedForm`]: a mechanism given by its equations of motion in closed form, `M(t, q)` and
//! `f(t, q, q')` written out (what `lagrange-derive` generates from a SymPy spec), made a
//! [`Mechanism`] by one generic impl: the mass solve, the law and their finiteness checks are
//! written here once, not in every generated file.

#[cfg(doc)]
use crate::Mechanism;
use crate::{check_finite, solve_spd, Cholesky, Error, GeneralizedForce, Lagrangian, Real, State};
use nalgebra::{SMatrix, SVector};

/// A mechanism written as its equations of motion in closed form:
///
/// ```text
/// M(t, q) q'' = f(t, q, q') + Q(t, q, q') + extra
/// ```
///
/// with `M` ([`ClosedForm::mass_formula`]) and `f` ([`ClosedForm::rhs_formula`]) given as
/// formulas, `Q` by [`Lagrangian::non_conservative_force`], and `T` and `V` by the
/// [`Lagrangian`] it also is (so that its energies, and the automatic path that checks it, come
/// from the same physics). One line, [`closed_form_mechanism!`](crate::closed_form_mechanism),
/// makes it a [`Mechanism`], the same way for every such type:
///
/// - `mass_matrix` and `rhs` are the two formulas;
/// - `solve_mass` ([`solve_mass`]) solves `M x = b` by the closed-form inverse for one or two
///   coordinates, by the fixed-size Cholesky solve ([`solve_spd`]) beyond, or by the constant
///   factor of [`ClosedForm::constant_mass`] when `M` is the same at every state;
/// - `law` ([`law`]) is `M^-1 (f + Q + extra)` with `M` and `f + Q` from
///   [`ClosedForm::equations`], which can share their common subexpressions;
/// - every solve returns `Ok` only with finite values ([`Error::NonFiniteState`] otherwise, as
///   everywhere in the library), and refuses a singular or indefinite `M` with
///   [`Error::SingularMassMatrix`] naming the pivot;
/// - `reads_velocities` is [`ClosedForm::READS_VELOCITIES`].
///
/// `lagrange-derive` writes these impls; writing one by hand works the same way.
///
/// ```
/// use lagrange_core::closed_form::ClosedForm;
/// use lagrange_core::nalgebra::{SMatrix, SVector};
/// use lagrange_core::prelude::*;
///
/// /// A pendulum of length `l` in gravity `g`, unit mass.
/// #[derive(Clone, Copy)]
/// struct Pendulum<T: Real> { l: T, g: T }
///
/// impl<T: Real> Lagrangian<T, 1> for Pendulum<T> {
///     fn kinetic<S: Scalar<Real = T>>(&self, _t: S, _q: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
///         qd[0] * qd[0] * (self.l * self.l * T::HALF)
///     }
///     fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 1>) -> S {
///         -q[0].cos() * (self.g * self.l)
///     }
/// }
///
/// impl<T: Real> ClosedForm<T, 1> for Pendulum<T> {
///     fn mass_formula(&self, _s: &State<T, 1>) -> SMatrix<T, 1, 1> {
///         SMatrix::from([[self.l * self.l]])
///     }
///     fn rhs_formula(&self, s: &State<T, 1>) -> SVector<T, 1> {
///         SVector::from([-self.g * self.l * s.q[0].sin()])
///     }
/// }
///
/// lagrange_core::closed_form_mechanism!(Pendulum, 1);
///
/// let p = Pendulum { l: 2.0, g: 9.81 };
/// let a = p.acceleration(&State::new(0.0, [0.5], [0.0]))?;
/// assert!((a[0] + 9.81 / 2.0 * 0.5f64.sin()).abs() < 1e-15);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
pub trait ClosedForm<T: Real, const N: usize>: Lagrangian<T, N> {
    /// What [`Mechanism::reads_velocities`] answers: `false` only when `f + Q` does not depend
    /// on the velocities at all (no damping, no Coriolis or centrifugal terms).
    const READS_VELOCITIES: bool = true;

    /// The mass matrix `M(t, q)`, symmetric; only its lower triangle is read by the solves.
    fn mass_formula(&self, state: &State<T, N>) -> SMatrix<T, N, N>;

    /// The right-hand side `f(t, q, q')` of `M q'' = f + Q`, without `Q`.
    fn rhs_formula(&self, state: &State<T, N>) -> SVector<T, N>;

    /// `M` and `f + Q` together, so that a formula can share the subexpressions of both: what
    /// the law evaluates. By default the two formulas and `Q` one after the other.
    fn equations(&self, state: &State<T, N>) -> (SMatrix<T, N, N>, SVector<T, N>) {
        let f = self.rhs_formula(state) + self.non_conservative_force(state);
        (self.mass_formula(state), f)
    }

    /// `M` factored once, when it is the same at every state (then the law solves with it and
    /// ignores the `M` of [`ClosedForm::equations`]); `None` by default.
    fn constant_mass(&self) -> Option<&ConstantMass<T, N>> {
        None
    }
}

/// `M x = b` for a [`ClosedForm`] at `state`: by the constant factor where there is one, else
/// by the closed-form inverse for one or two coordinates and the fixed-size Cholesky solve
/// beyond. What [`closed_form_mechanism!`](crate::closed_form_mechanism) makes its
/// [`Mechanism::solve_mass`].
///
/// # Errors
/// [`Error::SingularMassMatrix`] naming the first pivot of a singular or indefinite `M`;
/// [`Error::NonFiniteState`] for an `M` or an `x` that is not finite.
pub fn solve_mass<T: Real, const N: usize, X: ClosedForm<T, N>>(
    mechanism: &X,
    state: &State<T, N>,
    b: &SVector<T, N>,
) -> Result<SVector<T, N>, Error> {
    match mechanism.constant_mass() {
        Some(mass) => mass.solve(b),
        None => solve_symmetric(&mechanism.mass_formula(state), b),
    }
}

/// The law of a [`ClosedForm`]: `M^-1 (f + Q + extra)`, `M` and `f + Q` from
/// [`ClosedForm::equations`] (the constant factor used where there is one). What
/// [`closed_form_mechanism!`](crate::closed_form_mechanism) makes its [`Mechanism::law`].
///
/// # Errors
/// As [`solve_mass`].
#[inline]
pub fn law<T: Real, const N: usize, X: ClosedForm<T, N>, F: GeneralizedForce<T, N>>(
    mechanism: &X,
    state: &State<T, N>,
    extra: &F,
) -> Result<SVector<T, N>, Error> {
    let (m, f) = mechanism.equations(state);
    let b = extra.added_to(state, f);
    match mechanism.constant_mass() {
        Some(mass) => mass.solve(&b),
        None => solve_symmetric(&m, &b),
    }
}

/// Implements [`Mechanism`] for a type that implements [`ClosedForm`]: `closed_form_mechanism!(Type, N)` for
/// a `Type<T: Real>` with `N` coordinates. The impl is the same for every such type (written
/// by a macro rather than as a generic impl, which Rust's coherence rules would not allow
/// beside the other mechanisms' own impls):
///
/// - `mass_matrix` and `rhs` are [`ClosedForm::mass_formula`] and [`ClosedForm::rhs_formula`];
/// - `solve_mass` is [`solve_mass`] and `law` is [`law`];
/// - `reads_velocities` is [`ClosedForm::READS_VELOCITIES`];
/// - the rest are [`Mechanism`]'s defaults (the Jacobian by central differences of the law,
///   the applied force `M q'' - f`).
///
/// ```
/// use lagrange_core::closed_form::ClosedForm;
/// use lagrange_core::nalgebra::{SMatrix, SVector};
/// use lagrange_core::prelude::*;
///
/// /// A unit mass on a spring of stiffness `k`, `T` generic.
/// #[derive(Clone, Copy)]
/// struct Spring<T: Real> { k: T }
///
/// impl<T: Real> Lagrangian<T, 1> for Spring<T> {
///     fn kinetic<S: Scalar<Real = T>>(&self, _t: S, _q: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
///         qd[0] * qd[0] * T::HALF
///     }
///     fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 1>) -> S {
///         q[0] * q[0] * (self.k * T::HALF)
///     }
/// }
///
/// impl<T: Real> ClosedForm<T, 1> for Spring<T> {
///     fn mass_formula(&self, _s: &State<T, 1>) -> SMatrix<T, 1, 1> {
///         SMatrix::from([[T::one()]])
///     }
///     fn rhs_formula(&self, s: &State<T, 1>) -> SVector<T, 1> {
///         SVector::from([-self.k * s.q[0]])
///     }
/// }
///
/// lagrange_core::closed_form_mechanism!(Spring, 1);
///
/// let a = Spring { k: 4.0 }.acceleration(&State::new(0.0, [0.5], [0.0]))?;
/// assert_eq!(a[0], -2.0);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[macro_export]
macro_rules! closed_form_mechanism {
    ($name:ident, $n:literal) => {
        impl<T: $crate::Real> $crate::Mechanism<T, $n> for $name<T> {
            #[inline]
            fn mass_matrix(
                &self,
                state: &$crate::State<T, $n>,
            ) -> $crate::nalgebra::SMatrix<T, $n, $n> {
                <Self as $crate::closed_form::ClosedForm<T, $n>>::mass_formula(self, state)
            }

            #[inline]
            fn rhs(&self, state: &$crate::State<T, $n>) -> $crate::nalgebra::SVector<T, $n> {
                <Self as $crate::closed_form::ClosedForm<T, $n>>::rhs_formula(self, state)
            }

            fn solve_mass(
                &self,
                state: &$crate::State<T, $n>,
                b: &$crate::nalgebra::SVector<T, $n>,
            ) -> ::core::result::Result<$crate::nalgebra::SVector<T, $n>, $crate::Error> {
                $crate::closed_form::solve_mass(self, state, b)
            }

            #[inline]
            fn law<F: $crate::GeneralizedForce<T, $n>>(
                &self,
                state: &$crate::State<T, $n>,
                extra: &F,
            ) -> ::core::result::Result<$crate::nalgebra::SVector<T, $n>, $crate::Error> {
                $crate::closed_form::law(self, state, extra)
            }

            fn reads_velocities(&self) -> bool {
                <Self as $crate::closed_form::ClosedForm<T, $n>>::READS_VELOCITIES
            }
        }
    };
}

/// A mass matrix that is the same at every state, factored once (by Cholesky, [`Cholesky`]),
/// or the reason it has no factor: what a [`ClosedForm`] keeps when `M` does not depend on
/// the state, so that a step pays for a solve and never for a factorisation.
///
/// ```
/// use lagrange_core::closed_form::ConstantMass;
/// use lagrange_core::nalgebra::{SMatrix, SVector};
/// use lagrange_core::Error;
///
/// let mass = ConstantMass::new(&SMatrix::<f64, 2, 2>::new(2.0, 0.0, 0.0, 4.0));
/// assert_eq!(mass.solve(&SVector::from([2.0, 2.0])), Ok(SVector::from([1.0, 0.5])));
/// let singular = ConstantMass::new(&SMatrix::<f64, 2, 2>::new(1.0, 1.0, 1.0, 1.0));
/// assert_eq!(singular.solve(&SVector::from([1.0, 0.0])), Err(Error::SingularMassMatrix { pivot: 1 }));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConstantMass<T: Real, const N: usize> {
    factor: Result<Cholesky<T, N>, Error>,
}

impl<T: Real, const N: usize> ConstantMass<T, N> {
    /// `m` factored (only its lower triangle is read). A matrix that cannot be factored
    /// (singular, indefinite, not finite) is kept as its error, which every solve returns.
    #[must_use]
    pub fn new(m: &SMatrix<T, N, N>) -> Self {
        Self {
            factor: Cholesky::factor(m),
        }
    }

    /// `x` with `M x = b`.
    ///
    /// # Errors
    /// The factorisation's error ([`Error::SingularMassMatrix`], [`Error::NonFiniteState`]);
    /// [`Error::NonFiniteState`] when `x` is not finite (a factor so small that its inverse
    /// overflows, a `b` not finite).
    pub fn solve(&self, b: &SVector<T, N>) -> Result<SVector<T, N>, Error> {
        finite(self.factor?.solve(b))
    }
}

/// `x` when every component is finite, else [`Error::NonFiniteState`].
fn finite<T: Real, const N: usize>(x: SVector<T, N>) -> Result<SVector<T, N>, Error> {
    check_finite(x.as_slice(), Error::NonFiniteState).map(|()| x)
}

/// Solves `m x = b` for a symmetric `m` (its lower triangle read): by the closed-form inverse
/// for `N` = 1 or 2, by [`solve_spd`] beyond. Refuses `m` as the Cholesky solve would: a pivot
/// that is not positive, or lost to rounding, is [`Error::SingularMassMatrix`]; a non-finite
/// `m` or `x` is [`Error::NonFiniteState`].
fn solve_symmetric<T: Real, const N: usize>(
    m: &SMatrix<T, N, N>,
    b: &SVector<T, N>,
) -> Result<SVector<T, N>, Error> {
    if N == 1 {
        let d = m[(0, 0)];
        if !d.is_finite() {
            return Err(Error::NonFiniteState);
        }
        if d <= T::zero() {
            return Err(Error::SingularMassMatrix { pivot: 0 });
        }
        finite(b / d)
    } else if N == 2 {
        let (a, c, d) = (m[(0, 0)], m[(1, 0)], m[(1, 1)]);
        let det = a * d - c * c;
        if !det.is_finite() {
            return Err(Error::NonFiniteState);
        }
        if a <= T::zero() {
            return Err(Error::SingularMassMatrix { pivot: 0 });
        }
        if det <= a * d.abs() * T::EPSILON {
            return Err(Error::SingularMassMatrix { pivot: 1 });
        }
        let inv = T::one() / det;
        let mut x = SVector::zeros();
        x[0] = (d * b[0] - c * b[1]) * inv;
        x[1] = (a * b[1] - c * b[0]) * inv;
        finite(x)
    } else {
        solve_spd(m, b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Mechanism, Scalar};

    /// The closed forms refuse what the Cholesky solve refuses, and agree with it elsewhere.
    #[test]
    fn small_solves_agree_with_cholesky() {
        let m1 = SMatrix::<f64, 1, 1>::new(4.0);
        let b1 = SVector::from([2.0]);
        assert_eq!(solve_symmetric(&m1, &b1), solve_spd(&m1, &b1));
        let m2 = SMatrix::<f64, 2, 2>::new(4.0, 1.0, 1.0, 3.0);
        let b2 = SVector::from([1.0, 2.0]);
        let (x, y) = (solve_symmetric(&m2, &b2), solve_spd(&m2, &b2));
        assert!(x.is_ok_and(|x| y.is_ok_and(|y| (x - y).abs().max() < 1e-15)));
        for (m, pivot) in [
            (SMatrix::<f64, 2, 2>::new(0.0, 0.0, 0.0, 1.0), 0),
            (SMatrix::<f64, 2, 2>::new(-1.0, 0.0, 0.0, 1.0), 0),
            (SMatrix::<f64, 2, 2>::new(1.0, 1.0, 1.0, 1.0), 1),
            (SMatrix::<f64, 2, 2>::new(1.0, 2.0, 2.0, 1.0), 1),
        ] {
            let refused = Err(Error::SingularMassMatrix { pivot });
            assert_eq!(solve_symmetric(&m, &b2), refused, "{m:?}");
            assert_eq!(solve_spd(&m, &b2), refused, "{m:?}");
        }
        assert_eq!(
            solve_symmetric(&SMatrix::<f64, 1, 1>::new(-2.0), &b1),
            Err(Error::SingularMassMatrix { pivot: 0 })
        );
        let nan = SMatrix::<f64, 2, 2>::new(f64::NAN, 0.0, 0.0, 1.0);
        assert_eq!(solve_symmetric(&nan, &b2), Err(Error::NonFiniteState));
        let huge = SVector::from([f64::MAX, 1.0]);
        let small = SMatrix::<f64, 2, 2>::new(0.5, 0.0, 0.0, 0.5);
        assert_eq!(solve_symmetric(&small, &huge), Err(Error::NonFiniteState));
        assert_eq!(
            solve_symmetric(&SMatrix::<f64, 1, 1>::new(0.5), &SVector::from([f64::MAX])),
            Err(Error::NonFiniteState)
        );
    }

    /// A constant mass so small that its inverse overflows gives an error, never an infinity.
    #[test]
    fn constant_mass_is_finite_or_refuses() {
        let tiny = ConstantMass::new(&SMatrix::<f64, 1, 1>::new(f64::MIN_POSITIVE * 1e-10));
        assert_eq!(
            tiny.solve(&SVector::from([1.0])),
            Err(Error::NonFiniteState)
        );
        let unit = ConstantMass::new(&SMatrix::<f64, 1, 1>::new(2.0));
        assert_eq!(unit.solve(&SVector::from([1.0])), Ok(SVector::from([0.5])));
        let bad = ConstantMass::new(&SMatrix::<f64, 1, 1>::new(0.0));
        assert_eq!(
            bad.solve(&SVector::from([1.0])),
            Err(Error::SingularMassMatrix { pivot: 0 })
        );
    }

    /// On the edge of the rounding test, the closed form for two coordinates refuses and
    /// accepts what the Cholesky solve does: the second pivot `det / a` must be above
    /// `EPSILON` times its diagonal entry `d`, that is `det > a |d| EPSILON`.
    fn two_by_two_pivot_is_judged_against_its_diagonal<T: Real>() {
        let (one, two, eps) = (T::one(), T::TWO, T::EPSILON);
        // M = [1, 2; 2, 4 + 4 eps]: 4 + 4 eps is the float after 4, det = 4 eps exactly, not
        // above (4 + 4 eps) eps: refused at pivot 1 (a test against a / |d| EPSILON = eps / 4
        // would accept it).
        let four = two * two;
        let m = SMatrix::<T, 2, 2>::new(one, two, two, four + four * eps);
        let b = SVector::from([one, two]);
        let refused = Err(Error::SingularMassMatrix { pivot: 1 });
        assert_eq!(solve_symmetric(&m, &b), refused);
        assert_eq!(solve_spd(&m, &b), refused);
        // M = [1, 1/2; 1/2, 1/4 + eps/2]: 1/4 + eps/2 is two floats after 1/4, det = eps/2
        // exactly, above (1/4 + eps/2) eps: accepted (a test against a / |d| EPSILON = 4 eps
        // would refuse it). By Cramer's rule, with b = (1, 2),
        // x0 = (d - 1) / det = 1 - 3 / (2 eps) and x1 = (2 - 1/2) / det = 3 / eps, both
        // floats (integers below 2^(digits)), and every step of either solve exact.
        let quarter = T::HALF * T::HALF;
        let m = SMatrix::<T, 2, 2>::new(one, T::HALF, T::HALF, quarter + eps * T::HALF);
        let three = two + one;
        let x = SVector::from([one - three / (two * eps), three / eps]);
        assert_eq!(solve_symmetric(&m, &b), Ok(x));
        assert_eq!(solve_spd(&m, &b), Ok(x));
    }

    #[test]
    fn two_by_two_pivot_is_judged_against_its_diagonal_f32() {
        two_by_two_pivot_is_judged_against_its_diagonal::<f32>();
    }

    #[test]
    fn two_by_two_pivot_is_judged_against_its_diagonal_f64() {
        two_by_two_pivot_is_judged_against_its_diagonal::<f64>();
    }

    /// A damped spring, `m q'' = -k q - c q'`, written as a [`ClosedForm`] with its damping as
    /// the non-conservative force `Q = -c q'` and the default [`ClosedForm::equations`].
    #[derive(Clone, Copy)]
    struct DampedSpring<T: Real> {
        m: T,
        k: T,
        c: T,
    }

    impl<T: Real> Lagrangian<T, 1> for DampedSpring<T> {
        fn kinetic<S: Scalar<Real = T>>(&self, _: S, _: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
            qd[0] * qd[0] * (self.m * T::HALF)
        }
        fn potential<S: Scalar<Real = T>>(&self, _: S, q: &SVector<S, 1>) -> S {
            q[0] * q[0] * (self.k * T::HALF)
        }
        fn non_conservative_force(&self, s: &State<T, 1>) -> SVector<T, 1> {
            SVector::from([-self.c * s.qd[0]])
        }
    }

    impl<T: Real> ClosedForm<T, 1> for DampedSpring<T> {
        fn mass_formula(&self, _: &State<T, 1>) -> SMatrix<T, 1, 1> {
            SMatrix::from([[self.m]])
        }
        fn rhs_formula(&self, s: &State<T, 1>) -> SVector<T, 1> {
            SVector::from([-self.k * s.q[0]])
        }
    }

    crate::closed_form_mechanism!(DampedSpring, 1);

    /// The default `equations` is `M` and `f + Q`, and the law solves with it: for the damped
    /// spring (m, k, c) = (2, 4, 3/4) at q = 1/2, q' = -2, `f + Q = -k q - c q' = -2 + 3/2`
    /// and `q'' = (f + Q) / m = -1/4`, every figure exact in binary.
    fn equations_add_the_non_conservative_force<T: Real>() {
        let f = |x: f64| T::from_f64(x);
        let spring = DampedSpring {
            m: f(2.0),
            k: f(4.0),
            c: f(0.75),
        };
        let s = State::new(T::zero(), [f(0.5)], [f(-2.0)]);
        let force = -(4.0 * 0.5) - 0.75 * -2.0;
        let (m, b) = spring.equations(&s);
        assert_eq!(
            (m, b),
            (SMatrix::from([[f(2.0)]]), SVector::from([f(force)]))
        );
        assert_eq!(spring.acceleration(&s), Ok(SVector::from([f(force / 2.0)])));
    }

    #[test]
    fn equations_add_the_non_conservative_force_f32() {
        equations_add_the_non_conservative_force::<f32>();
    }

    #[test]
    fn equations_add_the_non_conservative_force_f64() {
        equations_add_the_non_conservative_force::<f64>();
    }
}
