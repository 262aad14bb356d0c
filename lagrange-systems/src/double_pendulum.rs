//! [`DoublePendulum`]: two point masses on two massless rods, a planar chain.

use crate::small_solve::solve_sym2_det;
use lagrange_core::nalgebra::{Matrix2, SVector, Vector2};
use lagrange_core::{
    free_law_force, validate, Error, Gather, GeneralizedForce, Lagrangian, Lanes, Mechanism, Real,
    Scalar, State,
};

/// Point masses `m1`, `m2` on massless rods `l1`, `l2`: the first hangs from a fixed pivot,
/// the second from the first mass, in gravity `g`.
///
/// ```text
/// q = [th1, th2]   absolute angles from the downward vertical, rad
///                  mass 1 at l1 (sin th1, -cos th1), mass 2 at that plus l2 (sin th2, -cos th2)
/// T = (m1 + m2) l1^2 th1'^2 / 2 + m2 l2^2 th2'^2 / 2 + m2 l1 l2 th1' th2' cos(th1 - th2)
/// V = -(m1 + m2) g l1 cos th1 - m2 g l2 cos th2
///
/// M = | (m1 + m2) l1^2           m2 l1 l2 cos(th1 - th2) |
///     | m2 l1 l2 cos(th1 - th2)  m2 l2^2                 |
/// f = | -m2 l1 l2 sin(th1 - th2) th2'^2 - (m1 + m2) g l1 sin th1 |
///     |  m2 l1 l2 sin(th1 - th2) th1'^2 - m2 g l2 sin th2        |
/// ```
///
/// `det M = m2 l1^2 l2^2 (m1 + m2 sin^2(th1 - th2)) > 0`: no singular configurations, and the
/// accelerations come from the closed-form 2x2 inverse. Chaotic for large energies.
///
/// ```
/// use lagrange_core::{Mechanism, State};
/// use lagrange_systems::DoublePendulum;
/// let dp = DoublePendulum::new(1.0, 1.0, 1.0, 1.0, 9.81)?;
/// let hanging = State::new(0.0, [0.0, 0.0], [0.0, 0.0]);
/// let a = dp.acceleration(&hanging)?;
/// assert_eq!((a[0], a[1]), (0.0, 0.0));
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DoublePendulum<T: Real> {
    m1: T,
    m2: T,
    l1: T,
    l2: T,
    gravity: T,
    /// Products of the parameters that every evaluation needs, formed once.
    k: Coefficients<T>,
}

/// The parameter products of `M`, `f` and `det M`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Coefficients<T> {
    /// `(m1 + m2) l1^2`.
    m11: T,
    /// `m2 l2^2`.
    m22: T,
    /// `m2 l1 l2`.
    coupling: T,
    /// `(m1 + m2) g l1`.
    weight1: T,
    /// `m2 g l2`.
    weight2: T,
    /// `m2 l1^2 l2^2`, so that `det M = m2 l1^2 l2^2 (m1 + m2 sin^2(th1 - th2))`.
    det_scale: T,
}

