//! [`FourBarLinkage`]: a planar closed chain of three moving bars, held closed by two
//! holonomic constraints.

use lagrange_core::constraints::{Constraints, HolonomicConstraints};
use lagrange_core::nalgebra::{Matrix2x3, SMatrix, SVector, Vector2, Vector3};
use lagrange_core::{
    all_finite, validate, Error, GeneralizedForce, Lagrangian, Mechanism, Real, Scalar, State,
};

/// Which of the two ways to close the loop at a given crank angle: the coupler-rocker joint
/// `C` on the left or on the right of the directed line from the crank tip `B` to the rocker
/// pivot `D`. The two are mirror images about that line; a motion never crosses from one to
/// the other except through a singular configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Branch {
    /// `C` to the left of `B -> D` (counterclockwise from it).
    Left,
    /// `C` to the right of `B -> D` (clockwise from it).
    Right,
}

/// A four-bar linkage in a vertical plane: a fixed ground link from pivot `A` at the origin to
/// pivot `D = (d, 0)`, a crank `A -> B` of length `a`, a coupler `B -> C` of length `b` and a
/// rocker `D -> C` of length `c`; uniform bars of masses `m1`, `m2`, `m3` (inertia `m l^2 / 12`
/// about each centre), in gravity `g`. One degree of freedom, described by three angles that
/// two loop-closure constraints tie together: a closed chain that generalized coordinates
/// cannot absorb without solving the loop in closed form.
///
/// ```text
/// q   = [th1, th2, th3]   crank, coupler and rocker angles from the downward vertical, rad:
///                         B = a u1, C = B + b u2 = D + c u3, with u = (sin th, -cos th)
/// T   = (I1 th1'^2 + I2 th2'^2 + I3 th3'^2) / 2 + k cos(th1 - th2) th1' th2'
///       I1 = (m1/3 + m2) a^2,  I2 = m2 b^2 / 3,  I3 = m3 c^2 / 3,  k = m2 a b / 2
/// V   = -g ((m1/2 + m2) a cos th1 + m2 b/2 cos th2 + m3 c/2 cos th3)
/// phi = [ a sin th1 + b sin th2 - c sin th3 - d,
///        -a cos th1 - b cos th2 + c cos th3     ] = 0                    (m)
/// J   = [ a cos th1   b cos th2  -c cos th3 ]
///       [ a sin th1   b sin th2  -c sin th3 ]
/// J'q' = [ -a sin th1 th1'^2 - b sin th2 th2'^2 + c sin th3 th3'^2,
///           a cos th1 th1'^2 + b cos th2 th2'^2 - c cos th3 th3'^2 ]
/// M q'' = f + J^T lambda,   lambda = the force (N) that the rocker exerts on the coupler at C
/// ```
///
/// The mass matrix is that of a double pendulum (crank, coupler) beside a pendulum (rocker),
/// `det = I3 (I1 I2 - k^2 cos^2) > 0` always. Singular configurations: where `J` loses rank,
/// all three moving links parallel (possible only when `a +- b +- c = d` for some signs);
/// reported as [`Error::RedundantConstraints`]. A Grashof crank-rocker (`a` shortest and
/// `a + max <= sum of the other two`) never reaches one. Energy `T + V` is conserved by the
/// exact motion.
///
/// This type is the two parts of the linkage: as a [`Mechanism`] the open chain (mass matrix,
/// `f`, closed-form mass solve and law, each computing its trigonometry once), as
/// [`Constraints`] the loop closure. The linkage itself, whose acceleration includes the
/// constraint forces, is [`Constrained::new`](lagrange_core::Constrained::new) of it.
///
/// ```
/// use lagrange_core::prelude::*;
/// use lagrange_systems::{Branch, FourBarLinkage};
/// let linkage = Constrained::new(FourBarLinkage::new([1.0_f64, 0.3, 1.0, 0.8], [1.0, 1.0, 1.0], 9.81)?);
/// let s = linkage.parts().assemble(0.0, 0.5, 2.0, Branch::Right)?;
/// assert!(linkage.residual(&s).position < 1e-15 && linkage.residual(&s).velocity < 1e-15);
/// let a = linkage.acceleration(&s)?;
/// assert!(a.iter().all(|x| x.is_finite()));
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FourBarLinkage<T: Real> {
    lengths: [T; 4],
    masses: [T; 3],
    gravity: T,
}

