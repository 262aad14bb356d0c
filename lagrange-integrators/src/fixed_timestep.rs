//! [`FixedTimestep`]: steps a mechanism at a fixed `dt` from variable frame times, with a cap
//! on the steps per frame and state interpolation for rendering.

use crate::{Clock, Integrator};
use lagrange_core::{validate, Error, Mechanism, Real, State};

/// What one frame did.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Frame<T> {
    /// Fixed steps taken.
    pub steps: u32,
    /// Simulated time given up because the frame needed more steps than the cap (zero in a
    /// frame that kept up): the simulation runs slower than real time instead of spiralling.
    /// Always finite.
    pub dropped: T,
}

/// Whole steps of the accumulated time are taken when within this many epsilons of a step,
/// so that frame times equal to `dt` give one step per frame despite rounding.
const STEP_SLACK_EPS: f64 = 64.0;

/// Whole steps in the accumulator below this count are dropped exactly (the fraction of a
/// step left over is kept); above it the accumulator is cleared: `2^22`, exact in `f32`.
const WHOLE_STEPS_EXACT: f64 = 4_194_304.0;

/// The fixed-timestep loop of a game or a real-time controller: frame times of any length
/// accumulate, the mechanism advances in steps of exactly `dt` (so that its behaviour does not
/// depend on the frame rate), and the state to draw is interpolated between the last two steps
/// by the fraction of a step left over.
///
/// ```text
/// accumulator += frame_time
/// while accumulator >= dt and steps < max_steps_per_frame: step; accumulator -= dt
/// beyond the cap, whole steps of the accumulator are dropped (reported in Frame::dropped)
/// drawn state = previous + alpha (current - previous),   alpha = accumulator / dt in [0, 1]
/// ```
///
/// The cap keeps a slow frame from demanding more steps than the next frame can afford (the
/// spiral of death): the simulation falls behind real time instead. Whatever a frame time (a
/// pause in a debugger, `T::MAX`), the time beyond the cap is dropped whole and the next
/// frames are stepped as if it had not come. The states' times are the start's plus the steps
/// taken times `dt`, summed without rounding drift ([`Clock`]): an `f32` clock at 1/120 s stays
/// within an ulp of `n dt` after 10^8 steps.
///
/// ```
/// use lagrange_integrators::prelude::*;
/// use lagrange_systems::SimplePendulum;
/// let p = SimplePendulum::new(1.0_f64, 1.0, 9.81, 0.0)?;
/// let mut sim = FixedTimestep::new(StormerVerlet::default(), 0.01, 8, State::at_rest([0.5]))?;
/// let frame = sim.advance(&p, 0.025)?; // two steps, half a step left over
/// assert_eq!(frame.steps, 2);
/// assert!((sim.alpha() - 0.5).abs() < 1e-12);
/// // Drawn half way between the steps at 0.01 s and 0.02 s: one step behind real time.
/// let drawn = sim.interpolated();
/// assert!((drawn.t - 0.015).abs() < 1e-12);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FixedTimestep<T: Real, const N: usize, I> {
    integrator: I,
    dt: T,
    max_steps_per_frame: u32,
    accumulator: T,
    previous: State<T, N>,
    current: State<T, N>,
    clock: Clock<T>,
}

impl<T: Real, const N: usize, I> FixedTimestep<T, N, I> {
    /// Steps of `dt` (positive, finite) by `integrator` from `start`, at most
    /// `max_steps_per_frame` (at least 1) per frame.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `dt` or `max_steps_per_frame`; [`Error::NonFiniteState`]
    /// for a non-finite `start`.
    pub fn new(
        integrator: I,
        dt: T,
        max_steps_per_frame: u32,
        start: State<T, N>,
    ) -> Result<Self, Error> {
        let dt = lagrange_core::validate::positive("dt", dt)?;
        if max_steps_per_frame == 0 {
            return Err(Error::InvalidParameter {
                name: "max_steps_per_frame",
                reason: "must be at least 1",
            });
        }
        start.check_finite()?;
        Ok(Self {
            integrator,
            dt,
            max_steps_per_frame,
            accumulator: T::zero(),
            previous: start,
            current: start,
            clock: Clock::new(start.t),
        })
    }

