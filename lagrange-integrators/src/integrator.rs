//! The [`Integrator`] trait every method implements (one way to step), what a step costs
//! ([`Cost`], [`Work`]), what a failed run reports ([`Failure`]), and the checks they share.

use crate::Clock;
use core::fmt;
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, Lanes, Mechanism, Real, State};

/// What a step of a method costs, in evaluations of the mechanism's acceleration law, for
/// every method alike: `fixed + per_iteration * iterations` accelerations and `jacobians`
/// Jacobians per step, where `iterations` is the number of iterations of the step's implicit
/// equations (Newton, or a fixed point), which [`Method::last_step`] reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Cost {
    /// Accelerations every step takes, whatever its iterations.
    pub fixed: u32,
    /// Accelerations per iteration of the step's implicit equations.
    pub per_iteration: u32,
    /// Acceleration Jacobians per step (at least; Newton may refresh them).
    pub jacobians: u32,
}

impl Cost {
    /// An explicit method: `evaluations` accelerations per step.
    #[must_use]
    pub const fn explicit(evaluations: u32) -> Self {
        Self {
            fixed: evaluations,
            per_iteration: 0,
            jacobians: 0,
        }
    }
}

/// The work the last step did (or, for an adaptive method, the last call of
/// [`Integrator::step`], with all its internal steps): [`Method::last_step`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Work {
    /// Acceleration evaluations.
    pub evaluations: u32,
    /// Acceleration Jacobian evaluations.
    pub jacobians: u32,
    /// Iterations of the implicit equations (Newton or fixed point); 0 for an explicit step.
    pub iterations: u32,
    /// Internal steps taken (1 for a fixed-step method).
    pub steps: u32,
    /// Internal steps rejected by an adaptive method's error control.
    pub rejected: u32,
}

impl Work {
    /// One step of a method whose work is fixed by its [`Cost`], with `iterations` iterations.
    #[must_use]
    pub const fn of(cost: Cost, iterations: u32) -> Self {
        Self {
            evaluations: cost.fixed + cost.per_iteration * iterations,
            jacobians: cost.jacobians,
            iterations,
            steps: 1,
            rejected: 0,
        }
    }
}

/// Why a run of [`Integrator::integrate`] stopped early, and where: the error, the step that
/// failed (counted from 0) and the last good state, which the caller may keep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Failure<T: Real, const N: usize> {
    /// What went wrong.
    pub error: Error,
    /// The step that failed: `step` steps were taken successfully before it.
    pub step: u64,
    /// The state after the last successful step (the start state when the first one failed);
    /// its time is when the failed step began.
    pub last: State<T, N>,
}

impl<T: Real, const N: usize> fmt::Display for Failure<T, N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "step {} (from t = {}) failed: {}",
            self.step, self.last.t, self.error
        )
    }
}

impl<T: Real, const N: usize> core::error::Error for Failure<T, N> {}

/// A failed run converts to its [`Error`], so that `?` works in a function returning one.
impl<T: Real, const N: usize> From<Failure<T, N>> for Error {
    fn from(f: Failure<T, N>) -> Self {
        f.error
    }
}

#[cfg(feature = "defmt")]
impl<T: Real, const N: usize> defmt::Format for Failure<T, N> {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(
            f,
            "Failure {{ error: {}, step: {}, last: {} }}",
            self.error,
            self.step,
            self.last
        );
    }
}

/// What a method is, whatever it steps: its name, order and cost, and the work of its last
/// step. Every [`Integrator`] is one.
pub trait Method {
    /// Short name for tables and logs.
    const NAME: &'static str;
    /// Order of the global error: halving `dt` divides the error by `2^ORDER`.
    const ORDER: u32;
    /// The acceleration evaluations of a step ([`Cost`]).
    const COST: Cost;
    /// The name of its order-4 composition ([`Yoshida4`](crate::Yoshida4)) when it is a
    /// symmetric base.
    const YOSHIDA4_NAME: &'static str = "Yoshida 4";
    /// How a step moves the coordinates under a constant acceleration `a`:
    /// `q1 = q0 + h q'0 + POSITION_SHARE h^2 a`. One half for every method exact on it (every
    /// method of order 2 or more, the default); one for semi-implicit and backward Euler,
    /// which move by the new velocity; zero for explicit Euler, which moves by the old one.
    /// A time-stepping contact solver ([`ImpulseStepper`](crate::ImpulseStepper)) moves the
    /// coordinates by the same share of its impulses' velocity change, as if they were a
    /// constant force over the step, so that a body held at rest does not creep.
    const POSITION_SHARE: f64 = 0.5;

