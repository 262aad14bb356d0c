//! # lagrange-integrators
//!
//! `no_std`, allocation-free integrators for any [`Mechanism`](lagrange_core::Mechanism),
//! generic over `f32`/`f64` and the number of degrees of freedom.
//!
//! The guide to the three crates, by task (your own mechanism, choosing an integrator,
//! contacts, scenes, firmware), is the book in the repository's `guide/` folder
//! (`cargo xtask guide` builds it).
//!
//! | integrator | order | kind | symplectic (energy behaviour) | accelerations per step | use it for |
//! |---|---|---|---|---|---|
//! | [`ExplicitEuler`] | 1 | explicit | no: gains energy | 1 | a baseline only |
//! | [`SemiImplicitEuler`] | 1 | explicit | constant `M`, forces of `q` only | 1 | cheap games with a constant mass matrix |
//! | [`VelocityVerlet`] | 2 | explicit | constant `M`, forces of `q` only (else it drifts) | 2 | long runs of such systems |
//! | [`StormerVerlet`] | 2 | explicit; its first kick implicit where `q''` depends on `q'` | constant `M`, forces of `q`; symmetric for every mechanism: bounded, no drift on regular motion | 2 (+1 per fixed-point iteration where `q''` depends on `q'`) | game physics and long runs of any conservative mechanism |
//! | [`Rk4`] | 4 | explicit | no: slow drift | 4 | accurate short and medium runs |
//! | [`Yoshida4`] | 4 | as its base | where its base is; symmetric: bounded, no drift | 3 base steps (6 over [`StormerVerlet`]) | long runs at high accuracy |
//! | [`ImplicitMidpoint`] | 2 | implicit (Newton) | constant `M`; symmetric, A-stable | 1 per Newton iteration + 1 Jacobian | long runs, stiff oscillations kept undamped |
//! | [`GaussLegendre2`] | 4 | implicit (Newton) | constant `M`; symmetric, A-stable | 2 per Newton iteration + 1 Jacobian | the most accurate fixed step, long runs |
//! | [`BackwardEuler`] | 1 | implicit (Newton), L-stable | no: damps | 1 per Newton iteration + 1 Jacobian | stiff, dissipative systems, robustness first |
//! | [`RadauIIA2`] | 3 | implicit (Newton), L-stable | no: damps `O(h^4)` | 2 per Newton iteration + 1 Jacobian | stiff mechanisms (stiff springs, penalties) |
//! | [`VariationalMidpoint`] | 2 | implicit (Newton on the discrete Euler-Lagrange equations) | yes, any Lagrangian, in `(q, p)`; cyclic momenta kept exactly | Lagrangian in dual numbers: 1 first-order per iteration + 1 second-order per Jacobian + 1 first-order | long runs of mechanisms whose mass matrix depends on `q`, momentum conservation, forced (Lagrange-d'Alembert) |
//! | [`DormandPrince54`] | 5 (4) | explicit, adaptive (PI control, dense output order 4, events) | no | 6 per accepted step | general purpose, tolerances `1e-3` to `1e-8` |
//! | [`DormandPrince853`] | 8 (5, 3) | explicit, adaptive (PI control, dense output order 7, events) | no | 12 per accepted step (+3 where dense output is sampled) | high accuracy, tolerances `1e-7` to `1e-14` |
//! | [`Verner76`] | 7 (6) | explicit, adaptive (PI control, dense output order 4, events) | no | 10 per accepted step | tolerances `1e-6` to `1e-11` on any law |
//! | [`Verner98`] | 9 (8) | explicit, adaptive (PI control, dense output order 4, events) | no | 16 per accepted step | tight tolerances `1e-9` to `1e-14` on any law |
//! | [`DormandPrinceNystrom64`] | 6 (4) | explicit Runge-Kutta-Nyström, adaptive (PI control, dense output order 4, events); laws that do not read `q'` only | no | 5 per accepted step | such laws (undamped pendulums, gravity, springs) at tolerances `1e-4` to `1e-9` |
//! | [`DormandPrinceNystrom86`] | 8 (6) | explicit Runge-Kutta-Nyström, adaptive (PI control, dense output order 4, events); laws that do not read `q'` only | no | 8 per accepted step | such laws at tolerances `1e-6` to `1e-10` |
//! | [`DormandPrinceNystrom1210`] | 12 (10) | explicit Runge-Kutta-Nyström, adaptive (PI control, dense output order 4, events); laws that do not read `q'` only | no | 17 per accepted step | such laws at tolerances `1e-9` to `1e-14` |
//!
//! "Constant `M`, forces of `q`" is the separable case, where `(q, q')` is a linear image of
//! `(q, p)` and these methods are symplectic: bounded energy error, no drift. Where the mass
//! matrix depends on `q` (pendulum chains, polar coordinates), only [`VariationalMidpoint`] is
//! symplectic; the symmetric methods are time-reversible there, which keeps the energy error of
//! regular (quasi-periodic) motion bounded without drift (measured over 10^6 steps of a double
//! pendulum and of a Kepler orbit). The implicit methods share one Newton solver
//! ([`NewtonSettings`]), with Jacobians from dual numbers for an
//! [`EulerLagrange`](lagrange_core::EulerLagrange) mechanism and by central differences
//! otherwise; the adaptive ones share one engine ([`EmbeddedRungeKutta`]).
//!
//! [`FixedTimestep`] drives any fixed-step integrator from variable frame times for games and
//! real-time loops: an accumulator, a cap on steps per frame, interpolated states to draw.
//!
//! [`scene`]: many mechanisms in banks ([`scene::Bank`]), advanced together by one such clock
//! ([`scene::Scene`]), with sleeping at rest chosen per bank.
//!
//! [`Projected`] wraps any of them to project onto constraints after every step;
//! [`ContactStepper`] wraps any of them to step through impacts and resting contacts (the laws
//! of [`lagrange_core::constraints::contact`]).
//!
//! ```
//! use lagrange_core::prelude::*;
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
mod clock;
mod contact_stepper;
mod explicit_euler;
mod fixed_timestep;
mod frame_clock;
mod gauss_legendre;
mod implicit_midpoint;
mod implicit_rk;
mod impulse_stepper;
mod integrator;
mod newton;
pub mod prelude;
mod projected;
mod radau_iia;
mod rk4;
pub mod scene;
mod semi_implicit_euler;
mod stormer_verlet;
mod variational;
mod velocity_verlet;
mod yoshida;

