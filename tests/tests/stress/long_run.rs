//! Long runs: 10^7 steps of the origin's pendulum (1 m, g = 9.81, 30 degrees at rest) with a
//! symplectic method (velocity Verlet at 1 ms, Yoshida 4 at 10 ms), f32 and f64: the relative
//! energy error stays within a stated bound and does not drift. A 10^5-step version runs in
//! the quick debug pass.

use lagrange_core::{Error, Lagrangian, Real, State};
use lagrange_integrators::{Integrator, StormerVerlet, VelocityVerlet, Yoshida4};
use lagrange_systems::SimplePendulum;
use lagrange_tests::pick;

const G: f64 = 9.81;
const TH0: f64 = core::f64::consts::FRAC_PI_6;
/// A typical fixed step of a game or a firmware loop, s.
const DT: f64 = 1e-3;
/// The run is cut into this many windows to look for drift.
const WINDOWS: u64 = 10;

/// The relative energy error of each window of a run.
struct Windows {
    /// Largest `|E - E0| / E0` in each window.
    max: Vec<f64>,
    /// Mean of `(E - E0) / E0` in each window.
    mean: Vec<f64>,
}

/// `steps` steps of `integrator` from the release state, energy measured in f64 from the
/// widened state (so that f32 runs are judged on their state, not on an f32 energy sum), with
/// `V = 0` at the hanging rest state.
fn energy_windows<T: Real, I: Integrator<T, 1, SimplePendulum<T>>>(
    mut integrator: I,
    dt: f64,
    steps: u64,
) -> Result<Windows, Error> {
    let p = SimplePendulum::new(T::one(), T::one(), T::from_f64(G), T::zero())?;
    let p64 = SimplePendulum::new(1.0, 1.0, G, 0.0)?;
    let widen = |s: &State<T, 1>| State::new(s.t.to_f64(), [s.q[0].to_f64()], [s.qd[0].to_f64()]);
    let rest = p64.energy(&State::at_rest([0.0]));
    let start = State::at_rest([T::from_f64(TH0)]);
    let e0 = p64.energy(&widen(&start)) - rest;
    let mut w = Windows {
        max: Vec::new(),
        mean: Vec::new(),
    };
    let mut s = start;
    for _ in 0..WINDOWS {
        let (mut max, mut sum) = (0.0f64, 0.0);
        s = integrator.integrate_with(&p, &s, T::from_f64(dt), steps / WINDOWS, |x| {
            let e = (p64.energy(&widen(x)) - rest - e0) / e0;
            max = max.max(e.abs());
            sum += e;
        })?;
        w.max.push(max);
        w.mean.push(sum / (steps / WINDOWS) as f64);
    }
    Ok(w)
}

/// Velocity Verlet is symplectic for the pendulum (constant mass matrix, force of `q` only).
///
/// Bound: on a linear oscillator of frequency `w` Stormer-Verlet's energy swings by
/// `(h w)^2 / 4` of itself and never drifts; the pendulum at 30 degrees is softer (mean
/// `w^2` about 2 % below `g / l`), so `(h w)^2 / 4 = 2.45e-6` bounds it: measured 2.398e-6 in
/// f64 at every window of 10^5 and of 10^7 steps. In f32 rounding adds a random walk of about
/// `eps sqrt(n)`: 6e-8 sqrt(10^7) = 1.9e-4 over 10^7 steps (measured max 1.55e-4; 1.4e-5 over
/// 10^5 steps), so the f32 bound is 5e-4.
///
/// Drift: in f64 the largest error of the last window equals the first's to 1e-12, and the
/// window means agree to 7e-11 (10^6-step windows) or 4.2e-8 (10^4-step windows, about five
/// periods, whose means depend on the phase at which they are cut). The drift bound 1e-7 is
/// 2.4 times that phase effect and 1/25 of the energy bound, so a drift of a few percent of
/// the swing over the run fails. In f32 the window means wander with the rounding walk
/// (measured within 1.1e-4 of each other): bound 5e-4.
fn verlet_energy_bounded_without_drift<T: Real>(steps: u64) -> Result<(), Error> {
    let w = energy_windows::<T, _>(VelocityVerlet, DT, steps)?;
    let bound = pick::<T>(5e-4, (DT * DT * G) / 4.0);
    let drift_bound = pick::<T>(5e-4, 1e-7);
    let worst = w.max.iter().copied().fold(0.0, f64::max);
    assert!(
        worst <= bound,
        "max relative energy error {worst:e} > {bound:e}: {:?}",
        w.max
    );
    let (first, last) = (w.mean[0], w.mean[w.mean.len() - 1]);
    assert!(
        (last - first).abs() <= drift_bound,
        "energy drifts: window means {:?}",
        w.mean
    );
    // The swing itself is there (the error is measured, not zero), and in f64 it is the same
    // in the last window as in the first.
    assert!(worst > 0.1 * (DT * DT * G) / 4.0, "{worst:e}");
    if T::EPSILON.to_f64() < 1e-10 {
        let (a, b) = (w.max[0], w.max[w.max.len() - 1]);
        assert!((a - b).abs() <= 1e-9, "window maxima {:?}", w.max);
    }
    Ok(())
}