impl<T: Real> DoublePendulum<T> {
    /// Masses `m1`, `m2` (kg, > 0), rod lengths `l1`, `l2` (m, > 0), `gravity` (m/s^2, >= 0).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first parameter out of range or not finite, or
    /// the one most responsible when a quantity formed from them leaves the range of `T`
    /// (the entries of `M`, the weights `(m1 + m2) g l1` and `m2 g l2`, and `det M`, which
    /// the motion divides by, at its smallest and largest).
    pub fn new(m1: T, m2: T, l1: T, l2: T, gravity: T) -> Result<Self, Error> {
        let m1 = validate::positive("m1", m1)?;
        let m2 = validate::positive("m2", m2)?;
        let l1 = validate::positive("l1", l1)?;
        let l2 = validate::positive("l2", l2)?;
        let gravity = validate::non_negative("gravity", gravity)?;
        let f = |name, x, power| (name, x, power);
        let (a1, a2, g) = (f("m1", m1, 1), f("m2", m2, 1), f("gravity", gravity, 1));
        let mu = validate::derived(m1 + m2, &[a1, a2])?;
        let k = Coefficients {
            m11: validate::divisor(mu * l1 * l1, &[a1, a2, f("l1", l1, 2)])?,
            m22: validate::divisor(m2 * l2 * l2, &[a2, f("l2", l2, 2)])?,
            coupling: validate::derived(m2 * l1 * l2, &[a2, f("l1", l1, 1), f("l2", l2, 1)])?,
            weight1: validate::derived(mu * gravity * l1, &[a1, a2, g, f("l1", l1, 1)])?,
            weight2: validate::derived(m2 * gravity * l2, &[a2, g, f("l2", l2, 1)])?,
            det_scale: validate::derived(
                m2 * l1 * l1 * l2 * l2,
                &[a2, f("l1", l1, 2), f("l2", l2, 2)],
            )?,
        };
        // det M = det_scale (m1 + m2 sin^2): from det_scale m1 (sin = 0) to det_scale mu.
        let det = [a2, f("l1", l1, 2), f("l2", l2, 2)];
        validate::divisor(k.det_scale * m1, &[det[0], det[1], det[2], a1])?;
        validate::derived(k.det_scale * mu, &[det[0], det[1], det[2], a1, a2])?;
        Ok(Self {
            m1,
            m2,
            l1,
            l2,
            gravity,
            k,
        })
    }
    /// Masses `[m1, m2]`, kg.
    #[must_use]
    pub fn masses(&self) -> [T; 2] {
        [self.m1, self.m2]
    }
    /// Rod lengths `[l1, l2]`, m.
    #[must_use]
    pub fn lengths(&self) -> [T; 2] {
        [self.l1, self.l2]
    }
    /// Gravity, m/s^2.
    #[must_use]
    pub fn gravity(&self) -> T {
        self.gravity
    }

    /// `M` from `cos(th1 - th2)`.
    #[inline]
    fn mass(&self, cos: T) -> Matrix2<T> {
        let off = self.k.coupling * cos;
        Matrix2::new(self.k.m11, off, off, self.k.m22)
    }

    /// `det M` from `sin(th1 - th2)`, in its product form, free of cancellation.
    #[inline]
    fn det(&self, sin: T) -> T {
        self.k.det_scale * (self.m1 + self.m2 * sin * sin)
    }

    /// The mass matrix, the right-hand side and `det M` together, sharing one
    /// `sin_cos(th1 - th2)`.
    // Inlined into the law: called, over lanes it took the group's parameters through memory,
    // and a bank of 1,024 double pendulums in lanes of 16 cost 17.8 rather than 16.1 ns per
    // instance-step.
    #[inline(always)]
    fn terms(&self, s: &State<T, 2>) -> (Matrix2<T>, Vector2<T>, T) {
        let k = &self.k;
        let (sin, cos) = (s.q[0] - s.q[1]).sin_cos();
        let f = Vector2::new(
            -k.coupling * sin * s.qd[1] * s.qd[1] - k.weight1 * s.q[0].sin(),
            k.coupling * sin * s.qd[0] * s.qd[0] - k.weight2 * s.q[1].sin(),
        );
        (self.mass(cos), f, self.det(sin))
    }
}

