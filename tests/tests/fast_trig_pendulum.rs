//! The origin's pendulum in `f32` with the default pure-`f32` sine (`fast_trig`) against the
//! same pendulum with `libm::sinf`: the error against the exact Jacobi solution must be no
//! worse.

use lagrange_cases::LibmTrigPendulum;
use lagrange_core::{Error, Mechanism, State};
use lagrange_integrators::{Integrator, Rk4, VelocityVerlet};
use lagrange_systems::exact::pendulum_from_rest;
use lagrange_systems::SimplePendulum;
use lagrange_tests::state_error;

const G: f64 = 9.81;

/// `max(|th - th_exact|, |th' - th'_exact|)` after `steps` steps of `dt` from `th0` at rest.
fn error<M: Mechanism<f32, 1>, I: Integrator<f32, 1, M>>(
    m: &M,
    mut integrator: I,
    th0: f64,
    dt: f64,
    steps: u64,
) -> Result<f64, Error> {
    let h = dt as f32;
    let end = integrator.integrate(m, &State::at_rest([th0 as f32]), h, steps)?;
    // The exact solution from the f32 start after the time actually stepped (the f32 clock
    // `end.t` drifts by its own rounding), so that only the stepping is measured.
    let elapsed = steps as f64 * f64::from(h);
    let (th, thd) = pendulum_from_rest(f64::from(th0 as f32), G.sqrt(), elapsed)?;
    Ok(state_error(&end, &[th, thd]))
}

/// The origin's pendulum (30 degrees, RK4 and velocity Verlet at 1 ms for 10 s): the error
/// with the pure-`f32` sine is no worse than with `libm::sinf`. Measured: RK4 1.243e-6 with
/// both (identical trajectories), velocity Verlet 1.769e-5 against 1.889e-5.
#[test]
fn origin_pendulum_no_worse_than_with_libm() -> Result<(), Error> {
    let p = SimplePendulum::new(1.0_f32, 1.0, G as f32, 0.0)?;
    let libm = LibmTrigPendulum(p);
    let th0 = core::f64::consts::FRAC_PI_6;
    let (fast, slow) = (
        error(&p, Rk4, th0, 1e-3, 10_000)?,
        error(&libm, Rk4, th0, 1e-3, 10_000)?,
    );
    println!("RK4: fast_trig {fast:.3e}, libm {slow:.3e}");
    assert!(fast <= slow, "RK4: fast_trig {fast:e}, libm {slow:e}");
    let (fast, slow) = (
        error(&p, VelocityVerlet, th0, 1e-3, 10_000)?,
        error(&libm, VelocityVerlet, th0, 1e-3, 10_000)?,
    );
    println!("velocity Verlet: fast_trig {fast:.3e}, libm {slow:.3e}");
    assert!(
        fast <= slow,
        "velocity Verlet: fast_trig {fast:e}, libm {slow:e}"
    );
    Ok(())
}

/// Over 60 release angles from 3 to 177 degrees (arguments up to pi, so the medium-range
/// reduction runs), RK4 and velocity Verlet at 1 ms for 10 s: the geometric mean over the runs
/// of (error with the pure-`f32` sine) / (error with `libm::sinf`) is at most 1.1. In `f32` the
/// error at 1 ms is mostly rounding, a random walk that any one-ulp difference in a sine
/// re-draws, so single runs differ both ways by factors up to 7 (near the separatrix); the
/// geometric mean weighs every run alike. Measured: 0.976 for RK4, 0.921 for velocity Verlet.
#[test]
fn fast_trig_keeps_the_pendulums_accuracy() -> Result<(), Error> {
    let p = SimplePendulum::new(1.0_f32, 1.0, G as f32, 0.0)?;
    let libm = LibmTrigPendulum(p);
    let mut log_ratio = [0.0; 2];
    let angles = 60;
    for i in 0..angles {
        let th0 = f64::to_radians(3.0 + 174.0 * f64::from(i) / f64::from(angles - 1));
        log_ratio[0] +=
            (error(&p, Rk4, th0, 1e-3, 10_000)? / error(&libm, Rk4, th0, 1e-3, 10_000)?).ln();
        log_ratio[1] += (error(&p, VelocityVerlet, th0, 1e-3, 10_000)?
            / error(&libm, VelocityVerlet, th0, 1e-3, 10_000)?)
        .ln();
    }
    for (k, name) in ["RK4", "velocity Verlet"].iter().enumerate() {
        let ratio = (log_ratio[k] / f64::from(angles)).exp();
        println!("{name}: geometric mean of error(fast_trig) / error(libm) = {ratio:.3}");
        assert!(
            ratio <= 1.1,
            "{name}: fast_trig is {ratio:.3} times as far off"
        );
    }
    Ok(())
}
