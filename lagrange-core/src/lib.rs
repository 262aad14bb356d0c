//! # lagrange-core
//!
//! The core of lagrange: `no_std`, allocation-free Lagrangian mechanics.
//!
//! The guide to the three crates, by task (your own mechanism, choosing an integrator,
//! contacts, scenes, firmware), is the book in the repository's `guide/` folder
//! (`cargo xtask guide` builds it).
//!
//! - [`Real`] (`f32`, `f64`) and [`Scalar`] (those and [`Dual`] numbers): every computation is
//!   generic over the scalar, and all math goes through `libm`.
//! - [`State`]: time, coordinates and velocities, `N` a const generic.
//! - [`Mechanism`]: `M(q) q'' = f + Q`, energies, and `acceleration()` by a fixed-size Cholesky
//!   solve ([`solve_spd`]) unless a system gives a closed form.
//! - [`Lagrangian`] and [`EulerLagrange`]: write `T` and `V` once and get the equations of
//!   motion by automatic differentiation.
//! - [`GeneralizedForce`], [`ViscousDamping`], [`Input`], [`Forced`]: forces added by wrapping;
//!   [`Controlled`]: a mechanism whose input is set between steps.
//! - [`constraints`]: holonomic and Pfaffian constraints with Lagrange multipliers
//!   ([`Constrained`]), Baumgarte [`Stabilization`] and [`Projection`] against drift.
//! - [`Jacobian`]: `d/dq` and `d/dq'` of the equations of motion, exact from dual numbers for
//!   [`EulerLagrange`], by [`central_difference_jacobian`] otherwise (for implicit integrators).
//! - [`links`]: where a mechanism's links are in the plane ([`links::Links`]), and the
//!   Jacobian of a point fixed on one (by dual numbers, or by hand): what collision
//!   detection needs of a mechanism.
//! - [`Error`]: one small `Copy` error type for every crate.
//! - [`closed_form`]: a mechanism given by its equations in closed form ([`ClosedForm`]: what
//!   `lagrange-derive` generates from a SymPy spec) is a [`Mechanism`] by one generic impl;
//!   [`parameters!`] writes a mechanism's parameter struct, validated constructor and defaults;
//!   [`agreement`] checks any mechanism against the automatic path of its own Lagrangian.
//!
//! ```
//! use lagrange_core::{EulerLagrange, Lagrangian, Mechanism, Scalar, State, ViscousDamping};
//! use nalgebra::SVector;
//!
//! /// A unit mass on a spring of stiffness `k`.
//! struct Oscillator { k: f64 }
//!
//! impl Lagrangian<f64, 1> for Oscillator {
//!     fn kinetic<S: Scalar<Real = f64>>(&self, _t: S, _q: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
//!         S::from_f64(0.5) * qd[0] * qd[0]
//!     }
//!     fn potential<S: Scalar<Real = f64>>(&self, _t: S, q: &SVector<S, 1>) -> S {
//!         S::from_f64(0.5) * S::from_real(self.k) * q[0] * q[0]
//!     }
//! }
//!
//! let system = EulerLagrange::new(Oscillator { k: 4.0 }).with_force(ViscousDamping::uniform(0.1)?);
//! let state = State::new(0.0, [1.0], [0.0]);
//! let qdd = system.acceleration(&state)?;
//! assert!((qdd[0] + 4.0).abs() < 1e-15);
//! assert!((system.energy(&state) - 2.0).abs() < 1e-15);
//! # Ok::<(), lagrange_core::Error>(())
//! ```

#![no_std]
#![forbid(unsafe_code)]

pub mod agreement;
mod cholesky;
pub mod closed_form;
pub mod constraints;
mod controlled;
mod dual;
mod error;
pub mod fast_trig;
mod forces;
mod free_law;
mod gather;
mod jacobian;
mod jet;
mod lagrangian;
mod lanes;
pub mod links;
mod mechanism;
mod parameters;
pub mod prelude;
mod scalar;
mod scalar_trig;
mod state;
mod tape;
mod tree_factor;
mod trig_memo;
pub mod validate;

pub use cholesky::{solve_spd, Cholesky};
pub use closed_form::ClosedForm;
pub use constraints::{
    Constrained, Constraints, Held, Holonomic, HolonomicConstraints, Pfaffian, PfaffianConstraints,
    Projection, Stabilization,
};
pub use controlled::Controlled;
pub use dual::Dual;
pub use error::Error;
pub use forces::{Borrowed, Forced, GeneralizedForce, Input, NoForce, ViscousDamping};
pub use free_law::free_law_force;
pub use gather::Gather;
pub use jacobian::{central_difference_jacobian, Jacobian};
pub use lagrangian::{EulerLagrange, Lagrangian};
pub use lanes::{divergences, Lanes, VECTOR_UNIT};
pub use mechanism::{jacobian_by_differences, Mechanism};
pub use nalgebra;
pub use scalar::{all_finite, check_finite, split_dot, Real, Scalar};
pub use state::State;
pub use tree_factor::TreeFactor;
