//! [`Controlled`]: a mechanism with an input that its owner sets between steps.

use crate::forces::{Forced, Input};
use crate::{all_finite, Error, Real};
use nalgebra::SVector;

/// A mechanism driven by an input that the caller sets between steps and that is held
/// constant over a step: a motor torque, the force on a cart. What a scene's bank writes
/// when it sets an instance's input, and compares to decide whether the write wakes it (an
/// unchanged input does not).
///
/// Implemented by the standard mechanisms with an input (`CartPole`, `Acrobot` in
/// lagrange-systems) and by any mechanism with an [`Input`] force added
/// ([`Mechanism::with_force`](crate::Mechanism::with_force)).
///
/// ```
/// use lagrange_core::prelude::*;
/// use lagrange_core::{Controlled, Forced};
/// # struct Cart;
/// # impl Lagrangian<f64, 1> for Cart {
/// #     fn kinetic<S: Scalar<Real = f64>>(&self, _: S, _: &SVector<S, 1>, qd: &SVector<S, 1>) -> S { qd[0] * qd[0] * 0.5 }
/// #     fn potential<S: Scalar<Real = f64>>(&self, _: S, _: &SVector<S, 1>) -> S { S::zero() }
/// # }
/// let mut pushed = EulerLagrange::new(Cart).with_force(Input::new([0.0]));
/// pushed.set_input(SVector::from([2.0]))?;
/// assert_eq!(pushed.acceleration(&State::at_rest([0.0]))?[0], 2.0);
/// assert!(pushed.set_input(SVector::from([f64::NAN])).is_err());
/// assert_eq!(pushed.input()[0], 2.0);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
pub trait Controlled<T: Real> {
    /// The input's value.
    type Input: Copy + PartialEq;

    /// The input in force.
    fn input(&self) -> Self::Input;

    /// Sets the input, used from the next evaluation on.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `input` for a value the mechanism refuses (not finite):
    /// the error names this method's own parameter, whatever the mechanism calls its input
    /// elsewhere (`force`, `torque`); the input is then unchanged.
    fn set_input(&mut self, input: Self::Input) -> Result<(), Error>;
}

/// The value of an [`Input`] force: one generalized force per coordinate.
impl<T: Real, const N: usize, M> Controlled<T> for Forced<M, Input<T, N>> {
    type Input = SVector<T, N>;

    fn input(&self) -> SVector<T, N> {
        self.force().value
    }

    fn set_input(&mut self, input: SVector<T, N>) -> Result<(), Error> {
        if all_finite(input.as_slice()) {
            self.force_mut().value = input;
            Ok(())
        } else {
            Err(Error::InvalidParameter {
                name: "input",
                reason: "must be finite",
            })
        }
    }
}
