//! Where each shape of a [`World`](super::World) is at a step's start, and how far it may
//! move in the step: each body's links posed once ([`Links::poses`] at its coordinates, and
//! at where its velocities take them), every shape on it placed from them. The broad phase,
//! each pair and each half-plane then read the shapes placed, not their links posed again (a
//! ragdoll's link pose is its whole tree's: ten shapes on it were thirty poses a step, and
//! as many again per pair).
//!
//! The reach is taken at the free velocities, before the impulses; where the impulses send a
//! body farther (see `outran`), its shapes are placed again with the reach of both.

use super::bodies::{Attached, Body};
use crate::shape::Shape;
use crate::sweep::Moving;
use crate::vec2::{length, sub};
use heapless::Vec;
use lagrange_core::links::{Links, Pose};
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Mechanism, Real};

/// A shape where it is this step.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Place<T> {
    /// The shape in world coordinates.
    pub(crate) shape: Shape<T>,
    /// Its link's pose (the world's frame for a static shape).
    pub(crate) pose: Pose<T>,
    /// Its link's pose at the step's end where its velocity takes it (`pose` for a static
    /// or sleeping shape).
    pub(crate) then: Pose<T>,
    /// How far any point of it moves in the step at its body's velocity (zero for a static
    /// or sleeping one): its link's origin's move and its turn times its reach from that
    /// origin.
    pub(crate) reach: T,
}

impl<T: Real> Place<T> {
    /// Its shape moving through the step, `s` the shape as attached (in its link's frame;
    /// in the world's for a static one).
    pub(crate) fn moving<'a>(&self, s: &'a Attached<T>) -> Moving<'a, T> {
        Moving {
            shape: &s.shape,
            from: self.pose,
            to: self.then,
            extent: s.extent,
        }
    }
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

/// A body's links posed at its coordinates, or where a velocity takes them in a step.
pub(super) struct Posed<T, const N: usize> {
    q: SVector<T, N>,
    poses: [Pose<T>; POSED],
}

impl<T: Real, const N: usize> Posed<T, N> {
    /// `body`'s links at `q`.
    fn at<M, L>(body: &Body<T, M, L, N>, q: SVector<T, N>) -> Self
    where
        M: Mechanism<T, N> + Links<T, N>,
    {
        let mut poses = [identity(); POSED];
        body.poses(&q, &mut poses[..M::LINKS.min(POSED)]);
        Self { q, poses }
    }

    /// `body`'s links where velocity `v` takes them in `dt`.
    pub(super) fn ahead<M, L>(body: &Body<T, M, L, N>, v: &SVector<T, N>, dt: T) -> Self
    where
        M: Mechanism<T, N> + Links<T, N>,
    {
        Self::at(body, body.state.q + v * dt)
    }

    /// Link `link`'s pose (every link below [`POSED`] is posed, and the array holds no more:
    /// a link past them is posed on its own).
    pub(super) fn link<M, L>(&self, body: &Body<T, M, L, N>, link: usize) -> Pose<T>
    where
        M: Mechanism<T, N> + Links<T, N>,
    {
        match self.poses.get(link) {
            Some(&p) if link < M::LINKS.min(POSED) => p,
            _ => body.pose(&self.q, link),
        }
    }

    /// How far any point of a shape reaching `extent` from the origin of link `link`, at
    /// `pose`, moves to here.
    pub(super) fn reach<M, L>(
        &self,
        body: &Body<T, M, L, N>,
        extent: T,
        link: usize,
        pose: &Pose<T>,
    ) -> T
    where
        M: Mechanism<T, N> + Links<T, N>,
    {
        travel(pose, &self.link(body, link), extent)
    }
}

/// How far any point of a shape reaching `extent` from its link's origin moves when the link
/// goes from `from` to `to`: the origin's move and the turn times the extent.
fn travel<T: Real>(from: &Pose<T>, to: &Pose<T>, extent: T) -> T {
    length(sub(to.origin, from.origin)) + (to.angle - from.angle).abs() * extent
}

/// Every shape of `shapes` placed (in their order), `by_body` naming the shapes on bodies
/// `(body, shape)` sorted by body, for a step of `dt`; each awake body's reach the farther of
/// its velocity's and, where given, its velocity in `also` (by body).
pub(crate) fn place<T, M, L, const N: usize, const B: usize, const S: usize>(
    places: &mut Vec<Place<T>, S>,
    shapes: &[Attached<T>],
    by_body: &[(u32, u32)],
    bodies: &Vec<Body<T, M, L, N>, B>,
    dt: T,
    also: Option<&[SVector<T, N>; B]>,
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
            then: identity(),
            reach: T::zero(),
        });
    }
    for group in by_body.chunk_by(|x, y| x.0 == y.0) {
        let Some((b, body)) = group
            .first()
            .and_then(|&(b, _)| Some((b as usize, bodies.get(b as usize)?)))
        else {
            continue;
        };
        let now = Posed::at(body, body.state.q);
        let awake = !body.asleep;
        let ahead = awake.then(|| Posed::ahead(body, &body.state.qd, dt));
        let also = also
            .and_then(|v| v.get(b))
            .filter(|v| awake && **v != body.state.qd)
            .map(|v| Posed::ahead(body, v, dt));
        for &(_, index) in group {
            let index = index as usize;
            let (Some(s), Some(place)) = (shapes.get(index), places.get_mut(index)) else {
                continue;
            };
            let link = s.on.map_or(0, |(_, link)| link);
            let pose = now.link(body, link);
            // Posed once: the sweep's end and the reach's (a link past `POSED` is a pose
            // call of its own).
            let then = ahead.as_ref().map_or(pose, |a| a.link(body, link));
            let reach = also
                .as_ref()
                .map(|a| a.reach(body, s.extent, link, &pose))
                .into_iter()
                .fold(T::zero().max(travel(&pose, &then, s.extent)), T::max);
            *place = Place {
                shape: s.shape.placed(&pose),
                pose,
                then,
                reach,
            };
        }
    }
}
