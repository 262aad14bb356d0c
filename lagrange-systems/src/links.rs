//! Where the links of the standard chains are ([`Links`]): each link's frame at its joint,
//! turned so that the link lies along its frame's `-y` axis (a pendulum's rod, hanging at
//! angle 0 from the downward vertical) or, for the cart-pole's pole, `+y` (upright at 0). A
//! point at `(0, -l)` of a pendulum's link is its bob. The point Jacobians of the chains are
//! by hand (the origin's derivative plus the offset turned a quarter turn per coordinate that
//! turns the link); the ragdoll's too (the point turned about each joint between it and the
//! torso), from one pose: a world's narrow phase asks for one per contact point, and the
//! dual-number default ([`Links::point`]) carried twelve derivatives through ten sines.

use crate::ragdoll::{self, PARENT, TORSO};
use crate::{
    Acrobot, CartPole, DoublePendulum, NLinkPendulum, Ragdoll, SimplePendulum, RAGDOLL_COORDINATES,
    RAGDOLL_LINKS,
};
use lagrange_core::links::{LinkPoint, Links, Pose};
use lagrange_core::nalgebra::{SMatrix, SVector};
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

/// The point `local` of a link whose frame is `pose`, and its Jacobian: `d origin/dq` (2 x N)
/// plus, for each coordinate turning the frame (`turns[k]`: `d angle/dq_k`), the offset turned
/// a further quarter turn.
fn point_on<T: Real, const N: usize>(
    pose: &Pose<T>,
    local: [T; 2],
    origin: SMatrix<T, 2, N>,
    turns: [T; N],
) -> LinkPoint<T, N> {
    let (s, c) = pose.angle.sin_cos();
    let (dx, dy) = (c * local[0] - s * local[1], s * local[0] + c * local[1]);
    let mut jacobian = origin;
    for k in 0..N {
        jacobian[(0, k)] -= dy * turns[k];
        jacobian[(1, k)] += dx * turns[k];
    }
    LinkPoint {
        position: [pose.origin[0] + dx, pose.origin[1] + dy],
        jacobian,
    }
}

/// `d origin/dq` of a link hanging from the ends of links `0..link` of a chain with absolute
/// angles `q` and `lengths`: column `j < link` is `l_j (cos q_j, sin q_j)`.
fn chain_origin<T: Real, const N: usize>(
    q: &SVector<T, N>,
    lengths: &[T],
    link: usize,
) -> SMatrix<T, 2, N> {
    let mut d = SMatrix::<T, 2, N>::zeros();
    for (j, &l) in lengths.iter().enumerate().take(link.min(N)) {
        let (s, c) = q[j].sin_cos();
        d[(0, j)] = l * c;
        d[(1, j)] = l * s;
    }
    d
}

