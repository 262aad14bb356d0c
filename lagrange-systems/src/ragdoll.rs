//! [`Ragdoll`]: a planar ragdoll, a tree of ten rigid links on a free torso, whose
//! accelerations come from the articulated-body recursion in `O(links)`.

use core::cmp::Ordering;

use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{
    all_finite, free_law_force, validate, Error, GeneralizedForce, Lagrangian, Mechanism, Real,
    Scalar, State, TreeFactor,
};

/// Generalized coordinates of a [`Ragdoll`]: the torso's position and angle, then nine joints.
pub const RAGDOLL_COORDINATES: usize = 12;

/// Rigid links of a [`Ragdoll`]: torso, head, two links per arm, two per leg.
pub const RAGDOLL_LINKS: usize = 10;

/// The links in order (link `k >= 1` turns about joint `k`, coordinate `q[k + 2]`).
pub(crate) const TORSO: usize = 0;
/// The head.
const HEAD: usize = 1;
/// Left upper arm; its forearm is `LEFT_ARM + 1`.
const LEFT_ARM: usize = 2;
/// Right upper arm; its forearm is `RIGHT_ARM + 1`.
const RIGHT_ARM: usize = 4;
/// Left thigh; its shin is `LEFT_LEG + 1`.
const LEFT_LEG: usize = 6;
/// Right thigh; its shin is `RIGHT_LEG + 1`.
const RIGHT_LEG: usize = 8;

/// The field of a [`RagdollBody`] that gives each link's mass, by its path (an error names it).
const MASS_NAMES: [&str; RAGDOLL_LINKS] = [
    "torso.mass",
    "head.mass",
    "upper_arm.mass",
    "forearm.mass",
    "upper_arm.mass",
    "forearm.mass",
    "thigh.mass",
    "shin.mass",
    "thigh.mass",
    "shin.mass",
];

/// The field that gives each link's length, likewise.
const LENGTH_NAMES: [&str; RAGDOLL_LINKS] = [
    "torso.length",
    "head.length",
    "upper_arm.length",
    "forearm.length",
    "upper_arm.length",
    "forearm.length",
    "thigh.length",
    "shin.length",
    "thigh.length",
    "shin.length",
];

/// The parent of each link (the torso's entry is unused).
pub(crate) const PARENT: [usize; RAGDOLL_LINKS] = [0, 0, 0, 2, 0, 4, 0, 6, 0, 8];

/// Each coordinate's parent in the tree the mass matrix has: the torso's `x`, `y`, angle one
/// after another, then each joint after its parent link's (the torso's angle for a link on
/// the torso).
const COORDINATE_PARENT: [Option<usize>; RAGDOLL_COORDINATES] = {
    let mut parent = [None; RAGDOLL_COORDINATES];
    parent[1] = Some(0);
    parent[2] = Some(1);
    let mut k = 1;
    while k < RAGDOLL_LINKS {
        parent[k + 2] = Some(if PARENT[k] == TORSO { 2 } else { PARENT[k] + 2 });
        k += 1;
    }
    parent
};

/// One rigid link: a uniform rod of `mass` (kg) and `length` (m), its centre of mass at
/// half its length, its moment of inertia `mass length^2 / 12` about it.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Segment<T> {
    /// Mass, kg.
    pub mass: T,
    /// Length, m.
    pub length: T,
}

/// The body of a [`Ragdoll`]: its links, where the limbs attach, gravity and joint damping.
///
/// [`RagdollBody::adult`] gives a 70 kg, 1.75 m adult (segment fractions after Winter's
/// anthropometric tables).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RagdollBody<T> {
    /// The torso, from the neck to the pelvis.
    pub torso: Segment<T>,
    /// The head, from the neck to the top of the head.
    pub head: Segment<T>,
    /// Each upper arm, shoulder to elbow.
    pub upper_arm: Segment<T>,
    /// Each forearm with its hand, elbow to finger tips.
    pub forearm: Segment<T>,
    /// Each thigh, hip to knee.
    pub thigh: Segment<T>,
    /// Each shin with its foot, knee to sole.
    pub shin: Segment<T>,
    /// Distance between the shoulders, m (>= 0): they sit at the neck end of the torso.
    pub shoulder_width: T,
    /// Distance between the hips, m (>= 0): they sit at the pelvis end of the torso.
    pub hip_width: T,
    /// Gravity, m/s^2 (>= 0), along -y.
    pub gravity: T,
    /// Viscous damping of every joint, N m s/rad (>= 0): `Q_k = -c q_k'` on the nine joint
    /// angles, none on the torso's free coordinates.
    pub joint_damping: T,
}

