//! [`RagdollContacts`]: a [`Ragdoll`]'s contacts with a floor (head, shoulders, hips,
//! elbows, hands, knees, feet) and its joint limits, for a `ContactStepper`.

use lagrange_core::constraints::contact::Contacts;
use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{entry_names, validate, Constraints, Error, Real};

use crate::ragdoll::{Mark, Pose, PARENT, RAGDOLL_COORDINATES as N, RAGDOLL_LINKS};
use crate::Ragdoll;

/// Points of a [`Ragdoll`] that touch the floor.
pub const RAGDOLL_FLOOR_POINTS: usize = 13;

/// Rows of [`RagdollContacts`]: the floor points, then a lower and an upper limit per joint.
pub const RAGDOLL_CONTACTS: usize = RAGDOLL_FLOOR_POINTS + 2 * (RAGDOLL_LINKS - 1);

/// An adult's joint ranges, rad, relative to the parent link (see [`Ragdoll`]): neck, left
/// shoulder, left elbow, right shoulder, right elbow, left hip, left knee, right hip, right
/// knee. The left limbs open towards negative angles, the right ones towards positive.
pub const ADULT_JOINT_LIMITS: [[f64; 2]; RAGDOLL_LINKS - 1] = [
    [-0.7, 0.7],
    [-3.0, 0.4],
    [-0.05, 2.6],
    [-0.4, 3.0],
    [-2.6, 0.05],
    [-1.6, 0.3],
    [-0.05, 2.4],
    [-0.3, 1.6],
    [-2.4, 0.05],
];

/// A [`Ragdoll`]'s unilateral contacts, [`RAGDOLL_CONTACTS`] rows:
///
/// ```text
/// rows 0..13   floor: y_p - floor >= 0 for the top of the head, the shoulders, the hips,
///              the elbows, the hands (finger tips), the knees and the feet (soles), in
///              that order, left before right
/// rows 13..31  joint k (1..9, coordinate q[k + 2]): q - lower >= 0, upper - q >= 0
/// ```
///
/// The Jacobian and the velocity-product term are in closed form (a point on link `k` moves
/// with the torso and with every joint between the two: `dp/dq_j = e_z x (p - o_j)`), and
/// the floor rows give their horizontal Jacobian as the tangent, for Coulomb friction.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RagdollContacts<T> {
    ragdoll: Ragdoll<T>,
    floor: T,
    limits: [[T; 2]; RAGDOLL_LINKS - 1],
    points: [Mark<T>; RAGDOLL_FLOOR_POINTS],
}

impl<T: Real> RagdollContacts<T> {
    /// The contacts of `ragdoll` with a floor at height `floor` (m) and its joints held in
    /// `limits` (rad, `[lower, upper]` per joint, in the order of [`ADULT_JOINT_LIMITS`]).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `floor` when not finite; `limits[j]`, naming the joint,
    /// when one of its bounds is not finite or its lower bound is not below its upper one.
    pub fn new(
        ragdoll: &Ragdoll<T>,
        floor: T,
        limits: [[T; 2]; RAGDOLL_LINKS - 1],
    ) -> Result<Self, Error> {
        const LIMITS: [&str; 32] = entry_names!("limits");
        let floor = validate::finite("floor", floor)?;
        for (j, [lower, upper]) in limits.into_iter().enumerate() {
            let name = validate::entry(&LIMITS, j, "limits");
            validate::finite(name, lower)?;
            validate::finite(name, upper)?;
            if lower.partial_cmp(&upper) != Some(core::cmp::Ordering::Less) {
                return Err(Error::InvalidParameter {
                    name,
                    reason: "each lower bound must be below its upper bound",
                });
            }
        }
        let joints = ragdoll.joints();
        let lengths = ragdoll.lengths();
        let end = |link: usize| Mark {
            link,
            along: lengths[link],
            across: T::zero(),
        };
        let points = [
            end(1),
            joints[2],
            joints[4],
            joints[6],
            joints[8],
            end(2),
            end(4),
            end(3),
            end(5),
            end(6),
            end(8),
            end(7),
            end(9),
        ];
        Ok(Self {
            ragdoll: *ragdoll,
            floor,
            limits,
            points,
        })
    }

    /// [`ADULT_JOINT_LIMITS`] and a floor at height `floor`.
    ///
    /// # Errors
    /// As [`RagdollContacts::new`].
    pub fn adult(ragdoll: &Ragdoll<T>, floor: T) -> Result<Self, Error> {
        Self::new(
            ragdoll,
            floor,
            ADULT_JOINT_LIMITS.map(|l| l.map(T::from_f64)),
        )
    }

    /// The floor's height, m.
    #[must_use]
    pub fn floor(&self) -> T {
        self.floor
    }

    /// The joint limits, rad.
    #[must_use]
    pub fn limits(&self) -> &[[T; 2]; RAGDOLL_LINKS - 1] {
        &self.limits
    }

    /// The world positions of the floor points at `q`, m, in the order of the rows.
    #[must_use]
    pub fn floor_points(&self, q: &SVector<T, N>) -> [[T; 2]; RAGDOLL_FLOOR_POINTS] {
        // One pose for all the points (a pose per point cost thirteen poses a residual).
        self.points_at(&self.ragdoll.pose(q), q)
    }

    /// [`RagdollContacts::floor_points`] at `q` posed as `pose`.
    fn points_at(&self, pose: &Pose<T>, q: &SVector<T, N>) -> [[T; 2]; RAGDOLL_FLOOR_POINTS] {
        self.points.map(|m| {
            let [px, py] = pose.point(m.link, m.along, m.across);
            [px + q[0], py + q[1]]
        })
    }

