//! The exact solutions every integrator is measured against, checked on their own: each
//! satisfies its differential equation (its velocity is the derivative of its position, its
//! acceleration the law's, by central differences), its start, and its invariants, on every
//! branch of its formula; the elliptic functions at known values and identities.

use lagrange_core::Error;
use lagrange_systems::exact::{
    damped_oscillator, eccentric_anomaly, elliptic_k, jacobi_sn_cn, kepler_orbit,
    pendulum_from_rest, pendulum_period,
};
use std::f64::consts::{FRAC_PI_2, PI};

/// Central-difference step for the derivatives of a solution: `EPSILON^(1/3)` scaled, where
/// truncation and rounding balance.
const H: f64 = 1e-5;

/// Central differences of a smooth solution with `H`: good to about 1e-9 of its scale
/// (truncation `H^2` times the third derivative, rounding `EPSILON / H`).
const DIFFERENCE_TOL: f64 = 1e-8;

/// `f(t)` by central differences.
fn derivative(f: impl Fn(f64) -> Result<f64, Error>, t: f64) -> Result<f64, Error> {
    Ok((f(t + H)? - f(t - H)?) / (2.0 * H))
}

/// `|a - b| <= tol (1 + |b|)`, with the values in the message.
fn close(a: f64, b: f64, tol: f64, what: &str) {
    assert!((a - b).abs() <= tol * (1.0 + b.abs()), "{what}: {a} vs {b}");
}

/// `K(k) = pi / (2 agm(1, sqrt(1 - k^2)))`, by an arithmetic-geometric mean of its own.
fn k_by_agm(k: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, (1.0 - k * k).sqrt());
    for _ in 0..40 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    PI / (2.0 * a)
}

/// `K(0) = pi / 2` and `K(k)` against an AGM of its own (a few ulps), `f32` too; a modulus
/// outside `[0, 1)` is refused.
#[test]
fn the_complete_elliptic_integral() -> Result<(), Error> {
    assert_eq!(elliptic_k(0.0f64)?, FRAC_PI_2);
    for k in [0.1, 0.5, 0.9, 0.999] {
        // The AGM's own rounding and the library's: a few ulps.
        close(elliptic_k(k)?, k_by_agm(k), 8.0 * f64::EPSILON, "K");
        let k32 = elliptic_k(k as f32)?;
        close(
            f64::from(k32),
            k_by_agm(f64::from(k as f32)),
            8.0 * f64::from(f32::EPSILON),
            "K f32",
        );
    }
    for bad in [-0.1, 1.0, f64::NAN] {
        assert!(elliptic_k(bad).is_err());
    }
    Ok(())
}

/// `sn` and `cn`: `sn^2 + cn^2 = 1`, `sn(K) = 1`, `sin` and `cos` at `k = 0`, and `sn' = cn dn`,
/// `cn' = -sn dn` with `dn = sqrt(1 - k^2 sn^2)`.
#[test]
fn the_jacobi_functions() -> Result<(), Error> {
    for u in [-2.0, 0.3, 1.7, 12.0] {
        let (s, c) = jacobi_sn_cn(u, 0.0f64)?;
        close(s, libm::sin(u), 4.0 * f64::EPSILON, "sn at k = 0");
        close(c, libm::cos(u), 4.0 * f64::EPSILON, "cn at k = 0");
    }
    for k in [0.3, 0.8, 0.99] {
        let quarter = elliptic_k(k)?;
        let (s, c) = jacobi_sn_cn(quarter, k)?;
        close(s, 1.0, 1e-14, "sn(K)");
        assert!(c.abs() < 1e-7, "cn(K) = {c}");
        for u in [-1.3, 0.2, 0.9, 2.5, 7.0] {
            let (s, c) = jacobi_sn_cn(u, k)?;
            close(s * s + c * c, 1.0, 4.0 * f64::EPSILON, "sn^2 + cn^2");
            let dn = (1.0 - k * k * s * s).sqrt();
            let ds = derivative(|u| jacobi_sn_cn(u, k).map(|p| p.0), u)?;
            let dc = derivative(|u| jacobi_sn_cn(u, k).map(|p| p.1), u)?;
            close(ds, c * dn, DIFFERENCE_TOL, "sn'");
            close(dc, -s * dn, DIFFERENCE_TOL, "cn'");
        }
    }
    // Far out in f32 (u = 1e35): the Landen scheme scales u by 2^n for its n steps, few
    // where the AGM has converged (4 at k = 0.5, none at 0), so the phase stays finite.
    for k in [0.0f32, 0.5] {
        let (s, c) = jacobi_sn_cn(1e35f32, k)?;
        // One rounding of each: a few ulps of f32.
        close(
            f64::from(s * s + c * c),
            1.0,
            4.0 * f64::from(f32::EPSILON),
            "far out",
        );
    }
    assert!(jacobi_sn_cn(f64::NAN, 0.5).is_err());
    assert!(jacobi_sn_cn(1.0, 1.0).is_err());
    Ok(())
}

