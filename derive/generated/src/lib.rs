//! # lagrange-generated
//!
//! Mechanisms that `lagrange-derive` (`cargo xtask derive`) generated from the SymPy specs in `derive/specs/`:
//! the origin's workflow, "derive symbolically, implement numerically". Each is `no_std`,
//! generic over the scalar, a [`Lagrangian`](lagrange_core::Lagrangian) and a
//! [`Mechanism`](lagrange_core::Mechanism) (and [`Constraints`](lagrange_core::Constraints)
//! where its spec gives rows `phi`), with a validated constructor and the spec's defaults.
//!
//! | type | spec | q |
//! |---|---|---|
//! | [`Pendulum`] | `pendulum.py`: the origin's pendulum, damped | `[th]` |
//! | [`DoublePendulum`] | `double_pendulum.py` | `[th1, th2]` |
//! | [`SpringCartPendulum`] | `spring_cart_pendulum.py`: a pendulum hanging from a cart held by a spring | `[x, th]` |
//! | [`TriplePendulum`] | `triple_pendulum.py`: a 3x3 mass matrix, solved by Cholesky | `[th1, th2, th3]` |
//! | [`KapitzaPendulum`] | `kapitza_pendulum.py`: a pivot driven up and down, time explicit in `T` | `[th]` |
//! | [`CartesianPendulum`] | `cartesian_pendulum.py`: one holonomic row | `[x, y]` |
//!
//! Like every function of the library that returns a `Result`, their solves and laws return
//! `Ok` only with finite values: parameters that are each valid but whose products overflow
//! or underflow (a mass of `1e-308`, whose inverse is infinite), or an extreme state, give
//! [`Error::NonFiniteState`](lagrange_core::Error::NonFiniteState).
//!
//! Do not edit the files: `cargo xtask derive --check` (part of `cargo xtask ci`) regenerates
//! each from the spec its header names and fails when one differs; `cargo xtask derive --update
//! FILE.rs` regenerates one. Each file holds a test against the automatic path of its
//! own `T` and `V`; `tests/hand_derived.rs` checks them against the hand-derived mechanisms of
//! `lagrange-systems`.

#![no_std]
#![forbid(unsafe_code)]

mod cartesian_pendulum;
mod double_pendulum;
mod kapitza_pendulum;
mod pendulum;
mod spring_cart_pendulum;
mod triple_pendulum;

pub use cartesian_pendulum::CartesianPendulum;
pub use double_pendulum::DoublePendulum;
pub use kapitza_pendulum::KapitzaPendulum;
pub use pendulum::Pendulum;
pub use spring_cart_pendulum::SpringCartPendulum;
pub use triple_pendulum::TriplePendulum;
