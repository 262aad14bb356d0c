//! The chaotic double pendulum (P2: unit masses and rods, both angles pi/2 at rest): two runs
//! from starts 1e-12 apart separate exponentially at a finite-time Lyapunov rate in a stated
//! range, and a renormalised (Benettin) estimate over the same window agrees with it; a
//! symplectic (variational) run's energy stays bounded throughout.
//!
//! f64 only: a start separation of 1e-12 rad is below f32's resolution of angles near pi/2
//! (1.2e-7), and an f32 pair would measure its own rounding.

use lagrange_core::{Error, EulerLagrange, Lagrangian, State};
use lagrange_integrators::{Integrator, Rk4, VariationalMidpoint};
use lagrange_systems::DoublePendulum;

/// Start separation, rad (on th1).
const D0: f64 = 1e-12;
/// Step, s: RK4's error per step (about 1e-13 here) is far below any separation used.
const DT: f64 = 1e-3;
/// Horizon, s: the separation reaches order one by about 30 s.
const HORIZON: f64 = 35.0;
/// Sampling interval of the separation, s.
const SAMPLE: f64 = 0.05;
/// The window of exponential growth: above the rounding floor and the start's transient,
/// below saturation at the size of the attractor.
const WINDOW: (f64, f64) = (1e-9, 1e-3);

/// Euclidean distance between two states over angles and rates.
fn distance(a: &State<f64, 2>, b: &State<f64, 2>) -> f64 {
    let (dq, dv) = (a.q - b.q, a.qd - b.qd);
    (dq.dot(&dq) + dv.dot(&dv)).sqrt()
}

fn p2() -> Result<(DoublePendulum<f64>, State<f64, 2>), Error> {
    let h = core::f64::consts::FRAC_PI_2;
    Ok((
        DoublePendulum::new(1.0, 1.0, 1.0, 1.0, 9.81)?,
        State::at_rest([h, h]),
    ))
}

/// `(t, separation)` every `SAMPLE` s of two runs from starts `D0` apart.
fn separation() -> Result<Vec<(f64, f64)>, Error> {
    let (dp, a0) = p2()?;
    let mut b0 = a0;
    b0.q[0] += D0;
    let per = (SAMPLE / DT).round() as u64;
    let (mut a, mut b) = (a0, b0);
    let mut out = Vec::new();
    for _ in 0..(HORIZON / SAMPLE).round() as u64 {
        a = Rk4.integrate(&dp, &a, DT, per)?;
        b = Rk4.integrate(&dp, &b, DT, per)?;
        out.push((a.t, distance(&a, &b)));
    }
    Ok(out)
}

/// Least-squares slope of `ln d` against `t`.
fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (mt, ml) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (t, d)| (a + t / n, b + d.ln() / n));
    let stt: f64 = points.iter().map(|(t, _)| (t - mt) * (t - mt)).sum();
    let stl: f64 = points.iter().map(|(t, d)| (t - mt) * (d.ln() - ml)).sum();
    stl / stt
}

/// Benettin's estimate over `[t0, t1]`: a companion run kept `eps` away, renormalised every
/// `SAMPLE` s, and the mean log growth per second over the window.
fn benettin(t0: f64, t1: f64, eps: f64) -> Result<f64, Error> {
    let (dp, mut a) = p2()?;
    let mut b = a;
    b.q[0] += eps;
    let per = (SAMPLE / DT).round() as u64;
    let mut sum = 0.0;
    let mut span = 0.0;
    while a.t < t1 - 0.5 * SAMPLE {
        a = Rk4.integrate(&dp, &a, DT, per)?;
        b = Rk4.integrate(&dp, &b, DT, per)?;
        let d = distance(&a, &b);
        if a.t > t0 + 0.5 * SAMPLE {
            sum += (d / eps).ln();
            span += SAMPLE;
        }
        // Back to distance eps along the current separation.
        b.q = a.q + (b.q - a.q) * (eps / d);
        b.qd = a.qd + (b.qd - a.qd) * (eps / d);
    }
    Ok(sum / span)
}