/// The pendulum let go from rest at `theta0`: starts there at rest, keeps its energy
/// `theta'^2 / 2 - w^2 cos theta`, obeys `theta'' = -w^2 sin theta`, and its period is the
/// one `pendulum_period` gives: zero at a quarter, `-theta0` at half, back at a whole.
#[test]
fn the_pendulum_from_rest() -> Result<(), Error> {
    for (theta0, w) in [(0.3, 1.0), (-1.2, 3.1), (2.9, 0.7)] {
        let (th, thd) = pendulum_from_rest(theta0, w, 0.0)?;
        close(th, theta0, 1e-14, "start");
        assert!(thd.abs() < 1e-14 * w, "start at rest: {thd}");
        let energy = -w * w * libm::cos(theta0);
        let period = pendulum_period(theta0, w)?;
        for t in [0.37, 1.9, 4.4, 11.0] {
            let (th, thd) = pendulum_from_rest(theta0, w, t)?;
            // Energy to a few ulps of w^2, scaled by the elliptic functions' rounding.
            close(
                0.5 * thd * thd - w * w * libm::cos(th),
                energy,
                1e-13 * w * w,
                "energy",
            );
            let v = derivative(|t| pendulum_from_rest(theta0, w, t).map(|p| p.0), t)?;
            close(v, thd, DIFFERENCE_TOL * w, "theta'");
            let a = derivative(|t| pendulum_from_rest(theta0, w, t).map(|p| p.1), t)?;
            close(a, -w * w * libm::sin(th), DIFFERENCE_TOL * w * w, "theta''");
        }
        // The quarter, half and whole period: a few ulps of the amplitude.
        let at = |t: f64| pendulum_from_rest(theta0, w, t).map(|p| p.0);
        assert!(at(0.25 * period)?.abs() < 1e-12, "quarter");
        close(at(0.5 * period)?, -theta0, 1e-12, "half");
        close(at(period)?, theta0, 1e-12, "whole");
    }
    // The small-angle limit: 2 pi / w.
    close(pendulum_period(1e-4, 2.0)?, PI, 1e-8, "small-angle period");
    for bad in [PI, -4.0, f64::NAN] {
        assert!(pendulum_from_rest(bad, 1.0, 0.5).is_err());
        assert!(pendulum_period(bad, 1.0).is_err());
    }
    assert!(pendulum_from_rest(0.5, -1.0, 0.5).is_err());
    Ok(())
}

