//! Where each shape of a [`World`](super::World) is at a step's start, and how far it may
//! move in the step: each body's links posed once ([`Links::poses`] at its coordinates, and
//! at where its velocities take them), every shape on it placed from them. The broad phase,
//! each pair and each half-plane then read the shapes placed, not their links posed again (a
//! ragdoll's link pose is its whole tree's: ten shapes on it were thirty poses a step, and
//! as many again per pair).

use super::bodies::{Attached, Body};
use crate::shape::Shape;
use crate::vec2::{length, sub};
use heapless::Vec;
use lagrange_core::links::{Links, Pose};
use lagrange_core::{Mechanism, Real};

/// A shape where it is this step.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Place<T> {
    /// The shape in world coordinates.
    pub(crate) shape: Shape<T>,
    /// Its link's pose (the world's frame for a static shape).
    pub(crate) pose: Pose<T>,
    /// How far any point of it moves in the step at its body's velocity (zero for a static
    /// or sleeping one): its link's origin's move and its turn times its reach from that
    /// origin.
    pub(crate) reach: T,
}

/// Links posed by one call of [`Links::poses`]; a link past them is posed on its own.
const POSED: usize = 16;

/// The pose of the world's frame.
fn identity<T: Real>() -> Pose<T> {
    Pose {
        origin: [T::zero(); 2],
        angle: T::zero(),
    }
}

/// Every shape of `shapes` placed (in their order), `by_body` naming the shapes on bodies
/// `(body, shape)` sorted by body, for a step of `dt`.
pub(crate) fn place<T, M, L, const N: usize, const B: usize, const S: usize>(
    places: &mut Vec<Place<T>, S>,
    shapes: &[Attached<T>],
    by_body: &[(u32, u32)],
    bodies: &Vec<Body<T, M, L, N>, B>,
    dt: T,
) where
    T: Real,
    M: Mechanism<T, N> + Links<T, N>,
{
    places.clear();
    for s in shapes {
        // Capacity S holds every shape; a static shape is where it is.
        let _ = places.push(Place {
            shape: s.shape,
            pose: identity(),
            reach: T::zero(),
        });
    }
    let posed = M::LINKS.min(POSED);
    for group in by_body.chunk_by(|x, y| x.0 == y.0) {
        let Some(body) = group.first().and_then(|&(b, _)| bodies.get(b as usize)) else {
            continue;
        };
        let q = body.state.q;
        let ahead = q + body.state.qd * dt;
        let mut now = [identity(); POSED];
        body.poses(&q, &mut now[..posed]);
        let mut next = now;
        if !body.asleep {
            body.poses(&ahead, &mut next[..posed]);
        }
        for &(_, index) in group {
            let index = index as usize;
            let (Some(s), Some(place)) = (shapes.get(index), places.get_mut(index)) else {
                continue;
            };
            let link = s.on.map_or(0, |(_, link)| link);
            let (pose, then) = (
                posed_link(&now, body, &q, link),
                posed_link(&next, body, &ahead, link),
            );
            let reach = if body.asleep {
                T::zero()
            } else {
                let extent = s
                    .shape
                    .vertices()
                    .iter()
                    .map(|&v| length(v))
                    .fold(T::zero(), T::max)
                    + s.shape.radius();
                length(sub(then.origin, pose.origin)) + (then.angle - pose.angle).abs() * extent
            };
            *place = Place {
                shape: s.shape.placed(&pose),
                pose,
                reach,
            };
        }
    }
}

/// Link `link` of `body` at `q` from its links posed there (`posed`), or posed on its own
/// past them (every link below [`POSED`] is posed, and the arrays hold no more).
fn posed_link<T, M, L, const N: usize>(
    posed: &[Pose<T>],
    body: &Body<T, M, L, N>,
    q: &lagrange_core::nalgebra::SVector<T, N>,
    link: usize,
) -> Pose<T>
where
    T: Real,
    M: Mechanism<T, N> + Links<T, N>,
{
    match posed.get(link) {
        Some(&p) if link < M::LINKS.min(POSED) => p,
        _ => body.pose(q, link),
    }
}
