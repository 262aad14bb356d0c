//! [`Constraints`]: `C` constraints on `N` coordinates in the form every solver uses, and their
//! [`Residual`].

use super::max_abs;
use crate::{Error, Real, State};
use nalgebra::{SMatrix, SVector};

/// `C` constraints on the `N` generalized coordinates of a mechanism, holonomic or Pfaffian
/// (nonholonomic), scleronomic (no explicit time), given at the three levels the solvers use:
///
/// ```text
/// phi(q) = 0                        position level, holonomic rows; Pfaffian rows give 0
/// J(q) q' = 0                       velocity level; holonomic rows: J = dphi/dq,
///                                   Pfaffian rows A(q) q' = 0: J = A
/// J(q) q'' + J'(q, q') q' = 0       acceleration level; J'q' = (dJ/dt) q' is the
///                                   velocity-product term
/// ```
///
/// Implement it by hand (closed forms, the fast path), or derive it from `phi` or `A` alone
/// with [`Holonomic`](crate::constraints::Holonomic) or
/// [`Pfaffian`](crate::constraints::Pfaffian) (dual numbers). A set may mix both kinds: a
/// Pfaffian row simply has a zero position residual, which makes projection leave it to the
/// velocity level and Baumgarte stabilisation damp its velocity residual alone.
///
/// The rows' units are the user's: residuals and tolerances are in them.
pub trait Constraints<T: Real, const N: usize, const C: usize> {
    /// The position residual `phi(q)`; zero for Pfaffian rows (the default: all rows Pfaffian).
    ///
    /// This and the other row functions have no error channel: for coordinates that are not
    /// finite or so extreme that a term overflows they give NaN or infinities (never a
    /// panic), which every solve that uses them refuses ([`Error::NonFiniteState`]).
    fn position_residual(&self, q: &SVector<T, N>) -> SVector<T, C> {
        let _ = q;
        SVector::zeros()
    }

    /// The constraint Jacobian `J(q)`: row `i` is `dphi_i/dq` for a holonomic row, the row of
    /// `A(q)` for a Pfaffian one.
    fn jacobian(&self, q: &SVector<T, N>) -> SMatrix<T, C, N>;

    /// The velocity-product term `J'(q, q') q' = (dJ/dt) q'`.
    fn velocity_product(&self, q: &SVector<T, N>, qd: &SVector<T, N>) -> SVector<T, C>;

    /// The residuals at `state`: `max_i |phi_i|` and `max_i |(J q')_i|`. Computed only when
    /// asked. No error channel: a residual that is NaN or infinite (a state that is not
    /// finite) is reported as that, never as small.
    fn residual(&self, state: &State<T, N>) -> Residual<T> {
        let phi = self.position_residual(&state.q);
        let w = self.jacobian(&state.q) * state.qd;
        Residual {
            position: max_abs(&phi),
            velocity: max_abs(&w),
        }
    }

    /// `Ok(())` when every row's position residual and velocity residual are within
    /// `tolerance` at `state`: the check for a consistent initial state.
    ///
    /// # Errors
    /// [`Error::NonFiniteState`] when `state` is not finite; [`Error::ConstraintViolated`]
    /// naming the first row beyond `tolerance` (or whose residual is NaN).
    fn check_state(&self, state: &State<T, N>, tolerance: T) -> Result<(), Error> {
        state.check_finite()?;
        let phi = self.position_residual(&state.q);
        let w = self.jacobian(&state.q) * state.qd;
        // Written so that a NaN residual counts as a violation.
        let within = |i: usize| phi[i].abs() <= tolerance && w[i].abs() <= tolerance;
        match (0..C).find(|&i| !within(i)) {
            Some(row) => Err(Error::ConstraintViolated { row }),
            None => Ok(()),
        }
    }
}

/// How far a state is from satisfying its constraints, in the constraints' own units.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Residual<T> {
    /// `max_i |phi_i(q)|` over the holonomic rows (0 with only Pfaffian rows).
    pub position: T,
    /// `max_i |(J q')_i|`.
    pub velocity: T,
}
