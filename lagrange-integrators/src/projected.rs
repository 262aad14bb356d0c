//! [`Projected`]: any integrator followed by a projection onto the constraints after each step.

use crate::Integrator;
use lagrange_core::constraints::{Constraints, Projection};
use lagrange_core::{Error, Mechanism, Real, State};

/// An integrator whose every step ends with a [`Projection`] of the new state back onto
/// `phi = 0` and `J q' = 0`, mass-weighted by the mechanism being stepped.
///
/// Order, cost and energy behaviour are the inner integrator's, plus one projection per step
/// (usually zero or one Newton iteration, then one linear velocity solve). The residual stays
/// at the projection's tolerance (position) and at rounding (velocity) however long the run.
///
/// A start state must satisfy the constraints to within the projection's tolerance (position
/// and velocity residuals alike): the first step from any state other than this stepper's last
/// output checks it, so an inconsistent initial state is an error rather than silently moved.
/// To move a state onto the constraints on purpose, call [`Projection::project`] first.
///
/// ```
/// use lagrange_core::{Constraints, Projection};
/// use lagrange_integrators::{Integrator, Projected, Rk4};
/// use lagrange_systems::CartesianPendulum;
///
/// let pendulum = CartesianPendulum::new(1.0, 1.0, 9.81)?;
/// let mut stepper = Projected::new(Rk4, pendulum, Projection::new(1e-12, 4)?);
/// let start = pendulum.state_from_angle(0.0, 0.5, 0.0);
/// let end = stepper.integrate(&pendulum, &start, 1e-3, 1000)?;
/// assert!(pendulum.residual(&end).position < 1e-12);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projected<I, K, T: Real, const N: usize, const C: usize> {
    integrator: I,
    constraints: K,
    projection: Projection<T>,
    last: Option<State<T, N>>,
}

impl<I, K, T: Real, const N: usize, const C: usize> Projected<I, K, T, N, C> {
    /// `integrator`, then `projection` onto `constraints`, every step.
    pub fn new(integrator: I, constraints: K, projection: Projection<T>) -> Self {
        Self {
            integrator,
            constraints,
            projection,
            last: None,
        }
    }

    /// The inner integrator.
    #[must_use]
    pub fn integrator(&self) -> &I {
        &self.integrator
    }

    /// The constraints projected onto.
    #[must_use]
    pub fn constraints(&self) -> &K {
        &self.constraints
    }

    /// The projection.
    #[must_use]
    pub fn projection(&self) -> &Projection<T> {
        &self.projection
    }
}

impl<I, K, T, const N: usize, const C: usize> Integrator<T, N> for Projected<I, K, T, N, C>
where
    T: Real,
    I: Integrator<T, N>,
    K: Constraints<T, N, C>,
{
    const NAME: &'static str = I::NAME;
    const ORDER: u32 = I::ORDER;
    const EVALS_PER_STEP: u32 = I::EVALS_PER_STEP;

    /// One step of the inner integrator, then the projection.
    ///
    /// # Errors
    /// [`Error::ConstraintViolated`] when `state` is a new start state that violates the
    /// constraints beyond the projection's tolerance; the inner integrator's errors;
    /// [`Projection::project`]'s errors.
    fn step<M: Mechanism<T, N>>(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        dt: T,
    ) -> Result<State<T, N>, Error> {
        if self.last.as_ref() != Some(state) {
            self.constraints
                .check_state(state, self.projection.tolerance())?;
        }
        let next = self.integrator.step(mechanism, state, dt)?;
        let projected = self
            .projection
            .project(mechanism, &self.constraints, &next)?;
        self.last = Some(projected);
        Ok(projected)
    }
}