/// The damped oscillator on each branch of its formula (the series near `lambda t^2 = 0`,
/// under-, critically and overdamped): starts at `(x0, v0)`, its velocity is `x'`, and
/// `m x'' + c x' + k x = 0`.
#[test]
fn the_damped_oscillator() -> Result<(), Error> {
    // (m, k, c): underdamped, critically damped, overdamped, a free particle, no damping.
    for (m, k, c) in [
        (1.0, 4.0, 0.5),
        (2.0, 8.0, 8.0),
        (1.0, 4.0, 10.0),
        (0.5, 0.0, 0.0),
        (1.5, 6.0, 0.0),
    ] {
        let (x0, v0) = (0.7, -1.3);
        let (x, v) = damped_oscillator(m, k, c, x0, v0, 0.0)?;
        close(x, x0, 1e-15, "x(0)");
        close(v, v0, 1e-15, "v(0)");
        // t from inside the series' reach to well outside it.
        for t in [0.05, 0.3, 1.1, 3.7] {
            let (x, v) = damped_oscillator(m, k, c, x0, v0, t)?;
            let dx = derivative(|t| damped_oscillator(m, k, c, x0, v0, t).map(|p| p.0), t)?;
            let dv = derivative(|t| damped_oscillator(m, k, c, x0, v0, t).map(|p| p.1), t)?;
            close(dx, v, DIFFERENCE_TOL, "x'");
            close(
                m * dv + c * v + k * x,
                0.0,
                DIFFERENCE_TOL * (m + c + k),
                "the law",
            );
        }
    }
    assert!(damped_oscillator(0.0, 1.0, 0.0, 1.0, 0.0, 1.0).is_err());
    assert!(damped_oscillator(1.0, -1.0, 0.0, 1.0, 0.0, 1.0).is_err());
    Ok(())
}

/// Kepler's equation `E - e sin E = M` holds for the eccentric anomaly, on both starts of
/// its Newton iteration (below and above `e = 0.8`) and over several turns of `M`.
#[test]
fn the_eccentric_anomaly() -> Result<(), Error> {
    for e in [0.0, 0.3, 0.79, 0.85, 0.97] {
        for m in [-7.0, -2.0, -0.1, 0.0, 0.4, 3.0, 3.1, 20.0] {
            let big_e = eccentric_anomaly(m, e)?;
            // Newton's tolerance, 4 EPSILON (pi + 1), plus the turns' rounding.
            close(big_e - e * libm::sin(big_e), m, 1e-14, "Kepler's equation");
        }
    }
    for bad in [-0.1, 1.0, f64::NAN] {
        assert!(eccentric_anomaly(1.0, bad).is_err());
    }
    Ok(())
}

/// The Kepler orbit: periapsis at `t = 0`, energy `-mu / 2a` and angular momentum
/// `sqrt(mu a (1 - e^2))` all along, `r'` and `phi'` the derivatives of `r` and `phi`, and a
/// whole turn after a period.
#[test]
fn the_kepler_orbit() -> Result<(), Error> {
    for (mu, a, e) in [
        (1.0, 1.0, 0.5),
        (3.0, 2.5, 0.1),
        (0.7, 0.8, 0.9),
        (1.0, 1.0, 0.0),
    ] {
        let s = kepler_orbit(mu, a, e, 0.0)?;
        close(s.q[0], a * (1.0 - e), 1e-15, "periapsis");
        // Zero but for the rounding of the anomaly's sine.
        assert!(s.q[1].abs() < 1e-15 && s.qd[0].abs() < 1e-15, "{s:?}");
        let period = 2.0 * PI * (a * a * a / mu).sqrt();
        for t in [0.2, 0.45 * period, 1.3 * period, -0.7] {
            let s = kepler_orbit(mu, a, e, t)?;
            let (r, rd, phid) = (s.q[0], s.qd[0], s.qd[1]);
            let energy = 0.5 * (rd * rd + r * r * phid * phid) - mu / r;
            // A few ulps of each term, the eccentric anomaly's tolerance through them.
            close(energy, -mu / (2.0 * a), 1e-13, "energy");
            close(
                r * r * phid,
                (mu * a * (1.0 - e * e)).sqrt(),
                1e-13,
                "angular momentum",
            );
            let dr = derivative(|t| kepler_orbit(mu, a, e, t).map(|s| s.q[0]), t)?;
            let dphi = derivative(|t| kepler_orbit(mu, a, e, t).map(|s| s.q[1]), t)?;
            close(dr, rd, DIFFERENCE_TOL, "r'");
            close(dphi, phid, DIFFERENCE_TOL, "phi'");
        }
        let turn = kepler_orbit(mu, a, e, period)?;
        close(turn.q[0], a * (1.0 - e), 1e-12, "r after a period");
        close(turn.q[1], 2.0 * PI, 1e-12, "phi after a period");
    }
    assert!(kepler_orbit(1.0, 1.0, 1.0, 0.0).is_err());
    assert!(kepler_orbit(-1.0, 1.0, 0.5, 0.0).is_err());
    Ok(())
}

