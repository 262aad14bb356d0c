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
    /// [`Contacts::tangent_jacobian`]): what a contact solver asks for each step. A set whose
    /// two share work (a ragdoll's link poses and point Jacobians) overrides it.
    fn jacobians(&self, q: &SVector<T, N>) -> (SMatrix<T, C, N>, Option<SMatrix<T, C, N>>) {
        (self.jacobian(q), self.tangent_jacobian(q))
    }
}

impl<T, const N: usize, const C: usize, P> Contacts<T, N, C> for Holonomic<P>
where
    T: Real,
    P: HolonomicConstraints<T, N, C>,
{
}
