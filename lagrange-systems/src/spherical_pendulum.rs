//! [`SphericalPendulum`]: a point mass on a massless rod free to swing in every direction.

use crate::small_solve::solve_diagonal2;
use lagrange_core::nalgebra::{Matrix2, SVector, Vector2};
use lagrange_core::{
    free_law_force, validate, Error, GeneralizedForce, Lagrangian, Mechanism, Real, Scalar, State,
};

/// What [`SphericalPendulum`] reports on the vertical axis.
const ON_AXIS: &str = "sin(th) = 0: spherical pendulum on the vertical axis";

/// A point mass `m` on a massless rod of length `l` about a fixed pivot, free to move on the
/// sphere of radius `l`, in gravity `g` along -y.
///
/// ```text
/// q = [th, phi]   th: polar angle from the downward vertical, rad; phi: azimuth, rad;
///                 the mass is at (l sin th cos phi, -l cos th, l sin th sin phi) from the pivot
/// T = m l^2 (th'^2 + sin^2 th phi'^2) / 2
/// V = -m g l cos th
///
/// M = diag(m l^2, m l^2 sin^2 th)
/// f = | m l^2 sin th cos th phi'^2 - m g l sin th |
///     | -2 m l^2 sin th cos th th' phi'           |
/// th''  = sin th cos th phi'^2 - (g / l) sin th
/// phi'' = -2 cos th th' phi' / sin th
/// ```
///
/// Parameters: mass kg, length m, gravity m/s^2. `phi` is cyclic, so besides `T + V` the
/// momentum `p_phi = m l^2 sin^2 th phi'` ([`SphericalPendulum::angular_momentum`], the angular
/// momentum about the vertical axis) is conserved.
///
/// Singular configurations: on the vertical axis, `sin th = 0` (hanging straight down or
/// standing straight up), the azimuth is undefined and `M` loses rank. There
/// [`Mechanism::acceleration`] returns [`Error::Singularity`], never NaN; it does the same where
/// `sin th` is so small that `sin^2 th` underflows or `phi''` overflows. Near the axis the
/// equations are correct but `phi''` grows like `1 / sin th`: a motion through the axis needs
/// other coordinates (or a start slightly off it, with the step size to match).
///
/// ```
/// use lagrange_core::{Error, Mechanism, State};
/// use lagrange_systems::SphericalPendulum;
/// let p = SphericalPendulum::new(1.0, 1.0, 9.81)?;
/// // A conical pendulum: th constant when phi'^2 = g / (l cos th).
/// let th = 0.5_f64;
/// let a = p.acceleration(&State::new(0.0, [th, 0.0], [0.0, (9.81 / th.cos()).sqrt()]))?;
/// assert!(a[0].abs() < 1e-14 && a[1] == 0.0);
/// assert!(matches!(
///     p.acceleration(&State::new(0.0, [0.0, 0.0], [1.0, 1.0])),
///     Err(Error::Singularity { .. })
/// ));
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SphericalPendulum<T: Real> {
    mass: T,
    length: T,
    gravity: T,
}

impl<T: Real> SphericalPendulum<T> {
    /// A pendulum of `mass` (kg, > 0) and `length` (m, > 0) in `gravity` (m/s^2, >= 0).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first parameter out of range or not finite, or
    /// the one most responsible when `m l^2` (which the motion divides by) or `m g l` leaves
    /// the range of `T`.
    pub fn new(mass: T, length: T, gravity: T) -> Result<Self, Error> {
        let mass = validate::positive("mass", mass)?;
        let length = validate::positive("length", length)?;
        let gravity = validate::non_negative("gravity", gravity)?;
        let m = ("mass", mass, 1);
        validate::divisor(mass * length * length, &[m, ("length", length, 2)])?;
        let g = ("gravity", gravity, 1);
        validate::derived(mass * gravity * length, &[m, g, ("length", length, 1)])?;
        Ok(Self {
            mass,
            length,
            gravity,
        })
    }
    /// Mass, kg.
    #[must_use]
    pub fn mass(&self) -> T {
        self.mass
    }
    /// Length, m.
    #[must_use]
    pub fn length(&self) -> T {
        self.length
    }
    /// Gravity, m/s^2.
    #[must_use]
    pub fn gravity(&self) -> T {
        self.gravity
    }
    /// The conserved momentum conjugate to the azimuth, `p_phi = m l^2 sin^2 th phi'`
    /// (kg m^2/s): the angular momentum about the vertical axis through the pivot. (No error
    /// channel: NaN or infinite for a state that is not finite or so extreme that it
    /// overflows.)
    #[must_use]
    pub fn angular_momentum(&self, s: &State<T, 2>) -> T {
        let sin = s.q[0].sin();
        self.inertia() * sin * sin * s.qd[1]
    }
    /// `m l^2`.
    fn inertia(&self) -> T {
        self.mass * self.length * self.length
    }
}

impl<T: Real> Mechanism<T, 2> for SphericalPendulum<T> {
    fn mass_matrix(&self, s: &State<T, 2>) -> Matrix2<T> {
        let sin = s.q[0].sin();
        let i = self.inertia();
        Matrix2::new(i, T::zero(), T::zero(), i * sin * sin)
    }
    fn rhs(&self, s: &State<T, 2>) -> Vector2<T> {
        let (sin, cos) = s.q[0].sin_cos();
        let (thd, phid) = (s.qd[0], s.qd[1]);
        let i = self.inertia();
        Vector2::new(
            i * sin * cos * phid * phid - self.mass * self.gravity * self.length * sin,
            -T::TWO * i * sin * cos * thd * phid,
        )
    }
    fn solve_mass(&self, s: &State<T, 2>, b: &Vector2<T>) -> Result<Vector2<T>, Error> {
        let sin = s.q[0].sin();
        let i = self.inertia();
        solve_diagonal2(s, [i, i * sin * sin], b, ON_AXIS)
    }
    fn law_force<F: GeneralizedForce<T, 2>>(
        &self,
        s: &State<T, 2>,
        extra: &F,
    ) -> Result<SVector<T, 2>, Error> {
        free_law_force(self, s, extra)
    }
}

impl<T: Real> Lagrangian<T, 2> for SphericalPendulum<T> {
    const READS_TIME: bool = false;
    /// `m |v|^2 / 2` with the Cartesian velocity of the mass.
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 2>, qd: &SVector<S, 2>) -> S {
        let (st, ct) = q[0].sin_cos();
        let (sp, cp) = q[1].sin_cos();
        let (thd, phid) = (qd[0], qd[1]);
        let vx = ct * cp * thd - st * sp * phid;
        let vy = st * thd;
        let vz = ct * sp * thd + st * cp * phid;
        S::from_real(T::HALF * self.inertia()) * (vx * vx + vy * vy + vz * vz)
    }
    /// `m g y` with `y = -l cos th`.
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 2>) -> S {
        -S::from_real(self.mass * self.gravity * self.length) * q[0].cos()
    }
}
