//! [`Links`]: where a mechanism's links are in the plane, and how a point fixed on one moves
//! with the coordinates: what collision detection needs of a mechanism (a shape on a link is
//! placed by the link's pose; a contact on it becomes a row through the point's Jacobian).

use crate::{Dual, Real, Scalar};
use nalgebra::{SMatrix, SVector};

/// The pose of a link in the plane: the origin of its frame and the angle of its frame's x
/// axis, counter-clockwise from the world's. A point at `local` on the link is at
/// `origin + R(angle) local`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Pose<S> {
    /// The origin of the link's frame, world coordinates.
    pub origin: [S; 2],
    /// The angle of the link's frame, radians, counter-clockwise.
    pub angle: S,
}

impl<S: Scalar> Pose<S> {
    /// Where the point `local` of the link's frame is in the world.
    #[must_use]
    pub fn point(&self, local: [S::Real; 2]) -> [S; 2] {
        let (s, c) = self.angle.sin_cos();
        let (x, y) = (S::from_real(local[0]), S::from_real(local[1]));
        [
            self.origin[0] + c * x - s * y,
            self.origin[1] + s * x + c * y,
        ]
    }
}

/// A point fixed on a link, where it is and how it moves: `position` and the Jacobian
/// `d position / dq` (its velocity is `jacobian q'`; an impulse `p` on it is the generalized
/// impulse `jacobian^T p`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkPoint<T: Real, const N: usize> {
    /// World coordinates of the point.
    pub position: [T; 2],
    /// `d position / dq`: row 0 for x, row 1 for y.
    pub jacobian: SMatrix<T, 2, N>,
}

/// Where the links of a mechanism with coordinates `q` are in the plane.
///
/// Write [`Links::pose`] once, generic over the scalar; [`Links::point`] then comes from one
/// evaluation in dual numbers (exact to rounding). A mechanism whose pose is cheap to
/// differentiate by hand (the standard ones) overrides [`Links::point`].
///
/// ```
/// use lagrange_core::links::{Links, Pose};
/// use lagrange_core::{nalgebra::SVector, Scalar};
///
/// /// A rod of length 2 turning about the origin, `q = [angle from the downward vertical]`.
/// struct Rod;
/// impl Links<f64, 1> for Rod {
///     const LINKS: usize = 1;
///     fn pose<S: Scalar<Real = f64> + 'static>(&self, q: &SVector<S, 1>, _link: usize) -> Pose<S> {
///         Pose { origin: [S::zero(), S::zero()], angle: q[0] }
///     }
/// }
///
/// // The rod's tip hangs along the link's -y axis.
/// let tip = Rod.point(&SVector::from([0.0]), 0, [0.0, -2.0]);
/// assert_eq!(tip.position, [0.0, -2.0]);
/// // Turning it moves the tip along +x at 2 m per radian.
/// assert_eq!((tip.jacobian[(0, 0)], tip.jacobian[(1, 0)]), (2.0, 0.0));
/// ```
pub trait Links<T: Real, const N: usize> {
    /// How many links; links are numbered `0..LINKS`.
    const LINKS: usize;

    /// The pose of link `link` (below [`Links::LINKS`]) at coordinates `q`. A link number out
    /// of range is the caller's error: return any pose (never panic).
    fn pose<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, N>, link: usize) -> Pose<S>;

    /// The poses of links `0, 1, ...` at coordinates `q`, as many as `poses` holds (entries
    /// past [`Links::LINKS`] are left as they are); by default one [`Links::pose`] each. A
    /// mechanism whose links share their work (a tree's angles, its trigonometry) overrides
    /// it with the same poses from one pass: what a world places a body's shapes with.
    ///
    /// ```
    /// use lagrange_core::links::{Links, Pose};
    /// use lagrange_core::{nalgebra::SVector, Scalar};
    ///
    /// /// Two rods of length 1 end to end, `q` their absolute angles from the downward vertical.
    /// struct Chain;
    /// impl Links<f64, 2> for Chain {
    ///     const LINKS: usize = 2;
    ///     fn pose<S: Scalar<Real = f64> + 'static>(&self, q: &SVector<S, 2>, link: usize) -> Pose<S> {
    ///         let origin = if link == 0 { [S::zero(); 2] } else { [q[0].sin(), -q[0].cos()] };
    ///         Pose { origin, angle: q[link.min(1)] }
    ///     }
    /// }
    ///
    /// let q = SVector::from([0.3, -0.2]);
    /// let mut poses = [Pose { origin: [0.0; 2], angle: 0.0 }; 3];
    /// Chain.poses(&q, &mut poses);
    /// assert_eq!(poses[1], Chain.pose(&q, 1));
    /// // A third entry is past the chain's links: left as it was.
    /// assert_eq!(poses[2].angle, 0.0);
    /// ```
    fn poses(&self, q: &SVector<T, N>, poses: &mut [Pose<T>]) {
        for (link, pose) in poses.iter_mut().enumerate().take(Self::LINKS) {
            *pose = self.pose(q, link);
        }
    }

    /// The Jacobian `d at / dq` of the point at `at` (world coordinates) fixed on link
    /// `link`, whose pose at `q` is `pose` (the caller has it: a world places its shapes by
    /// it). By default the point in the link's frame, then [`Links::point`]; a mechanism
    /// whose Jacobian needs no trigonometry given the point (a rigid body's) overrides it.
    ///
    /// ```
    /// use lagrange_core::links::{Links, Pose};
    /// use lagrange_core::{nalgebra::SVector, Scalar};
    ///
    /// struct Rod;
    /// impl Links<f64, 1> for Rod {
    ///     const LINKS: usize = 1;
    ///     fn pose<S: Scalar<Real = f64> + 'static>(&self, q: &SVector<S, 1>, _link: usize) -> Pose<S> {
    ///         Pose { origin: [S::zero(); 2], angle: q[0] }
    ///     }
    /// }
    ///
    /// let q = SVector::from([0.5]);
    /// let pose = Rod.pose(&q, 0);
    /// let at = pose.point([0.0, -2.0]);
    /// let j = Rod.jacobian_at(&q, 0, &pose, at);
    /// assert!((j - Rod.point(&q, 0, [0.0, -2.0]).jacobian).abs().max() < 1e-15);
    /// ```
    fn jacobian_at(
        &self,
        q: &SVector<T, N>,
        link: usize,
        pose: &Pose<T>,
        at: [T; 2],
    ) -> SMatrix<T, 2, N> {
        let (s, c) = pose.angle.sin_cos();
        let (dx, dy) = (at[0] - pose.origin[0], at[1] - pose.origin[1]);
        let local = [c * dx + s * dy, c * dy - s * dx];
        self.point(q, link, local).jacobian
    }

    /// The point `local` of link `link` at coordinates `q`: where it is and its Jacobian, by
    /// one evaluation of [`Links::pose`] in dual numbers.
    fn point(&self, q: &SVector<T, N>, link: usize, local: [T; 2]) -> LinkPoint<T, N> {
        let seeded = SVector::<Dual<T, N>, N>::from_fn(|k, _| Dual::variable(q[k], k));
        let [x, y] = self.pose(&seeded, link).point(local);
        LinkPoint {
            position: [x.re, y.re],
            jacobian: SMatrix::from_fn(|i, k| if i == 0 { x.eps[k] } else { y.eps[k] }),
        }
    }
}
