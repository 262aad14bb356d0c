//! [`Counting`]: a mechanism wrapper that counts acceleration evaluations, used in the
//! untimed run of each point so that the timed runs pay nothing for it.

use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{
    Error, GeneralizedForce, Jacobian, Lagrangian, Mechanism, Real, Scalar, State,
};
use std::cell::Cell;

/// `inner`, counting acceleration evaluations (calls of its law, [`Mechanism::law`], and the
/// one inside each [`Mechanism::law_jacobian`]) and Jacobian evaluations. Every method is forwarded,
/// so that the inner mechanism's own fast paths and exact Jacobians are kept.
pub struct Counting<'a, M> {
    inner: &'a M,
    calls: Cell<u64>,
    jacobians: Cell<u64>,
}

impl<'a, M> Counting<'a, M> {
    /// Wraps `inner` with a zero count.
    pub fn new(inner: &'a M) -> Self {
        Self {
            inner,
            calls: Cell::new(0),
            jacobians: Cell::new(0),
        }
    }
    /// Acceleration evaluations so far.
    pub fn calls(&self) -> u64 {
        self.calls.get()
    }
    /// Jacobian evaluations so far (implicit methods).
    pub fn jacobians(&self) -> u64 {
        self.jacobians.get()
    }
}

impl<T: Real, const N: usize, M: Lagrangian<T, N>> Lagrangian<T, N> for Counting<'_, M> {
    const EXPLICIT_TIME: bool = M::EXPLICIT_TIME;
    const DRIVEN: bool = M::DRIVEN;
    const READS_TIME: bool = M::READS_TIME;
    fn kinetic<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>, qd: &SVector<S, N>) -> S {
        self.inner.kinetic(t, q, qd)
    }
    fn potential<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>) -> S {
        self.inner.potential(t, q)
    }
    fn non_conservative_force(&self, s: &State<T, N>) -> SVector<T, N> {
        self.inner.non_conservative_force(s)
    }
}

impl<T: Real, const N: usize, M: Mechanism<T, N>> Mechanism<T, N> for Counting<'_, M> {
    fn mass_matrix(&self, s: &State<T, N>) -> SMatrix<T, N, N> {
        self.inner.mass_matrix(s)
    }
    fn rhs(&self, s: &State<T, N>) -> SVector<T, N> {
        self.inner.rhs(s)
    }
    fn solve_mass(&self, s: &State<T, N>, b: &SVector<T, N>) -> Result<SVector<T, N>, Error> {
        self.inner.solve_mass(s, b)
    }
    fn law<F: GeneralizedForce<T, N>>(
        &self,
        s: &State<T, N>,
        extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        self.calls.set(self.calls.get() + 1);
        self.inner.law(s, extra)
    }
    fn law_jacobian<F: GeneralizedForce<T, N>>(
        &self,
        s: &State<T, N>,
        extra: &F,
    ) -> Result<(SVector<T, N>, Jacobian<T, N>), Error> {
        self.calls.set(self.calls.get() + 1);
        self.jacobians.set(self.jacobians.get() + 1);
        self.inner.law_jacobian(s, extra)
    }
    fn law_force<F: GeneralizedForce<T, N>>(
        &self,
        s: &State<T, N>,
        extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        self.inner.law_force(s, extra)
    }
    fn reads_velocities(&self) -> bool {
        self.inner.reads_velocities()
    }
}
