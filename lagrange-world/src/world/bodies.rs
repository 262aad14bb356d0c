//! A [`World`](super::World)'s bodies and the shapes on them.

use crate::shape::Shape;
use crate::sweep::half_width;
use crate::vec2::{add, length, Vec2};
use lagrange_core::links::{Links, Pose};
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, Mechanism, Real, State};

/// An island's name as it falls asleep: its least body key, and the count of steps in which
/// islands fell asleep before (the key alone named a body's island of long ago as well, and
/// a ball that struck it woke a stranger it had once slept beside).
pub(crate) type Island = (u32, u64);

/// An instance of the world's mechanism: its state and whether it sleeps.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Body<T: Real, M, L, const N: usize> {
    pub(crate) key: u32,
    pub(crate) mechanism: M,
    /// Its own rows (joint limits).
    pub(crate) limits: L,
    pub(crate) state: State<T, N>,
    /// Where its mechanism's origin is in the world (a pendulum's pivot).
    pub(crate) origin: Vec2<T>,
    pub(crate) asleep: bool,
    /// How long it has moved slower than the sleep speed, s.
    pub(crate) still: T,
    /// The island it fell asleep with: what wakes with it (see [`Island`]).
    pub(crate) island: Island,
}

impl<T: Real, M: Mechanism<T, N>, L, const N: usize> Body<T, M, L, N> {
    /// Awake, never still, its mechanism's origin at `origin`.
    pub(crate) fn new(
        key: u32,
        mechanism: M,
        limits: L,
        state: State<T, N>,
        origin: Vec2<T>,
    ) -> Self {
        Self {
            key,
            mechanism,
            limits,
            state,
            origin,
            asleep: false,
            still: T::zero(),
            island: (key, u64::MAX),
        }
    }

    /// Step 1 of a world's step: the velocity after the free law, `v + dt a(q, v)`.
    pub(crate) fn free(&mut self, dt: T) -> Result<(), Error> {
        let a = self.mechanism.acceleration(&self.state)?;
        self.state.qd += a * dt;
        self.state.check_finite()
    }

    /// Link `link`'s pose in the world at coordinates `q`.
    pub(crate) fn pose(&self, q: &SVector<T, N>, link: usize) -> Pose<T>
    where
        M: Links<T, N>,
    {
        let pose = self.mechanism.pose(q, link);
        Pose {
            origin: add(pose.origin, self.origin),
            ..pose
        }
    }

    /// Links `0..poses.len()` posed in the world at coordinates `q` (as [`Body::pose`]
    /// each, from one [`Links::poses`]).
    pub(crate) fn poses(&self, q: &SVector<T, N>, poses: &mut [Pose<T>])
    where
        M: Links<T, N>,
    {
        self.mechanism.poses(q, poses);
        for pose in poses {
            pose.origin = add(pose.origin, self.origin);
        }
    }

    /// Awake, its time at rest started again.
    pub(crate) fn wake(&mut self) {
        self.asleep = false;
        self.still = T::zero();
    }

    /// Asleep with island `island`: at rest.
    pub(crate) fn sleep(&mut self, island: Island) {
        self.asleep = true;
        self.island = island;
        self.state.qd.fill(T::zero());
    }
}

/// A shape: on link `on.1` of body `on.0` (in the link's frame), or static (`on` none, in
/// world coordinates), with its collision filter.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Attached<T> {
    pub(crate) key: u32,
    pub(crate) on: Option<(usize, usize)>,
    pub(crate) shape: Shape<T>,
    /// How far the shape reaches from its link's origin: its farthest vertex and its
    /// radius (what a turn of the link moves its farthest point by, per radian).
    pub(crate) extent: T,
    /// Half its thinnest width (`sweep::half_width`): a shape closing on it this far in a
    /// step may pass the features closest at the step's start (see `sweep`).
    pub(crate) half_width: T,
    pub(crate) group: u32,
    pub(crate) mask: u32,
}

impl<T: Real> Attached<T> {
    /// In group 1, colliding with every group.
    pub(crate) fn new(key: u32, on: Option<(usize, usize)>, shape: Shape<T>) -> Self {
        let extent = shape
            .vertices()
            .iter()
            .map(|&v| length(v))
            .fold(T::zero(), T::max)
            + shape.radius();
        Self {
            key,
            on,
            shape,
            extent,
            half_width: half_width(&shape),
            group: 1,
            mask: u32::MAX,
        }
    }
}
