//! [`Kepler`]: a unit mass orbiting a fixed centre of inverse-square attraction.

use crate::small_solve::{positive_radius, radial_accelerations, solve_diagonal2};
use lagrange_core::nalgebra::{Matrix2, SVector, Vector2};
use lagrange_core::{
    free_law_force, validate, Error, GeneralizedForce, Lagrangian, Mechanism, Real, Scalar, State,
};

/// What [`Kepler`] reports at `r <= 0`.
const AT_CENTRE: &str = "radius r <= 0: orbiting body at the centre of attraction";

/// The Kepler problem: a body of unit mass in the plane, attracted to a fixed centre at the
/// origin with gravitational parameter `mu`, in polar coordinates.
///
/// ```text
/// q = [r, phi]   r: distance from the centre (> 0); phi: polar angle, rad (unwrapped)
/// T = (r'^2 + r^2 phi'^2) / 2
/// V = -mu / r
///
/// M = diag(1, r^2)
/// f = | r phi'^2 - mu / r^2 |
///     | -2 r r' phi'        |
/// r''   = r phi'^2 - mu / r^2
/// phi'' = -2 r' phi' / r
/// ```
///
/// Parameter: `mu = G M`, length^3/time^2 (with unit mass the energy is per unit mass). `phi`
/// is cyclic, so besides the energy `E = T + V` the angular momentum `h = r^2 phi'`
/// ([`Kepler::angular_momentum`]) is conserved. A bound orbit (`E < 0`) has semi-major axis
/// `a = -mu / (2 E)`, period `2 pi sqrt(a^3 / mu)` and eccentricity
/// `e = sqrt(1 + 2 E h^2 / mu^2)`; [`exact::kepler_orbit`](crate::exact::kepler_orbit) gives
/// its exact motion through Kepler's equation.
///
/// Singular configurations: the centre, `r = 0` (collision: `V` and `M^-1` blow up, `phi` is
/// undefined), and `r < 0`, outside the coordinates. There [`Mechanism::acceleration`] returns
/// [`Error::Singularity`], as it does where `r` is so small that `q''` overflows. A close
/// periapsis passage needs a step much smaller than `r / |v|` there.
///
/// ```
/// use lagrange_core::prelude::*;
/// use lagrange_systems::Kepler;
/// let k = Kepler::new(1.0)?;
/// // A circular orbit of radius 2: phi'^2 = mu / r^3, no radial acceleration.
/// let s = State::new(0.0, [2.0, 0.0], [0.0, (1.0f64 / 8.0).sqrt()]);
/// let a = k.acceleration(&s)?;
/// assert!(a[0].abs() < 1e-16 && a[1] == 0.0);
/// assert!((k.energy(&s) + 0.25).abs() < 1e-15);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Kepler<T: Real> {
    mu: T,
}

impl<T: Real> Kepler<T> {
    /// The Kepler problem with gravitational parameter `mu` (> 0).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `mu` when not positive and finite.
    pub fn new(mu: T) -> Result<Self, Error> {
        Ok(Self {
            mu: validate::positive("mu", mu)?,
        })
    }
    /// The gravitational parameter.
    #[must_use]
    pub fn mu(&self) -> T {
        self.mu
    }
    /// The conserved angular momentum per unit mass, `h = r^2 phi'`. (No error channel: NaN
    /// or infinite for a state that is not finite or so extreme that it overflows.)
    #[must_use]
    pub fn angular_momentum(&self, s: &State<T, 2>) -> T {
        s.q[0] * s.q[0] * s.qd[1]
    }
}

impl<T: Real> Mechanism<T, 2> for Kepler<T> {
    fn mass_matrix(&self, s: &State<T, 2>) -> Matrix2<T> {
        let r = s.q[0];
        Matrix2::new(T::one(), T::zero(), T::zero(), r * r)
    }
    #[inline]
    fn rhs(&self, s: &State<T, 2>) -> Vector2<T> {
        let (r, rd, phid) = (s.q[0], s.qd[0], s.qd[1]);
        Vector2::new(r * phid * phid - self.mu / (r * r), -T::TWO * r * rd * phid)
    }
    #[inline]
    fn solve_mass(&self, s: &State<T, 2>, b: &Vector2<T>) -> Result<Vector2<T>, Error> {
        let r = s.q[0];
        positive_radius(s, AT_CENTRE)?;
        solve_diagonal2(s, [T::one(), r * r], b, AT_CENTRE)
    }
    /// The closed form `r'' = r phi'^2 - mu / r^2`, `phi'' = -2 r' phi' / r` (`M^-1 f`, `r`
    /// cancelled), plus `M^-1` of the extra force: as the elastic pendulum's, one division
    /// fewer than through `M^-1 (f + Q + extra)` and one test of the result rather than of the
    /// state first. Inlined into the integrators' stages: out of line, the call and the result
    /// passed through memory kept the RK4 step above the hand-written loop's (as for
    /// [`DoublePendulum`](crate::DoublePendulum)).
    #[inline(always)]
    fn law<F: GeneralizedForce<T, 2>>(
        &self,
        s: &State<T, 2>,
        extra: &F,
    ) -> Result<SVector<T, 2>, Error> {
        let (r, rd, phid) = (s.q[0], s.qd[0], s.qd[1]);
        let r2 = r * r;
        let mut qdd = Vector2::new(r * phid * phid - self.mu / r2, -T::TWO * rd * phid / r);
        if !F::IS_ZERO {
            let e = extra.force(s);
            qdd += Vector2::new(e[0], e[1] / r2);
        }
        radial_accelerations(s, qdd, r2, AT_CENTRE)
    }
    fn law_force<F: GeneralizedForce<T, 2>>(
        &self,
        s: &State<T, 2>,
        extra: &F,
    ) -> Result<SVector<T, 2>, Error> {
        // The law refuses r <= 0, and so does its force.
        positive_radius(s, AT_CENTRE)?;
        free_law_force(self, s, extra)
    }
}

impl<T: Real> Lagrangian<T, 2> for Kepler<T> {
    const READS_TIME: bool = false;
    /// `|v|^2 / 2` with the Cartesian velocity `d/dt (r cos phi, r sin phi)`.
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 2>, qd: &SVector<S, 2>) -> S {
        let (r, rd, phid) = (q[0], qd[0], qd[1]);
        let (sin, cos) = q[1].sin_cos();
        let vx = rd * cos - r * sin * phid;
        let vy = rd * sin + r * cos * phid;
        S::from_f64(0.5) * (vx * vx + vy * vy)
    }
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 2>) -> S {
        -S::from_real(self.mu) / q[0]
    }
}
