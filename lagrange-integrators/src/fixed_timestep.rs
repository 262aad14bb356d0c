//! [`FixedTimestep`]: steps a mechanism at a fixed `dt` from variable frame times, with a cap
//! on the steps per frame and state interpolation for rendering.

use crate::{Frame, FrameClock, Integrator};
use lagrange_core::{Error, Mechanism, Real, State};

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
/// taken times `dt`, summed without rounding drift ([`FrameClock`]): an `f32` clock at 1/120 s stays
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
    clock: FrameClock<T>,
    previous: State<T, N>,
    current: State<T, N>,
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
        // The start is checked first: its time is a state's, not a parameter of this call.
        start.check_finite()?;
        let clock = FrameClock::new(dt, max_steps_per_frame, start.t)?;
        Ok(Self {
            integrator,
            clock,
            previous: start,
            current: start,
        })
    }

    /// Adds `frame_time` (zero or positive, finite) to the accumulated time and takes the
    /// fixed steps it pays for, up to the cap ([`FrameClock::advance`]).
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
        let saved = (self.clock, self.previous, self.current);
        let (integrator, previous, current) =
            (&mut self.integrator, &mut self.previous, &mut self.current);
        let dt = self.clock.dt();
        let frame = self.clock.advance(frame_time, |t| {
            let mut next = integrator.run_step(mechanism, current, dt)?;
            next.t = t;
            *previous = *current;
            *current = next;
            Ok(())
        });
        if frame.is_err() {
            (self.clock, self.previous, self.current) = saved;
        }
        frame
    }

    /// The fraction of a step accumulated but not yet taken, in `[0, 1]`.
    #[must_use]
    pub fn alpha(&self) -> T {
        self.clock.alpha()
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
        self.clock.dt()
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
        self.clock.reset(state.t)?;
        self.previous = state;
        self.current = state;
        Ok(())
    }
}
