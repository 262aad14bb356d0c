//! [`Acrobot`]: Spong's two-link underactuated arm, driven only at the elbow.

use crate::small_solve::solve_sym2;
use lagrange_core::nalgebra::{Matrix2, SVector, Vector2};
use lagrange_core::{
    free_law_force, validate, Controlled, Error, Gather, GeneralizedForce, Lagrangian, Lanes,
    Mechanism, Real, Scalar, State,
};

/// Spong's acrobot: two rigid links in a vertical plane, the first hinged to a fixed pivot
/// (unactuated), the second hinged to the end of the first and driven there by a torque `tau`,
/// in gravity `g`.
///
/// ```text
/// q = [th1, th2]   th1: link 1 from the downward vertical, rad (absolute);
///                  th2: link 2 RELATIVE to link 1, rad (0 = straight);
///                  link 1's centre of mass at lc1 (sin th1, -cos th1), link 2's at
///                  l1 (sin th1, -cos th1) + lc2 (sin(th1 + th2), -cos(th1 + th2))
/// T = (m1 lc1^2 + i1) th1'^2 / 2 + i2 (th1' + th2')^2 / 2
///     + m2 (l1^2 th1'^2 + lc2^2 (th1' + th2')^2 + 2 l1 lc2 cos th2 th1' (th1' + th2')) / 2
/// V = -m1 g lc1 cos th1 - m2 g (l1 cos th1 + lc2 cos(th1 + th2))
/// Q = [0, tau]
///
/// M = | d11  d12 |   d11 = m1 lc1^2 + m2 (l1^2 + lc2^2 + 2 l1 lc2 cos th2) + i1 + i2
///     | d12  d22 |   d12 = m2 (lc2^2 + l1 lc2 cos th2) + i2,   d22 = m2 lc2^2 + i2
/// f = | m2 l1 lc2 sin th2 (th2'^2 + 2 th1' th2') - (m1 lc1 + m2 l1) g sin th1 - phi2 |
///     | -m2 l1 lc2 sin th2 th1'^2 - phi2                                              |
///     phi2 = m2 lc2 g sin(th1 + th2)
/// ```
///
/// Spong's equations `d11 th1'' + d12 th2'' + h1 + phi1 = 0`,
/// `d12 th1'' + d22 th2'' + h2 + phi2 = tau` in this sign convention.
///
/// Parameters: link masses `m1`, `m2` kg; link lengths `l1`, `l2` m (`l2` fixes only where
/// the tip is, [`Acrobot::tip`]); distances `lc1`, `lc2` m from each link's hinge to its centre
/// of mass; moments of inertia `i1`, `i2` kg m^2 about each centre of mass; gravity m/s^2; the
/// elbow torque ([`Acrobot::set_torque`]) N m, held constant over a step and changed by the
/// controller between steps.
///
/// `det M = (m1 lc1^2 + i1)(m2 lc2^2 + i2) + m2 l1^2 i2 + m2^2 l1^2 lc2^2 sin^2 th2`, positive
/// everywhere because the constructor requires both links to have inertia about their hinges:
/// no singular configurations. Energy `T + V` is conserved while `tau = 0`.
///
/// ```
/// use lagrange_core::{Mechanism, State};
/// use lagrange_systems::Acrobot;
/// let mut acrobot = Acrobot::<f64>::spong();
/// let hanging = State::new(0.0, [0.0, 0.0], [0.0, 0.0]);
/// assert_eq!(acrobot.acceleration(&hanging)?.as_slice(), &[0.0, 0.0]);
/// // A positive elbow torque bends the elbow forwards and swings link 1 back.
/// acrobot.set_torque(1.0)?;
/// let a = acrobot.acceleration(&hanging)?;
/// assert!(a[1] > 0.0 && a[0] < 0.0);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Acrobot<T: Real> {
    m1: T,
    m2: T,
    l1: T,
    l2: T,
    lc1: T,
    lc2: T,
    i1: T,
    i2: T,
    gravity: T,
    torque: T,
}