impl<T: Real> Gather<T, 2> for DoublePendulum<T> {
    type Gathered<const L: usize> = DoublePendulum<Lanes<T, L>>;
    /// Lane by lane: every parameter gathered.
    fn gather<const L: usize>(instances: [&Self; L]) -> Self::Gathered<L> {
        let lanes = |field: fn(&Self) -> T| Lanes::gather(&instances, field);
        DoublePendulum {
            m1: lanes(|m| m.m1),
            m2: lanes(|m| m.m2),
            l1: lanes(|m| m.l1),
            l2: lanes(|m| m.l2),
            gravity: lanes(|m| m.gravity),
            k: Coefficients {
                m11: lanes(|m| m.k.m11),
                m22: lanes(|m| m.k.m22),
                coupling: lanes(|m| m.k.coupling),
                weight1: lanes(|m| m.k.weight1),
                weight2: lanes(|m| m.k.weight2),
                det_scale: lanes(|m| m.k.det_scale),
            },
        }
    }
    #[inline(always)] // see `Gather::window`
    fn window<const W: usize, const L: usize>(
        wide: &Self::Gathered<W>,
        at: usize,
    ) -> Self::Gathered<L> {
        DoublePendulum {
            m1: wide.m1.window(at),
            m2: wide.m2.window(at),
            l1: wide.l1.window(at),
            l2: wide.l2.window(at),
            gravity: wide.gravity.window(at),
            k: Coefficients {
                m11: wide.k.m11.window(at),
                m22: wide.k.m22.window(at),
                coupling: wide.k.coupling.window(at),
                weight1: wide.k.weight1.window(at),
                weight2: wide.k.weight2.window(at),
                det_scale: wide.k.det_scale.window(at),
            },
        }
    }
    fn put<const L: usize>(&self, lanes: &mut Self::Gathered<L>, lane: usize) {
        lanes.m1.set(lane, self.m1);
        lanes.m2.set(lane, self.m2);
        lanes.l1.set(lane, self.l1);
        lanes.l2.set(lane, self.l2);
        lanes.gravity.set(lane, self.gravity);
        lanes.k.m11.set(lane, self.k.m11);
        lanes.k.m22.set(lane, self.k.m22);
        lanes.k.coupling.set(lane, self.k.coupling);
        lanes.k.weight1.set(lane, self.k.weight1);
        lanes.k.weight2.set(lane, self.k.weight2);
        lanes.k.det_scale.set(lane, self.k.det_scale);
    }
}

impl<T: Real> Mechanism<T, 2> for DoublePendulum<T> {
    fn mass_matrix(&self, s: &State<T, 2>) -> Matrix2<T> {
        self.mass((s.q[0] - s.q[1]).cos())
    }
    fn rhs(&self, s: &State<T, 2>) -> Vector2<T> {
        self.terms(s).1
    }
    fn solve_mass(&self, s: &State<T, 2>, b: &Vector2<T>) -> Result<Vector2<T>, Error> {
        let (sin, cos) = (s.q[0] - s.q[1]).sin_cos();
        solve_sym2_det(&self.mass(cos), self.det(sin), b)
    }
    /// The closed form.
    // Inlined into the integrators' stages: a call would spill every live float around it
    // (no callee-saved float registers on x86-64), 15% of an RK4 step here.
    #[inline(always)]
    fn law<F: GeneralizedForce<T, 2>>(
        &self,
        s: &State<T, 2>,
        extra: &F,
    ) -> Result<SVector<T, 2>, Error> {
        let (m, f, det) = self.terms(s);
        solve_sym2_det(&m, det, &extra.added_to(s, f))
    }
    fn law_force<F: GeneralizedForce<T, 2>>(
        &self,
        s: &State<T, 2>,
        extra: &F,
    ) -> Result<SVector<T, 2>, Error> {
        free_law_force(self, s, extra)
    }
}

impl<T: Real> Lagrangian<T, 2> for DoublePendulum<T> {
    const READS_TIME: bool = false;
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 2>, qd: &SVector<S, 2>) -> S {
        let mu_l1l1 = S::from_real(T::HALF * (self.m1 + self.m2) * self.l1 * self.l1);
        let m2_l2l2 = S::from_real(T::HALF * self.m2 * self.l2 * self.l2);
        let c = S::from_real(self.m2 * self.l1 * self.l2);
        mu_l1l1 * qd[0] * qd[0] + m2_l2l2 * qd[1] * qd[1] + c * qd[0] * qd[1] * (q[0] - q[1]).cos()
    }
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 2>) -> S {
        let g = self.gravity;
        -S::from_real(g * (self.m1 + self.m2) * self.l1) * q[0].cos()
            - S::from_real(g * self.m2 * self.l2) * q[1].cos()
    }
}
