//! Composable forces and energy behaviour: damping added by wrapping equals damping built in,
//! damping never adds energy, inputs do work, conserved quantities stay conserved.

use lagrange_core::nalgebra::SVector;
use lagrange_core::{
    Error, EulerLagrange, Input, Lagrangian, Mechanism, Real, State, ViscousDamping,
};
use lagrange_integrators::{Integrator, Rk4};
use lagrange_systems::{BeadOnRotatingHoop, DoublePendulum, SimplePendulum};
use lagrange_tests::{for_f32_and_f64, pick};

/// A pendulum with damping `b` built in and the undamped one wrapped with `ViscousDamping(b)`
/// compute the same accelerations to rounding, and the same through the automatic path.
fn wrapped_damping_equals_built_in<T: Real>() -> Result<(), Error> {
    let (m, l, g, b) = (
        T::from_f64(2.0),
        T::from_f64(0.7),
        T::from_f64(9.81),
        T::from_f64(0.3),
    );
    let built_in = SimplePendulum::new(m, l, g, b)?;
    let wrapped = SimplePendulum::new(m, l, g, T::zero())?.with_force(ViscousDamping::uniform(b)?);
    let auto = EulerLagrange::new(built_in);
    for i in 0..50 {
        let x = T::from_f64(f64::from(i) * 0.13 - 3.0);
        let s = State::new(T::zero(), [x], [T::from_f64(2.0) - x]);
        let a = built_in.acceleration(&s)?[0];
        let tol = T::from_f64(8.0) * T::EPSILON * (a.abs() + T::from_f64(20.0));
        assert!((a - wrapped.acceleration(&s)?[0]).abs() <= tol);
        assert!((a - auto.acceleration(&s)?[0]).abs() <= tol);
    }
    Ok(())
}

/// Damping only removes energy: over 20 s of RK4 the energy of a damped double pendulum never
/// rises from one step to the next. Measured largest step-to-step change: f64 -6.0e-9 J
/// (every step loses energy), slack 1e-13 J for rounding (~30 ulps of the 30 J start); f32
/// +7.2e-7 J (rounding of energies of order 30 J where the step's loss is below it), slack
/// 3.6e-6 J.
fn damping_never_adds_energy<T: Real>() -> Result<(), Error> {
    let dp = DoublePendulum::new(T::one(), T::one(), T::one(), T::one(), T::from_f64(9.81))?
        .with_force(ViscousDamping::new([T::from_f64(0.2), T::from_f64(0.1)])?);
    let mut s = State::new(
        T::zero(),
        [T::from_f64(2.0), T::from_f64(-1.0)],
        [T::zero(); 2],
    );
    let e_start = dp.energy(&s);
    let mut e = e_start;
    let slack = pick::<T>(3.6e-6, 1e-13);
    let mut rise = f64::NEG_INFINITY;
    for _ in 0..20_000 {
        s = Rk4.step(&dp, &s, T::from_f64(1e-3))?;
        let next = dp.energy(&s);
        rise = rise.max(next.to_f64() - e.to_f64());
        assert!(
            next.to_f64() <= e.to_f64() + slack,
            "energy rose from {e} to {next} at t = {}",
            s.t
        );
        e = next;
    }
    println!("damped double pendulum: largest step-to-step energy change {rise:.2e} J");
    // And a lot of it is gone: 20 s at these damping rates leave well under half.
    let bottom = dp.energy(&State::at_rest([T::zero(); 2])).to_f64();
    assert!(e.to_f64() - bottom < 0.5 * (e_start.to_f64() - bottom));
    Ok(())
}

/// A constant input torque does work `tau * (th(T) - th(0))` on a pendulum: the energy balance
/// closes to the integration error. Measured 4.7e-15 J in f64 (bound 2.4e-14), 9.7e-7 J in f32
/// (rounding; bound 5e-6).
fn input_does_work<T: Real>() -> Result<(), Error> {
    let tau = T::from_f64(0.5);
    let p = SimplePendulum::new(T::one(), T::one(), T::from_f64(9.81), T::zero())?
        .with_force(Input::new([tau]));
    let start = State::at_rest([T::from_f64(0.2)]);
    let end = Rk4.integrate(&p, &start, T::from_f64(1e-3), 3000)?;
    let work = tau * (end.q[0] - start.q[0]);
    let balance = (p.energy(&end) - p.energy(&start) - work).abs().to_f64();
    println!("input torque: energy balance off by {balance:.2e} J");
    assert!(
        balance < pick::<T>(5e-6, 2.4e-14),
        "energy balance off by {balance}"
    );
    Ok(())
}

/// An input can be changed between steps through `force_mut`, as a controller would.
#[test]
fn input_changes_between_steps() -> Result<(), Error> {
    let mut p = SimplePendulum::new(1.0, 1.0, 9.81, 0.0)?.with_force(Input::new([0.0]));
    let s = State::at_rest([0.0]);
    assert_eq!(p.acceleration(&s)?[0], 0.0);
    p.force_mut().value = SVector::from([2.0]);
    assert_eq!(p.acceleration(&s)?[0], 2.0);
    Ok(())
}

/// Closures are generalized forces too.
#[test]
fn closure_force() -> Result<(), Error> {
    let p = SimplePendulum::new(1.0, 2.0, 9.81, 0.0)?
        .with_force(|s: &State<f64, 1>| SVector::from([-s.q[0]]));
    let a = p.acceleration(&State::at_rest([0.5]))?[0];
    assert!((a - (-9.81 * 2.0 * 0.5f64.sin() - 0.5) / 4.0).abs() < 1e-15);
    Ok(())
}

/// The bead's Jacobi integral is conserved while `T + V` is not (the drive does work).
/// RK4 at dt = 1e-3 over 10 s: the integral drifts by 4.7e-12 in f64 (truncation; bound
/// 2.4e-11) and 1.4e-6 in f32 (rounding; bound 7e-6); the energy itself changes by order one.
fn bead_conserves_jacobi_integral<T: Real>() -> Result<(), Error> {
    let hoop = BeadOnRotatingHoop::new(T::one(), T::HALF, T::from_f64(6.0), T::from_f64(9.81))?;
    let start = State::new(T::zero(), [T::from_f64(0.3)], [T::one()]);
    let end = Rk4.integrate(&hoop, &start, T::from_f64(1e-3), 10_000)?;
    let drift = (hoop.jacobi_integral(&end) - hoop.jacobi_integral(&start))
        .abs()
        .to_f64();
    println!("bead: Jacobi integral drift {drift:.2e}");
    assert!(
        drift < pick::<T>(7e-6, 2.4e-11),
        "Jacobi integral drift {drift}"
    );
    let energy_change = (hoop.energy(&end) - hoop.energy(&start)).abs().to_f64();
    assert!(
        energy_change > 1e-2,
        "T + V changed only by {energy_change}"
    );
    Ok(())
}

for_f32_and_f64!(
    wrapped_damping_equals_built_in,
    damping_never_adds_energy,
    input_does_work,
    bead_conserves_jacobi_integral
);