impl<T: Real> Acrobot<T> {
    /// An acrobot with link masses `m1`, `m2` (kg, > 0), lengths `l1`, `l2` (m, > 0), hinge to
    /// centre of mass distances `lc1`, `lc2` (m, >= 0), inertias about the centres of mass
    /// `i1`, `i2` (kg m^2, >= 0), in `gravity` (m/s^2, >= 0), with no torque applied. Each link
    /// needs inertia about its hinge: `m1 lc1^2 + i1 > 0` and `m2 lc2^2 + i2 > 0`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first parameter out of range or not finite,
    /// `i1` (`i2`) when link 1 (2) has no inertia about its hinge, or the parameter most
    /// responsible when a quantity formed from them leaves the range of `T` (the hinge
    /// inertias, the entries of the mass matrix, its determinant at its smallest and largest,
    /// the weight terms).
    #[allow(clippy::too_many_arguments)] // the nine parameters of the conventions, in order
    pub fn new(
        m1: T,
        m2: T,
        l1: T,
        l2: T,
        lc1: T,
        lc2: T,
        i1: T,
        i2: T,
        gravity: T,
    ) -> Result<Self, Error> {
        let a = Self {
            m1: validate::positive("m1", m1)?,
            m2: validate::positive("m2", m2)?,
            l1: validate::positive("l1", l1)?,
            l2: validate::positive("l2", l2)?,
            lc1: validate::non_negative("lc1", lc1)?,
            lc2: validate::non_negative("lc2", lc2)?,
            i1: validate::non_negative("i1", i1)?,
            i2: validate::non_negative("i2", i2)?,
            gravity: validate::non_negative("gravity", gravity)?,
            torque: T::zero(),
        };
        let f = |name, x, power| (name, x, power);
        let hinge_inertia = |name, i: T, m: T, lc: T, m_name, lc_name| {
            let factors = [f(m_name, m, 1), f(lc_name, lc, 2), f(name, i, 1)];
            validate::derived(m * lc * lc, &factors[..2])?;
            let hinge = i + m * lc * lc;
            if hinge > T::zero() {
                validate::divisor(hinge, &factors)
            } else {
                Err(Error::InvalidParameter {
                    name,
                    reason: "the link needs inertia about its hinge: i + m lc^2 must be positive",
                })
            }
        };
        let i1h = hinge_inertia("i1", a.i1, a.m1, a.lc1, "m1", "lc1")?;
        let d22 = hinge_inertia("i2", a.i2, a.m2, a.lc2, "m2", "lc2")?;
        // The mass matrix: d22, k cos, d11 up to d11_max; its determinant from
        // i1h d22 (a lower bound) to d11_max d22; the weights; the potential's range.
        let (m1, m2, l1, lc1, lc2, i1, i2, g) = (
            f("m1", a.m1, 1),
            f("m2", a.m2, 1),
            f("l1", a.l1, 1),
            f("lc1", a.lc1, 1),
            f("lc2", a.lc2, 1),
            f("i1", a.i1, 1),
            f("i2", a.i2, 1),
            f("gravity", a.gravity, 1),
        );
        let k = validate::derived(a.m2 * a.l1 * a.lc2, &[m2, l1, lc2])?;
        let reach = validate::derived(a.m2 * a.l1 * a.l1, &[m2, f("l1", a.l1, 2)])?;
        let all = [
            m1,
            m2,
            f("l1", a.l1, 2),
            f("lc1", a.lc1, 2),
            f("lc2", a.lc2, 2),
            i1,
            i2,
        ];
        let d11_max = validate::derived(i1h + reach + d22 + T::TWO * k, &all)?;
        validate::derived(d11_max * d22, &all)?;
        validate::divisor(i1h * d22, &all)?;
        let w = validate::derived(a.m1 * a.lc1 + a.m2 * a.l1, &[m1, lc1, m2, l1])?;
        validate::derived(w * a.gravity, &[m1, lc1, m2, l1, g])?;
        validate::derived(a.m2 * a.lc2 * a.gravity, &[m2, lc2, g])?;
        let reach2 = validate::derived(a.m2 * (a.l1 + a.lc2), &[m2, l1, lc2])?;
        validate::derived(
            a.gravity * (a.m1 * a.lc1 + reach2),
            &[g, m1, lc1, m2, l1, lc2],
        )?;
        Ok(a)
    }

    /// Spong's and Sutton and Barto's benchmark acrobot: `m1 = m2 = 1` kg, `l1 = l2 = 1` m,
    /// `lc1 = lc2 = 0.5` m, `i1 = i2 = 1` kg m^2, `g = 9.8` m/s^2, no torque.
    #[must_use]
    pub fn spong() -> Self {
        let (one, half) = (T::one(), T::HALF);
        Self {
            m1: one,
            m2: one,
            l1: one,
            l2: one,
            lc1: half,
            lc2: half,
            i1: one,
            i2: one,
            gravity: T::from_f64(9.8),
            torque: T::zero(),
        }
    }

