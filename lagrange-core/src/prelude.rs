//! The names nearly every user of lagrange-core needs: `use lagrange_core::prelude::*;`.
//!
//! The scalar traits, [`State`], the two halves of a mechanism ([`Lagrangian`],
//! [`Mechanism`]), the automatic path ([`EulerLagrange`]), forces and constraints, and
//! nalgebra's fixed-size vector.

pub use crate::constraints::{Constrained, Constraints, Projection, Stabilization};
pub use crate::{
    Controlled, Error, EulerLagrange, GeneralizedForce, Input, Lagrangian, Mechanism, Real, Scalar,
    State, ViscousDamping,
};
pub use nalgebra::SVector;
