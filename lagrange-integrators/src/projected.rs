//! [`Projected`]: any integrator followed by a projection onto the constraints after each step.

use crate::integrator::{continues, Work};
use crate::{Cost, Integrator, Method};
use lagrange_core::constraints::{Constraints, Projection};
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, Mechanism, Real, State};

/// An integrator whose every step ends with a [`Projection`] of the new state back onto
/// `phi = 0` and `J q' = 0`, mass-weighted, for a mechanism that carries its constraint rows
/// (a [`Constrained`](lagrange_core::Constrained) mechanism, which gives both its law and its
/// rows: they are given once).
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
/// use lagrange_integrators::prelude::*;
/// use lagrange_systems::CartesianPendulum;
///
/// let pendulum = Constrained::new(CartesianPendulum::new(1.0, 1.0, 9.81)?);
/// let mut stepper = Projected::new(Rk4, Projection::new(1e-12, 4)?);
/// let start = pendulum.parts().state_from_angle(0.0, 0.5, 0.0);
/// let end = stepper.integrate(&pendulum, &start, 1e-3, 1000)?;
/// assert!(pendulum.residual(&end).position < 1e-12);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projected<T: Real, const N: usize, const C: usize, I> {
    integrator: I,
    projection: Projection<T>,
    last: Option<State<T, N>>,
}

impl<T: Real, const N: usize, const C: usize, I> Projected<T, N, C, I> {
    /// `integrator`, then `projection` onto the stepped mechanism's rows, every step.
    pub fn new(integrator: I, projection: Projection<T>) -> Self {
        Self {
            integrator,
            projection,
            last: None,
        }
    }

    /// The inner integrator.
    #[must_use]
    pub fn integrator(&self) -> &I {
        &self.integrator
    }

    /// The projection.
    #[must_use]
    pub fn projection(&self) -> &Projection<T> {
        &self.projection
    }
}

impl<T: Real, I: Method, const N: usize, const C: usize> Method for Projected<T, N, C, I> {
    const NAME: &'static str = I::NAME;
    const ORDER: u32 = I::ORDER;
    const POSITION_SHARE: f64 = I::POSITION_SHARE;
    /// The inner integrator's (the projection solves with the mass matrix, evaluating no
    /// accelerations).
    const COST: Cost = I::COST;

    fn last_step(&self) -> Work {
        self.integrator.last_step()
    }
}

impl<T, M, I, const N: usize, const C: usize> Integrator<T, N, M> for Projected<T, N, C, I>
where
    T: Real,
    M: Mechanism<T, N> + Constraints<T, N, C>,
    I: Integrator<T, N, M>,
{
    /// One step of the inner integrator, then the projection.
    ///
    /// # Errors
    /// [`Error::ConstraintViolated`] when `state` is a new start state that violates the
    /// constraints beyond the projection's tolerance; the inner integrator's errors;
    /// [`Projection::project`]'s errors.
    fn step(&mut self, mechanism: &M, state: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        self.projected(mechanism, state, dt, false)
    }

    /// A step of the inner integrator's run ([`Integrator::run_step`]), then the projection.
    fn run_step(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        dt: T,
    ) -> Result<State<T, N>, Error> {
        self.projected(mechanism, state, dt, true)
    }

    /// The inner integrator's.
    fn law_acceleration(&self, mechanism: &M, state: &State<T, N>) -> Result<SVector<T, N>, Error> {
        self.integrator.law_acceleration(mechanism, state)
    }
}

impl<T: Real, const N: usize, const C: usize, I> Projected<T, N, C, I> {
    /// A step (of a run, `run`) of the inner integrator, then the projection.
    fn projected<M>(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        dt: T,
        run: bool,
    ) -> Result<State<T, N>, Error>
    where
        M: Mechanism<T, N> + Constraints<T, N, C>,
        I: Integrator<T, N, M>,
    {
        if !self.last.is_some_and(|last| continues(&last, state)) {
            mechanism.check_state(state, self.projection.tolerance())?;
        }
        let next = if run {
            self.integrator.run_step(mechanism, state, dt)?
        } else {
            self.integrator.step(mechanism, state, dt)?
        };
        let projected = self.projection.project(mechanism, mechanism, &next)?;
        self.last = Some(projected);
        Ok(projected)
    }
}
