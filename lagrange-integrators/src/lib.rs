//! # lagrange-integrators
//!
//! `no_std`, allocation-free integrators for any [`Mechanism`](lagrange_core::Mechanism),
//! generic over `f32`/`f64` and the number of degrees of freedom.
//!
//! | integrator | order | kind | symplectic | evaluations per step | use it for |
//! |---|---|---|---|---|---|
//! | [`ExplicitEuler`] | 1 | explicit | no (gains energy) | 1 | a baseline only |
//! | [`SemiImplicitEuler`] | 1 | explicit | constant `M`, forces of `q` only | 1 | cheap games, stiff-free toys |
//! | [`VelocityVerlet`] | 2 | explicit | constant `M`, forces of `q` only | 2 | long conservative runs at moderate accuracy |
//! | [`Rk4`] | 4 | explicit | no (slow drift) | 4 | accurate short and medium runs |
//!
//! ```
//! use lagrange_core::{Mechanism, State};
//! use lagrange_integrators::{Integrator, Rk4};
//! use lagrange_systems::SimplePendulum;
//!
//! let pendulum = SimplePendulum::new(1.0, 1.0, 9.81, 0.0)?;
//! let start = State::new(0.0, [core::f64::consts::FRAC_PI_6], [0.0]);
//! let end = Rk4.integrate(&pendulum, &start, 1e-3, 10_000)?;
//! let drift = (pendulum.energy(&end) - pendulum.energy(&start)).abs();
//! assert!(drift < 1e-9);
//! # Ok::<(), lagrange_core::Error>(())
//! ```

#![no_std]
#![forbid(unsafe_code)]

mod adaptive;
mod backward_euler;
mod explicit_euler;
mod fixed_timestep;
mod gauss_legendre;
mod implicit_midpoint;
mod implicit_rk;
mod integrator;
mod lagrangian_system;
mod newton;
mod radau_iia;
mod rk4;
mod semi_implicit_euler;
mod stormer_verlet;
mod variational;
mod velocity_verlet;
mod yoshida;

pub use adaptive::{
    AdaptiveSettings, Dop853Pair, Dopri5Pair, DormandPrince54, DormandPrince853, EmbeddedPair,
    EmbeddedRungeKutta, Statistics, Stop,
};
pub use backward_euler::{BackwardEuler, BackwardEulerTableau};
pub use explicit_euler::ExplicitEuler;
pub use fixed_timestep::{FixedTimestep, Frame};
pub use gauss_legendre::{GaussLegendre2, GaussLegendre2Tableau};
pub use implicit_midpoint::{ImplicitMidpoint, MidpointTableau};
pub use implicit_rk::{ImplicitRungeKutta, ImplicitTableau};
pub use integrator::Integrator;
pub use lagrangian_system::LagrangianSystem;
pub use newton::NewtonSettings;
pub use radau_iia::{RadauIIA2, RadauIIA2Tableau};
pub use rk4::Rk4;
pub use semi_implicit_euler::SemiImplicitEuler;
pub use stormer_verlet::StormerVerlet;
pub use variational::{PhaseState, VariationalMidpoint};
pub use velocity_verlet::VelocityVerlet;
pub use yoshida::{SymmetricSecondOrder, Yoshida4, YOSHIDA4_WEIGHTS};