impl<T: Real> Links<T, 1> for SimplePendulum<T> {
    /// The rod, from the pivot at the origin.
    const LINKS: usize = 1;
    fn pose<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 1>, _link: usize) -> Pose<S> {
        at([S::zero(), S::zero()], q[0])
    }
    fn point(&self, q: &SVector<T, 1>, link: usize, local: [T; 2]) -> LinkPoint<T, 1> {
        point_on(&self.pose(q, link), local, SMatrix::zeros(), [T::one()])
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
    fn point(&self, q: &SVector<T, 2>, link: usize, local: [T; 2]) -> LinkPoint<T, 2> {
        let link = link.min(1);
        let mut turns = [T::zero(); 2];
        turns[link] = T::one();
        let origin = chain_origin(q, &self.lengths(), link);
        point_on(&self.pose(q, link), local, origin, turns)
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
    fn point(&self, q: &SVector<T, N>, link: usize, local: [T; 2]) -> LinkPoint<T, N> {
        let link = link.min(N.saturating_sub(1));
        let mut turns = [T::zero(); N];
        if let Some(t) = turns.get_mut(link) {
            *t = T::one();
        }
        let origin = chain_origin(q, &self.lengths(), link);
        point_on(&self.pose(q, link), local, origin, turns)
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
    fn point(&self, q: &SVector<T, 2>, link: usize, local: [T; 2]) -> LinkPoint<T, 2> {
        let link = link.min(1);
        // The elbow moves with th1 only; link 1 turns with both.
        let turns = if link == 0 {
            [T::one(), T::zero()]
        } else {
            [T::one(); 2]
        };
        let origin = chain_origin(q, &self.lengths()[..1], link);
        point_on(&self.pose(q, link), local, origin, turns)
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
    fn point(&self, q: &SVector<T, 2>, link: usize, local: [T; 2]) -> LinkPoint<T, 2> {
        let mut origin = SMatrix::<T, 2, 2>::zeros();
        origin[(0, 0)] = T::one();
        let turns = if link == 0 {
            [T::zero(); 2]
        } else {
            [T::zero(), -T::one()]
        };
        point_on(&self.pose(q, link.min(1)), local, origin, turns)
    }
}

/// Link `link` (clamped to the links) of a ragdoll at `q` in the world, from the ragdoll's
/// pose of every link relative to its torso and their absolute angles.
fn ragdoll_link<S: Scalar>(
    q: &SVector<S, RAGDOLL_COORDINATES>,
    pose: &ragdoll::Pose<S>,
    angle: &[S; RAGDOLL_LINKS],
    link: usize,
) -> Pose<S> {
    let link = link.min(RAGDOLL_LINKS - 1);
    let origin = pose.origin[link];
    at([q[0] + origin[0], q[1] + origin[1]], angle[link])
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
        // The ragdoll's own pose of every link (its inherent method, not this one).
        ragdoll_link(q, &self.pose(q), &self.angles(q), link)
    }

    /// Every link from one pose.
    fn poses(&self, q: &SVector<T, RAGDOLL_COORDINATES>, poses: &mut [Pose<T>]) {
        let (pose, angle) = (self.pose(q), self.angles(q));
        for (link, out) in poses.iter_mut().enumerate().take(RAGDOLL_LINKS) {
            *out = ragdoll_link(q, &pose, &angle, link);
        }
    }

    /// As [`Links::point`], from the link's pose: the joints between it and the torso found
    /// back from it (the torso's children need no trigonometry, their children one
    /// `sin_cos`), where the ragdoll's pose of every link took ten.
    fn jacobian_at(
        &self,
        q: &SVector<T, RAGDOLL_COORDINATES>,
        link: usize,
        pose: &Pose<T>,
        at: [T; 2],
    ) -> SMatrix<T, 2, RAGDOLL_COORDINATES> {
        let mut jacobian = SMatrix::<T, 2, RAGDOLL_COORDINATES>::zeros();
        jacobian[(0, 0)] = T::one();
        jacobian[(1, 1)] = T::one();
        jacobian[(0, 2)] = q[1] - at[1];
        jacobian[(1, 2)] = at[0] - q[0];
        let (mut k, mut origin, mut angle) = (link.min(RAGDOLL_LINKS - 1), pose.origin, pose.angle);
        while k != TORSO {
            jacobian[(0, k + 2)] = origin[1] - at[1];
            jacobian[(1, k + 2)] = at[0] - origin[0];
            if PARENT[k] == TORSO {
                break;
            }
            (origin, angle) = self.parent_frame(q, k, origin, angle);
            k = PARENT[k];
        }
        jacobian
    }

    /// By hand, from one pose: the torso's translation moves the point as it is; each
    /// coordinate that turns the link (the torso's angle and every joint from the torso out
    /// to it) turns the point about that joint, `perp(point - joint)`.
    fn point(
        &self,
        q: &SVector<T, RAGDOLL_COORDINATES>,
        link: usize,
        local: [T; 2],
    ) -> LinkPoint<T, RAGDOLL_COORDINATES> {
        let link = link.min(RAGDOLL_LINKS - 1);
        let pose = self.pose(q);
        let (s, c) = (pose.sin[link], pose.cos[link]);
        let [ox, oy] = pose.origin[link];
        // Relative to the torso's centre of mass, where the torso's angle turns it about.
        let p = [
            ox + c * local[0] - s * local[1],
            oy + s * local[0] + c * local[1],
        ];
        let mut jacobian = SMatrix::<T, 2, RAGDOLL_COORDINATES>::zeros();
        jacobian[(0, 0)] = T::one();
        jacobian[(1, 1)] = T::one();
        jacobian[(0, 2)] = -p[1];
        jacobian[(1, 2)] = p[0];
        let mut k = link;
        while k != TORSO {
            let [jx, jy] = pose.origin[k];
            jacobian[(0, k + 2)] = jy - p[1];
            jacobian[(1, k + 2)] = p[0] - jx;
            k = PARENT[k];
        }
        LinkPoint {
            position: [q[0] + p[0], q[1] + p[1]],
            jacobian,
        }
    }
}