pub use adaptive::{
    lower_triangular, AdaptiveSettings, Dop853Pair, Dopri5Pair, DormandPrince54, DormandPrince853,
    DormandPrinceNystrom1210, DormandPrinceNystrom64, DormandPrinceNystrom86, EmbeddedPair,
    EmbeddedRungeKutta, Nystrom, Nystrom1210Pair, Nystrom64Pair, Nystrom86Pair, Statistics, Stop,
    Verner76, Verner76Pair, Verner98, Verner98Pair, ENERGY_PROJECTION_LIMIT,
};
pub use backward_euler::{BackwardEuler, BackwardEulerTableau};
pub use clock::Clock;
pub use contact_stepper::ContactStepper;
pub use explicit_euler::ExplicitEuler;
pub use fixed_timestep::FixedTimestep;
pub use frame_clock::{Frame, FrameClock};
pub use gauss_legendre::{GaussLegendre2, GaussLegendre2Tableau};
pub use implicit_midpoint::{ImplicitMidpoint, MidpointTableau};
pub use implicit_rk::{ImplicitRungeKutta, ImplicitTableau};
pub use impulse_stepper::{ImpulseReport, ImpulseSettings, ImpulseStepper};
pub use integrator::{Cost, Failure, Integrator, Method, Work};
pub use lagrange_core::constraints::contact::{ActiveRows, ContactModel, Contacts, Impact};
pub use newton::NewtonSettings;
pub use projected::Projected;
pub use radau_iia::{RadauIIA2, RadauIIA2Tableau};
pub use rk4::Rk4;
pub use semi_implicit_euler::SemiImplicitEuler;
pub use stormer_verlet::StormerVerlet;
pub use variational::{PhaseState, VariationalMidpoint};
pub use velocity_verlet::VelocityVerlet;
pub use yoshida::{SymmetricBase, Yoshida4, YOSHIDA4_WEIGHTS};