    /// Link masses `[m1, m2]`, kg.
    #[must_use]
    pub fn masses(&self) -> [T; 2] {
        [self.m1, self.m2]
    }
    /// Link lengths `[l1, l2]`, m.
    #[must_use]
    pub fn lengths(&self) -> [T; 2] {
        [self.l1, self.l2]
    }
    /// Hinge to centre of mass distances `[lc1, lc2]`, m.
    #[must_use]
    pub fn com_distances(&self) -> [T; 2] {
        [self.lc1, self.lc2]
    }
    /// Moments of inertia about the centres of mass `[i1, i2]`, kg m^2.
    #[must_use]
    pub fn inertias(&self) -> [T; 2] {
        [self.i1, self.i2]
    }
    /// Gravity, m/s^2.
    #[must_use]
    pub fn gravity(&self) -> T {
        self.gravity
    }
    /// The elbow torque, N m.
    #[must_use]
    pub fn torque(&self) -> T {
        self.torque
    }
    /// Sets the elbow torque (N m, any finite sign), used from the next evaluation on.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `torque` when not finite (the torque is left unchanged).
    pub fn set_torque(&mut self, torque: T) -> Result<(), Error> {
        self.torque = validate::finite("torque", torque)?;
        Ok(())
    }
    /// Position `(x, y)` of the tip of link 2 relative to the pivot, m. (No error channel: NaN
    /// for angles that are not finite.)
    #[must_use]
    pub fn tip(&self, s: &State<T, 2>) -> (T, T) {
        let (s1, c1) = s.q[0].sin_cos();
        let (s12, c12) = (s.q[0] + s.q[1]).sin_cos();
        (self.l1 * s1 + self.l2 * s12, -self.l1 * c1 - self.l2 * c12)
    }

    /// The mass matrix and right-hand side together, sharing the trigonometry.
    fn terms(&self, s: &State<T, 2>) -> (Matrix2<T>, Vector2<T>) {
        let (s2, c2) = s.q[1].sin_cos();
        let s1 = s.q[0].sin();
        let s12 = (s.q[0] + s.q[1]).sin();
        let (w1, w2) = (s.qd[0], s.qd[1]);
        let (m2, l1, lc2, g) = (self.m2, self.l1, self.lc2, self.gravity);
        let d22 = m2 * lc2 * lc2 + self.i2;
        let k = m2 * l1 * lc2;
        let d12 = d22 + k * c2;
        let d11 = self.m1 * self.lc1 * self.lc1 + m2 * l1 * l1 + self.i1 + d22 + T::TWO * k * c2;
        let phi2 = m2 * lc2 * g * s12;
        let f = Vector2::new(
            k * s2 * (w2 * w2 + T::TWO * w1 * w2) - (self.m1 * self.lc1 + m2 * l1) * g * s1 - phi2,
            -k * s2 * w1 * w1 - phi2,
        );
        (Matrix2::new(d11, d12, d12, d22), f)
    }
}

/// The input is the elbow torque, N m.
impl<T: Real> Controlled<T> for Acrobot<T> {
    type Input = T;
    fn input(&self) -> T {
        self.torque()
    }
    /// # Errors
    /// [`Error::InvalidParameter`] `input` when not finite (the torque is left unchanged).
    fn set_input(&mut self, input: T) -> Result<(), Error> {
        self.set_torque(validate::finite("input", input)?)
    }
}

