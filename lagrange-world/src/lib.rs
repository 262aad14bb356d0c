//! # lagrange-world
//!
//! Collision geometry for lagrange, `no_std` and allocation-free, generic over `f32` and
//! `f64`: the layer that finds where bodies touch, for the contact steppers to solve.
//!
//! - [`Shape`]: a convex shape as a core (a point, a segment, a convex polygon of up to
//!   [`MAX_VERTICES`] vertices) rounded by a radius: circles, capsules, boxes, polygons and
//!   rounded boxes in one form. Made in a body's frame, placed in the world at a link's
//!   [`Pose`](lagrange_core::links::Pose) (from [`Links`](lagrange_core::links::Links)).
//! - [`collide`]: the narrow phase of two shapes, a [`Manifold`] of up to two
//!   [`ContactPoint`]s with their gaps and feature ids, within a speculative margin;
//!   [`collide_half_plane`] against a static [`HalfPlane`] (a floor, a wall).
//! - [`Pair`] (two mechanisms as one, their coordinates side by side) and [`ShapePairs`]
//!   (contact rows between shapes on two links, from the narrow phase): two bodies that
//!   touch, solved by the contact steppers with momentum kept.
//! - Queries: [`Shape::distance`] of a point (signed), [`Shape::ray`] (where a ray first
//!   meets a shape, a [`RayHit`]).
//! - [`BroadPhase`]: the pairs of [`Proxy`] boxes that overlap and may touch (not both
//!   static or asleep, not of one body, collision groups and masks), by sweep and prune, in
//!   an order that does not depend on the order they were added.
//! - [`World`]: instances of a mechanism with shapes on their links, static shapes and
//!   half-planes, stepped together: contacts found by the broad and narrow phases, solved as
//!   sequential impulses in the bodies' generalized coordinates (momentum kept, a bounded
//!   cost a step), fast pairs taken where their paths first meet in the step (a ball at
//!   1,000 m/s bounces off a plank 1 cm thick), islands that fall asleep and wake as a
//!   whole, contact events, ray and point queries. A pyramid of 55 boxes stands and sleeps.
//!   [`OneOf`] makes a world of two kinds of body (balls and the pendulums they strike;
//!   nested, more), each with its own law and links.
//! - [`PlaneContacts`]: the contact rows of a mechanism's shapes against static half-planes,
//!   for `ImpulseStepper` and `ContactStepper` (a crate on the floor, a wheel rolling down a
//!   slope), from its [`Links`](lagrange_core::links::Links) alone.
//!
//! ```
//! use lagrange_core::links::Pose;
//! use lagrange_world::{collide_half_plane, HalfPlane, Shape};
//!
//! // A 0.5 m crate turned by 0.1 rad, its centre 0.27 m above the floor.
//! let floor = HalfPlane::new([0.0_f64, 1.0], 0.0)?;
//! let crate_ = Shape::rectangle(0.5, 0.5)?.placed(&Pose { origin: [0.0, 0.27], angle: 0.1 });
//! let m = collide_half_plane(&floor, &crate_, 0.01);
//! // One corner is in the floor: 0.27 - 0.25 (cos 0.1 + sin 0.1) = -0.0037 m.
//! assert_eq!(m.points().len(), 1);
//! assert!((m.points()[0].gap + 0.0037).abs() < 1e-4);
//! # Ok::<(), lagrange_core::Error>(())
//! ```

#![no_std]
#![forbid(unsafe_code)]

mod broad;
mod collide;
mod manifold;
mod one_of;
mod pair;
mod plane_contacts;
mod query;
mod shape;
mod shape_pairs;
mod sweep;
mod vec2;
mod world;

pub use broad::{BroadPhase, Proxy};
pub use collide::{collide, collide_half_plane, HalfPlane};
pub use manifold::{ContactPoint, Manifold};
pub use one_of::OneOf;
pub use pair::Pair;
pub use plane_contacts::PlaneContacts;
pub use query::RayHit;
pub use shape::{Shape, MAX_VERTICES};
pub use shape_pairs::{OnLink, ShapePairs};
pub use vec2::Vec2;
pub use world::{
    Clock, ContactEvent, CoordinateLimits, Limits, NoLimits, PlacedShape, Profile, World, WorldHit,
    WorldReport, WorldSettings, MAX_OWN_ROWS, MAX_PLANES,
};
