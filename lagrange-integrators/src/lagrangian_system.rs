//! [`LagrangianSystem`]: a mechanism known by its Lagrangian and its non-conservative forces,
//! which is what the variational integrator discretises.

use lagrange_core::nalgebra::SVector;
use lagrange_core::{
    central_difference_jacobian, EulerLagrange, Forced, GeneralizedForce, Jacobian, Lagrangian,
    Real, Scalar, State,
};

/// A mechanism given by its Lagrangian `L(t, q, q')`, evaluable in any [`Scalar`] (so that it
/// can be differentiated), and its non-conservative generalized forces `Q(t, q, q')`.
///
/// Implemented by [`EulerLagrange`] (the automatic path: any [`Lagrangian`], including every
/// standard mechanism of `lagrange-systems`) and by [`Forced`] over it, so that
/// `EulerLagrange::new(l).with_force(damping)` works with the
/// [`VariationalMidpoint`](crate::VariationalMidpoint) integrator as with any other.
pub trait LagrangianSystem<T: Real, const N: usize> {
    /// `L = T - V` at `(t, q, q')`.
    fn lagrangian<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>, qd: &SVector<S, N>) -> S;

    /// The non-conservative generalized forces `Q` at `state`.
    fn force(&self, state: &State<T, N>) -> SVector<T, N>;

    /// `(dQ/dq, dQ/dq')` at `state`; central differences by default.
    fn force_jacobian(&self, state: &State<T, N>) -> Jacobian<T, N> {
        central_difference_jacobian(state, |s| self.force(s))
    }
}

impl<T: Real, const N: usize, L: Lagrangian<T, N>> LagrangianSystem<T, N> for EulerLagrange<L> {
    fn lagrangian<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>, qd: &SVector<S, N>) -> S {
        let l = self.lagrangian();
        l.kinetic(t, q, qd) - l.potential(t, q)
    }

    fn force(&self, state: &State<T, N>) -> SVector<T, N> {
        self.lagrangian().non_conservative_force(state)
    }
}

impl<T, const N: usize, M, F> LagrangianSystem<T, N> for Forced<M, F>
where
    T: Real,
    M: LagrangianSystem<T, N>,
    F: GeneralizedForce<T, N>,
{
    fn lagrangian<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>, qd: &SVector<S, N>) -> S {
        self.mechanism().lagrangian(t, q, qd)
    }

    fn force(&self, state: &State<T, N>) -> SVector<T, N> {
        self.mechanism().force(state) + self.force().force(state)
    }

    fn force_jacobian(&self, state: &State<T, N>) -> Jacobian<T, N> {
        self.mechanism().force_jacobian(state) + self.force().jacobian(state)
    }
}