    /// Every row's gap at `q` posed as `pose`: the floor points' heights above the floor,
    /// then each joint's distance from its lower and upper limits.
    fn gaps_at(&self, pose: &Pose<T>, q: &SVector<T, N>) -> SVector<T, RAGDOLL_CONTACTS> {
        let points = self.points_at(pose, q);
        SVector::from_fn(|i, _| match points.get(i) {
            Some(p) => p[1] - self.floor,
            None => {
                let row = i - RAGDOLL_FLOOR_POINTS;
                let (joint, upper) = (row / 2, row % 2 == 1);
                let [lower_bound, upper_bound] = self.limits[joint];
                let x = q[joint + 3];
                if upper {
                    upper_bound - x
                } else {
                    x - lower_bound
                }
            }
        })
    }

    /// The Jacobian of every row (floor points' heights, then the limits) and the tangent
    /// Jacobian (the floor points' horizontal positions; zero rows for the limits), written
    /// into `j` and `t` (every entry: nothing of what they held is kept).
    fn write_rows(
        &self,
        pose: &Pose<T>,
        j: &mut SMatrix<T, RAGDOLL_CONTACTS, N>,
        t: &mut SMatrix<T, RAGDOLL_CONTACTS, N>,
    ) {
        // In storage order: nalgebra's `fill` walks a strided iterator an entry at a time.
        j.as_mut_slice().fill(T::zero());
        t.as_mut_slice().fill(T::zero());
        for (i, m) in self.points.iter().enumerate() {
            let i = i.min(RAGDOLL_CONTACTS - 1);
            let p = pose.point(m.link, m.along, m.across);
            j[(i, 1)] = T::one();
            t[(i, 0)] = T::one();
            // The torso turns about its centre of mass, the origin of the pose.
            j[(i, 2)] = p[0];
            t[(i, 2)] = -p[1];
            let mut k = m.link;
            while k != 0 {
                let link = k.min(RAGDOLL_LINKS - 1);
                let o = pose.origin[link];
                j[(i, link + 2)] = p[0] - o[0];
                t[(i, link + 2)] = -(p[1] - o[1]);
                k = PARENT[link];
            }
        }
        for joint in 0..RAGDOLL_LINKS - 1 {
            let row = RAGDOLL_FLOOR_POINTS + 2 * joint;
            j[(row, joint + 3)] = T::one();
            j[(row + 1, joint + 3)] = -T::one();
        }
    }

    /// [`RagdollContacts::write_rows`] at `q`, into new matrices.
    fn rows(
        &self,
        q: &SVector<T, N>,
    ) -> (
        SMatrix<T, RAGDOLL_CONTACTS, N>,
        SMatrix<T, RAGDOLL_CONTACTS, N>,
    ) {
        let (mut j, mut t) = (SMatrix::zeros(), SMatrix::zeros());
        self.write_rows(&self.ragdoll.pose(q), &mut j, &mut t);
        (j, t)
    }
}

impl<T: Real> Constraints<T, N, RAGDOLL_CONTACTS> for RagdollContacts<T> {
    fn position_residual(&self, q: &SVector<T, N>) -> SVector<T, RAGDOLL_CONTACTS> {
        self.gaps_at(&self.ragdoll.pose(q), q)
    }

    fn jacobian(&self, q: &SVector<T, N>) -> SMatrix<T, RAGDOLL_CONTACTS, N> {
        self.rows(q).0
    }

    /// `y_p''` at `q'' = 0`: `-sum w_k^2 r_k` over the links from the point to the torso,
    /// `r_k` the stretch of link `k` on the way; zero for the limits (linear in `q`).
    fn velocity_product(
        &self,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
    ) -> SVector<T, RAGDOLL_CONTACTS> {
        let pose = self.ragdoll.pose(q);
        let mut w = [T::zero(); RAGDOLL_LINKS];
        w[0] = qd[2];
        for k in 1..RAGDOLL_LINKS {
            w[k] = w[PARENT[k]] + qd[k + 2];
        }
        let mut out = SVector::zeros();
        for (i, m) in self.points.iter().enumerate() {
            let mut p = pose.point(m.link, m.along, m.across);
            let mut k = m.link;
            let mut sum = T::zero();
            loop {
                let o = pose.origin[k];
                sum -= w[k] * w[k] * (p[1] - o[1]);
                if k == 0 {
                    break;
                }
                p = o;
                k = PARENT[k];
            }
            out[i] = sum;
        }
        out
    }
}

impl<T: Real> Contacts<T, N, RAGDOLL_CONTACTS> for RagdollContacts<T> {
    /// The floor points' horizontal Jacobian; none for the limits.
    fn tangent_jacobian(&self, q: &SVector<T, N>) -> Option<SMatrix<T, RAGDOLL_CONTACTS, N>> {
        Some(self.rows(q).1)
    }

    /// Both from one pose and one pass over the points.
    fn jacobians(
        &self,
        q: &SVector<T, N>,
        normal: &mut SMatrix<T, RAGDOLL_CONTACTS, N>,
        tangent: &mut SMatrix<T, RAGDOLL_CONTACTS, N>,
    ) -> bool {
        self.write_rows(&self.ragdoll.pose(q), normal, tangent);
        true
    }

    /// All three from one pose.
    fn gaps_and_jacobians(
        &self,
        q: &SVector<T, N>,
        gaps: &mut SVector<T, RAGDOLL_CONTACTS>,
        normal: &mut SMatrix<T, RAGDOLL_CONTACTS, N>,
        tangent: &mut SMatrix<T, RAGDOLL_CONTACTS, N>,
    ) -> bool {
        let pose = self.ragdoll.pose(q);
        *gaps = self.gaps_at(&pose, q);
        self.write_rows(&pose, normal, tangent);
        true
    }
}
