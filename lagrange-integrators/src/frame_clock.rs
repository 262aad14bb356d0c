//! [`FrameClock`]: the fixed-timestep clock of a game or a real-time loop, shared by
//! [`FixedTimestep`](crate::FixedTimestep) and scenes: an accumulator of frame times, a cap on
//! the steps per frame, the fraction of a step left over to interpolate by, and a drift-free
//! time.

use crate::Clock;
use lagrange_core::{validate, Error, Real};

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

/// Frame times of any length accumulate; whole steps of exactly `dt` are taken from them, at
/// most `max_steps_per_frame` per frame; the fraction of a step left over says where between
/// the last two steps to draw.
///
/// ```text
/// accumulator += frame_time
/// while accumulator >= dt and steps < max_steps_per_frame: step; accumulator -= dt
/// beyond the cap, whole steps of the accumulator are dropped (Frame::dropped)
/// alpha = accumulator / dt in [0, 1]
/// ```
///
/// The cap keeps a slow frame from demanding more steps than the next frame can afford (the
/// spiral of death): the simulation falls behind real time instead. Whatever a frame time (a
/// pause in a debugger, `T::MAX`), the time beyond the cap is dropped whole and the next
/// frames are stepped as if it had not come. The time after `n` steps is the start's plus
/// `n dt`, summed without rounding drift ([`Clock`]): an `f32` clock at 1/120 s stays within
/// an ulp of `n dt` after 10^8 steps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameClock<T> {
    dt: T,
    max_steps_per_frame: u32,
    accumulator: T,
    clock: Clock<T>,
}

impl<T: Real> FrameClock<T> {
    /// Steps of `dt` (positive, finite) from time `t0` (finite), at most `max_steps_per_frame`
    /// (at least 1) per frame.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `dt`, `max_steps_per_frame` or `t0`.
    pub fn new(dt: T, max_steps_per_frame: u32, t0: T) -> Result<Self, Error> {
        let dt = validate::positive("dt", dt)?;
        if max_steps_per_frame == 0 {
            return Err(Error::InvalidParameter {
                name: "max_steps_per_frame",
                reason: "must be at least 1",
            });
        }
        Ok(Self {
            dt,
            max_steps_per_frame,
            accumulator: T::zero(),
            clock: Clock::new(validate::finite("t0", t0)?),
        })
    }

    /// Adds `frame_time` (zero or positive, finite) and calls `step` with the time each due
    /// step ends at, up to the cap, then drops what the cap left over.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `frame_time` when negative or not finite (nothing changes);
    /// [`Error::NonFiniteState`] when the time after a step overflows; the first error of
    /// `step`, after which the steps before it count and the failed step's
    /// time stays accumulated.
    pub fn advance(
        &mut self,
        frame_time: T,
        mut step: impl FnMut(T) -> Result<(), Error>,
    ) -> Result<Frame<T>, Error> {
        let frame_time = validate::non_negative("frame_time", frame_time)?;
        // A frame time so large that the sum overflows is as good as the largest: the cap
        // drops it anyway.
        self.accumulator = (self.accumulator + frame_time).min(T::MAX);
        let mut steps = 0;
        while self.due(self.accumulator) && steps < self.max_steps_per_frame {
            let mut next = self.clock;
            next.tick(self.dt);
            let t = next.time();
            if !t.is_finite() {
                return Err(Error::NonFiniteState);
            }
            step(t)?;
            self.clock = next;
            self.accumulator -= self.dt;
            steps += 1;
        }
        let mut dropped = T::zero();
        if self.due(self.accumulator) {
            // Keep the fraction of a step; drop the whole steps beyond the cap (all of the
            // time when it is too large for its whole steps to be counted exactly).
            let whole = (self.accumulator / self.dt).floor();
            let kept = if whole < T::from_f64(WHOLE_STEPS_EXACT) {
                self.accumulator - whole * self.dt
            } else {
                T::zero()
            };
            // A remainder that is a whole step but for rounding is one: dropped too.
            let kept = if self.due(kept) {
                T::zero()
            } else {
                kept.max(T::zero())
            };
            dropped = self.accumulator - kept;
            self.accumulator = kept;
        }
        Ok(Frame { steps, dropped })
    }

    /// True when `accumulated` pays for a whole step.
    fn due(&self, accumulated: T) -> bool {
        accumulated >= self.dt * (T::one() - T::from_f64(STEP_SLACK_EPS) * T::EPSILON)
    }

    /// The fraction of a step accumulated but not yet taken, in `[0, 1]`.
    #[must_use]
    pub fn alpha(&self) -> T {
        (self.accumulator / self.dt).max(T::zero()).min(T::one())
    }

    /// The time after the last step.
    #[must_use]
    pub fn time(&self) -> T {
        self.clock.time()
    }

    /// The fixed step.
    #[must_use]
    pub fn dt(&self) -> T {
        self.dt
    }

    /// Starts again at time `t` (finite) with nothing accumulated.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `t` when not finite.
    pub fn reset(&mut self, t: T) -> Result<(), Error> {
        self.clock = Clock::new(validate::finite("t", t)?);
        self.accumulator = T::zero();
        Ok(())
    }
}
