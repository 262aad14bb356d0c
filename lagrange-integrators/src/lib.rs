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
//! [`Projected`] wraps any of them to project onto constraints after every step;
//! [`ContactStepper`] ([`impacts`]) wraps any of them to step through impacts and resting
//! contacts.
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

mod explicit_euler;
pub mod impacts;
mod integrator;
mod projected;
mod rk4;
mod semi_implicit_euler;
mod velocity_verlet;

pub use explicit_euler::ExplicitEuler;
pub use impacts::{ContactModel, ContactStepper, Contacts, Impact};
pub use integrator::Integrator;
pub use projected::Projected;
pub use rk4::Rk4;
pub use semi_implicit_euler::SemiImplicitEuler;
pub use velocity_verlet::VelocityVerlet;
