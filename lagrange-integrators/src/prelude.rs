//! The names a program that steps mechanisms needs: `use lagrange_integrators::prelude::*;`.
//!
//! Everything of [`lagrange_core::prelude`], the [`Integrator`] trait and the integrators and
//! drivers most programs use, and scenes.

pub use crate::scene::{Bank, NeverSleeps, Scene, Sleeps};
pub use crate::{
    AdaptiveSettings, ContactModel, ContactStepper, DormandPrince54, DormandPrince853,
    DormandPrinceNystrom1210, DormandPrinceNystrom64, DormandPrinceNystrom86, FixedTimestep,
    GaussLegendre2, ImpulseSettings, ImpulseStepper, Integrator, Method, Projected, Rk4,
    SemiImplicitEuler, StormerVerlet, VariationalMidpoint, VelocityVerlet, Verner76, Verner98,
    Yoshida4,
};
pub use lagrange_core::prelude::*;