impl<T: Real> Gather<T, 2> for Acrobot<T> {
    type Gathered<const L: usize> = Acrobot<Lanes<T, L>>;
    /// Lane by lane: every parameter gathered.
    fn gather<const L: usize>(instances: [&Self; L]) -> Self::Gathered<L> {
        let lanes = |field: fn(&Self) -> T| Lanes::gather(&instances, field);
        Acrobot {
            m1: lanes(|m| m.m1),
            m2: lanes(|m| m.m2),
            l1: lanes(|m| m.l1),
            l2: lanes(|m| m.l2),
            lc1: lanes(|m| m.lc1),
            lc2: lanes(|m| m.lc2),
            i1: lanes(|m| m.i1),
            i2: lanes(|m| m.i2),
            gravity: lanes(|m| m.gravity),
            torque: lanes(|m| m.torque),
        }
    }
    #[inline(always)] // see `Gather::window`
    fn window<const W: usize, const L: usize>(
        wide: &Self::Gathered<W>,
        at: usize,
    ) -> Self::Gathered<L> {
        Acrobot {
            m1: wide.m1.window(at),
            m2: wide.m2.window(at),
            l1: wide.l1.window(at),
            l2: wide.l2.window(at),
            lc1: wide.lc1.window(at),
            lc2: wide.lc2.window(at),
            i1: wide.i1.window(at),
            i2: wide.i2.window(at),
            gravity: wide.gravity.window(at),
            torque: wide.torque.window(at),
        }
    }
    fn put<const L: usize>(&self, lanes: &mut Self::Gathered<L>, lane: usize) {
        lanes.m1.set(lane, self.m1);
        lanes.m2.set(lane, self.m2);
        lanes.l1.set(lane, self.l1);
        lanes.l2.set(lane, self.l2);
        lanes.lc1.set(lane, self.lc1);
        lanes.lc2.set(lane, self.lc2);
        lanes.i1.set(lane, self.i1);
        lanes.i2.set(lane, self.i2);
        lanes.gravity.set(lane, self.gravity);
        lanes.torque.set(lane, self.torque);
    }
}

impl<T: Real> Mechanism<T, 2> for Acrobot<T> {
    fn mass_matrix(&self, s: &State<T, 2>) -> Matrix2<T> {
        self.terms(s).0
    }
    fn rhs(&self, s: &State<T, 2>) -> Vector2<T> {
        self.terms(s).1
    }
    fn solve_mass(&self, s: &State<T, 2>, b: &Vector2<T>) -> Result<Vector2<T>, Error> {
        solve_sym2(&self.mass_matrix(s), b)
    }
    /// The closed form.
    fn law<F: GeneralizedForce<T, 2>>(
        &self,
        s: &State<T, 2>,
        extra: &F,
    ) -> Result<SVector<T, 2>, Error> {
        let (mass, f) = self.terms(s);
        solve_sym2(
            &mass,
            &extra.added_to(s, f + self.non_conservative_force(s)),
        )
    }
    fn law_force<F: GeneralizedForce<T, 2>>(
        &self,
        s: &State<T, 2>,
        extra: &F,
    ) -> Result<SVector<T, 2>, Error> {
        free_law_force(self, s, extra)
    }
}

impl<T: Real> Lagrangian<T, 2> for Acrobot<T> {
    const READS_TIME: bool = false;
    /// Each link's `m |v_c|^2 / 2` with the Cartesian velocity of its centre of mass, plus its
    /// spin `i w^2 / 2` at its absolute rate (`th1'`, `th1' + th2'`).
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 2>, qd: &SVector<S, 2>) -> S {
        let (s1, c1) = q[0].sin_cos();
        let (s12, c12) = (q[0] + q[1]).sin_cos();
        let (w1, w12) = (qd[0], qd[0] + qd[1]);
        let (l1, lc1, lc2) = (
            S::from_real(self.l1),
            S::from_real(self.lc1),
            S::from_real(self.lc2),
        );
        // d/dt of lc1 (sin th1, -cos th1) and of l1 (sin th1, -cos th1) + lc2 (sin th12, ...).
        let (v1x, v1y) = (lc1 * c1 * w1, lc1 * s1 * w1);
        let (v2x, v2y) = (
            l1 * c1 * w1 + lc2 * c12 * w12,
            l1 * s1 * w1 + lc2 * s12 * w12,
        );
        let half = S::from_f64(0.5);
        half * S::from_real(self.m1) * (v1x * v1x + v1y * v1y)
            + half * S::from_real(self.m2) * (v2x * v2x + v2y * v2y)
            + half * S::from_real(self.i1) * w1 * w1
            + half * S::from_real(self.i2) * w12 * w12
    }
    /// `g (m1 y1 + m2 y2)` with the centres of mass' heights.
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 2>) -> S {
        let c1 = q[0].cos();
        let c12 = (q[0] + q[1]).cos();
        let y1 = -S::from_real(self.lc1) * c1;
        let y2 = -S::from_real(self.l1) * c1 - S::from_real(self.lc2) * c12;
        S::from_real(self.gravity) * (S::from_real(self.m1) * y1 + S::from_real(self.m2) * y2)
    }
    fn non_conservative_force(&self, _s: &State<T, 2>) -> Vector2<T> {
        Vector2::new(T::zero(), self.torque)
    }
}
