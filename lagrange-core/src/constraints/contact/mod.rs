//! Unilateral contacts `g(q) >= 0` (ground, walls, joint limits) as laws: which rows are in
//! force and how they hold the motion ([`ActiveRows`]), and the jump of the velocities at an
//! impact ([`Impacts`], recorded as an [`Impact`]). Locating the contacts inside a step is
//! stepping, and belongs to `ContactStepper` in lagrange-integrators.
//!
//! - [`Contacts`]: the contact set (any [`Constraints`](super::Constraints) whose rows are
//!   gaps), with an optional tangent for friction.
//! - [`ContactModel`]: restitution `e` in `[0, 1]`, the resting threshold, the event time
//!   tolerance, Coulomb friction.
//! - [`Delassus`]: the rows' mass-weighted geometry `J M^-1 J^T` and their complementarity
//!   problem solved exactly, which every contact solve of the library shares.

mod active_rows;
mod contacts;
mod impulse;
mod lcp;
mod model;

pub use active_rows::{drop_dependent_contacts, ActiveRows};
pub use contacts::Contacts;
pub use impulse::{within_kinetic_energy, Impact, Impacts};
pub use lcp::{each_column, Complementary, Delassus, Row};
pub use model::ContactModel;
