//! [`SpringChain`]: masses in a line joined by springs, a Lagrangian whose mass matrix is
//! constant, with or without saying so.

use lagrange_core::nalgebra::SVector;
use lagrange_core::{Lagrangian, Real, Scalar};

/// `N` masses in a line joined by springs, the first to a wall:
///
/// ```text
/// T = sum m_i x_i'^2 / 2
/// V = sum (k_i s_i^2 / 2 + s_i^4 / 4),   s_i = x_i - x_(i-1)   (x_0 = 0: the wall)
/// ```
///
/// The mass matrix `diag(m)` is constant; `CLAIM` says whether the Lagrangian declares it
/// ([`Lagrangian::CONSTANT_MASS`]), so that the automatic path with the skip and without it
/// can be compared on the same equations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpringChain<T, const N: usize, const CLAIM: bool> {
    /// The masses, kg.
    pub masses: [T; N],
    /// The stiffnesses of the springs, N/m (the first joins mass 0 to the wall).
    pub stiffnesses: [T; N],
}

impl<T: Real, const N: usize, const CLAIM: bool> Lagrangian<T, N> for SpringChain<T, N, CLAIM> {
    const CONSTANT_MASS: bool = CLAIM;
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, _q: &SVector<S, N>, qd: &SVector<S, N>) -> S {
        let mut t = S::zero();
        for i in 0..N {
            t += qd[i] * qd[i] * (T::HALF * self.masses[i]);
        }
        t
    }
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, N>) -> S {
        let mut v = S::zero();
        let mut before = S::zero();
        for i in 0..N {
            let stretch = q[i] - before;
            v += stretch * stretch * (T::HALF * self.stiffnesses[i])
                + stretch * stretch * stretch * stretch * T::from_f64(0.25);
            before = q[i];
        }
        v
    }
}
