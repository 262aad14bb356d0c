//! Where the links of the standard chains are ([`Links`]): each link's frame at its joint,
//! turned so that the link lies along its frame's `-y` axis (a pendulum's rod, hanging at
//! angle 0 from the downward vertical) or, for the cart-pole's pole, `+y` (upright at 0). A
//! point at `(0, -l)` of a pendulum's link is its bob. The point Jacobians come from the
//! poses in dual numbers ([`Links::point`]'s default).

use crate::{
    Acrobot, CartPole, DoublePendulum, NLinkPendulum, Ragdoll, SimplePendulum, RAGDOLL_COORDINATES,
    RAGDOLL_LINKS,
};
use lagrange_core::links::{Links, Pose};
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Real, Scalar};

/// The end of a link of length `l` hanging at `angle` from `origin`.
fn end<S: Scalar>(origin: [S; 2], angle: S, l: S::Real) -> [S; 2] {
    let (s, c) = angle.sin_cos();
    let l = S::from_real(l);
    [origin[0] + l * s, origin[1] - l * c]
}

fn at<S: Scalar>(origin: [S; 2], angle: S) -> Pose<S> {
    Pose { origin, angle }
}

impl<T: Real> Links<T, 1> for SimplePendulum<T> {
    /// The rod, from the pivot at the origin.
    const LINKS: usize = 1;
    fn pose<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 1>, _link: usize) -> Pose<S> {
        at([S::zero(), S::zero()], q[0])
    }
}

impl<T: Real> Links<T, 2> for DoublePendulum<T> {
    /// Link 0 from the pivot at the origin, link 1 from the first bob.
    const LINKS: usize = 2;
    fn pose<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 2>, link: usize) -> Pose<S> {
        let origin = [S::zero(), S::zero()];
        if link == 0 {
            at(origin, q[0])
        } else {
            at(end(origin, q[0], self.lengths()[0]), q[1])
        }
    }
}

impl<T: Real, const N: usize> Links<T, N> for NLinkPendulum<T, N> {
    /// Link `k` from bob `k - 1` (link 0 from the pivot at the origin).
    const LINKS: usize = N;
    fn pose<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, N>, link: usize) -> Pose<S> {
        let lengths = self.lengths();
        let mut origin = [S::zero(), S::zero()];
        for k in 0..link.min(N) {
            origin = end(origin, q[k], lengths[k]);
        }
        at(origin, q[link.min(N.saturating_sub(1))])
    }
}

impl<T: Real> Links<T, 2> for Acrobot<T> {
    /// Link 0 from the pivot at the origin; link 1 from its end, at `th1 + th2`.
    const LINKS: usize = 2;
    fn pose<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 2>, link: usize) -> Pose<S> {
        let origin = [S::zero(), S::zero()];
        if link == 0 {
            at(origin, q[0])
        } else {
            at(end(origin, q[0], self.lengths()[0]), q[0] + q[1])
        }
    }
}

impl<T: Real> Links<T, 2> for CartPole<T> {
    /// Link 0 the cart, its frame at `(x, 0)` unturned; link 1 the pole from the same point,
    /// upright along its frame's `+y` (the frame turned by `-th`: `th` is clockwise from the
    /// upward vertical), its centre of mass at `(0, l)`.
    const LINKS: usize = 2;
    fn pose<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 2>, link: usize) -> Pose<S> {
        let origin = [q[0], S::zero()];
        if link == 0 {
            at(origin, S::zero())
        } else {
            at(origin, -q[1])
        }
    }
}

impl<T: Real> Links<T, RAGDOLL_COORDINATES> for Ragdoll<T> {
    /// In the order of `q` and [`Ragdoll::segments`]: the torso (its frame at its centre of
    /// mass, the neck at `(0, L/2)`, the pelvis at `(0, -L/2)`), the head and the limbs (each
    /// from its joint, along `-y`).
    const LINKS: usize = RAGDOLL_LINKS;
    fn pose<S: Scalar<Real = T> + 'static>(
        &self,
        q: &SVector<S, RAGDOLL_COORDINATES>,
        link: usize,
    ) -> Pose<S> {
        let link = link.min(RAGDOLL_LINKS - 1);
        // The ragdoll's own pose of every link (its inherent method, not this one).
        let origin = self.pose(q).origin[link];
        at([q[0] + origin[0], q[1] + origin[1]], self.angles(q)[link])
    }
}
