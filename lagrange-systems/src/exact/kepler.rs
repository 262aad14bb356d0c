//! Exact Kepler orbits: Kepler's equation solved by Newton's method.

use lagrange_core::{validate, Error, Real, State};

/// Newton iterations allowed for Kepler's equation: far more than the handful that quadratic
/// convergence needs from the starting guess used (the tests cover `e` up to 0.999).
const MAX_NEWTON_STEPS: u32 = 50;

/// The eccentric anomaly `E` solving Kepler's equation `E - e sin E = M` for a mean anomaly `M`
/// and eccentricity `0 <= e < 1`, by Newton's method from `E = M + e sin M` (or from `pi` for
/// large `e`), after reducing `M` to `[-pi, pi]`; the result is shifted back by the same whole
/// turns, so `E` is continuous in `M`.
///
/// Converges when the residual is at the rounding level of `E - e sin E - M`.
///
/// # Errors
/// [`Error::InvalidParameter`] `eccentricity` outside `[0, 1)` or `mean_anomaly` not finite;
/// [`Error::NoConvergence`] if Newton's method has not converged after its iteration limit.
///
/// ```
/// use lagrange_systems::exact::eccentric_anomaly;
/// let e = eccentric_anomaly(1.0_f64, 0.5)?;
/// assert!((e - 0.5 * e.sin() - 1.0).abs() < 1e-15);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
pub fn eccentric_anomaly<T: Real>(mean_anomaly: T, eccentricity: T) -> Result<T, Error> {
    let e = eccentricity_in_range(eccentricity)?;
    let m_total = validate::finite("mean_anomaly", mean_anomaly)?;
    let two_pi = T::TWO * T::PI;
    let turns = (m_total / two_pi).round();
    let m = m_total - turns * two_pi;
    let mut big_e = if e < T::from_f64(0.8) {
        m + e * m.sin()
    } else if m < T::zero() {
        -T::PI
    } else {
        T::PI
    };
    let tolerance = T::from_f64(4.0) * T::EPSILON * (T::PI + T::one());
    for _ in 0..MAX_NEWTON_STEPS {
        let (sin, cos) = big_e.sin_cos();
        let residual = big_e - e * sin - m;
        big_e -= residual / (T::one() - e * cos);
        if residual.abs() <= tolerance {
            return Ok(big_e + turns * two_pi);
        }
    }
    Err(Error::NoConvergence {
        iterations: MAX_NEWTON_STEPS,
    })
}

/// `e` when it is a valid eccentricity of a bound orbit.
fn eccentricity_in_range<T: Real>(e: T) -> Result<T, Error> {
    if e.is_finite() && e >= T::zero() && e < T::one() {
        Ok(e)
    } else {
        Err(Error::InvalidParameter {
            name: "eccentricity",
            reason: "must be in [0, 1) (a bound orbit)",
        })
    }
}

/// The exact state at time `t` of the [`Kepler`](crate::Kepler) problem on the bound orbit of
/// gravitational parameter `mu`, semi-major axis `a` and eccentricity `e`, at periapsis on the
/// `phi = 0` axis at `t = 0` and moving with `phi` increasing:
///
/// ```text
/// n = sqrt(mu / a^3)                    (mean motion; period 2 pi / n)
/// E - e sin E = n t                     (Kepler's equation, eccentric anomaly E)
/// r    = a (1 - e cos E)
/// phi  = 2 atan2(sqrt(1 + e) sin(E/2), sqrt(1 - e) cos(E/2))   (unwrapped: phi(t) is continuous)
/// r'   = sqrt(mu a) e sin E / r
/// phi' = sqrt(mu a (1 - e^2)) / r^2
/// ```
///
/// The start state is `r = a (1 - e)`, `phi = 0`, `r' = 0`,
/// `phi' = sqrt(mu (1 + e) / (a (1 - e))) / (a (1 - e))`.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `mu` or `semi_major_axis` (not > 0), `eccentricity`
/// (outside `[0, 1)`) or `t` (not finite), or the one most responsible when the mean motion
/// `n`, the mean anomaly `n t` or `mu a` leaves the range of `T`; [`Error::NoConvergence`] as
/// [`eccentric_anomaly`]; [`Error::NonFiniteState`] when the state overflows (`phi'` near
/// the periapsis of a tiny, very eccentric orbit).
///
/// ```
/// use lagrange_systems::exact::kepler_orbit;
/// // Problem P4: mu = 1, a = 1, e = 0.5; after one period the body is back at periapsis.
/// let s = kepler_orbit(1.0_f64, 1.0, 0.5, 2.0 * core::f64::consts::PI)?;
/// assert!((s.q[0] - 0.5).abs() < 1e-14 && (s.q[1] - 2.0 * core::f64::consts::PI).abs() < 1e-14);
/// assert!((s.qd[1] - 12.0f64.sqrt()).abs() < 1e-13);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
pub fn kepler_orbit<T: Real>(
    mu: T,
    semi_major_axis: T,
    eccentricity: T,
    t: T,
) -> Result<State<T, 2>, Error> {
    let mu = validate::positive("mu", mu)?;
    let a = validate::positive("semi_major_axis", semi_major_axis)?;
    let e = eccentricity_in_range(eccentricity)?;
    let t = validate::finite("t", t)?;
    // The mean motion n = sqrt(mu / a^3) and the mean anomaly n t, blamed on their factors
    // (powers doubled: n^2 = mu a^-3).
    let (fmu, fa) = (("mu", mu, 1), ("semi_major_axis", a, 3));
    let cube = validate::derived(a * a * a, &[fa])?;
    let n = validate::divisor((mu / cube).sqrt(), &[fmu, ("semi_major_axis", a, -3)])?;
    let mean_anomaly = validate::derived(n * t, &[fmu, ("semi_major_axis", a, -3), ("t", t, 2)])?;
    validate::derived(mu * a, &[("mu", mu, 1), ("semi_major_axis", a, 1)])?;
    let big_e = eccentric_anomaly(mean_anomaly, e)?;
    let (sin, cos) = big_e.sin_cos();
    let r = a * (T::one() - e * cos);
    // E/2 is in [-pi/2, pi/2] after removing whole turns, so atan2 needs no branch fix-up;
    // the turns are added back to phi.
    let two_pi = T::TWO * T::PI;
    let turns = (big_e / two_pi).round();
    let half = T::HALF * (big_e - turns * two_pi);
    let (sh, ch) = half.sin_cos();
    let phi =
        T::TWO * ((T::one() + e).sqrt() * sh).atan2((T::one() - e).sqrt() * ch) + turns * two_pi;
    let rd = (mu * a).sqrt() * e * sin / r;
    let phid = (mu * a * (T::one() - e * e)).sqrt() / (r * r);
    let s = State::new(t, [r, phi], [rd, phid]);
    // What is left to overflow is r^2 near periapsis of a tiny, very eccentric orbit.
    s.check_finite().map(|()| s)
}