    /// The work of the last step ([`Work`]); by default that of [`Method::COST`] with no
    /// iterations.
    fn last_step(&self) -> Work {
        Work::of(Self::COST, 0)
    }
}

/// A method that advances a [`Mechanism`]'s state by a time `dt`: the one way to step that
/// every method of the library offers (fixed-step, symmetric, implicit, variational, adaptive)
/// and every driver uses ([`FixedTimestep`](crate::FixedTimestep), [`Projected`](crate::Projected),
/// [`ContactStepper`](crate::ContactStepper), scenes).
///
/// A step returns a new state and leaves the old one untouched, so that on an error the caller
/// still holds the last good state. A method may keep what it learnt from its last step (a
/// first guess, a step size, momenta): it uses it only when the next step starts from the
/// state it returned, and starts afresh from any other state.
///
/// `dt` is positive everywhere: every driver runs forward in time, and stepping backward
/// through dissipation or an impact is not defined. (To run a conservative mechanism
/// backward, negate its velocities; a composition's negative substeps go through
/// [`SymmetricBase::signed_step`](crate::SymmetricBase::signed_step).)
pub trait Integrator<T: Real, const N: usize, M: Mechanism<T, N>>: Method {
    /// Advances `state` by `dt` (positive), landing on `state.t + dt` exactly.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `dt` when `dt` is not positive and finite;
    /// [`Error::StepSizeUnderflow`] when `state.t + dt` rounds to `state.t`;
    /// [`Error::NonFiniteState`] when `state` is not finite, or the new state is not (a step
    /// past the stability limit, or a time `state.t + dt` that overflows); whatever the
    /// mechanism's law returns.
    fn step(&mut self, mechanism: &M, state: &State<T, N>, dt: T) -> Result<State<T, N>, Error>;

    /// The accelerations of the law this method steps, at `state`: the mechanism's own
    /// ([`Mechanism::acceleration`]) by default; a [`ContactStepper`](crate::ContactStepper)
    /// holds the contacts resting now (a ball on the floor does not accelerate). What a
    /// scene's sleep test reads, with the velocities zeroed.
    ///
    /// # Errors
    /// As [`Mechanism::acceleration`].
    fn law_acceleration(&self, mechanism: &M, state: &State<T, N>) -> Result<SVector<T, N>, Error> {
        mechanism.acceleration(state)
    }

    /// Steps `L` instances at once, side by side in lanes (their mechanisms gathered by
    /// [`Gather::gather`](lagrange_core::Gather::gather)), each lane bit for bit what
    /// [`Integrator::run_step`] gives for its instance alone: where the method keeps nothing between steps, `Some`; `None` by
    /// default, and then the caller steps the instances one by one. The result is that of
    /// every lane only if no comparison diverged across the lanes meanwhile
    /// ([`lagrange_core::divergences`]): the caller reads the count before and after, and
    /// steps the instances one by one otherwise (or on an error).
    ///
    /// The library's methods inline the whole step into the caller (`#[inline(always)]`, the
    /// stages included): left to a call, the gathered mechanism went through memory, every
    /// one of its fields gathered, and a scene's bank of 1,024 pendulums by RK4 ran at 1.9
    /// times the speed of one by one rather than 2.0. Each method therefore writes its check
    /// and step out again here rather than share a helper that takes the step as a function:
    /// called through that function, the step was not inlined, and the bank fell to 1.6.
    fn step_lanes<const L: usize, G: Mechanism<Lanes<T, L>, N>>(
        &self,
        mechanism: &G,
        state: &State<Lanes<T, L>, N>,
        dt: T,
    ) -> Option<Result<State<Lanes<T, L>, N>, Error>> {
        let _ = (mechanism, state, dt);
        None
    }

