//! Impacts: unilateral contacts `g(q) >= 0` (ground, walls, joint limits), found inside the
//! step, resolved by velocity jumps, and held as constraints while resting.
//!
//! - [`Contacts`]: the contact set (any `Constraints` whose rows are gaps), with an optional
//!   tangent for friction.
//! - [`ContactModel`]: restitution `e` in `[0, 1]`, the resting threshold, the event time
//!   tolerance, Coulomb friction.
//! - [`ContactStepper`]: any integrator with event location by bisection, impacts
//!   (`q'+ = q'- - (1 + e) M^-1 J^T (J M^-1 J^T)^-1 J q'-`), resting contacts, projection.
//! - [`Impact`]: what an observer of [`ContactStepper::step_observed`] receives.

mod active_rows;
mod contacts;
mod impulse;
mod model;
mod stepper;

pub use active_rows::ActiveRows;
pub use contacts::Contacts;
pub use impulse::Impact;
pub use model::ContactModel;
pub use stepper::ContactStepper;