impl<T: Real> RagdollBody<T> {
    /// A 70 kg, 1.75 m adult: torso 34.8 kg, 0.52 m; head 5.7 kg, 0.24 m; upper arms 2.0 kg,
    /// 0.30 m; forearms with hands 1.5 kg, 0.43 m; thighs 7.0 kg, 0.43 m; shins with feet
    /// 4.3 kg, 0.50 m; shoulders 0.36 m apart, hips 0.18 m; `g = 9.81`; joint damping
    /// 0.5 N m s/rad.
    #[must_use]
    pub fn adult() -> Self {
        let seg = |mass: f64, length: f64| Segment {
            mass: T::from_f64(mass),
            length: T::from_f64(length),
        };
        Self {
            torso: seg(34.8, 0.52),
            head: seg(5.7, 0.24),
            upper_arm: seg(2.0, 0.30),
            forearm: seg(1.5, 0.43),
            thigh: seg(7.0, 0.43),
            shin: seg(4.3, 0.50),
            shoulder_width: T::from_f64(0.36),
            hip_width: T::from_f64(0.18),
            gravity: T::from_f64(9.81),
            joint_damping: T::from_f64(0.5),
        }
    }
}

/// A point fixed on a link: `along` its axis and `across` it, in its frame.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Mark<T> {
    /// The link.
    pub link: usize,
    /// Along the link's axis `d = (sin a, -cos a)`, m.
    pub along: T,
    /// Across it, along `n = (cos a, sin a)`, m.
    pub across: T,
}

/// A planar ragdoll: a free torso with a head, two arms and two legs of two links each, every
/// link a uniform rod ([`Segment`]), joined by hinges, in gravity `g` along -y.
///
/// ```text
/// q = [x, y, th,  neck,  l_shoulder, l_elbow,  r_shoulder, r_elbow,  l_hip, l_knee,  r_hip, r_knee]
///
/// (x, y)   the torso's centre of mass, m
/// th       the torso's angle from the downward vertical: its axis from neck to pelvis is
///          d0 = (sin th, -cos th), so th = 0 stands upright; n0 = (cos th, sin th) across it
/// joints   each link's angle RELATIVE to its parent, rad; a link of absolute angle a points
///          from its joint along d = (sin a, -cos a): limbs hang along the torso at 0, the
///          head points up at 0 (absolute angle th + pi + neck)
///
/// attachments (in the torso's frame, along d0 and across n0, from its centre of mass):
///   neck (-L/2, 0), shoulders (-L/2, -/+ w_s/2), hips (+L/2, -/+ w_h/2); the left limbs
///   on the -n0 side (the viewer's left when upright), each forearm at its upper arm's end,
///   each shin at its thigh's end
///
/// T = sum_k ( m_k |v_k|^2 + I_k w_k^2 ) / 2     v_k the link's centre-of-mass velocity,
///                                              w_k its absolute angular rate
/// V = g sum_k m_k y_k
/// Q = -c [0, 0, 0, q_3' .. q_11']              joint damping
/// ```
///
/// Accelerations: the articulated-body algorithm (Featherstone), in planar spatial vectors
/// `(w, v_x, v_y)` taken about the torso's centre of mass, with a floating base: one pass out
/// (velocities, bias forces), one pass in (articulated inertias, 3x3 and symmetric), one 3x3
/// solve for the torso, one pass out (joint accelerations). No mass matrix is formed: the cost
/// is linear in the number of links (about 2,000 flops), against `O(N^3)` for a dense solve.
/// [`Mechanism::mass_matrix`] (composite rigid bodies) and [`Mechanism::rhs`] (inverse
/// dynamics) are there for checks and for methods that ask for them; the automatic
/// Euler-Lagrange path of the same `T` and `V` agrees with them (the tests).
///
/// Contacts (the floor, joint limits) are [`RagdollContacts`](crate::RagdollContacts), for a
/// `ContactStepper`.
///
/// ```
/// use lagrange_core::{Mechanism, State};
/// use lagrange_systems::{Ragdoll, RagdollBody};
/// let doll = Ragdoll::new(RagdollBody::<f64>::adult())?;
/// // Standing still in the air: everything falls at g, nothing turns.
/// let mut q = [0.0; 12];
/// q[1] = 2.0;
/// let a = doll.acceleration(&State::at_rest(q))?;
/// assert!((a[1] + 9.81).abs() < 1e-12 && a[2].abs() < 1e-12);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Ragdoll<T> {
    body: RagdollBody<T>,
    /// Mass of each link.
    mass: [T; RAGDOLL_LINKS],
    /// Moment of inertia of each link about its centre of mass.
    inertia: [T; RAGDOLL_LINKS],
    /// Length of each link (the torso's: neck to pelvis).
    length: [T; RAGDOLL_LINKS],
    /// Where each link's joint sits on its parent (the torso's entry is unused).
    joint: [Mark<T>; RAGDOLL_LINKS],
    /// Each link's angle at a joint angle of zero, relative to its parent: pi for the head.
    rest: [T; RAGDOLL_LINKS],
}

