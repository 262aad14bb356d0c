//! The spring-mass-damper against the exact damped oscillator, under-, critically and
//! over-damped.

use lagrange_core::{Error, Lagrangian, Real, State};
use lagrange_integrators::{Integrator, Rk4};
use lagrange_systems::exact::damped_oscillator;
use lagrange_systems::SpringMassDamper;
use lagrange_tests::{for_f32_and_f64, pick};

/// `m = 1`, `k = 4` (`w0 = 2`), from `x0 = 1`, `v0 = 0.5`; damping `c` under (`c^2 < 4 k m =
/// 16`), at and over the critical value.
const M: f64 = 1.0;
const K: f64 = 4.0;
const X0: f64 = 1.0;
const V0: f64 = 0.5;
const REGIMES: [(&str, f64); 3] = [
    ("under-damped", 0.4),
    ("critically damped", 4.0),
    ("over-damped", 10.0),
];

/// The exact solution solves the equation: at 200 times over 10 s its five-point central
/// differences (h = 1e-4) give back `x' = v` and `m v' = -k x - c v`. The difference quotients
/// err by `h^4 |x^(5)| / 30 ~ 1e-14` and by rounding `~ eps / h ~ 2e-12`; measured worst
/// 8.5e-12, bound 3e-11. At `t = 0` it is the start state exactly.
#[test]
fn exact_solution_solves_the_equation() -> Result<(), Error> {
    let h = 1e-4;
    let mut worst = 0.0f64;
    for (name, c) in REGIMES {
        let exact = |t: f64| damped_oscillator(M, K, c, X0, V0, t);
        assert_eq!(exact(0.0)?, (X0, V0), "{name}");
        for i in 1..=200 {
            let t = 0.05 * f64::from(i);
            let (x, v) = exact(t)?;
            let (x1, v1) = exact(t + h)?;
            let (x2, v2) = exact(t + 2.0 * h)?;
            let (x_1, v_1) = exact(t - h)?;
            let (x_2, v_2) = exact(t - 2.0 * h)?;
            let dx = (8.0 * (x1 - x_1) - (x2 - x_2)) / (12.0 * h);
            let dv = (8.0 * (v1 - v_1) - (v2 - v_2)) / (12.0 * h);
            let e = (dx - v).abs().max((M * dv + K * x + c * v).abs());
            assert!(e < 3e-11, "{name} at t = {t}: residual {e:e}");
            worst = worst.max(e);
        }
    }
    println!("exact damped oscillator: worst residual {worst:.1e}");
    Ok(())
}

/// Where the power series hands over to the closed forms (`|lambda| t^2 = 1`) the two agree to
/// rounding: the state just below the hand-over, moved by one Euler step of the equation across
/// it (`2e-14 t`, whose own error is `~1e-28`), equals the state just above. Measured 4.4e-16,
/// bound 2e-15.
#[test]
fn series_meets_closed_form() -> Result<(), Error> {
    for (name, c) in REGIMES {
        let lambda = K / M - (c / (2.0 * M)).powi(2);
        if lambda == 0.0 {
            continue;
        }
        let t = 1.0 / lambda.abs().sqrt();
        let (t_below, t_above) = (t * (1.0 - 1e-14), t * (1.0 + 1e-14));
        let (x, v) = damped_oscillator(M, K, c, X0, V0, t_below)?;
        let (x_above, v_above) = damped_oscillator(M, K, c, X0, V0, t_above)?;
        let dt = t_above - t_below;
        let (x_moved, v_moved) = (x + v * dt, v - (K * x + c * v) / M * dt);
        let e = (x_moved - x_above).abs().max((v_moved - v_above).abs());
        println!("{name}: series against closed form {e:.1e}");
        assert!(
            e < 2e-15,
            "{name}: ({x_moved}, {v_moved}) against ({x_above}, {v_above})"
        );
    }
    Ok(())
}

/// RK4 at dt = 1e-3 over 10 s tracks the exact solution in every regime, and the built-in
/// damping never lets the energy rise. Largest error over the run, measured: f64 1.0e-12
/// (under-damped), 5.3e-13 (critical), 2.5e-11 (over-damped: its fast mode, rate 9.6/s, is
/// the hardest for RK4), RK4's truncation; f32 2.4e-6, 1.2e-6, 5.4e-7, rounding. Bounds 1e-10 and 1e-5.
/// Energy: in f64 it never rose (measured: every step lost energy), slack 1e-15 for rounding;
/// in f32 it rose by one ulp (2.4e-7 of ~2) where the damping's loss is below rounding, slack
/// 1e-6.
fn rk4_tracks_the_damped_oscillator<T: Real>() -> Result<(), Error> {
    let c = T::from_f64;
    for (name, damping) in REGIMES {
        let smd = SpringMassDamper::new(c(M), c(K), c(damping))?;
        let start = State::new(T::zero(), [c(X0)], [c(V0)]);
        let (mut worst, mut rise, mut last) = (0.0f64, f64::NEG_INFINITY, smd.energy(&start));
        let mut failure = None;
        // Time from the step count: in f32, `t` summed step by step drifts by ~1e-4 s.
        let dt = c(1e-3);
        let mut steps = 0u32;
        Rk4.integrate_with(&smd, &start, dt, 10_000, |s| {
            steps += 1;
            match damped_oscillator(M, K, damping, X0, V0, f64::from(steps) * dt.to_f64()) {
                Ok((x, v)) => {
                    let e = (s.q[0].to_f64() - x)
                        .abs()
                        .max((s.qd[0].to_f64() - v).abs());
                    worst = worst.max(e);
                }
                Err(e) => failure = Some(e),
            }
            let energy = smd.energy(s);
            rise = rise.max((energy - last).to_f64());
            last = energy;
        })?;
        if let Some(e) = failure {
            return Err(e);
        }
        println!(
            "{name} ({}): worst error {worst:.1e}, largest energy rise {rise:.1e}",
            core::any::type_name::<T>()
        );
        assert!(worst < pick::<T>(1e-5, 1e-10), "{name}: error {worst:e}");
        assert!(
            rise <= pick::<T>(1e-6, 1e-15),
            "{name}: energy rose by {rise:e}"
        );
    }
    Ok(())
}

for_f32_and_f64!(rk4_tracks_the_damped_oscillator);
