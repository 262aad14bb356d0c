//! [`ElasticPendulum`]: a point mass on a linear spring swinging from a fixed pivot.

use crate::small_solve::{positive_radius, radial_accelerations, solve_diagonal2};
use lagrange_core::nalgebra::{Matrix2, SVector, Vector2};
use lagrange_core::{
    free_law_force, validate, Error, GeneralizedForce, Lagrangian, Mechanism, Real, Scalar, State,
};

/// What [`ElasticPendulum`] reports at `r <= 0`.
const SPRING_COLLAPSED: &str = "spring length r <= 0";

/// A point mass `m` on a massless linear spring of stiffness `k` and rest length `l0`, free to
/// stretch and to swing in a vertical plane about a fixed pivot, in gravity `g`.
///
/// ```text
/// q = [r, th]   r: spring length, m (> 0); th: angle from the downward vertical, rad;
///               the mass is at (r sin th, -r cos th) from the pivot
/// T = m (r'^2 + r^2 th'^2) / 2
/// V = -m g r cos th + k (r - l0)^2 / 2
///
/// M = diag(m, m r^2)
/// f = | m r th'^2 + m g cos th - k (r - l0) |
///     | -2 m r r' th' - m g r sin th        |
/// r''  = r th'^2 + g cos th - k (r - l0) / m
/// th'' = -(g sin th + 2 r' th') / r
/// ```
///
/// Parameters: mass kg, stiffness N/m, rest length m, gravity m/s^2. The pivot, `r = 0`, is a
/// singular configuration (`M` loses rank and `th` is undefined) and `r < 0` is outside the
/// coordinates: there [`Mechanism::acceleration`] returns [`Error::Singularity`], as it does
/// where `r` is so small that `th''` overflows. Elsewhere no singularities. Energy `T + V` is
/// conserved. A stiff spring (`k / m >> g / l0`) makes the system stiff for explicit methods.
///
/// ```
/// use lagrange_core::{Error, Mechanism, State};
/// use lagrange_systems::ElasticPendulum;
/// let p = ElasticPendulum::<f64>::new(1.0, 100.0, 1.0, 9.81)?;
/// // Hanging at the static stretch, at rest: in equilibrium.
/// let a = p.acceleration(&State::new(0.0, [1.0 + 9.81 / 100.0, 0.0], [0.0, 0.0]))?;
/// assert!(a[0].abs() < 1e-13 && a[1] == 0.0);
/// assert!(matches!(
///     p.acceleration(&State::new(0.0, [0.0, 0.3], [0.0, 0.0])),
///     Err(Error::Singularity { .. })
/// ));
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ElasticPendulum<T: Real> {
    mass: T,
    stiffness: T,
    rest_length: T,
    gravity: T,
    /// `k / m`, the spring's share of `r''` per metre of stretch.
    k_over_m: T,
}

impl<T: Real> ElasticPendulum<T> {
    /// A `mass` (kg, > 0) on a spring of `stiffness` (N/m, > 0) and `rest_length` (m, >= 0),
    /// in `gravity` (m/s^2, >= 0).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first parameter out of range or not finite, or
    /// the one most responsible when `1 / m`, the weight `m g` or `k / m` overflows.
    pub fn new(mass: T, stiffness: T, rest_length: T, gravity: T) -> Result<Self, Error> {
        let mass = validate::positive("mass", mass)?;
        let stiffness = validate::positive("stiffness", stiffness)?;
        let rest_length = validate::non_negative("rest_length", rest_length)?;
        let gravity = validate::non_negative("gravity", gravity)?;
        validate::divisor(mass, &[("mass", mass, 1)])?;
        validate::derived(
            mass * gravity,
            &[("mass", mass, 1), ("gravity", gravity, 1)],
        )?;
        let k_over_m = validate::derived(
            stiffness / mass,
            &[("stiffness", stiffness, 1), ("mass", mass, -1)],
        )?;
        Ok(Self {
            mass,
            stiffness,
            rest_length,
            gravity,
            k_over_m,
        })
    }
    /// Mass, kg.
    #[must_use]
    pub fn mass(&self) -> T {
        self.mass
    }
    /// Spring stiffness, N/m.
    #[must_use]
    pub fn stiffness(&self) -> T {
        self.stiffness
    }
    /// Spring rest length, m.
    #[must_use]
    pub fn rest_length(&self) -> T {
        self.rest_length
    }
    /// Gravity, m/s^2.
    #[must_use]
    pub fn gravity(&self) -> T {
        self.gravity
    }
}

