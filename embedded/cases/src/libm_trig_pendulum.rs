//! [`LibmTrigPendulum`]: the simple pendulum in `f32` with `libm::sinf`, the baseline that the
//! pure-`f32` sine is measured against.

use lagrange_core::nalgebra::{Matrix1, SVector, Vector1};
use lagrange_core::{Error, Lagrangian, Mechanism, Scalar, State};
use lagrange_systems::SimplePendulum;

/// A [`SimplePendulum<f32>`] whose right-hand side calls `libm::sinf` (which computes in `f64`)
/// instead of [`Real::sin`](lagrange_core::Real)'s default pure-`f32` sine; every other
/// operation, and its Lagrangian (energies), is the pendulum's own.
///
/// ```text
/// m l^2 th'' = -m g l sinf(th) - b th'
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LibmTrigPendulum(pub SimplePendulum<f32>);

impl Lagrangian<f32, 1> for LibmTrigPendulum {
    fn kinetic<S: Scalar<Real = f32>>(&self, t: S, q: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
        self.0.kinetic(t, q, qd)
    }
    fn potential<S: Scalar<Real = f32>>(&self, t: S, q: &SVector<S, 1>) -> S {
        self.0.potential(t, q)
    }
    fn non_conservative_force(&self, s: &State<f32, 1>) -> SVector<f32, 1> {
        self.0.non_conservative_force(s)
    }
}

impl Mechanism<f32, 1> for LibmTrigPendulum {
    fn mass_matrix(&self, s: &State<f32, 1>) -> Matrix1<f32> {
        self.0.mass_matrix(s)
    }
    fn rhs(&self, s: &State<f32, 1>) -> SVector<f32, 1> {
        let p = &self.0;
        Vector1::new(-p.mass() * p.gravity() * p.length() * libm::sinf(s.q[0]))
    }
    fn solve_mass(&self, s: &State<f32, 1>, b: &SVector<f32, 1>) -> Result<SVector<f32, 1>, Error> {
        self.0.solve_mass(s, b)
    }
}