/// Where every link is: sine and cosine of its absolute angle, its origin (the torso's
/// centre of mass for the torso, its joint for a limb) and its centre of mass, relative to
/// the torso's centre of mass.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pose<S> {
    pub sin: [S; RAGDOLL_LINKS],
    pub cos: [S; RAGDOLL_LINKS],
    pub origin: [[S; 2]; RAGDOLL_LINKS],
    pub com: [[S; 2]; RAGDOLL_LINKS],
}

impl<S: Scalar> Pose<S> {
    /// The point `along`, `across` of link `link`, relative to the torso's centre of mass.
    pub fn point(&self, link: usize, along: S, across: S) -> [S; 2] {
        let link = link.min(RAGDOLL_LINKS - 1);
        let (s, c) = (self.sin[link], self.cos[link]);
        let [ox, oy] = self.origin[link];
        [ox + along * s + across * c, oy - along * c + across * s]
    }
}

/// A planar spatial vector `(w, v_x, v_y)` (motion) or `(n, f_x, f_y)` (force).
type V3<T> = [T; 3];
/// A symmetric 3x3 planar spatial inertia, rows of [`V3`].
type M3<T> = [[T; 3]; 3];

/// `a . b`.
fn dot<T: Real>(a: &V3<T>, b: &V3<T>) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `m v`.
fn mul<T: Real>(m: &M3<T>, v: &V3<T>) -> V3<T> {
    [dot(&m[0], v), dot(&m[1], v), dot(&m[2], v)]
}

