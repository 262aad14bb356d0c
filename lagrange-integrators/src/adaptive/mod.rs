//! Adaptive explicit Runge-Kutta integrators: error control, dense output, events.

mod controller;
mod dop853;
mod dopri5;
mod embedded;
mod energy;
mod events;
mod hermite;
mod nystrom;
mod nystrom1210;
mod nystrom64;
mod nystrom86;
mod settings;
mod sums;
mod verner76;
mod verner98;

pub use dop853::{Dop853Pair, DormandPrince853};
pub use dopri5::{Dopri5Pair, DormandPrince54};
pub use embedded::{EmbeddedPair, EmbeddedRungeKutta, Statistics};
pub use events::Stop;
pub use nystrom::{lower_triangular, Nystrom};
pub use nystrom1210::{DormandPrinceNystrom1210, Nystrom1210Pair};
pub use nystrom64::{DormandPrinceNystrom64, Nystrom64Pair};
pub use nystrom86::{DormandPrinceNystrom86, Nystrom86Pair};
pub use settings::{AdaptiveSettings, ENERGY_PROJECTION_LIMIT};
pub use verner76::{Verner76, Verner76Pair};
pub use verner98::{Verner98, Verner98Pair};
