//! # lagrange-systems
//!
//! Hand-derived standard mechanisms, `no_std` and allocation-free, each generic over `f32` and
//! `f64`, each implementing both [`Mechanism`](lagrange_core::Mechanism) (closed-form
//! equations, the fast path) and [`Lagrangian`](lagrange_core::Lagrangian) (so the automatic
//! Euler-Lagrange path can check it). Conventions: gravity `g > 0` along -y, angles in radians
//! from the downward vertical.
//!
//! The guide to the three crates, by task (your own mechanism, choosing an integrator,
//! contacts, scenes, firmware), is the book in the repository's `guide/` folder
//! (`cargo xtask guide` builds it).
//!
//! | type | q | parameters |
//! |---|---|---|
//! | [`FallingParticle`] | `[y]` | mass, gravity |
//! | [`SimplePendulum`] | `[th]` | mass, length, gravity, damping |
//! | [`BeadOnRotatingHoop`] | `[th]` | mass, radius, omega, gravity |
//! | [`DoublePendulum`] | `[th1, th2]` | m1, m2, l1, l2, gravity |
//! | [`NLinkPendulum`] | `[th1..thN]` | `masses: [T; N]`, `lengths: [T; N]`, gravity |
//! | [`SpringMassDamper`] | `[x]` | mass, stiffness, damping |
//! | [`ElasticPendulum`] | `[r, th]` | mass, stiffness, rest_length, gravity |
//! | [`SphericalPendulum`] | `[th, phi]` | mass, length, gravity |
//! | [`CartPole`] | `[x, th]`, th from the upward vertical | cart_mass, pole_mass, pole_half_length, gravity; input force |
//! | [`Acrobot`] | `[th1, th2]`, th2 relative to link 1 | m1, m2, l1, l2, lc1, lc2, i1, i2, gravity; input torque |
//! | [`SwingingAtwood`] | `[r, th]` | big_mass, small_mass, gravity |
//! | [`Kepler`] | `[r, phi]` | mu |
//! | [`RigidBody`] | `[x, y, th]`: centre of mass and angle | mass, inertia, gravity (or `rectangle`, `disk`); one link ([`Links`](lagrange_core::links::Links)) |
//! | [`Ragdoll`] | `[x, y, th, 9 joints]`: torso centre and angle, joints relative | [`RagdollBody`]: ten segments, shoulder and hip widths, gravity, joint damping (`O(links)` accelerations; contacts: [`RagdollContacts`]) |
//!
//! Constrained mechanisms (Lagrange multipliers, see
//! [`lagrange_core::constraints`]): each also implements
//! [`Constraints`](lagrange_core::Constraints), hand-derived, and the generic form the dual
//! numbers check it against; its `acceleration` includes the constraint forces.
//!
//! | type | q | constraints | parameters |
//! |---|---|---|---|
//! | [`CartesianPendulum`] | `[x, y]` | 1 holonomic: `x^2 + y^2 = l^2` | mass, length, gravity |
//! | [`FourBarLinkage`] | `[th1, th2, th3]` | 2 holonomic: loop closure | 4 lengths, 3 masses, gravity |
//! | [`RollingDisk`] | `[x, y, psi, phi]` | 2 Pfaffian: rolling without slipping | mass, radius |
//!
//! [`exact`] holds closed-form solutions used as references: the large-amplitude pendulum, the
//! damped oscillator and Kepler orbits.
//!
//! ```
//! use lagrange_core::{Mechanism, State};
//! use lagrange_systems::DoublePendulum;
//! let dp = DoublePendulum::new(1.0_f32, 1.0, 1.0, 1.0, 9.81)?;
//! let a = dp.acceleration(&State::new(0.0, [0.5, -0.5], [0.0, 0.0]))?;
//! assert!(a[0] < 0.0 && a[1] > 0.0);
//! # Ok::<(), lagrange_core::Error>(())
//! ```

#![no_std]
#![forbid(unsafe_code)]

mod acrobot;
mod bead_on_rotating_hoop;
mod cart_pole;
mod cartesian_pendulum;
mod double_pendulum;
mod elastic_pendulum;
pub mod exact;
mod falling_particle;
mod four_bar_linkage;
mod kepler;
mod links;
mod n_link_pendulum;
mod ragdoll;
mod ragdoll_contacts;
mod rigid_body;
mod rolling_disk;
mod simple_pendulum;
mod small_solve;
mod spherical_pendulum;
mod spring_mass_damper;
mod swinging_atwood;

pub use bead_on_rotating_hoop::BeadOnRotatingHoop;
pub use cartesian_pendulum::CartesianPendulum;
pub use double_pendulum::DoublePendulum;
pub use falling_particle::FallingParticle;
pub use four_bar_linkage::{Branch, FourBarLinkage};
pub use rigid_body::RigidBody;
pub use rolling_disk::RollingDisk;
pub use simple_pendulum::SimplePendulum;

pub use acrobot::Acrobot;
pub use cart_pole::CartPole;
pub use elastic_pendulum::ElasticPendulum;
pub use kepler::Kepler;
pub use n_link_pendulum::NLinkPendulum;
pub use ragdoll::{Ragdoll, RagdollBody, Segment, RAGDOLL_COORDINATES, RAGDOLL_LINKS};
pub use ragdoll_contacts::{
    RagdollContacts, ADULT_JOINT_LIMITS, RAGDOLL_CONTACTS, RAGDOLL_FLOOR_POINTS,
};
pub use spherical_pendulum::SphericalPendulum;
pub use spring_mass_damper::SpringMassDamper;
pub use swinging_atwood::SwingingAtwood;
