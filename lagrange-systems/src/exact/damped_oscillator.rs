//! The exact motion of a linear damped oscillator, in every damping regime.

use lagrange_core::{validate, Error, Real};

/// Terms of the power series of `C` and `S` summed before the remainder is below `EPSILON`:
/// the series is used for `|lambda| t^2 < 1`, where term `n` is below `1 / (2n)!`.
const SERIES_TERMS: usize = 12;

/// The exact state `(x(t), x'(t))` of `m x'' + c x' + k x = 0` from `x(0) = x0`, `x'(0) = v0`
/// (the [`SpringMassDamper`](crate::SpringMassDamper)), for every damping regime:
///
/// ```text
/// gamma = c / (2 m),  w0^2 = k / m,  lambda = w0^2 - gamma^2
/// x(t)  = e^(-gamma t) (x0 C(t) + (v0 + gamma x0) S(t))
/// x'(t) = e^(-gamma t) (v0 C(t) - (gamma v0 + w0^2 x0) S(t))
///
/// under-damped (lambda > 0, w = sqrt(lambda)):   C = cos(w t),   S = sin(w t) / w
/// critically damped (lambda = 0):                 C = 1,          S = t
/// over-damped (lambda < 0, s = sqrt(-lambda)):   C = cosh(s t),  S = sinh(s t) / s
/// ```
///
/// `C` and `S` are one pair of entire functions of `lambda t^2`, so the three cases join
/// smoothly: where `|lambda| t^2 < 1` they are summed as their power series (exact at critical
/// damping, and free of the cancellation `sinh(s t) / s` suffers as `s -> 0`); in the
/// over-damped case the exponentials are combined first, so nothing overflows for large `t`.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `mass` (not > 0), `stiffness` or `damping` (not >= 0),
/// or `x0`, `v0`, `t` (not finite); the one most responsible when a quantity formed from them
/// overflows (`c / (2 m)`, `k / m`, `(c / (2 m))^2`, `v0 + gamma x0`, `gamma v0 + w0^2 x0`),
/// `t` when the phase `w t` does; [`Error::NonFiniteState`] when the state at `t` overflows
/// (a negative time of a damped motion, an over-damped one far back).
///
/// ```
/// use lagrange_systems::exact::damped_oscillator;
/// // Critically damped (c^2 = 4 k m) from x0 = 1 at rest: x = (1 + w0 t) e^(-w0 t).
/// let (x, v) = damped_oscillator(1.0, 4.0, 4.0, 1.0, 0.0, 0.5)?;
/// assert!((x - 2.0 * (-1.0f64).exp()).abs() < 1e-15);
/// assert!((v + 4.0 * 0.5 * (-1.0f64).exp()).abs() < 1e-15);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
pub fn damped_oscillator<T: Real>(
    mass: T,
    stiffness: T,
    damping: T,
    x0: T,
    v0: T,
    t: T,
) -> Result<(T, T), Error> {
    let m = validate::positive("mass", mass)?;
    let k = validate::non_negative("stiffness", stiffness)?;
    let c = validate::non_negative("damping", damping)?;
    let x0 = validate::finite("x0", x0)?;
    let v0 = validate::finite("v0", v0)?;
    let t = validate::finite("t", t)?;
    let f = |name, x, power| (name, x, power);
    let (fm, fc, fk) = (f("mass", m, -1), f("damping", c, 1), f("stiffness", k, 1));
    let gamma = validate::derived(c / (T::TWO * m), &[fc, fm])?;
    let w0_2 = validate::derived(k / m, &[fk, fm])?;
    let gamma_2 = validate::derived(gamma * gamma, &[f("damping", c, 2), f("mass", m, -2)])?;
    let lambda = w0_2 - gamma_2;
    // x = e^(-gamma t) (x0 C + b S), x' = e^(-gamma t) (v0 C - d S).
    let (fx, fv) = (f("x0", x0, 1), f("v0", v0, 1));
    let b = validate::derived(v0 + gamma * x0, &[fv, fc, fm, fx])?;
    let d = validate::derived(gamma * v0 + w0_2 * x0, &[fc, fm, fv, fk, fx])?;
    let z = lambda * t * t;
    let (x, v) = if z.abs() < T::one() {
        let (cc, ss) = series(z, t);
        let decay = (-gamma * t).exp();
        (decay * (x0 * cc + b * ss), decay * (v0 * cc - d * ss))
    } else if lambda > T::zero() {
        let w = lambda.sqrt();
        let phase = w * t;
        if !phase.is_finite() {
            return Err(Error::InvalidParameter {
                name: "t",
                reason: "so large that the phase w t overflows",
            });
        }
        let (sin, cos) = phase.sin_cos();
        let decay = (-gamma * t).exp();
        let ss = sin / w;
        (decay * (x0 * cos + b * ss), decay * (v0 * cos - d * ss))
    } else {
        // e^(-gamma t) cosh(s t) = (e^((s - gamma) t) + e^(-(s + gamma) t)) / 2, and sinh alike.
        let s = (-lambda).sqrt();
        let slow = ((s - gamma) * t).exp() * T::HALF;
        let fast = (-(s + gamma) * t).exp() * T::HALF;
        (
            (x0 + b / s) * slow + (x0 - b / s) * fast,
            (v0 - d / s) * slow + (v0 + d / s) * fast,
        )
    };
    if x.is_finite() && v.is_finite() {
        Ok((x, v))
    } else {
        Err(Error::NonFiniteState)
    }
}

/// `C = sum (-z)^n / (2n)!` and `S = t sum (-z)^n / (2n + 1)!` for `z = lambda t^2`, `|z| < 1`.
fn series<T: Real>(z: T, t: T) -> (T, T) {
    let (mut cc, mut ss) = (T::one(), T::one());
    let (mut term_c, mut term_s) = (T::one(), T::one());
    for n in 1..=SERIES_TERMS {
        let two_n = T::from_f64(2.0 * n as f64);
        term_c = -term_c * z / (two_n * (two_n - T::one()));
        term_s = -term_s * z / (two_n * (two_n + T::one()));
        cc += term_c;
        ss += term_s;
    }
    (cc, t * ss)
}
