//! A falling particle has constant acceleration, so RK4 and velocity Verlet integrate it
//! exactly: what remains is rounding.

use lagrange_core::{Error, Mechanism, Real, State};
use lagrange_integrators::{Integrator, Rk4, VelocityVerlet};
use lagrange_systems::FallingParticle;
use lagrange_tests::for_f32_and_f64;

const STEPS: u64 = 1000;

/// Integrates from y = 100 m, v = 3 m/s with dt = 1e-3 for 1 s and compares with
/// `y0 + v0 t - g t^2 / 2`. Each step rounds a handful of operations on values of size ~100, so
/// the error is a random walk bounded by `STEPS * 4 eps * 100`.
fn exact_to_rounding<T: Real, I: Integrator<T, 1, FallingParticle<T>>>(
    mut integrator: I,
) -> Result<(), Error> {
    let g = T::from_f64(9.81);
    let p = FallingParticle::new(T::from_f64(2.0), g)?;
    let start = State::new(T::zero(), [T::from_f64(100.0)], [T::from_f64(3.0)]);
    let end = integrator.integrate(&p, &start, T::from_f64(1e-3), STEPS)?;
    let t = end.t.to_f64();
    let y = 100.0 + 3.0 * t - 0.5 * 9.81 * t * t;
    let v = 3.0 - 9.81 * t;
    let tol = STEPS as f64 * 4.0 * T::EPSILON.to_f64() * 100.0;
    assert!(
        (end.q[0].to_f64() - y).abs() < tol,
        "{}: y = {}, exact {y}",
        I::NAME,
        end.q[0]
    );
    assert!(
        (end.qd[0].to_f64() - v).abs() < tol,
        "{}: v = {}, exact {v}",
        I::NAME,
        end.qd[0]
    );
    assert!((t - 1.0).abs() < tol);
    // And the acceleration itself is -g exactly.
    assert_eq!(p.acceleration(&end)?[0], -g);
    Ok(())
}

fn rk4_is_exact<T: Real>() -> Result<(), Error> {
    exact_to_rounding::<T, _>(Rk4)
}

fn verlet_is_exact<T: Real>() -> Result<(), Error> {
    exact_to_rounding::<T, _>(VelocityVerlet)
}

for_f32_and_f64!(rk4_is_exact, verlet_is_exact);