    /// Adds `frame_time` (zero or positive, finite) to the accumulated time and takes the
    /// fixed steps it pays for, up to the cap.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `frame_time` when negative or not finite; the first error
    /// of a step. Either way the frame is refused whole: the states, the accumulated time and
    /// the clock are as before the call (the integrator may have learnt from the frame's
    /// successful steps, but it continues only from the state it returned, so the next frame
    /// steps from the current state afresh).
    pub fn advance<M: Mechanism<T, N>>(
        &mut self,
        mechanism: &M,
        frame_time: T,
    ) -> Result<Frame<T>, Error>
    where
        I: Integrator<T, N, M>,
    {
        let frame_time = validate::non_negative("frame_time", frame_time)?;
        let saved = (self.accumulator, self.previous, self.current, self.clock);
        let frame = self.frame(mechanism, frame_time);
        if frame.is_err() {
            (self.accumulator, self.previous, self.current, self.clock) = saved;
        }
        frame
    }

    /// The steps of [`FixedTimestep::advance`] for a valid `frame_time`.
    fn frame<M: Mechanism<T, N>>(&mut self, mechanism: &M, frame_time: T) -> Result<Frame<T>, Error>
    where
        I: Integrator<T, N, M>,
    {
        // A frame time so large that the sum overflows is as good as the largest: the cap
        // drops it anyway.
        self.accumulator = (self.accumulator + frame_time).min(T::MAX);
        let mut steps = 0;
        while self.due() && steps < self.max_steps_per_frame {
            let mut next = self
                .integrator
                .run_step(mechanism, &self.current, self.dt)?;
            self.clock.tick(self.dt);
            next.t = self.clock.time();
            if !next.t.is_finite() {
                return Err(Error::NonFiniteState);
            }
            self.previous = self.current;
            self.current = next;
            self.accumulator -= self.dt;
            steps += 1;
        }
        let mut dropped = T::zero();
        if self.due() {
            // Keep the fraction of a step; drop the whole steps beyond the cap (all of the
            // time when it is too large for its whole steps to be counted exactly).
            let whole = (self.accumulator / self.dt).floor();
            let kept = if whole < T::from_f64(WHOLE_STEPS_EXACT) {
                self.accumulator - whole * self.dt
            } else {
                T::zero()
            };
            // A remainder that is a whole step but for rounding is one: dropped too.
            let kept = if kept >= self.dt * (T::one() - T::from_f64(STEP_SLACK_EPS) * T::EPSILON) {
                T::zero()
            } else {
                kept.max(T::zero())
            };
            dropped = self.accumulator - kept;
            self.accumulator = kept;
        }
        Ok(Frame { steps, dropped })
    }

    /// True when the accumulated time pays for a whole step.
    fn due(&self) -> bool {
        self.accumulator >= self.dt * (T::one() - T::from_f64(STEP_SLACK_EPS) * T::EPSILON)
    }

    /// The fraction of a step accumulated but not yet taken, in `[0, 1]`.
    #[must_use]
    pub fn alpha(&self) -> T {
        (self.accumulator / self.dt).max(T::zero()).min(T::one())
    }

    /// The state to draw: linear interpolation between the last two steps by
    /// [`FixedTimestep::alpha`] (it lags the simulation by up to one step, and never
    /// extrapolates). The two states are finite; only a difference between them that
    /// overflows (states near `T::MAX`) makes it infinite.
    #[must_use]
    pub fn interpolated(&self) -> State<T, N> {
        let a = self.alpha();
        let (p, c) = (&self.previous, &self.current);
        State {
            t: c.t + (a - T::one()) * (c.t - p.t),
            q: p.q + (c.q - p.q) * a,
            qd: p.qd + (c.qd - p.qd) * a,
        }
    }

    /// The state after the last step.
    #[must_use]
    pub fn current(&self) -> &State<T, N> {
        &self.current
    }

    /// The state before the last step.
    #[must_use]
    pub fn previous(&self) -> &State<T, N> {
        &self.previous
    }

    /// The fixed step.
    #[must_use]
    pub fn dt(&self) -> T {
        self.dt
    }

    /// The integrator (to read its statistics or change its settings).
    pub fn integrator_mut(&mut self) -> &mut I {
        &mut self.integrator
    }

    /// Starts again from `state` with nothing accumulated.
    ///
    /// # Errors
    /// [`Error::NonFiniteState`] for a non-finite `state`.
    pub fn reset(&mut self, state: State<T, N>) -> Result<(), Error> {
        state.check_finite()?;
        self.previous = state;
        self.current = state;
        self.accumulator = T::zero();
        self.clock = Clock::new(state.t);
        Ok(())
    }
}