impl<T: Real> FourBarLinkage<T> {
    /// `lengths = [ground d, crank a, coupler b, rocker c]` (m, each > 0),
    /// `masses = [crank, coupler, rocker]` (kg, each > 0), `gravity` (m/s^2, >= 0).
    ///
    /// The loop closes at some crank angle exactly when no link is longer than the other three
    /// together (the polygon inequality): the distance from the crank tip to the rocker pivot
    /// ranges over `[|d - a|, d + a]`, and the coupler and rocker reach `[|b - c|, b + c]`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first entry out of range or not finite
    /// (`lengths[i]`, `masses[i]`) or `gravity`; the longest link (`lengths[i]`) when it is
    /// longer than the other three together, so that the loop closes at no crank angle; or
    /// the parameter most responsible when a quantity formed from them leaves the range of
    /// `T` (the inertias and the determinant of the mass matrix, which the motion divides
    /// by, the coupling, the weights and the sum of the lengths).
    pub fn new(lengths: [T; 4], masses: [T; 3], gravity: T) -> Result<Self, Error> {
        const LENGTHS: [&str; 4] = ["lengths[0]", "lengths[1]", "lengths[2]", "lengths[3]"];
        const MASSES: [&str; 3] = ["masses[0]", "masses[1]", "masses[2]"];
        for (name, l) in LENGTHS.into_iter().zip(lengths) {
            validate::positive(name, l)?;
        }
        for (name, m) in MASSES.into_iter().zip(masses) {
            validate::positive(name, m)?;
        }
        let gravity = validate::non_negative("gravity", gravity)?;
        let linkage = Self {
            lengths,
            masses,
            gravity,
        };
        let f = |i: usize, power| (LENGTHS[i], lengths[i], power);
        let mf = |i: usize| (MASSES[i], masses[i], 1);
        let all_lengths = [f(0, 1), f(1, 1), f(2, 1), f(3, 1)];
        let total = validate::derived(lengths.iter().fold(T::zero(), |a, &l| a + l), &all_lengths)?;
        // Squares of lengths and of distances between joints (assemble's law of cosines).
        let squares = [f(0, 2), f(1, 2), f(2, 2), f(3, 2)];
        validate::derived(total * total, &squares)?;
        let longest = (0..4).fold(0, |a, i| if lengths[i] > lengths[a] { i } else { a });
        if lengths[longest] > total - lengths[longest] {
            return Err(Error::InvalidParameter {
                name: LENGTHS[longest],
                reason:
                    "longer than the other three links together: the loop closes at no crank angle",
            });
        }
        let (i1, i2, i3, k) = linkage.inertias();
        let (a2, b2, c2) = (f(1, 2), f(2, 2), f(3, 2));
        validate::divisor(i1, &[mf(0), mf(1), a2])?;
        validate::divisor(i2, &[mf(1), b2])?;
        validate::divisor(i3, &[mf(2), c2])?;
        validate::derived(k, &[mf(1), f(1, 1), f(2, 1)])?;
        // det of the crank-coupler block: i1 i2 - k^2 cos^2, at least m2 a^2 b^2 (m1/9 + m2/12).
        let block = [mf(0), mf(1), mf(1), a2, b2];
        validate::derived(i1 * i2, &block)?;
        validate::divisor(i1 * i2 - k * k, &block)?;
        let [w1, w2, w3] = linkage.weights();
        let g = ("gravity", gravity, 1);
        validate::derived(w1, &[g, mf(0), mf(1), f(1, 1)])?;
        validate::derived(w2, &[g, mf(1), f(2, 1)])?;
        validate::derived(w3, &[g, mf(2), f(3, 1)])?;
        validate::derived(
            w1 + w2 + w3,
            &[g, mf(0), mf(1), mf(2), f(1, 1), f(2, 1), f(3, 1)],
        )?;
        Ok(linkage)
    }

    /// `[ground, crank, coupler, rocker]` lengths, m.
    #[must_use]
    pub fn lengths(&self) -> [T; 4] {
        self.lengths
    }
    /// `[crank, coupler, rocker]` masses, kg.
    #[must_use]
    pub fn masses(&self) -> [T; 3] {
        self.masses
    }
    /// Gravity, m/s^2.
    #[must_use]
    pub fn gravity(&self) -> T {
        self.gravity
    }

