//! [`free_law_force`]: the force an unconstrained law applies besides `f`, in closed form, for
//! the [`Mechanism::law_force`] of a free mechanism.

use crate::mechanism::finite;
use crate::{Error, GeneralizedForce, Lagrangian, Real, State};
use nalgebra::SVector;

#[cfg(doc)]
use crate::{Constrained, Mechanism};

/// The generalized force an unconstrained law applies besides `f` at `state`: the mechanism's
/// own non-conservative force `Q` plus `extra`,
///
/// ```text
/// M q'' - f = Q + extra        where  M q'' = f + Q + extra
/// ```
///
/// without evaluating the law. The default [`Mechanism::law_force`] computes the same force as
/// `M q'' - f`, at the cost of the whole law, `M` and `f` (and their rounding); a mechanism
/// whose law is the free one (the default law, or a closed form of it) overrides
/// `law_force` with this, which is what a variational integrator evaluates at every
/// iteration. Not for a constrained law, whose force adds the constraint forces
/// ([`Constrained`] states its own). It does not evaluate the law, so it does not refuse a
/// configuration the law refuses: an override that must (a radius at or below zero) checks
/// that first.
///
/// # Errors
/// [`Error::NonFiniteState`] when the force is not finite (a user's `Q` or `extra` that
/// returns NaN).
///
/// ```
/// use lagrange_core::prelude::*;
/// use lagrange_core::free_law_force;
/// use lagrange_core::nalgebra::{SMatrix, Vector1};
///
/// /// A damped spring: `m x'' = -k x - c x'`.
/// struct Spring;
/// impl Lagrangian<f64, 1> for Spring {
///     fn kinetic<S: Scalar<Real = f64>>(&self, _: S, _: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
///         qd[0] * qd[0] * 0.5
///     }
///     fn potential<S: Scalar<Real = f64>>(&self, _: S, q: &SVector<S, 1>) -> S {
///         q[0] * q[0] * 0.5
///     }
///     fn non_conservative_force(&self, s: &State<f64, 1>) -> SVector<f64, 1> {
///         Vector1::new(-0.5 * s.qd[0])
///     }
/// }
/// impl Mechanism<f64, 1> for Spring {
///     fn mass_matrix(&self, _: &State<f64, 1>) -> SMatrix<f64, 1, 1> {
///         SMatrix::identity()
///     }
///     fn rhs(&self, s: &State<f64, 1>) -> SVector<f64, 1> {
///         -s.q
///     }
///     fn law_force<F: GeneralizedForce<f64, 1>>(
///         &self,
///         s: &State<f64, 1>,
///         extra: &F,
///     ) -> Result<SVector<f64, 1>, Error> {
///         free_law_force(self, s, extra)
///     }
/// }
///
/// let s = State::new(0.0, [1.0], [2.0]);
/// let push = |_: &State<f64, 1>| Vector1::new(3.0);
/// assert_eq!(Spring.law_force(&s, &push)?[0], -0.5 * 2.0 + 3.0);
/// # Ok::<(), Error>(())
/// ```
#[inline]
pub fn free_law_force<T, const N: usize, M, F>(
    mechanism: &M,
    state: &State<T, N>,
    extra: &F,
) -> Result<SVector<T, N>, Error>
where
    T: Real,
    M: Lagrangian<T, N> + ?Sized,
    F: GeneralizedForce<T, N>,
{
    finite(extra.added_to(state, mechanism.non_conservative_force(state)))
}