/// `a + b`.
fn add<T: Real>(a: &V3<T>, b: &V3<T>) -> V3<T> {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `v k`.
fn scale<T: Real>(v: &V3<T>, k: T) -> V3<T> {
    [v[0] * k, v[1] * k, v[2] * k]
}

/// The motion cross product `v x m` (planar: no angular part).
fn cross_motion<T: Real>(v: &V3<T>, m: &V3<T>) -> V3<T> {
    [
        T::zero(),
        v[2] * m[0] - v[0] * m[2],
        v[0] * m[1] - v[1] * m[0],
    ]
}

/// The force cross product `v x* f`.
fn cross_force<T: Real>(v: &V3<T>, f: &V3<T>) -> V3<T> {
    [v[1] * f[2] - v[2] * f[1], -v[0] * f[2], v[0] * f[1]]
}

/// The spatial inertia about the origin of a body of mass `m` and moment of inertia `i`
/// about its centre of mass at `c`.
fn inertia_at<T: Real>(m: T, i: T, c: [T; 2]) -> M3<T> {
    let (mx, my) = (m * c[0], m * c[1]);
    [
        [i + mx * c[0] + my * c[1], -my, mx],
        [-my, m, T::zero()],
        [mx, T::zero(), m],
    ]
}

/// A hinge's motion subspace about the origin: turning about the point `p`.
fn hinge<T: Real>(p: [T; 2]) -> V3<T> {
    [T::one(), p[1], -p[0]]
}

/// Solves the symmetric positive definite `m x = b` (3x3) by Cholesky.
fn solve3<T: Real>(m: &M3<T>, b: &V3<T>) -> Result<V3<T>, Error> {
    let mut l = [[T::zero(); 3]; 3];
    for i in 0..3 {
        for j in 0..=i {
            let mut sum = m[i][j];
            for (a, b) in l[i].iter().zip(&l[j]).take(j) {
                sum -= *a * *b;
            }
            if i == j {
                if sum.partial_cmp(&T::zero()) != Some(Ordering::Greater) {
                    return Err(Error::SingularMassMatrix { pivot: i });
                }
                l[i][i] = sum.sqrt();
            } else {
                l[i][j] = sum / l[j][j];
            }
        }
    }
    let mut y = [T::zero(); 3];
    for i in 0..3 {
        let mut sum = b[i];
        for k in 0..i {
            sum -= l[i][k] * y[k];
        }
        y[i] = sum / l[i][i];
    }
    let mut x = [T::zero(); 3];
    for i in (0..3).rev() {
        let mut sum = y[i];
        for k in i + 1..3 {
            sum -= l[k][i] * x[k];
        }
        x[i] = sum / l[i][i];
    }
    Ok(x)
}

impl<T: Real> Ragdoll<T> {
    /// A ragdoll of `body`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the field of `body` by its path: `torso.mass`,
    /// `head.length`, ... (every segment's mass and length: positive and finite),
    /// `shoulder_width`, `hip_width`, `gravity` or `joint_damping` (zero or positive, finite);
    /// or the field most responsible when a quantity the motion forms from them leaves the
    /// range of `T`: a segment's moment of inertia `mass length^2 / 12` (overflow or
    /// underflow: the recursion divides by it), the total mass, the whole body's moment of
    /// inertia about the torso (total mass times its reach squared, the reach being the sum of
    /// the lengths and widths) or its weight times its reach.
    pub fn new(body: RagdollBody<T>) -> Result<Self, Error> {
        let segments = [
            body.torso,
            body.head,
            body.upper_arm,
            body.forearm,
            body.upper_arm,
            body.forearm,
            body.thigh,
            body.shin,
            body.thigh,
            body.shin,
        ];
        for k in 0..RAGDOLL_LINKS {
            validate::positive(MASS_NAMES[k], segments[k].mass)?;
            validate::positive(LENGTH_NAMES[k], segments[k].length)?;
        }
        let half_shoulders = validate::non_negative("shoulder_width", body.shoulder_width)?;
        let half_hips = validate::non_negative("hip_width", body.hip_width)?;
        let gravity = validate::non_negative("gravity", body.gravity)?;
        validate::non_negative("joint_damping", body.joint_damping)?;
        let twelfth = T::from_f64(1.0 / 12.0);
        let mut inertia = [T::zero(); RAGDOLL_LINKS];
        for (k, (i, s)) in inertia.iter_mut().zip(&segments).enumerate() {
            let factors = [(MASS_NAMES[k], s.mass, 1), (LENGTH_NAMES[k], s.length, 2)];
            *i = validate::divisor(s.mass * s.length * s.length * twelfth, &factors)?;
        }
        // The whole body: its mass, its reach (every length and width laid end to end), the
        // heaviest segment and the longest field, which an overflow of a whole-body quantity
        // is blamed on.
        let heaviest = (0..RAGDOLL_LINKS)
            .max_by(|&a, &b| {
                segments[a]
                    .mass
                    .partial_cmp(&segments[b].mass)
                    .unwrap_or(Ordering::Equal)
            })
            .unwrap_or(TORSO);
        let heaviest = (MASS_NAMES[heaviest], segments[heaviest].mass, 1);
        let mut longest = (LENGTH_NAMES[TORSO], body.torso.length);
        let widths = [
            ("shoulder_width", body.shoulder_width),
            ("hip_width", body.hip_width),
        ];
        for (name, x) in (0..RAGDOLL_LINKS)
            .map(|k| (LENGTH_NAMES[k], segments[k].length))
            .chain(widths)
        {
            if x > longest.1 {
                longest = (name, x);
            }
        }
        let mass_terms: [(&'static str, T, i32); RAGDOLL_LINKS] =
            core::array::from_fn(|k| (MASS_NAMES[k], segments[k].mass, 1));
        let total = validate::derived(
            segments.iter().fold(T::zero(), |a, s| a + s.mass),
            &mass_terms,
        )?;
        let reach = validate::derived(
            segments.iter().fold(T::zero(), |a, s| a + s.length)
                + body.shoulder_width
                + body.hip_width,
            &[(longest.0, longest.1, 1)],
        )?;
        validate::derived(
            total * reach * reach,
            &[heaviest, (longest.0, longest.1, 2)],
        )?;
        validate::derived(
            total * gravity * reach,
            &[heaviest, ("gravity", gravity, 1), (longest.0, longest.1, 1)],
        )?;
        let (half_shoulders, half_hips) = (half_shoulders * T::HALF, half_hips * T::HALF);
        let mass = segments.map(|s| s.mass);
        let length = segments.map(|s| s.length);
        let half = body.torso.length * T::HALF;
        let at = |link: usize, along: T, across: T| Mark {
            link,
            along,
            across,
        };
        let joint = [
            at(TORSO, T::zero(), T::zero()),
            at(TORSO, -half, T::zero()),
            at(TORSO, -half, -half_shoulders),
            at(LEFT_ARM, body.upper_arm.length, T::zero()),
            at(TORSO, -half, half_shoulders),
            at(RIGHT_ARM, body.upper_arm.length, T::zero()),
            at(TORSO, half, -half_hips),
            at(LEFT_LEG, body.thigh.length, T::zero()),
            at(TORSO, half, half_hips),
            at(RIGHT_LEG, body.thigh.length, T::zero()),
        ];
        let mut rest = [T::zero(); RAGDOLL_LINKS];
        rest[HEAD] = T::PI;
        Ok(Self {
            body,
            mass,
            inertia,
            length,
            joint,
            rest,
        })
    }

    /// The body it was built from.
    #[must_use]
    pub fn body(&self) -> &RagdollBody<T> {
        &self.body
    }

    /// Total mass, kg.
    #[must_use]
    pub fn total_mass(&self) -> T {
        self.mass.iter().fold(T::zero(), |a, &m| a + m)
    }

    /// Each link as a segment from its start to its end, world coordinates, m: the torso from
    /// the neck to the pelvis, every other link from its joint to its far end (the head to
    /// its top, the forearms to the finger tips, the shins to the soles). In the order of
    /// `q`: torso, head, left upper arm, left forearm, right upper arm, right forearm, left
    /// thigh, left shin, right thigh, right shin.
    #[must_use]
    pub fn segments(&self, q: &SVector<T, RAGDOLL_COORDINATES>) -> [[[T; 2]; 2]; RAGDOLL_LINKS] {
        let pose = self.pose(q);
        let (x, y) = (q[0], q[1]);
        core::array::from_fn(|k| {
            let start = if k == TORSO {
                -self.length[TORSO] * T::HALF
            } else {
                T::zero()
            };
            let end = start + self.length[k];
            [start, end].map(|along| {
                let [px, py] = pose.point(k, along, T::zero());
                [px + x, py + y]
            })
        })
    }

    /// Length of each link (the torso's from neck to pelvis).
    pub(crate) fn lengths(&self) -> &[T; RAGDOLL_LINKS] {
        &self.length
    }

    /// Where each link's joint sits on its parent.
    pub(crate) fn joints(&self) -> &[Mark<T>; RAGDOLL_LINKS] {
        &self.joint
    }

    /// Every link's angle, origin and centre of mass at `q`, relative to the torso's centre
    /// of mass (generic: dual numbers for the automatic path).
    pub(crate) fn pose<S: Scalar<Real = T>>(&self, q: &SVector<S, RAGDOLL_COORDINATES>) -> Pose<S> {
        let zero = S::zero();
        let mut pose = Pose {
            sin: [zero; RAGDOLL_LINKS],
            cos: [zero; RAGDOLL_LINKS],
            origin: [[zero; 2]; RAGDOLL_LINKS],
            com: [[zero; 2]; RAGDOLL_LINKS],
        };
        let angle = self.angles(q);
        (pose.sin[TORSO], pose.cos[TORSO]) = angle[TORSO].sin_cos();
        for k in 1..RAGDOLL_LINKS {
            let j = self.joint[k];
            (pose.sin[k], pose.cos[k]) = angle[k].sin_cos();
            pose.origin[k] = pose.point(PARENT[k], S::from_real(j.along), S::from_real(j.across));
            let half = S::from_real(self.length[k] * T::HALF);
            pose.com[k] = pose.point(k, half, zero);
        }
        pose
    }

    /// The origin and absolute angle of link `k`'s parent from `k`'s own at `q` (`k` not
    /// the torso): the parent's angle is `k`'s less its joint's turn, and `k`'s joint sits
    /// at its mark on the parent (one `sin_cos`, of the parent's angle).
    pub(crate) fn parent_frame(
        &self,
        q: &SVector<T, RAGDOLL_COORDINATES>,
        k: usize,
        origin: [T; 2],
        angle: T,
    ) -> ([T; 2], T) {
        let k = k.min(RAGDOLL_LINKS - 1);
        let parent = angle - q[(k + 2).min(RAGDOLL_COORDINATES - 1)] - self.rest[k];
        let (s, c) = parent.sin_cos();
        let j = self.joint[k];
        let at = [
            origin[0] - (j.along * s + j.across * c),
            origin[1] - (-(j.along * c) + j.across * s),
        ];
        (at, parent)
    }

    /// Each link's absolute angle: a link points from its joint along `(sin a, -cos a)`.
    pub(crate) fn angles<S: Scalar<Real = T>>(
        &self,
        q: &SVector<S, RAGDOLL_COORDINATES>,
    ) -> [S; RAGDOLL_LINKS] {
        let mut angle = [S::zero(); RAGDOLL_LINKS];
        angle[TORSO] = q[2];
        for k in 1..RAGDOLL_LINKS {
            angle[k] = angle[PARENT[k]] + q[k + 2] + S::from_real(self.rest[k]);
        }
        angle
    }

    /// Each link's absolute angular rate.
    fn rates<S: Scalar<Real = T>>(
        &self,
        qd: &SVector<S, RAGDOLL_COORDINATES>,
    ) -> [S; RAGDOLL_LINKS] {
        let mut w = [S::zero(); RAGDOLL_LINKS];
        w[TORSO] = qd[2];
        for k in 1..RAGDOLL_LINKS {
            w[k] = w[PARENT[k]] + qd[k + 2];
        }
        w
    }

    /// Velocities, motion subspaces and bias accelerations of every link at `state` (the
    /// first pass of both recursions), with the links' spatial inertias.
    fn outward(&self, pose: &Pose<T>, qd: &SVector<T, RAGDOLL_COORDINATES>) -> Outward<T> {
        let mut out = Outward {
            v: [[T::zero(); 3]; RAGDOLL_LINKS],
            s: [[T::zero(); 3]; RAGDOLL_LINKS],
            c: [[T::zero(); 3]; RAGDOLL_LINKS],
            inertia: [[[T::zero(); 3]; 3]; RAGDOLL_LINKS],
        };
        out.v[TORSO] = [qd[2], qd[0], qd[1]];
        out.inertia[TORSO] = inertia_at(self.mass[TORSO], self.inertia[TORSO], [T::zero(); 2]);
        for k in 1..RAGDOLL_LINKS {
            let s = hinge(pose.origin[k]);
            let vj = scale(&s, qd[k + 2]);
            let v = add(&out.v[PARENT[k]], &vj);
            out.c[k] = cross_motion(&v, &vj);
            out.v[k] = v;
            out.s[k] = s;
            out.inertia[k] = inertia_at(self.mass[k], self.inertia[k], pose.com[k]);
        }
        out
    }

    /// The articulated-body algorithm: `q''` under the generalized forces `tau` (conjugate to
    /// `q`), with gravity `g`.
    fn articulated(
        &self,
        pose: &Pose<T>,
        qd: &SVector<T, RAGDOLL_COORDINATES>,
        tau: &SVector<T, RAGDOLL_COORDINATES>,
        g: T,
    ) -> Result<SVector<T, RAGDOLL_COORDINATES>, Error> {
        let out = self.outward(pose, qd);
        // Articulated inertias and bias forces, gravity as an external force I (0, 0, -g).
        let mut ia = out.inertia;
        let mut pa: [V3<T>; RAGDOLL_LINKS] = core::array::from_fn(|k| {
            let iv = mul(&out.inertia[k], &out.v[k]);
            let gravity = [
                -self.mass[k] * g * pose.com[k][0],
                T::zero(),
                -self.mass[k] * g,
            ];
            let bias = cross_force(&out.v[k], &iv);
            [
                bias[0] - gravity[0],
                bias[1] - gravity[1],
                bias[2] - gravity[2],
            ]
        });
        let mut u_vec = [[T::zero(); 3]; RAGDOLL_LINKS];
        let mut inv_d = [T::zero(); RAGDOLL_LINKS];
        let mut u = [T::zero(); RAGDOLL_LINKS];
        for k in (1..RAGDOLL_LINKS).rev() {
            let s = &out.s[k];
            let uk = mul(&ia[k], s);
            let d = dot(s, &uk);
            if d.partial_cmp(&T::zero()) != Some(Ordering::Greater) {
                return Err(if d.is_finite() {
                    Error::SingularMassMatrix { pivot: k + 2 }
                } else {
                    Error::NonFiniteState
                });
            }
            let id = d.recip();
            let uu = tau[k + 2] - dot(s, &pa[k]);
            let mut a = ia[k];
            for (r, row) in a.iter_mut().enumerate() {
                for (col, x) in row.iter_mut().enumerate() {
                    *x -= uk[r] * uk[col] * id;
                }
            }
            let pass = add(&add(&pa[k], &mul(&a, &out.c[k])), &scale(&uk, uu * id));
            let p = PARENT[k];
            for (row, arow) in ia[p].iter_mut().zip(a.iter()) {
                for (x, y) in row.iter_mut().zip(arow.iter()) {
                    *x += *y;
                }
            }
            pa[p] = add(&pa[p], &pass);
            u_vec[k] = uk;
            inv_d[k] = id;
            u[k] = uu;
        }
        // The torso: its spatial acceleration from its articulated inertia.
        let f0 = [tau[2] - pa[0][0], tau[0] - pa[0][1], tau[1] - pa[0][2]];
        let a0 = solve3(&ia[TORSO], &f0)?;
        let mut acc = [[T::zero(); 3]; RAGDOLL_LINKS];
        acc[TORSO] = a0;
        let mut qdd = SVector::<T, RAGDOLL_COORDINATES>::zeros();
        for k in 1..RAGDOLL_LINKS {
            let a = add(&acc[PARENT[k]], &out.c[k]);
            let x = (u[k] - dot(&u_vec[k], &a)) * inv_d[k];
            acc[k] = add(&a, &scale(&out.s[k], x));
            qdd[k + 2] = x;
        }
        // The centre of mass's acceleration from the spatial one: a_O + w x v.
        qdd[0] = a0[1] - qd[2] * qd[1];
        qdd[1] = a0[2] + qd[2] * qd[0];
        qdd[2] = a0[0];
        if all_finite(qdd.as_slice()) {
            Ok(qdd)
        } else {
            Err(Error::NonFiniteState)
        }
    }
}

/// The first pass: per link its spatial velocity `v`, hinge subspace `s`, bias acceleration
/// `c = v x (s q')`, spatial inertia.
struct Outward<T> {
    v: [V3<T>; RAGDOLL_LINKS],
    s: [V3<T>; RAGDOLL_LINKS],
    c: [V3<T>; RAGDOLL_LINKS],
    inertia: [M3<T>; RAGDOLL_LINKS],
}

/// The motion subspace of the torso's generalized coordinate `i` (`x`, `y`, `th`).
fn torso_axis<T: Real>(i: usize) -> V3<T> {
    let mut s = [T::zero(); 3];
    s[(i + 1) % 3] = T::one();
    s
}

impl<T: Real> Mechanism<T, RAGDOLL_COORDINATES> for Ragdoll<T> {
    /// Composite rigid bodies: `M_jk = s_j . (I^c_j s_k)` for `k` on the path from `j` to the
    /// torso, `I^c_j` the inertia of link `j` and all it carries.
    fn mass_matrix(
        &self,
        s: &State<T, RAGDOLL_COORDINATES>,
    ) -> SMatrix<T, RAGDOLL_COORDINATES, RAGDOLL_COORDINATES> {
        let pose = self.pose(&s.q);
        let out = self.outward(&pose, &s.qd);
        let mut composite = out.inertia;
        for k in (1..RAGDOLL_LINKS).rev() {
            let c = composite[k];
            for (row, crow) in composite[PARENT[k]].iter_mut().zip(c.iter()) {
                for (x, y) in row.iter_mut().zip(crow.iter()) {
                    *x += *y;
                }
            }
        }
        let mut m = SMatrix::zeros();
        for k in 1..RAGDOLL_LINKS {
            let f = mul(&composite[k], &out.s[k]);
            m[(k + 2, k + 2)] = dot(&out.s[k], &f);
            let mut p = PARENT[k];
            while p != TORSO {
                let x = dot(&out.s[p], &f);
                m[(k + 2, p + 2)] = x;
                m[(p + 2, k + 2)] = x;
                p = PARENT[p];
            }
            for i in 0..3 {
                let x = dot(&torso_axis(i), &f);
                m[(k + 2, i)] = x;
                m[(i, k + 2)] = x;
            }
        }
        for i in 0..3 {
            let f = mul(&composite[TORSO], &torso_axis(i));
            for j in 0..3 {
                m[(j, i)] = dot(&torso_axis(j), &f);
            }
        }
        m
    }

    /// Inverse dynamics at `q'' = 0` (Newton-Euler), negated: the velocity-product and
    /// gravity terms.
    fn rhs(&self, s: &State<T, RAGDOLL_COORDINATES>) -> SVector<T, RAGDOLL_COORDINATES> {
        let pose = self.pose(&s.q);
        let out = self.outward(&pose, &s.qd);
        let g = self.body.gravity;
        let w = s.qd[2];
        let mut acc = [[T::zero(); 3]; RAGDOLL_LINKS];
        acc[TORSO] = [T::zero(), w * s.qd[1], -w * s.qd[0]];
        let mut f: [V3<T>; RAGDOLL_LINKS] = [[T::zero(); 3]; RAGDOLL_LINKS];
        for k in 0..RAGDOLL_LINKS {
            if k > 0 {
                acc[k] = add(&acc[PARENT[k]], &out.c[k]);
            }
            let iv = mul(&out.inertia[k], &out.v[k]);
            let inertial = add(&mul(&out.inertia[k], &acc[k]), &cross_force(&out.v[k], &iv));
            let m = self.mass[k];
            f[k] = [
                inertial[0] + m * g * pose.com[k][0],
                inertial[1],
                inertial[2] + m * g,
            ];
        }
        let mut rhs = SVector::zeros();
        for k in (1..RAGDOLL_LINKS).rev() {
            rhs[k + 2] = -dot(&out.s[k], &f[k]);
            let fk = f[k];
            f[PARENT[k]] = add(&f[PARENT[k]], &fk);
        }
        rhs[0] = -f[TORSO][1];
        rhs[1] = -f[TORSO][2];
        rhs[2] = -f[TORSO][0];
        rhs
    }

    /// `M^-1 b` by the articulated-body recursion at rest, without gravity.
    fn solve_mass(
        &self,
        s: &State<T, RAGDOLL_COORDINATES>,
        b: &SVector<T, RAGDOLL_COORDINATES>,
    ) -> Result<SVector<T, RAGDOLL_COORDINATES>, Error> {
        self.articulated(&self.pose(&s.q), &SVector::zeros(), b, T::zero())
    }

    /// The mass matrix (composite rigid bodies, one pose) factored once, then each column
    /// that is not zero solved by it: the same jumps as one articulated-body recursion per
    /// column, to rounding, at a third of the work for a contact step's twenty columns.
    fn velocity_jumps<const K: usize>(
        &self,
        s: &State<T, RAGDOLL_COORDINATES>,
        impulses: &mut SMatrix<T, RAGDOLL_COORDINATES, K>,
    ) -> Result<(), Error> {
        // Along the tree: each limb couples with the torso and its own joints, not the others.
        let factor = TreeFactor::factor(
            &self.mass_matrix(&State {
                qd: SVector::zeros(),
                ..*s
            }),
            &COORDINATE_PARENT,
        )?;
        factor.solve_columns(impulses);
        if all_finite(impulses.as_slice()) {
            Ok(())
        } else {
            Err(Error::NonFiniteState)
        }
    }

    /// The articulated-body recursion, `O(links)`.
    fn law<F: GeneralizedForce<T, RAGDOLL_COORDINATES>>(
        &self,
        s: &State<T, RAGDOLL_COORDINATES>,
        extra: &F,
    ) -> Result<SVector<T, RAGDOLL_COORDINATES>, Error> {
        let tau = free_law_force(self, s, extra)?;
        self.articulated(&self.pose(&s.q), &s.qd, &tau, self.body.gravity)
    }

    fn law_force<F: GeneralizedForce<T, RAGDOLL_COORDINATES>>(
        &self,
        s: &State<T, RAGDOLL_COORDINATES>,
        extra: &F,
    ) -> Result<SVector<T, RAGDOLL_COORDINATES>, Error> {
        free_law_force(self, s, extra)
    }
}

impl<T: Real> Ragdoll<T> {
    /// The kinetic energy at `pose` with velocities `qd`: each link's centre-of-mass velocity
    /// from its parent's, `v = v_parent + w_parent x (o - o_parent)` at the joint `o`, then
    /// `+ w x (c - o)` to the centre of mass `c`.
    fn kinetic_at<S: Scalar<Real = T>>(
        &self,
        pose: &Pose<S>,
        qd: &SVector<S, RAGDOLL_COORDINATES>,
    ) -> S {
        let w = self.rates(qd);
        let turn = |w: S, [x, y]: [S; 2]| [-w * y, w * x];
        let mut origin_v = [[S::zero(); 2]; RAGDOLL_LINKS];
        origin_v[TORSO] = [qd[0], qd[1]];
        let mut t = (qd[0] * qd[0] + qd[1] * qd[1]) * (self.mass[TORSO] * T::HALF)
            + w[TORSO] * w[TORSO] * (self.inertia[TORSO] * T::HALF);
        for k in 1..RAGDOLL_LINKS {
            let p = PARENT[k];
            let arm = [
                pose.origin[k][0] - pose.origin[p][0],
                pose.origin[k][1] - pose.origin[p][1],
            ];
            let [dx, dy] = turn(w[p], arm);
            origin_v[k] = [origin_v[p][0] + dx, origin_v[p][1] + dy];
            let lever = [
                pose.com[k][0] - pose.origin[k][0],
                pose.com[k][1] - pose.origin[k][1],
            ];
            let [cx, cy] = turn(w[k], lever);
            let (vx, vy) = (origin_v[k][0] + cx, origin_v[k][1] + cy);
            t += (vx * vx + vy * vy) * (self.mass[k] * T::HALF)
                + w[k] * w[k] * (self.inertia[k] * T::HALF);
        }
        t
    }

    /// The potential energy at `pose` with coordinates `q`.
    fn potential_at<S: Scalar<Real = T>>(
        &self,
        pose: &Pose<S>,
        q: &SVector<S, RAGDOLL_COORDINATES>,
    ) -> S {
        let mut v = q[1] * (self.mass[TORSO] * self.body.gravity);
        for k in 1..RAGDOLL_LINKS {
            v += (q[1] + pose.com[k][1]) * (self.mass[k] * self.body.gravity);
        }
        v
    }
}

impl<T: Real> Lagrangian<T, RAGDOLL_COORDINATES> for Ragdoll<T> {
    const READS_TIME: bool = false;
    /// `sum_k (m_k |v_k|^2 + I_k w_k^2) / 2`, each link's centre-of-mass velocity from its
    /// parent's: `v = v_parent + w_parent x (o - o_parent)` at the joint `o`, then
    /// `+ w x (c - o)` to the centre of mass `c`.
    fn kinetic<S: Scalar<Real = T>>(
        &self,
        _t: S,
        q: &SVector<S, RAGDOLL_COORDINATES>,
        qd: &SVector<S, RAGDOLL_COORDINATES>,
    ) -> S {
        self.kinetic_at(&self.pose(q), qd)
    }

    /// `g sum_k m_k y_k`.
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, RAGDOLL_COORDINATES>) -> S {
        self.potential_at(&self.pose(q), q)
    }

    /// `T + V` from one pose (the same numbers as the two apart).
    fn energy(&self, state: &State<T, RAGDOLL_COORDINATES>) -> T {
        let pose = self.pose(&state.q);
        self.kinetic_at(&pose, &state.qd) + self.potential_at(&pose, &state.q)
    }

    /// Joint damping on the nine joint angles.
    fn non_conservative_force(
        &self,
        state: &State<T, RAGDOLL_COORDINATES>,
    ) -> SVector<T, RAGDOLL_COORDINATES> {
        let c = self.body.joint_damping;
        SVector::from_fn(|i, _| if i < 3 { T::zero() } else { -c * state.qd[i] })
    }
}