    /// One step of a run whose own clock keeps the time (the runs of
    /// [`Integrator::integrate`], [`FixedTimestep`](crate::FixedTimestep),
    /// [`Projected`](crate::Projected), [`ContactStepper`](crate::ContactStepper)): as
    /// [`Integrator::step`], except that a `dt` below the resolution of `state.t` (where
    /// `state.t + dt` rounds to `state.t`, as after days of an `f32` game clock at 1/120 s) is
    /// taken, not refused. The run's [`Clock`] carries the exact time and sets the new state's
    /// time; the step evaluates the mechanism at the rounded times.
    ///
    /// The default is [`Integrator::step`], which refuses such a step; every fixed-step method
    /// of the library overrides it (the adaptive pairs do not: their steps are chosen in time,
    /// and need a time that moves).
    ///
    /// # Errors
    /// As [`Integrator::step`], but for [`Error::StepSizeUnderflow`] where only the rounded
    /// time would not move.
    fn run_step(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        dt: T,
    ) -> Result<State<T, N>, Error> {
        self.step(mechanism, state, dt)
    }

    /// Takes `steps` steps of `dt` from `state` and returns the last state. The time of the
    /// `k`-th state is `state.t + k dt` rounded once from its exact value ([`Clock`]), so
    /// that a long run keeps its clock: after 10^8 `f32` steps of 1/120 s it is within an ulp
    /// of the exact time. The steps are [`Integrator::run_step`]s, so a `dt` below the
    /// resolution of the state's time is taken as long as the run as a whole moves the time.
    ///
    /// # Errors
    /// The first error of any step, with the step and the last good state ([`Failure`]).
    /// Before any step, `dt` and `state` are checked (even when `steps` is zero) and so is
    /// the run's end time `state.t + max(steps, 1) dt`: [`Error::StepSizeUnderflow`] when it
    /// rounds to `state.t`, [`Error::NonFiniteState`] when it overflows.
    fn integrate(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        dt: T,
        steps: u64,
    ) -> Result<State<T, N>, Failure<T, N>> {
        self.integrate_with(mechanism, state, dt, steps, |_| {})
    }

    /// As [`Integrator::integrate`], calling `observe` with every new state.
    ///
    /// # Errors
    /// As [`Integrator::integrate`].
    fn integrate_with<F: FnMut(&State<T, N>)>(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        dt: T,
        steps: u64,
        observe: F,
    ) -> Result<State<T, N>, Failure<T, N>> {
        step_loop(
            state,
            dt,
            steps,
            |s| self.run_step(mechanism, s, dt),
            observe,
        )
    }
}

/// `steps` applications of `advance` from `state`, calling `observe` with each new state, the
/// time of each from an exact [`Clock`]: the loop of [`Integrator::integrate_with`],
/// shared with the methods that override it to inline their stages.
///
/// # Errors
/// `dt`, `state` or the run refused ([`check_run`]), or the first error of `advance`, as a
/// [`Failure`].
#[inline(always)]
pub(crate) fn step_loop<T: Real, const N: usize>(
    state: &State<T, N>,
    dt: T,
    steps: u64,
    advance: impl FnMut(&State<T, N>) -> Result<State<T, N>, Error>,
    observe: impl FnMut(&State<T, N>),
) -> Result<State<T, N>, Failure<T, N>> {
    check_run(state, dt, steps).map_err(|e| fail(e, 0, state))?;
    let mut clock = Clock::new(state.t);
    tested_steps(state, &mut clock, (0, steps), dt, advance, observe)
}

/// The [`Failure`] of step `step` from `last`: every run's way of reporting one.
pub(crate) fn fail<T: Real, const N: usize>(
    error: Error,
    step: u64,
    last: &State<T, N>,
) -> Failure<T, N> {
    Failure {
        error,
        step,
        last: *last,
    }
}

/// Steps `first..first + count` of a run from `state`, on its `clock`: each new state's time
/// from the clock and tested, then observed.
#[inline(always)]
fn tested_steps<T: Real, const N: usize>(
    state: &State<T, N>,
    clock: &mut Clock<T>,
    (first, count): (u64, u64),
    dt: T,
    mut advance: impl FnMut(&State<T, N>) -> Result<State<T, N>, Error>,
    mut observe: impl FnMut(&State<T, N>),
) -> Result<State<T, N>, Failure<T, N>> {
    let mut s = *state;
    for k in first..first + count {
        let mut next = advance(&s).map_err(|e| fail(e, k, &s))?;
        clock.tick(dt);
        next.t = clock.time();
        if !next.t.is_finite() {
            return Err(fail(Error::NonFiniteState, k, &s));
        }
        s = next;
        observe(&s);
    }
    Ok(s)
}

