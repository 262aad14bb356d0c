//! The [`Integrator`] trait every fixed-step method implements, and the checks they share.

use lagrange_core::{Error, Mechanism, Real, State};

/// A one-step method that advances a [`Mechanism`]'s state by `dt`.
///
/// A step returns a new state and leaves the old one untouched, so that on an error the caller
/// still holds the last good state.
pub trait Integrator<T: Real, const N: usize> {
    /// Short name for tables and logs.
    const NAME: &'static str;
    /// Order of the global error: halving `dt` divides the error by `2^ORDER`.
    const ORDER: u32;
    /// Acceleration evaluations per step (for an implicit method: per Newton iteration, and
    /// each step also evaluates one acceleration Jacobian).
    const EVALS_PER_STEP: u32;

    /// Advances `state` by `dt` (which may be negative, to integrate backwards).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `dt` when `dt` is zero or not finite;
    /// [`Error::NonFiniteState`] when `state` is not finite, or the new state is not (a step past
    /// the stability limit); whatever [`Mechanism::acceleration`] returns.
    fn step<M: Mechanism<T, N>>(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        dt: T,
    ) -> Result<State<T, N>, Error>;

    /// Takes `steps` steps of `dt` from `state` and returns the last state.
    ///
    /// # Errors
    /// The first error of any step.
    fn integrate<M: Mechanism<T, N>>(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        dt: T,
        steps: u64,
    ) -> Result<State<T, N>, Error> {
        self.integrate_with(mechanism, state, dt, steps, |_| {})
    }

    /// As [`Integrator::integrate`], calling `observe` with every new state.
    ///
    /// # Errors
    /// The first error of any step.
    fn integrate_with<M: Mechanism<T, N>, F: FnMut(&State<T, N>)>(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        dt: T,
        steps: u64,
        observe: F,
    ) -> Result<State<T, N>, Error> {
        step_loop(state, steps, |s| self.step(mechanism, s, dt), observe)
    }
}

/// `steps` applications of `advance` from `state`, calling `observe` with each new state: the
/// loop of [`Integrator::integrate_with`], shared with the methods that override it to inline
/// their stages.
#[inline(always)]
pub(crate) fn step_loop<T: Real, const N: usize>(
    state: &State<T, N>,
    steps: u64,
    mut advance: impl FnMut(&State<T, N>) -> Result<State<T, N>, Error>,
    mut observe: impl FnMut(&State<T, N>),
) -> Result<State<T, N>, Error> {
    let mut s = *state;
    for _ in 0..steps {
        s = advance(&s)?;
        observe(&s);
    }
    Ok(s)
}

/// `dt` when it is finite and not zero and the state it is to step from is finite.
pub(crate) fn check_step<T: Real, const N: usize>(s: &State<T, N>, dt: T) -> Result<T, Error> {
    let dt = check_dt(dt)?;
    s.check_finite().map(|()| dt)
}

/// `dt` when it is finite and not zero.
pub(crate) fn check_dt<T: Real>(dt: T) -> Result<T, Error> {
    if dt.is_finite() && dt != T::zero() {
        Ok(dt)
    } else {
        Err(Error::InvalidParameter {
            name: "dt",
            reason: "must be finite and not zero",
        })
    }
}

/// The state a step produced, or [`Error::NonFiniteState`] when it blew up.
pub(crate) fn finish<T: Real, const N: usize>(s: State<T, N>) -> Result<State<T, N>, Error> {
    s.check_finite().map(|()| s)
}
