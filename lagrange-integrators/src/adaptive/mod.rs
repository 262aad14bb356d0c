//! Adaptive explicit Runge-Kutta integrators: error control, dense output, events.

mod controller;
mod dop853;
mod dopri5;
mod embedded;
mod events;
mod settings;

pub use dop853::{Dop853Pair, DormandPrince853};
pub use dopri5::{Dopri5Pair, DormandPrince54};
pub use embedded::{EmbeddedPair, EmbeddedRungeKutta, Statistics};
pub use events::Stop;
pub use settings::AdaptiveSettings;