    /// The consistent state at time `t` with the crank at angle `crank` turning at
    /// `crank_rate`, the loop closed on `branch`: the coupler and rocker angles from the
    /// triangle `B C D` (law of cosines), their rates from `J q' = 0`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `crank` when the loop cannot close at this angle (the
    /// distance from `B` to `D` is outside `[|b - c|, b + c]`) or `crank`, `crank_rate` or `t`
    /// is not finite, `crank_rate` when the coupler's or rocker's rate overflows;
    /// [`Error::Singularity`] at a toggle (coupler and rocker in line), where the rates are
    /// not determined by the crank's.
    pub fn assemble(
        &self,
        t: T,
        crank: T,
        crank_rate: T,
        branch: Branch,
    ) -> Result<State<T, 3>, Error> {
        validate::finite("t", t)?;
        validate::finite("crank_rate", crank_rate)?;
        let [d, a, b, c] = self.lengths;
        let (s1, c1) = validate::finite("crank", crank)?.sin_cos();
        // E = D - B, its direction as an angle from the downward vertical.
        let (ex, ey) = (d - a * s1, a * c1);
        let e = (ex * ex + ey * ey).sqrt();
        let cos_alpha = (b * b + e * e - c * c) / (T::TWO * b * e);
        let closes = cos_alpha.abs() <= T::one(); // false for NaN too
        if !closes {
            return Err(Error::InvalidParameter {
                name: "crank",
                reason: "the loop cannot close at this crank angle",
            });
        }
        let alpha = cos_alpha.acos();
        let th_e = ex.atan2(-ey);
        let th2 = match branch {
            Branch::Left => th_e + alpha,
            Branch::Right => th_e - alpha,
        };
        let (s2, c2) = th2.sin_cos();
        let (cx, cy) = (a * s1 + b * s2, -a * c1 - b * c2);
        let th3 = (cx - d).atan2(-cy);
        let (s3, c3) = th3.sin_cos();
        // [b c2, -c c3; b s2, -c s3] [w2; w3] = -w1 [a c1; a s1]
        let det = b * c * (s2 * c3 - c2 * s3);
        if det.abs() <= T::EPSILON.sqrt() * b * c {
            return Err(Error::Singularity {
                what: "coupler and rocker in line (toggle)",
            });
        }
        let (r0, r1) = (-crank_rate * a * c1, -crank_rate * a * s1);
        let w2 = (-c * s3 * r0 + c * c3 * r1) / det;
        let w3 = (-b * s2 * r0 + b * c2 * r1) / det;
        let rate = [("crank_rate", crank_rate, 1)];
        validate::derived(w2, &rate)?;
        validate::derived(w3, &rate)?;
        Ok(State::new(t, [crank, th2, th3], [crank_rate, w2, w3]))
    }

    /// `M`, from the angles' sines and cosines.
    fn mass_matrix_from(&self, t: &Trig<T>) -> SMatrix<T, 3, 3> {
        let (i1, i2, i3, k) = self.inertias();
        let kc = k * t.cos12;
        SMatrix::<T, 3, 3>::new(
            i1,
            kc,
            T::zero(),
            kc,
            i2,
            T::zero(),
            T::zero(),
            T::zero(),
            i3,
        )
    }

    /// `f`, from the angles' sines and cosines and the rates.
    fn rhs_from(&self, t: &Trig<T>, qd: &Vector3<T>) -> Vector3<T> {
        let (_, _, _, k) = self.inertias();
        let [w1, w2, w3] = self.weights();
        let ks = k * t.sin12;
        Vector3::new(
            -ks * qd[1] * qd[1] - w1 * t.sin[0],
            ks * qd[0] * qd[0] - w2 * t.sin[1],
            -w3 * t.sin[2],
        )
    }

    /// `M^-1 b` in closed form: a 2x2 block (crank, coupler) and the rocker's inertia.
    fn solve_mass_from(&self, t: &Trig<T>, b: &Vector3<T>) -> Result<Vector3<T>, Error> {
        let (i1, i2, i3, k) = self.inertias();
        let kc = k * t.cos12;
        let det = i1 * i2 - kc * kc;
        if !det.is_finite() {
            return Err(Error::NonFiniteState);
        }
        if det <= T::zero() {
            return Err(Error::SingularMassMatrix { pivot: 1 });
        }
        let x = Vector3::new(
            (i2 * b[0] - kc * b[1]) / det,
            (i1 * b[1] - kc * b[0]) / det,
            b[2] / i3,
        );
        if all_finite(x.as_slice()) {
            Ok(x)
        } else {
            Err(Error::NonFiniteState)
        }
    }

    /// `phi`.
    fn phi_from(&self, t: &Trig<T>) -> Vector2<T> {
        let [d, a, b, c] = self.lengths;
        Vector2::new(
            a * t.sin[0] + b * t.sin[1] - c * t.sin[2] - d,
            -a * t.cos[0] - b * t.cos[1] + c * t.cos[2],
        )
    }

    /// `J`.
    fn jacobian_from(&self, t: &Trig<T>) -> Matrix2x3<T> {
        let [_, a, b, c] = self.lengths;
        Matrix2x3::new(
            a * t.cos[0],
            b * t.cos[1],
            -c * t.cos[2],
            a * t.sin[0],
            b * t.sin[1],
            -c * t.sin[2],
        )
    }

    /// `J'q'`.
    fn velocity_product_from(&self, t: &Trig<T>, qd: &Vector3<T>) -> Vector2<T> {
        let [_, a, b, c] = self.lengths;
        let (w1, w2, w3) = (qd[0] * qd[0], qd[1] * qd[1], qd[2] * qd[2]);
        Vector2::new(
            -a * t.sin[0] * w1 - b * t.sin[1] * w2 + c * t.sin[2] * w3,
            a * t.cos[0] * w1 + b * t.cos[1] * w2 - c * t.cos[2] * w3,
        )
    }

