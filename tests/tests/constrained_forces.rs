//! Forces added by wrapping act through the constraints: `with_force` on a constrained
//! mechanism keeps its multipliers.

use lagrange_core::{
    Constrained, Error, Input, Lagrangian, Mechanism, Projection, Real, State, ViscousDamping,
};
use lagrange_integrators::{Integrator, Projected, Rk4};
use lagrange_systems::{CartesianPendulum, RollingDisk, SimplePendulum};
use lagrange_tests::{for_f32_and_f64, pick};

/// Viscous damping `c` on `x'` and `y'` of the Cartesian pendulum is a torque `-c l^2 th'`
/// about the pivot: it must track the simple pendulum with damping `b = c l^2`. RK4 (+
/// projection) at dt = 1e-3 for 5 s from 1 rad: measured largest angle difference 1.5e-11 rad
/// (f64), 1.6e-6 rad (f32); bounds 7.5e-11 and 8e-6 rad.
fn damping_acts_through_the_rod<T: Real>() -> Result<(), Error> {
    let (m, l, g, c) = (
        T::from_f64(2.0),
        T::from_f64(0.7),
        T::from_f64(9.81),
        T::from_f64(0.3),
    );
    let simple = SimplePendulum::new(m, l, g, c * l * l)?;
    let cartesian = Constrained::new(CartesianPendulum::new(m, l, g)?);
    let damped = cartesian.with_force(ViscousDamping::uniform(c)?);
    let tol = T::from_f64(pick::<T>(1e-5, 1e-13));
    let mut stepper = Projected::new(Rk4, Projection::new(tol, 4)?);
    let dt = T::from_f64(1e-3);
    let mut s = State::at_rest([T::one()]);
    let mut cs = cartesian
        .parts()
        .state_from_angle(T::zero(), T::one(), T::zero());
    let mut worst: f64 = 0.0;
    for _ in 0..5000 {
        s = Rk4.step(&simple, &s, dt)?;
        cs = stepper.step(&damped, &cs, dt)?;
        worst = worst.max((cartesian.parts().angle(&cs).0 - s.q[0]).abs().to_f64());
    }
    println!("damped Cartesian vs damped angle, 5 s: {worst:.2e} rad");
    assert!(worst < pick::<T>(8e-6, 7.5e-11), "{worst:e}");
    assert!(simple.energy(&s) < simple.energy(&State::at_rest([T::one()])));
    Ok(())
}

/// A drive torque `tau` on the rolling angle of the disk accelerates the rolling by
/// `tau / (I_s + m R^2)` (the contact force makes the mass roll along), not by `tau / I_s`;
/// a steering torque `tau_psi` turns the heading by `tau_psi / I_t` (the contact force has no
/// moment about the vertical), whatever the heading and the rates (Newton's laws for the
/// disk, not its Lagrangian: `I_t = m R^2 / 4`, `I_s = m R^2 / 2`); to 8 ulps.
fn drive_torque_acts_through_the_contact<T: Real>() -> Result<(), Error> {
    let (m, r) = (T::from_f64(2.0), T::from_f64(0.4));
    let disk = Constrained::new(RollingDisk::new(m, r)?);
    for (tau_psi, tau, heading) in [(0.0, 0.6, 0.0), (0.25, 0.6, 0.7), (-0.4, -0.1, 2.9)] {
        let (tau_psi, tau) = (T::from_f64(tau_psi), T::from_f64(tau));
        let driven = disk.with_force(Input::new([T::zero(), T::zero(), tau_psi, tau]));
        let s = disk.parts().rolling(
            T::zero(),
            [T::zero(), T::zero(), T::from_f64(heading), T::zero()],
            T::from_f64(0.5),
            T::from_f64(3.0),
        )?;
        let a = driven.acceleration(&s)?;
        let mr2 = m * r * r;
        let (rolling, turning) = (
            tau / (T::HALF * mr2 + mr2),
            tau_psi / (T::HALF * T::HALF * mr2),
        );
        let tol = T::from_f64(8.0) * T::EPSILON * (rolling.abs() + turning.abs());
        assert!((a[3] - rolling).abs() <= tol, "{} vs {rolling}", a[3]);
        assert!((a[2] - turning).abs() <= tol, "{} vs {turning}", a[2]);
    }
    Ok(())
}

for_f32_and_f64!(
    damping_acts_through_the_rod,
    drive_torque_acts_through_the_contact
);