#[test]
fn verlet_1e5_steps_f32() -> Result<(), Error> {
    verlet_energy_bounded_without_drift::<f32>(100_000)
}

#[test]
fn verlet_1e5_steps_f64() -> Result<(), Error> {
    verlet_energy_bounded_without_drift::<f64>(100_000)
}

#[test]
#[ignore = "long run: cargo xtask ci runs it in release"]
fn verlet_1e7_steps_f32() -> Result<(), Error> {
    verlet_energy_bounded_without_drift::<f32>(10_000_000)
}

#[test]
#[ignore = "long run: cargo xtask ci runs it in release"]
fn verlet_1e7_steps_f64() -> Result<(), Error> {
    verlet_energy_bounded_without_drift::<f64>(10_000_000)
}

/// Yoshida's fourth-order composition of Stormer-Verlet (symplectic here) at a 10 ms game
/// step, `h w = 0.031`. Its energy error is fourth order: measured 7.603e-8 in f64, the same
/// in every window of 10^5 and of 10^7 steps (window maxima within 4e-13 of each other, window
/// means within 1e-12): bound 1e-7, and the maxima of the first and last windows within 1e-10
/// of each other. In f32 rounding dominates: measured max 1.88e-5, window means within
/// 1.4e-5 of each other: bound 1e-4 on both.
fn yoshida_energy_bounded_without_drift<T: Real>(steps: u64) -> Result<(), Error> {
    let w = energy_windows::<T, _>(Yoshida4::new(StormerVerlet::<T, 1>::default()), 1e-2, steps)?;
    let worst = w.max.iter().copied().fold(0.0, f64::max);
    let bound = pick::<T>(1e-4, 1e-7);
    assert!(
        worst <= bound,
        "max relative energy error {worst:e}: {:?}",
        w.max
    );
    let (first, last) = (w.mean[0], w.mean[w.mean.len() - 1]);
    assert!(
        (last - first).abs() <= pick::<T>(1e-4, 1e-10),
        "energy drifts: window means {:?}",
        w.mean
    );
    if T::EPSILON.to_f64() < 1e-10 {
        let (a, b) = (w.max[0], w.max[w.max.len() - 1]);
        assert!((a - b).abs() <= 1e-10, "window maxima {:?}", w.max);
    }
    Ok(())
}

#[test]
fn yoshida_1e5_steps_f32() -> Result<(), Error> {
    yoshida_energy_bounded_without_drift::<f32>(100_000)
}

#[test]
fn yoshida_1e5_steps_f64() -> Result<(), Error> {
    yoshida_energy_bounded_without_drift::<f64>(100_000)
}

#[test]
#[ignore = "long run: cargo xtask ci runs it in release"]
fn yoshida_1e7_steps_f32() -> Result<(), Error> {
    yoshida_energy_bounded_without_drift::<f32>(10_000_000)
}

#[test]
#[ignore = "long run: cargo xtask ci runs it in release"]
fn yoshida_1e7_steps_f64() -> Result<(), Error> {
    yoshida_energy_bounded_without_drift::<f64>(10_000_000)
}
