//! Scenes: many mechanisms, one clock, and sleeping, with no heap and no `dyn`.
//!
//! - A [`Bank`] holds up to `K` instances of one mechanism type, each with its own
//!   parameters, input and state, stepped by copies of one integrator.
//! - A [`Scene`] holds banks of different types and integrators ([`Banks`]: one bank, a
//!   tuple or an array of them) and advances them from frame times with one fixed-timestep
//!   clock ([`FrameClock`]: accumulator, cap, interpolation).
//! - Sleeping is chosen per bank as a type parameter: [`NeverSleeps`] (the plain loop) or
//!   [`Sleeps`] (rest at an equilibrium over a count of steps; velocities zeroed; awake
//!   instances packed so that sleepers cost nothing in the step loop).
//!
//! The order of a step is fixed: the scene takes the steps a frame pays for one after the
//! other; within one, the banks step in their order in the tuple (or array), and within a
//! bank the awake instances in their place order. No instance's bits depend on that order,
//! nor on the order the instances were added in: instances do not interact, each keeps its
//! own integrator, and all arithmetic goes through the scalar traits (no fused multiply-add),
//! so a scene gives the same bits on x86_64, wasm32 and the Cortex-M4F.
//!
//! ```
//! use lagrange_integrators::prelude::*;
//! use lagrange_integrators::scene::{Bank, NeverSleeps, Scene, Sleeps};
//! use lagrange_systems::{CartPole, SimplePendulum};
//!
//! // A bank of pendulums that sleep and a bank of cart-poles that never do, at 120 Hz.
//! let props: Bank<f32, 1, 64, SimplePendulum<f32>, StormerVerlet<f32, 1>, Sleeps<f32>> =
//!     Bank::new(StormerVerlet::default(), Sleeps::new(1e-6, 1e-3, 60)?)?;
//! let carts: Bank<f32, 2, 8, CartPole<f32>, Rk4> = Bank::new(Rk4, NeverSleeps)?;
//! let mut scene = Scene::new((props, carts), 1.0 / 120.0, 8)?;
//!
//! let (props, carts) = scene.banks_mut();
//! let lamp = props.add(SimplePendulum::new(1.0, 0.5, 9.81, 0.2)?, State::at_rest([0.3]))?;
//! let cart = carts.add(CartPole::new(1.0, 0.1, 0.5, 9.8)?, State::at_rest([0.0, 0.05]))?;
//! carts.set_input(cart, 1.5)?;
//!
//! let frame = scene.advance(1.0 / 60.0)?; // a 60 Hz frame: two steps
//! assert_eq!((frame.steps, frame.failed), (2, 0));
//! let drawn = scene.banks().0.interpolated(lamp, scene.alpha())?;
//! assert!(drawn.q[0] < 0.3);
//! # Ok::<(), lagrange_core::Error>(())
//! ```

mod awake;
mod bank;
mod banks;
mod columns;
mod layout;
mod sleep;
mod slot;
mod states;

pub use bank::{Bank, Energies, Id, Status};
pub use banks::Banks;
pub use layout::{InLanes, Layout, OneByOne, LANES};
pub use sleep::{NeverSleeps, Sleep, Sleeps};

use crate::FrameClock;
use lagrange_core::{Error, Real};

/// What one frame of a [`Scene`] did.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SceneFrame<T> {
    /// Fixed steps taken.
    pub steps: u32,
    /// Simulated time given up to the cap on steps per frame ([`FrameClock`]).
    pub dropped: T,
    /// Instances whose step failed in this frame: each keeps its last good state and waits,
    /// set aside, for something to wake it ([`Status::Failed`]); the others go on.
    pub failed: u32,
}

/// Banks of mechanisms advanced from frame times by one fixed-timestep clock: every fixed
/// step steps every awake instance of every bank, in the order of the module's docs
/// ([`crate::scene`]). Starts at time 0.
#[derive(Debug, Clone)]
pub struct Scene<T: Real, B> {
    clock: FrameClock<T>,
    banks: B,
}

impl<T: Real, B: Banks<T>> Scene<T, B> {
    /// `banks` (whose clocks, and instances' times, are set to 0) stepped by `dt` (positive,
    /// finite), at most `max_steps_per_frame` (at least 1) per frame.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `dt` or `max_steps_per_frame`.
    pub fn new(mut banks: B, dt: T, max_steps_per_frame: u32) -> Result<Self, Error> {
        let clock = FrameClock::new(dt, max_steps_per_frame, T::zero())?;
        banks.set_time(clock.time());
        Ok(Self { clock, banks })
    }

    /// Adds `frame_time` (zero or positive, finite) and takes the fixed steps it pays for, up
    /// to the cap ([`FrameClock::advance`]).
    ///
    /// Whatever the frame time (`T::MAX`, a pause in a debugger), the time beyond the cap is
    /// dropped whole: a frame of exactly `dt` after it takes one step.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `frame_time` when negative or not finite (nothing
    /// changes); [`Error::NonFiniteState`] when the scene's time after a step would overflow
    /// (a `dt` near `T::MAX`): the steps before it are taken, and the time of the step
    /// refused stays accumulated, as in [`FrameClock::advance`]. An instance whose step fails
    /// does not stop the others: it is counted in [`SceneFrame::failed`].
    pub fn advance(&mut self, frame_time: T) -> Result<SceneFrame<T>, Error> {
        let banks = &mut self.banks;
        let dt = self.clock.dt();
        let mut failed = 0u32;
        let frame = self.clock.advance(frame_time, |t| {
            failed = failed.saturating_add(banks.step(dt, t));
            Ok(())
        })?;
        Ok(SceneFrame {
            steps: frame.steps,
            dropped: frame.dropped,
            failed,
        })
    }

    /// The fraction of a step accumulated but not yet taken, in `[0, 1]`: what
    /// [`Bank::interpolated`] draws by.
    #[must_use]
    pub fn alpha(&self) -> T {
        self.clock.alpha()
    }

    /// The time of the last step.
    #[must_use]
    pub fn time(&self) -> T {
        self.clock.time()
    }

    /// The fixed step.
    #[must_use]
    pub fn dt(&self) -> T {
        self.clock.dt()
    }

    /// The banks, to read.
    #[must_use]
    pub fn banks(&self) -> &B {
        &self.banks
    }

    /// The banks, to add, remove, write and wake instances.
    pub fn banks_mut(&mut self) -> &mut B {
        &mut self.banks
    }
}
