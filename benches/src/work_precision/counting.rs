//! [`Counting`]: a mechanism wrapper that counts acceleration evaluations, used in the
//! untimed run of each point so that the timed runs pay nothing for it.

use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{Error, Jacobian, Mechanism, Real, State};
use std::cell::Cell;

/// `inner`, counting acceleration evaluations (calls to [`Mechanism::acceleration`] and
/// [`Mechanism::acceleration_with`], and the one inside each
/// [`Mechanism::acceleration_jacobian`]) and Jacobian evaluations. Every method is forwarded,
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

impl<T: Real, const N: usize, M: Mechanism<T, N>> Mechanism<T, N> for Counting<'_, M> {
    fn mass_matrix(&self, s: &State<T, N>) -> SMatrix<T, N, N> {
        self.inner.mass_matrix(s)
    }
    fn rhs(&self, s: &State<T, N>) -> SVector<T, N> {
        self.inner.rhs(s)
    }
    fn generalized_force(&self, s: &State<T, N>) -> SVector<T, N> {
        self.inner.generalized_force(s)
    }
    fn kinetic_energy(&self, s: &State<T, N>) -> T {
        self.inner.kinetic_energy(s)
    }
    fn potential_energy(&self, s: &State<T, N>) -> T {
        self.inner.potential_energy(s)
    }
    fn energy(&self, s: &State<T, N>) -> T {
        self.inner.energy(s)
    }
    fn solve_mass(&self, s: &State<T, N>, b: &SVector<T, N>) -> Result<SVector<T, N>, Error> {
        self.inner.solve_mass(s, b)
    }
    fn acceleration(&self, s: &State<T, N>) -> Result<SVector<T, N>, Error> {
        self.calls.set(self.calls.get() + 1);
        self.inner.acceleration(s)
    }
    fn acceleration_with(
        &self,
        s: &State<T, N>,
        extra: &SVector<T, N>,
    ) -> Result<SVector<T, N>, Error> {
        self.calls.set(self.calls.get() + 1);
        self.inner.acceleration_with(s, extra)
    }
    fn equation_jacobian(&self, s: &State<T, N>, qdd: &SVector<T, N>) -> Jacobian<T, N> {
        self.jacobians.set(self.jacobians.get() + 1);
        self.inner.equation_jacobian(s, qdd)
    }
    fn acceleration_jacobian(
        &self,
        s: &State<T, N>,
    ) -> Result<(SVector<T, N>, Jacobian<T, N>), Error> {
        self.calls.set(self.calls.get() + 1);
        self.jacobians.set(self.jacobians.get() + 1);
        self.inner.acceleration_jacobian(s)
    }
}
