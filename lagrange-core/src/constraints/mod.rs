//! Constraints that generalized coordinates cannot absorb, handled with Lagrange multipliers.
//!
//! - [`Constraints`]: `C` holonomic (`phi(q) = 0`) or Pfaffian (`A(q) q' = 0`) rows, with their
//!   Jacobian `J` and velocity-product term `J'q'`; hand-derived, or from `phi` or `A` alone by
//!   dual numbers through [`Holonomic`] and [`Pfaffian`].
//! - The [`Constrained`] wrapper (a free mechanism and its rows, [`Held`] together or written as
//!   one type): `q''` and the multipliers `lambda` (the constraint forces) from the KKT system,
//!   solved inside by its Schur complement `J M^-1 J^T` (fixed-size, on the stack), so that any
//!   integrator steps a constrained mechanism. Dependent rows give
//!   [`Error::RedundantConstraints`](crate::Error::RedundantConstraints).
//! - [`contact`]: unilateral contacts, their rows in force and their impacts.
//! - Drift control: [`Stabilization::Baumgarte`] inside the acceleration, or a
//!   [`Projection`] back onto `phi = 0` and `J q' = 0` after each step.
//! - Diagnostics on demand: [`Constraints::residual`] and [`Constraints::check_state`].
//!
//! Everything is `no_std`, allocation-free, and generic over `f32`/`f64`, the number of
//! coordinates `N` and the number of constraints `C`.

mod automatic;
mod constrained;
pub mod contact;
mod projection;
mod schur;
mod set;

pub use automatic::{Holonomic, HolonomicConstraints, Pfaffian, PfaffianConstraints};
pub use constrained::{Constrained, ConstrainedAcceleration, Held, Stabilization};
pub use projection::Projection;
pub(crate) use schur::Schur;
pub use set::{Constraints, Residual};

use crate::Real;
use nalgebra::SVector;

/// `max_i |v_i|`; the first non-finite `|v_i|` (NaN or infinity) when there is one, so that a
/// blown-up residual is never reported as small.
pub(crate) fn max_abs<T: Real, const C: usize>(v: &SVector<T, C>) -> T {
    let mut worst = T::zero();
    for &x in v.iter() {
        let a = x.abs();
        if !a.is_finite() {
            return a;
        }
        worst = worst.max(a);
    }
    worst
}
