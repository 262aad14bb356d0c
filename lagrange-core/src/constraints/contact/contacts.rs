//! [`Contacts`]: unilateral constraints `g(q) >= 0`, with an optional tangent for friction.

use crate::constraints::{Constraints, Holonomic, HolonomicConstraints};
use crate::nalgebra::SMatrix;
use crate::nalgebra::SVector;
use crate::Real;

/// A set of `C` rows of which some are unilateral contacts `g_i(q) >= 0` (ground, walls,
/// joint limits on a coordinate): the gap `g` is the row's
/// [`position_residual`](Constraints::position_residual), its gradient the Jacobian row, and
/// the contact force `J^T lambda` pushes when `lambda_i > 0`. The other rows, if any, are
/// bilateral (see `ContactStepper::with_bilateral`).
///
/// Every [`Constraints`] set can be a contact set: implement this trait with no methods for a
/// frictionless one (it is implemented for [`Holonomic`]).
pub trait Contacts<T: Real, const N: usize, const C: usize>: Constraints<T, N, C> {
    /// For friction: row `i` is the Jacobian of the tangential position of contact `i`'s
    /// point, so that `(T q')_i` is its sliding velocity along the surface (a point against
    /// the ground: its horizontal velocity). `None` (the default): frictionless.
    fn tangent_jacobian(&self, q: &SVector<T, N>) -> Option<SMatrix<T, C, N>> {
        let _ = q;
        None
    }

    /// The Jacobian and the tangent Jacobian together (as [`Constraints::jacobian`] and
    /// [`Contacts::tangent_jacobian`]), written into `normal` and `tangent`: what a contact
    /// solver asks for each step, into storage it keeps from step to step: every entry of
    /// `normal` is written, and of `tangent` where there is one. Whether there is a tangent
    /// (where there is none, `tangent` is left as it was). A set whose two share work (a
    /// ragdoll's link poses and point Jacobians) overrides it, and writes in place.
    ///
    /// ```
    /// use lagrange_core::constraints::contact::Contacts;
    /// use lagrange_core::nalgebra::{SMatrix, SVector};
    /// use lagrange_core::{Holonomic, HolonomicConstraints, Scalar};
    ///
    /// /// A point at (q0, q1) above the ground y = 0.
    /// struct Ground;
    /// impl HolonomicConstraints<f64, 2, 1> for Ground {
    ///     fn phi<S: Scalar<Real = f64> + 'static>(&self, q: &SVector<S, 2>) -> SVector<S, 1> {
    ///         SVector::from([q[1]])
    ///     }
    /// }
    ///
    /// let (mut normal, mut tangent) = (SMatrix::<f64, 1, 2>::zeros(), SMatrix::zeros());
    /// let friction = Holonomic::new(Ground).jacobians(&SVector::from([0.5, 2.0]), &mut normal, &mut tangent);
    /// assert_eq!(normal, SMatrix::<f64, 1, 2>::new(0.0, 1.0));
    /// // A holonomic set has no tangent: frictionless.
    /// assert!(!friction);
    /// ```
    fn jacobians(
        &self,
        q: &SVector<T, N>,
        normal: &mut SMatrix<T, C, N>,
        tangent: &mut SMatrix<T, C, N>,
    ) -> bool {
        *normal = self.jacobian(q);
        match self.tangent_jacobian(q) {
            Some(t) => {
                *tangent = t;
                true
            }
            None => false,
        }
    }

    /// The gaps ([`Constraints::position_residual`]) with [`Contacts::jacobians`], written
    /// into `gaps`, `normal` and `tangent`: what a contact solver asks for in a step it
    /// expects rows in contact. By default the two calls; a set whose gaps and rows share
    /// work (a ragdoll's one pose) overrides it.
    fn gaps_and_jacobians(
        &self,
        q: &SVector<T, N>,
        gaps: &mut SVector<T, C>,
        normal: &mut SMatrix<T, C, N>,
        tangent: &mut SMatrix<T, C, N>,
    ) -> bool {
        *gaps = self.position_residual(q);
        self.jacobians(q, normal, tangent)
    }
}

impl<T, const N: usize, const C: usize, P> Contacts<T, N, C> for Holonomic<P>
where
    T: Real,
    P: HolonomicConstraints<T, N, C>,
{
}