/// The steps of [`unobserved_loop`] from its last tested state, taken again and each tested.
#[cold]
#[inline(never)]
fn retested<T: Real, const N: usize>(
    from: &State<T, N>,
    clock: &mut Clock<T>,
    steps: (u64, u64),
    dt: T,
    advance: &mut impl FnMut(&State<T, N>) -> Result<State<T, N>, Error>,
) -> Result<State<T, N>, Failure<T, N>> {
    tested_steps(from, clock, steps, dt, |x| finish(advance(x)?), |_| {})
}

/// Steps between the finiteness tests of an unobserved run ([`unobserved_loop`]).
pub(crate) const TESTED_EVERY: u64 = 8;

/// The loop of [`Integrator::integrate`] (nothing observes the states) for a method whose
/// step adds to the state, `y1 = y0 + ...`, so that a component once NaN or infinite stays
/// so, or the step fails: `advance` returns its new state untested, and the run tests one
/// state in [`TESTED_EVERY`] (at 14 coordinates in `f32` a test of every RK4 step cost 10%
/// of the step). A step that fails on a finite state is the run's first failure (every state
/// before it was finite). A failed test takes the steps since the last tested state again,
/// each tested by `finish` ([`step_loop`]'s way). Either way the error, its step and the last
/// good state are those of a run tested at every step, and no `Ok` state is ever NaN or
/// infinite.
///
/// # Errors
/// As [`step_loop`].
#[inline(always)]
pub(crate) fn unobserved_loop<T: Real, const N: usize>(
    state: &State<T, N>,
    dt: T,
    steps: u64,
    mut advance: impl FnMut(&State<T, N>) -> Result<State<T, N>, Error>,
) -> Result<State<T, N>, Failure<T, N>> {
    check_run(state, dt, steps).map_err(|e| fail(e, 0, state))?;
    let mut s = *state;
    let mut clock = Clock::new(state.t);
    let mut done = 0;
    while done < steps {
        let count = (steps - done).min(TESTED_EVERY);
        let (from, from_clock) = (s, clock);
        // A step's own time not finite (which `finish` tests before the clock's replaces
        // it), and the first error with its step in the chunk.
        let mut bad_time = false;
        let mut error = None;
        for j in 0..count {
            match advance(&s) {
                Ok(mut next) => {
                    bad_time |= !next.t.is_finite();
                    clock.tick(dt);
                    next.t = clock.time();
                    s = next;
                }
                Err(e) => {
                    error = Some((e, j));
                    break;
                }
            }
        }
        match (error, !bad_time && s.is_finite()) {
            (None, true) => {}
            // A finite state: every state before it was finite too, so this is the run's
            // first failure, found without evaluating the law again.
            (Some((e, j)), true) => return Err(fail(e, done + j, &s)),
            _ => {
                clock = from_clock;
                s = retested(&from, &mut clock, (done, count), dt, &mut advance)?;
            }
        }
        done += count;
    }
    Ok(s)
}

/// `dt` when it is positive and finite and advances the time of `s`, which must be finite,
/// to a finite time.
pub(crate) fn check_step<T: Real, const N: usize>(s: &State<T, N>, dt: T) -> Result<T, Error> {
    let dt = check_dt(dt)?;
    s.check_finite()?;
    advances(s.t, dt).map(|()| dt)
}

/// `dt` when it is positive and finite, `s` is finite, and a run of `steps` steps of `dt` (at
/// least one) from `s` ends at a time that differs from `s.t` and is finite.
pub(crate) fn check_run<T: Real, const N: usize>(
    s: &State<T, N>,
    dt: T,
    steps: u64,
) -> Result<T, Error> {
    let dt = check_dt(dt)?;
    s.check_finite()?;
    // One step (or none) is checked as a step is; a longer run by its clock (within an ulp).
    let end = if steps <= 1 {
        s.t + dt
    } else {
        Clock::after(s.t, dt, steps)
    };
    if end == s.t {
        Err(Error::StepSizeUnderflow)
    } else if !end.is_finite() {
        Err(Error::NonFiniteState)
    } else {
        Ok(dt)
    }
}