impl<T: Real> Mechanism<T, 2> for ElasticPendulum<T> {
    fn mass_matrix(&self, s: &State<T, 2>) -> Matrix2<T> {
        let r = s.q[0];
        Matrix2::new(self.mass, T::zero(), T::zero(), self.mass * r * r)
    }
    #[inline]
    fn rhs(&self, s: &State<T, 2>) -> Vector2<T> {
        let (r, rd, thd) = (s.q[0], s.qd[0], s.qd[1]);
        let (sin, cos) = s.q[1].sin_cos();
        let (m, g) = (self.mass, self.gravity);
        Vector2::new(
            m * r * thd * thd + m * g * cos - self.stiffness * (r - self.rest_length),
            -T::TWO * m * r * rd * thd - m * g * r * sin,
        )
    }
    #[inline]
    fn solve_mass(&self, s: &State<T, 2>, b: &Vector2<T>) -> Result<Vector2<T>, Error> {
        let r = s.q[0];
        positive_radius(s, SPRING_COLLAPSED)?;
        solve_diagonal2(s, [self.mass, self.mass * r * r], b, SPRING_COLLAPSED)
    }
    /// The closed form of the type's docs (`M^-1 f`: `f`'s masses cancelled), plus `M^-1` of
    /// the extra force. Through `M^-1 (f + Q + extra)` it took two divisions where this takes
    /// one, and the f32 RK4 step was 1.38 times the hand-written loop's. Inlined into the
    /// integrators' stages: out of line, the call and the result passed through memory kept
    /// the RK4 step above the hand-written loop's (as for
    /// [`DoublePendulum`](crate::DoublePendulum)).
    #[inline(always)]
    fn law<F: GeneralizedForce<T, 2>>(
        &self,
        s: &State<T, 2>,
        extra: &F,
    ) -> Result<SVector<T, 2>, Error> {
        let (r, rd, thd) = (s.q[0], s.qd[0], s.qd[1]);
        let (sin, cos) = s.q[1].sin_cos();
        let g = self.gravity;
        let mut qdd = Vector2::new(
            r * thd * thd + g * cos - self.k_over_m * (r - self.rest_length),
            -(T::TWO * rd * thd + g * sin) / r,
        );
        if !F::IS_ZERO {
            let e = extra.force(s);
            qdd += Vector2::new(e[0] / self.mass, e[1] / (self.mass * r * r));
        }
        radial_accelerations(s, qdd, self.mass * r * r, SPRING_COLLAPSED)
    }

    fn law_force<F: GeneralizedForce<T, 2>>(
        &self,
        s: &State<T, 2>,
        extra: &F,
    ) -> Result<SVector<T, 2>, Error> {
        // The law refuses r <= 0, and so does its force.
        positive_radius(s, SPRING_COLLAPSED)?;
        free_law_force(self, s, extra)
    }
}

impl<T: Real> Lagrangian<T, 2> for ElasticPendulum<T> {
    const READS_TIME: bool = false;
    /// `m |v|^2 / 2` with the Cartesian velocity of the mass.
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 2>, qd: &SVector<S, 2>) -> S {
        let (r, rd, thd) = (q[0], qd[0], qd[1]);
        let (sin, cos) = q[1].sin_cos();
        let vx = rd * sin + r * cos * thd;
        let vy = -rd * cos + r * sin * thd;
        S::from_real(T::HALF * self.mass) * (vx * vx + vy * vy)
    }
    /// `m g y + k (r - l0)^2 / 2` with `y = -r cos th`.
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 2>) -> S {
        let y = -q[0] * q[1].cos();
        let stretch = q[0] - S::from_real(self.rest_length);
        S::from_real(self.mass * self.gravity) * y
            + S::from_real(T::HALF * self.stiffness) * stretch * stretch
    }
}
