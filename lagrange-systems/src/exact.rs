//! Exact solutions used as references: the large-amplitude pendulum through Jacobi elliptic
//! functions, computed by the arithmetic-geometric mean; the damped oscillator
//! ([`damped_oscillator`]) and the same driven by `F0 cos(w t)` ([`DrivenOscillator`]); Kepler
//! orbits through Kepler's equation ([`kepler_orbit`]).

use lagrange_core::{validate, Error, Real};

/// Most AGM steps ever needed: convergence is quadratic, so 8 suffice in f64 for `k < 1 - 1e-15`.
const MAX_AGM_STEPS: usize = 16;

/// The complete elliptic integral of the first kind `K(k)` for modulus `0 <= k < 1`.
///
/// # Errors
/// [`Error::InvalidParameter`] `k` outside `[0, 1)`.
pub fn elliptic_k<T: Real>(k: T) -> Result<T, Error> {
    let k = modulus(k)?;
    let (a, _, _) = agm(k);
    Ok(T::PI / (T::TWO * a[a.len() - 1]))
}

/// Jacobi elliptic functions `(sn(u, k), cn(u, k))` for modulus `0 <= k < 1`, by the descending
/// Landen (AGM) scheme.
///
/// # Errors
/// [`Error::InvalidParameter`] `k` outside `[0, 1)`, or `u` not finite or so large that the
/// scheme's phase `2^n a_n u` overflows.
pub fn jacobi_sn_cn<T: Real>(u: T, k: T) -> Result<(T, T), Error> {
    let k = modulus(k)?;
    let u = validate::finite("u", u)?;
    sn_cn(u, k).ok_or(Error::InvalidParameter {
        name: "u",
        reason: "so large that the phase 2^n a_n u of the Landen scheme overflows",
    })
}

/// `(sn(u, k), cn(u, k))` for a valid modulus and a finite `u`; `None` when the phase of the
/// Landen scheme overflows.
fn sn_cn<T: Real>(u: T, k: T) -> Option<(T, T)> {
    let (a, c, n) = agm(k);
    // phi_n = 2^n a_n u, then phi_{j-1} = (phi_j + asin(c_j / a_j sin phi_j)) / 2.
    let mut phi = u * a[n] * T::TWO.powi(i32::try_from(n).unwrap_or(0));
    if !phi.is_finite() {
        return None;
    }
    for j in (1..=n).rev() {
        phi = T::HALF * (phi + (c[j] / a[j] * phi.sin()).asin());
    }
    let (sn, cn) = phi.sin_cos();
    (sn.is_finite() && cn.is_finite()).then_some((sn, cn))
}

/// `k` when it is a valid modulus.
fn modulus<T: Real>(k: T) -> Result<T, Error> {
    if k.is_finite() && k >= T::zero() && k < T::one() {
        Ok(k)
    } else {
        Err(Error::InvalidParameter {
            name: "k",
            reason: "elliptic modulus must be in [0, 1)",
        })
    }
}

/// The AGM sequences `a_j`, `c_j` of `(1, sqrt(1 - k^2))` and the index `n` of the last step.
/// `a` is filled from `n` on with `a_n`, so `a[len - 1]` is the mean.
fn agm<T: Real>(k: T) -> ([T; MAX_AGM_STEPS], [T; MAX_AGM_STEPS], usize) {
    let mut a = [T::one(); MAX_AGM_STEPS];
    let mut c = [T::zero(); MAX_AGM_STEPS];
    let mut b = (T::one() - k * k).sqrt();
    c[0] = k;
    let mut n = 0;
    while n + 1 < MAX_AGM_STEPS && c[n].abs() > T::EPSILON * a[n] {
        a[n + 1] = T::HALF * (a[n] + b);
        c[n + 1] = T::HALF * (a[n] - b);
        b = (a[n] * b).sqrt();
        n += 1;
    }
    for j in n + 1..MAX_AGM_STEPS {
        a[j] = a[n];
    }
    (a, c, n)
}

/// The exact motion of an undamped pendulum released from rest at `theta0` (`|theta0| < pi`)
/// with small-angle frequency `omega = sqrt(g / l)`: `(th(t), th'(t))` with
///
/// ```text
/// th(t)  = 2 asin(k sn(K(k) - omega t, k))
/// th'(t) = -2 k omega cn(K(k) - omega t, k),     k = sin(theta0 / 2)
/// ```
///
/// # Errors
/// [`Error::InvalidParameter`] for `|theta0| >= pi` (or so close to `pi` that the modulus
/// rounds to 1), `omega <= 0` or a non-finite argument; `omega` or `t` when the phase
/// `omega t` overflows (the one most responsible), `omega` when the rate `2 omega` does.
///
/// ```
/// use lagrange_systems::exact::pendulum_from_rest;
/// let (th, thd) = pendulum_from_rest(core::f64::consts::FRAC_PI_6, 9.81f64.sqrt(), 10.0)?;
/// assert!((th - 0.42364451550064823946757401794).abs() < 1e-13);
/// assert!((thd - 0.94557421856406366991857838953).abs() < 1e-13);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
pub fn pendulum_from_rest<T: Real>(theta0: T, omega: T, t: T) -> Result<(T, T), Error> {
    let (k, omega) = amplitude(theta0, omega)?;
    let t = validate::finite("t", t)?;
    // th' is at most 2 omega; the phase K - omega t must stay finite.
    validate::derived(T::TWO * omega, &[("omega", omega, 1)])?;
    let phase = [("omega", omega, 1), ("t", t, 1)];
    let u = validate::derived(elliptic_k(k.abs())? - omega * t, &phase)?;
    let (sn, cn) = sn_cn(u, k.abs()).ok_or_else(|| validate::overflowed(&phase))?;
    // For a negative start the motion is the mirror image.
    Ok((T::TWO * (k * sn).asin(), -T::TWO * k * omega * cn))
}

/// `(sin(theta0 / 2), omega)` when `theta0` is an amplitude strictly between `-pi`
/// and `pi` whose modulus `sin(theta0 / 2)` is below 1 in magnitude, and `omega > 0`.
fn amplitude<T: Real>(theta0: T, omega: T) -> Result<(T, T), Error> {
    let omega = validate::positive("omega", omega)?;
    let theta0 = validate::finite("theta0", theta0)?;
    if theta0.abs() >= T::PI {
        return Err(Error::InvalidParameter {
            name: "theta0",
            reason: "must be strictly between -pi and pi (a rotating or inverted start)",
        });
    }
    let k = (T::HALF * theta0).sin();
    if k.abs() >= T::one() {
        return Err(Error::InvalidParameter {
            name: "theta0",
            reason: "so close to pi that the modulus sin(theta0 / 2) rounds to 1",
        });
    }
    Ok((k, omega))
}

/// The period `4 K(sin(theta0/2)) / omega` of a pendulum of amplitude `theta0`.
///
/// # Errors
/// [`Error::InvalidParameter`] for `|theta0| >= pi` (or so close to `pi` that the modulus
/// rounds to 1), `omega <= 0`, a non-finite argument, or `omega` so small that the period
/// overflows.
pub fn pendulum_period<T: Real>(theta0: T, omega: T) -> Result<T, Error> {
    let (k, omega) = amplitude(theta0, omega)?;
    let period = T::from_f64(4.0) * elliptic_k(k.abs())? / omega;
    validate::derived(period, &[("omega", omega, -1)])
}

mod damped_oscillator;
mod driven_oscillator;
mod kepler;

pub use damped_oscillator::damped_oscillator;
pub use driven_oscillator::DrivenOscillator;
pub use kepler::{eccentric_anomaly, kepler_orbit};