/// `dt` when it is positive and finite and takes the time of `s`, which must be finite, to a
/// finite time (it may not move the rounded time: a step of a run, [`Integrator::run_step`]).
pub(crate) fn check_run_step<T: Real, const N: usize>(s: &State<T, N>, dt: T) -> Result<T, Error> {
    let dt = check_dt(dt)?;
    s.check_finite()?;
    if T::every_lane_finite(&[s.t + dt]) {
        Ok(dt)
    } else {
        Err(Error::NonFiniteState)
    }
}

/// `h` when it is finite and not zero and takes the time of `s`, which must be finite, to a
/// finite time (it may not move the rounded time: a substep of a run,
/// [`SymmetricBase::signed_run_step`](crate::SymmetricBase::signed_run_step)).
pub(crate) fn check_signed_run<T: Real, const N: usize>(s: &State<T, N>, h: T) -> Result<T, Error> {
    if !h.is_finite() || h == T::zero() {
        return Err(Error::InvalidParameter {
            name: "h",
            reason: "must be finite and not zero",
        });
    }
    s.check_finite()?;
    if (s.t + h).is_finite() {
        Ok(h)
    } else {
        Err(Error::NonFiniteState)
    }
}

/// `h` when it is finite and moves the time of `s` (either way) to a finite time, `s` being
/// finite: the check of a composition's signed substep ([`SymmetricBase::signed_step`],
/// whose step is `h`).
///
/// [`SymmetricBase::signed_step`]: crate::SymmetricBase::signed_step
pub(crate) fn check_signed<T: Real, const N: usize>(s: &State<T, N>, h: T) -> Result<T, Error> {
    if !h.is_finite() {
        return Err(Error::InvalidParameter {
            name: "h",
            reason: "must be finite",
        });
    }
    s.check_finite()?;
    advances(s.t, h).map(|()| h)
}

/// `dt` when it is positive and finite (in every lane: a test that fails counts no
/// divergence, [`Real::every_lane_finite`]).
#[inline(always)]
pub(crate) fn check_dt<T: Real>(dt: T) -> Result<T, Error> {
    if T::every_lane_finite(&[dt]) & T::every_lane_positive(&[dt]) {
        Ok(dt)
    } else {
        Err(Error::InvalidParameter {
            name: "dt",
            reason: "must be positive and finite",
        })
    }
}

/// `Ok` when `t + dt` differs from `t` and is finite: a step that cannot move the clock is an
/// error, not a silent no-op ([`Error::StepSizeUnderflow`]), and one that would carry it past
/// the largest finite time would end in a state that is not finite
/// ([`Error::NonFiniteState`]). `t` is finite; the tests count no divergence across lanes
/// ([`Real::every_lane_finite`]).
#[inline(always)]
pub(crate) fn advances<T: Real>(t: T, dt: T) -> Result<(), Error> {
    let end = t + dt;
    if !T::every_lane_positive(&[(end - t).abs()]) {
        Err(Error::StepSizeUnderflow)
    } else if !T::every_lane_finite(&[end]) {
        Err(Error::NonFiniteState)
    } else {
        Ok(())
    }
}

/// True when `given` is `last`, the state a method returned, as a driver hands it back: the
/// same coordinates and velocities bit for bit, and the same time but for the rounding of a
/// clock that sums its steps exactly ([`Clock`]) where the method added one step to the time.
/// A method continues its run (momenta, controller, resting contacts) only from such a state.
pub(crate) fn continues<T: Real, const N: usize>(last: &State<T, N>, given: &State<T, N>) -> bool {
    let slack = T::from_f64(CLOCK_SLACK_EPS) * T::EPSILON * last.t.abs().max(given.t.abs());
    last.q == given.q && last.qd == given.qd && (last.t - given.t).abs() <= slack
}

/// The time of a state handed back by a driver may differ from the one a method returned by
/// the rounding of one addition and the clock's own (an ulp or two): this many epsilons.
const CLOCK_SLACK_EPS: f64 = 8.0;

/// The state a step produced, or [`Error::NonFiniteState`] when it blew up.
pub(crate) fn finish<T: Real, const N: usize>(s: State<T, N>) -> Result<State<T, N>, Error> {
    s.check_finite().map(|()| s)
}