    /// `(I1, I2, I3, k)` of the mass matrix.
    fn inertias(&self) -> (T, T, T, T) {
        let [_, a, b, c] = self.lengths;
        let [m1, m2, m3] = self.masses;
        let third = T::from_f64(3.0).recip();
        (
            (m1 * third + m2) * a * a,
            m2 * b * b * third,
            m3 * c * c * third,
            T::HALF * m2 * a * b,
        )
    }

    /// `g` times the first moments `((m1/2 + m2) a, m2 b/2, m3 c/2)`: `V = -sum w_i cos th_i`.
    fn weights(&self) -> [T; 3] {
        let [_, a, b, c] = self.lengths;
        let [m1, m2, m3] = self.masses;
        let g = self.gravity;
        [
            g * (T::HALF * m1 + m2) * a,
            g * T::HALF * m2 * b,
            g * T::HALF * m3 * c,
        ]
    }
}

impl<T: Real> Mechanism<T, 3> for FourBarLinkage<T> {
    fn mass_matrix(&self, s: &State<T, 3>) -> SMatrix<T, 3, 3> {
        self.mass_matrix_from(&Trig::new(&s.q))
    }
    fn rhs(&self, s: &State<T, 3>) -> Vector3<T> {
        self.rhs_from(&Trig::new(&s.q), &s.qd)
    }
    fn solve_mass(&self, s: &State<T, 3>, b: &Vector3<T>) -> Result<Vector3<T>, Error> {
        self.solve_mass_from(&Trig::new(&s.q), b)
    }
    /// The open chain's law with its trigonometry computed once.
    fn law<F: GeneralizedForce<T, 3>>(
        &self,
        s: &State<T, 3>,
        extra: &F,
    ) -> Result<Vector3<T>, Error> {
        let trig = Trig::new(&s.q);
        self.solve_mass_from(&trig, &extra.added_to(s, self.rhs_from(&trig, &s.qd)))
    }
}

impl<T: Real> Constraints<T, 3, 2> for FourBarLinkage<T> {
    fn position_residual(&self, q: &Vector3<T>) -> Vector2<T> {
        self.phi_from(&Trig::new(q))
    }
    fn jacobian(&self, q: &Vector3<T>) -> Matrix2x3<T> {
        self.jacobian_from(&Trig::new(q))
    }
    fn velocity_product(&self, q: &Vector3<T>, qd: &Vector3<T>) -> Vector2<T> {
        self.velocity_product_from(&Trig::new(q), qd)
    }
}

/// Sines and cosines of the three angles and of `th1 - th2`, computed once per evaluation.
struct Trig<T> {
    sin: [T; 3],
    cos: [T; 3],
    sin12: T,
    cos12: T,
}

impl<T: Real> Trig<T> {
    fn new(q: &Vector3<T>) -> Self {
        let (s1, c1) = q[0].sin_cos();
        let (s2, c2) = q[1].sin_cos();
        let (s3, c3) = q[2].sin_cos();
        Self {
            sin: [s1, s2, s3],
            cos: [c1, c2, c3],
            sin12: s1 * c2 - c1 * s2,
            cos12: c1 * c2 + s1 * s2,
        }
    }
}

impl<T: Real> HolonomicConstraints<T, 3, 2> for FourBarLinkage<T> {
    fn phi<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 3>) -> SVector<S, 2> {
        let [d, a, b, c] = self.lengths.map(S::from_real);
        Vector2::new(
            a * q[0].sin() + b * q[1].sin() - c * q[2].sin() - d,
            -a * q[0].cos() - b * q[1].cos() + c * q[2].cos(),
        )
    }
}

/// The open chain (crank and coupler as a double pendulum, rocker as a pendulum), for the
/// automatic Euler-Lagrange check.
impl<T: Real> Lagrangian<T, 3> for FourBarLinkage<T> {
    const READS_TIME: bool = false;
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 3>, qd: &SVector<S, 3>) -> S {
        let (i1, i2, i3, k) = self.inertias();
        let h = |x: T| S::from_real(T::HALF * x);
        h(i1) * qd[0] * qd[0]
            + h(i2) * qd[1] * qd[1]
            + h(i3) * qd[2] * qd[2]
            + S::from_real(k) * (q[0] - q[1]).cos() * qd[0] * qd[1]
    }
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 3>) -> S {
        let [w1, w2, w3] = self.weights().map(S::from_real);
        -(w1 * q[0].cos() + w2 * q[1].cos() + w3 * q[2].cos())
    }
}