/// A parameter so large or so small that a quantity formed from it overflows is named, with
/// the way it went wrong: the pendulum's rate (its speed scale 2 w), its period (divided by a
/// tiny w), and the oscillator's mass, divided by in k / m and in (c / 2m)^2.
#[test]
fn the_parameter_to_blame_is_named() {
    let named = |e: Result<(f64, f64), Error>| match e {
        Err(Error::InvalidParameter { name, reason }) => Some((name, reason)),
        _ => None,
    };
    let large = "too large: a quantity formed from the parameters overflows";
    let small = "too small: a quantity formed from the parameters (divided by it) overflows";
    assert_eq!(
        named(pendulum_from_rest(0.5, 0.6 * f64::MAX, 0.0)),
        Some(("omega", large))
    );
    assert_eq!(
        named(pendulum_period(0.5, 1e-320).map(|p| (p, p))),
        Some(("omega", small))
    );
    assert_eq!(
        named(damped_oscillator(1e-300, 1e10, 0.0, 1.0, 0.0, 1.0)),
        Some(("mass", small))
    );
    assert_eq!(
        named(damped_oscillator(1e-150, 0.0, 1e10, 1.0, 0.0, 1.0)),
        Some(("mass", small))
    );
}

/// The Kepler orbit names the parameter most responsible when a quantity it forms overflows,
/// by the powers the quantity holds it to. The mean anomaly `n t` (`(n t)^2 = mu a^-3 t^2`)
/// of `mu = 1e-15`, `a = 10^(-320/3)` (its cube a subnormal 1e-320, so that `mu / a^3 =
/// 1e305` and `n = 1e152.5` are finite) and `t = 1e157.5` is 1e310: its logarithm's shares are
/// `mu` -34.5, `a` +736.8 (`a^-3`, the largest), `t` +725.3 (`t^2`), so the error names
/// `semi_major_axis` (too small: it is divided by), not `t`. The product `mu a` under
/// `sqrt(mu a)` (the rates' scale) of `mu = 1e250`, `a = 1e100` overflows (1e350) where `a^3`,
/// `n` and `n t` do not: `mu`, its larger factor, is named, rather than a rate overflowing to
/// a non-finite state.
#[test]
fn the_kepler_orbit_blames_the_factor_most_responsible() {
    let named = |r: Result<lagrange_core::State<f64, 2>, Error>| match r {
        Err(Error::InvalidParameter { name, reason }) => Some((name, reason)),
        _ => None,
    };
    let large = "too large: a quantity formed from the parameters overflows";
    let small = "too small: a quantity formed from the parameters (divided by it) overflows";
    let a = 10f64.powf(-320.0 / 3.0);
    assert!((a * a * a) > 0.0 && (1e-15 / (a * a * a)).is_finite());
    assert_eq!(
        named(kepler_orbit(1e-15, a, 0.5, 10f64.powf(157.5))),
        Some(("semi_major_axis", small))
    );
    assert_eq!(
        named(kepler_orbit(1e250, 1e100, 0.5, 1.0)),
        Some(("mu", large))
    );
}
