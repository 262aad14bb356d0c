//! Constraints written once, generic over a [`Scalar`], with the Jacobian and the
//! velocity-product term derived by dual numbers: [`Holonomic`] from `phi(q)`, [`Pfaffian`]
//! from `A(q)`.

use super::Constraints;
use crate::{Dual, Real, Scalar};
use nalgebra::{SMatrix, SVector};

/// `C` holonomic constraints `phi(q) = 0`, written generic over the scalar so that they can be
/// both evaluated and differentiated. Wrap them in [`Holonomic`] to get [`Constraints`].
///
/// ```
/// use lagrange_core::constraints::{Constraints, Holonomic, HolonomicConstraints};
/// use lagrange_core::{Real, Scalar};
/// use nalgebra::{SVector, Vector1, Vector2};
///
/// /// A point (x, y) held on a circle of radius l about the origin.
/// struct Circle { l: f64 }
///
/// impl HolonomicConstraints<f64, 2, 1> for Circle {
///     fn phi<S: Scalar<Real = f64> + 'static>(&self, q: &SVector<S, 2>) -> SVector<S, 1> {
///         let l = S::from_real(self.l);
///         Vector1::new((q[0] * q[0] + q[1] * q[1] - l * l) * S::from_f64(0.5))
///     }
/// }
///
/// let c = Holonomic::new(Circle { l: 1.0 });
/// let (q, qd) = (Vector2::new(0.6, -0.8), Vector2::new(0.8, 0.6));
/// assert_eq!(c.jacobian(&q), nalgebra::Matrix1x2::new(0.6, -0.8));
/// // J'q' = |q'|^2 for this constraint.
/// assert!((c.velocity_product(&q, &qd)[0] - 1.0).abs() < 1e-15);
/// ```
pub trait HolonomicConstraints<T: Real, const N: usize, const C: usize> {
    /// The position residuals `phi(q)`, zero on the constraint manifold.
    fn phi<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, N>) -> SVector<S, C>;
}

/// `C` Pfaffian (velocity-level, possibly nonholonomic) constraints `A(q) q' = 0`, with `A`
/// written generic over the scalar. Wrap them in [`Pfaffian`] to get [`Constraints`].
pub trait PfaffianConstraints<T: Real, const N: usize, const C: usize> {
    /// The constraint matrix `A(q)`.
    fn matrix<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, N>) -> SMatrix<S, C, N>;
}

/// The [`Constraints`] that [`HolonomicConstraints`] define:
///
/// ```text
/// J    = dphi/dq                                  one dual evaluation of phi, N directions
/// J'q' = d2/ds2 phi(q + s q') at s = 0            one nested dual evaluation, 1 direction
/// ```
///
/// Exact to rounding, no symbolic step, no heap: the general path for a user's own
/// constraints and the oracle hand-derived ones are tested against.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Holonomic<P> {
    constraints: P,
}

impl<P> Holonomic<P> {
    /// The constraint set of `constraints`.
    pub fn new(constraints: P) -> Self {
        Self { constraints }
    }
    /// The constraints as written.
    #[must_use]
    pub fn constraints(&self) -> &P {
        &self.constraints
    }
}

impl<T, const N: usize, const C: usize, P> Constraints<T, N, C> for Holonomic<P>
where
    T: Real,
    P: HolonomicConstraints<T, N, C>,
{
    fn position_residual(&self, q: &SVector<T, N>) -> SVector<T, C> {
        self.constraints.phi(q)
    }

    fn jacobian(&self, q: &SVector<T, N>) -> SMatrix<T, C, N> {
        let seeded = SVector::<Dual<T, N>, N>::from_fn(|k, _| Dual::variable(q[k], k));
        let r = self.constraints.phi(&seeded);
        SMatrix::from_fn(|i, k| r[i].eps[k])
    }

    fn velocity_product(&self, q: &SVector<T, N>, qd: &SVector<T, N>) -> SVector<T, C> {
        // q + s q' with s seeded in both the outer and the inner direction, so that the
        // inner derivative of the outer derivative is d2/ds2.
        let line = SVector::<Dual<Dual<T, 1>, 1>, N>::from_fn(|k, _| {
            Dual::new(Dual::new(q[k], [qd[k]]), [Dual::constant(qd[k])])
        });
        self.constraints.phi(&line).map(|r| r.eps[0].eps[0])
    }
}

/// The [`Constraints`] that [`PfaffianConstraints`] define:
///
/// ```text
/// J    = A(q)
/// J'q' = (dA/ds (q + s q') at s = 0) q'           one dual evaluation of A, 1 direction
/// ```
///
/// with a zero position residual (no `phi` exists for a nonholonomic row).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Pfaffian<P> {
    constraints: P,
}

impl<P> Pfaffian<P> {
    /// The constraint set of `constraints`.
    pub fn new(constraints: P) -> Self {
        Self { constraints }
    }
    /// The constraints as written.
    #[must_use]
    pub fn constraints(&self) -> &P {
        &self.constraints
    }
}

impl<T, const N: usize, const C: usize, P> Constraints<T, N, C> for Pfaffian<P>
where
    T: Real,
    P: PfaffianConstraints<T, N, C>,
{
    fn jacobian(&self, q: &SVector<T, N>) -> SMatrix<T, C, N> {
        self.constraints.matrix(q)
    }

    fn velocity_product(&self, q: &SVector<T, N>, qd: &SVector<T, N>) -> SVector<T, C> {
        let line = SVector::<Dual<T, 1>, N>::from_fn(|k, _| Dual::new(q[k], [qd[k]]));
        let a = self.constraints.matrix(&line);
        SVector::from_fn(|i, _| {
            let mut g = T::zero();
            for k in 0..N {
                g += a[(i, k)].eps[0] * qd[k];
            }
            g
        })
    }
}
