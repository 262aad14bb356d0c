//! [`SwingingAtwood`]: Atwood's machine whose lighter mass swings like a pendulum.

use crate::small_solve::{positive_radius, solve_diagonal2};
use lagrange_core::nalgebra::{Matrix2, SVector, Vector2};
use lagrange_core::{
    free_law_force, validate, Error, GeneralizedForce, Lagrangian, Mechanism, Real, Scalar, State,
};

/// What [`SwingingAtwood`] reports at `r <= 0`.
const AT_PULLEY: &str = "string length r <= 0: swinging mass at the pulley";

/// The swinging Atwood's machine: a massless inextensible string over a point pulley at the
/// origin carries a big mass `M` hanging straight down on one side and a small mass `m` swinging
/// in a vertical plane on the other, in gravity `g`.
///
/// ```text
/// q = [r, th]   r: length of string on the swinging side, m (> 0); th: its angle from the
///               downward vertical, rad; the small mass is at (r sin th, -r cos th) and the
///               big mass rises as r grows
/// T = (M + m) r'^2 / 2 + m r^2 th'^2 / 2
/// V = g r (M - m cos th)
///
/// M = diag(M + m, m r^2)
/// f = | m r th'^2 - g (M - m cos th) |
///     | -2 m r r' th' - m g r sin th |
/// r''  = (m r th'^2 - g (M - m cos th)) / (M + m)
/// th'' = -(g sin th + 2 r' th') / r
/// ```
///
/// Parameters: big and small masses kg, gravity m/s^2. Energy `T + V` is conserved; it bounds
/// `r <= E / (g (M - m))` when `M > m`. The motion is integrable for `M / m = 3` (Tufillaro)
/// and chaotic for most other ratios.
///
/// Singular configurations: the pulley, `r = 0`, where `M` loses rank and `th` is undefined,
/// and `r < 0`, outside the coordinates. There [`Mechanism::acceleration`] returns
/// [`Error::Singularity`], as it does where `r` is so small that `th''` overflows. Some
/// trajectories pass very close to the pulley, where `th''` grows like `1 / r` and a fixed step
/// must be small enough to resolve it: from rest at `r = 1`, `th = 0.5` with `M / m = 2`, `r`
/// falls to about 1.5e-3 and RK4 at `dt = 1e-3` loses the orbit there.
///
/// ```
/// use lagrange_core::{Error, Mechanism, State};
/// use lagrange_systems::SwingingAtwood;
/// let sam = SwingingAtwood::new(3.0, 1.0, 9.81)?;
/// // Released at rest with the string horizontal: the big mass pulls the string in while the
/// // small mass starts to swing down.
/// let a = sam.acceleration(&State::new(0.0, [1.0, core::f64::consts::FRAC_PI_2], [0.0, 0.0]))?;
/// assert!((a[0] + 9.81 * 3.0 / 4.0).abs() < 1e-13 && (a[1] + 9.81).abs() < 1e-13);
/// assert!(matches!(
///     sam.acceleration(&State::new(0.0, [0.0, 0.1], [0.0, 0.0])),
///     Err(Error::Singularity { .. })
/// ));
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SwingingAtwood<T: Real> {
    big_mass: T,
    small_mass: T,
    gravity: T,
}

impl<T: Real> SwingingAtwood<T> {
    /// A `big_mass` (kg, > 0) hanging and a `small_mass` (kg, > 0) swinging, in `gravity`
    /// (m/s^2, >= 0).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first parameter out of range or not finite, or
    /// the one most responsible when the total mass (which the motion divides by), `1 / m` or
    /// a weight `M g`, `m g` overflows.
    pub fn new(big_mass: T, small_mass: T, gravity: T) -> Result<Self, Error> {
        let big_mass = validate::positive("big_mass", big_mass)?;
        let small_mass = validate::positive("small_mass", small_mass)?;
        let gravity = validate::non_negative("gravity", gravity)?;
        let (big, small, g) = (
            ("big_mass", big_mass, 1),
            ("small_mass", small_mass, 1),
            ("gravity", gravity, 1),
        );
        validate::divisor(big_mass + small_mass, &[big, small])?;
        validate::divisor(small_mass, &[small])?;
        validate::derived(gravity * big_mass, &[g, big])?;
        validate::derived(small_mass * gravity, &[small, g])?;
        Ok(Self {
            big_mass,
            small_mass,
            gravity,
        })
    }
    /// The hanging mass `M`, kg.
    #[must_use]
    pub fn big_mass(&self) -> T {
        self.big_mass
    }
    /// The swinging mass `m`, kg.
    #[must_use]
    pub fn small_mass(&self) -> T {
        self.small_mass
    }
    /// Gravity, m/s^2.
    #[must_use]
    pub fn gravity(&self) -> T {
        self.gravity
    }
}

impl<T: Real> Mechanism<T, 2> for SwingingAtwood<T> {
    fn mass_matrix(&self, s: &State<T, 2>) -> Matrix2<T> {
        let r = s.q[0];
        Matrix2::new(
            self.big_mass + self.small_mass,
            T::zero(),
            T::zero(),
            self.small_mass * r * r,
        )
    }
    fn rhs(&self, s: &State<T, 2>) -> Vector2<T> {
        let (r, rd, thd) = (s.q[0], s.qd[0], s.qd[1]);
        let (sin, cos) = s.q[1].sin_cos();
        let (m, g) = (self.small_mass, self.gravity);
        Vector2::new(
            m * r * thd * thd - g * (self.big_mass - m * cos),
            -T::TWO * m * r * rd * thd - m * g * r * sin,
        )
    }
    fn solve_mass(&self, s: &State<T, 2>, b: &Vector2<T>) -> Result<Vector2<T>, Error> {
        let r = s.q[0];
        positive_radius(s, AT_PULLEY)?;
        solve_diagonal2(
            s,
            [self.big_mass + self.small_mass, self.small_mass * r * r],
            b,
            AT_PULLEY,
        )
    }
    fn law_force<F: GeneralizedForce<T, 2>>(
        &self,
        s: &State<T, 2>,
        extra: &F,
    ) -> Result<SVector<T, 2>, Error> {
        // The law refuses r <= 0, and so does its force.
        positive_radius(s, AT_PULLEY)?;
        free_law_force(self, s, extra)
    }
}

impl<T: Real> Lagrangian<T, 2> for SwingingAtwood<T> {
    const READS_TIME: bool = false;
    /// The big mass moves at `r'`; the small one's Cartesian velocity is squared.
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 2>, qd: &SVector<S, 2>) -> S {
        let (r, rd, thd) = (q[0], qd[0], qd[1]);
        let (sin, cos) = q[1].sin_cos();
        let vx = rd * sin + r * cos * thd;
        let vy = -rd * cos + r * sin * thd;
        S::from_real(T::HALF * self.big_mass) * rd * rd
            + S::from_real(T::HALF * self.small_mass) * (vx * vx + vy * vy)
    }
    /// `g (M y_M + m y_m)` with `y_M = r` (up to a constant) and `y_m = -r cos th`.
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 2>) -> S {
        S::from_real(self.gravity)
            * (S::from_real(self.big_mass) * q[0]
                - S::from_real(self.small_mass) * q[0] * q[1].cos())
    }
}