/// Measured (dt = 1e-3; dt = 5e-4 gives the same to 4e-5): the separation stays near 1e-11
/// for about 10 s (P2's known transient: 196-fold growth by t = 10, where
/// `shared/BENCH_PROBLEMS.md` says about 140-fold), then grows from 1e-9 at t = 10.95 to 1e-3
/// at t = 24.55 at 1.023 per second. The stated range for that finite-time exponent is
/// [0.8, 1.25] per second: about 20 % either side, where a change of the equations of motion
/// (a sign, a mass term) or of the integration moves it by more. Benettin's renormalised
/// estimate over the same window, which never leaves the linear regime, gives 0.987: the two
/// must agree within 10 % (measured 3.6 %).
#[test]
fn nearby_starts_separate_exponentially() -> Result<(), Error> {
    let sep = separation()?;
    let at_10 = sep
        .iter()
        .find(|(t, _)| (t - 10.0).abs() < 0.5 * SAMPLE)
        .map_or(f64::NAN, |&(_, d)| d / D0);
    assert!((50.0..=500.0).contains(&at_10), "growth by t = 10: {at_10}");
    let window: Vec<(f64, f64)> = sep
        .iter()
        .copied()
        .filter(|&(_, d)| d >= WINDOW.0 && d <= WINDOW.1)
        .collect();
    assert!(
        !window.is_empty(),
        "the separation never enters {WINDOW:?}: {sep:?}"
    );
    let (t0, t1) = (window[0].0, window[window.len() - 1].0);
    assert!(t1 - t0 >= 8.0, "growth window {t0}..{t1} too short to fit");
    let lambda = slope(&window);
    assert!(
        (0.8..=1.25).contains(&lambda),
        "finite-time Lyapunov exponent {lambda}"
    );
    let reference = benettin(t0, t1, 1e-8)?;
    assert!(
        (lambda / reference - 1.0).abs() <= 0.1,
        "two-run slope {lambda} against Benettin {reference}"
    );
    Ok(())
}

/// The largest relative energy error (energy from the hanging rest state) of the variational
/// midpoint integrator on P2 over `steps` steps of `dt`, and the same over the first and last
/// tenths of the run.
fn variational_energy(dt: f64, steps: u64) -> Result<(f64, f64, f64), Error> {
    let (dp, start) = p2()?;
    let system = EulerLagrange::new(dp);
    let rest = dp.energy(&State::at_rest([0.0, 0.0]));
    let e0 = dp.energy(&start) - rest;
    let tenth = steps / 10;
    let (mut first, mut last, mut max, mut k) = (0.0f64, 0.0f64, 0.0f64, 0u64);
    VariationalMidpoint::default().integrate_with(&system, &start, dt, steps, |s| {
        k += 1;
        let e = ((dp.energy(s) - rest - e0) / e0).abs();
        max = max.max(e);
        if k <= tenth {
            first = first.max(e);
        }
        if k > steps - tenth {
            last = last.max(e);
        }
    })?;
    Ok((first, last, max))
}

/// The variational midpoint integrator is symplectic in `(q, p)` for any Lagrangian, here one
/// whose mass matrix depends on `q`, and its energy error stays bounded through the chaotic
/// motion of P2 (E = 3 g, both bobs flung over). Measured at dt = 1e-3: largest relative error
/// 1.9e-5 over 30 s, 2.7e-5 over 1000 s (10^6 steps), where the largest over the last tenth
/// (2.4e-5) is below that over the first (2.6e-5). Bound 1e-4 on the whole run; over 10^6
/// steps the last tenth may not exceed the first by more than 2x (a linear drift gives about
/// 10x). The first tenth of the short run holds too little of the chaotic motion (1.2e-6 there
/// against 1.9e-5 overall) for that comparison.
#[test]
fn variational_energy_bounded_through_chaos() -> Result<(), Error> {
    let (_, _, max) = variational_energy(1e-3, 30_000)?;
    assert!(max <= 1e-4, "max relative energy error {max:e}");
    Ok(())
}

/// The same over 10^6 steps (1000 s of chaotic motion), in release, with the drift test.
#[test]
#[ignore = "long run: cargo xtask ci runs it in release"]
fn variational_energy_bounded_through_1e6_chaotic_steps() -> Result<(), Error> {
    let (first, last, max) = variational_energy(1e-3, 1_000_000)?;
    assert!(max <= 1e-4, "max relative energy error {max:e}");
    assert!(
        last <= 2.0 * first,
        "energy drifts: first tenth {first:e}, last {last:e}"
    );
    Ok(())
}
