//! The stress suite, one test binary (each integration-test binary costs a link and, in the
//! release pass of `cargo xtask ci`, a thin-LTO optimisation of its own):
//!
//! - [`long_run`]: 10^7 steps of the pendulum with a symplectic method, f32 and f64, energy
//!   bounded without drift (the 10^7-step runs are `#[ignore]`d: `cargo xtask ci` runs them
//!   in release).
//! - [`stability`]: step sizes up to and past each explicit method's stability limit.
//! - [`chaos`]: the chaotic double pendulum's finite-time Lyapunov exponent.
//! - [`properties`] and [`properties_more`]: property tests over random valid and invalid
//!   parameters and states for every standard system.

mod chaos;
mod long_run;
mod properties;
mod properties_more;
mod stability;
