//! Measured order of convergence of every fixed-step integrator: the slope of log(error)
//! against log(dt) must be within 0.2 of the stated order (f64).

use lagrange_core::{Error, Mechanism, State};
use lagrange_integrators::{ExplicitEuler, Integrator, Rk4, SemiImplicitEuler, VelocityVerlet};
use lagrange_systems::exact::pendulum_from_rest;
use lagrange_systems::{DoublePendulum, SimplePendulum};
use lagrange_tests::{fitted_order, state_error};

/// Allowed distance of the measured from the stated order.
const ORDER_TOLERANCE: f64 = 0.2;
/// Horizon of each run, s.
const T_END: f64 = 1.0;

/// The final-state error of `I` at each step size against `reference`, and the fitted order.
fn measured_order<I: Integrator<f64, N> + Default, M: Mechanism<f64, N>, const N: usize>(
    m: &M,
    start: &State<f64, N>,
    reference: &[f64],
    dts: &[f64],
) -> Result<f64, Error> {
    let mut errs = Vec::new();
    for &dt in dts {
        let end = I::default().integrate(m, start, dt, (T_END / dt).round() as u64)?;
        errs.push(state_error(&end, reference));
    }
    let order = fitted_order(dts, &errs);
    println!(
        "{:<20} errors {errs:?} -> order {order:.3} (stated {})",
        I::NAME,
        I::ORDER
    );
    assert!(
        (order - f64::from(I::ORDER)).abs() < ORDER_TOLERANCE,
        "{}: measured order {order}, stated {}",
        I::NAME,
        I::ORDER
    );
    Ok(order)
}

/// Step sizes halving from `dt0`, four of them: coarse enough to stay above rounding, fine
/// enough to be in the asymptotic regime.
fn halvings(dt0: f64) -> [f64; 4] {
    [dt0, dt0 / 2.0, dt0 / 4.0, dt0 / 8.0]
}

/// The origin's pendulum (30 degrees at rest) against the exact solution at t = 1 s.
#[test]
fn orders_on_the_pendulum() -> Result<(), Error> {
    let g: f64 = 9.81;
    let th0 = core::f64::consts::FRAC_PI_6;
    let p = SimplePendulum::new(1.0, 1.0, g, 0.0)?;
    let start = State::at_rest([th0]);
    let (th, thd) = pendulum_from_rest(th0, g.sqrt(), T_END)?;
    let r = [th, thd];
    measured_order::<ExplicitEuler, _, 1>(&p, &start, &r, &halvings(1e-3))?;
    measured_order::<SemiImplicitEuler, _, 1>(&p, &start, &r, &halvings(1e-3))?;
    measured_order::<VelocityVerlet, _, 1>(&p, &start, &r, &halvings(1e-2))?;
    measured_order::<Rk4, _, 1>(&p, &start, &r, &halvings(5e-2))?;
    Ok(())
}

/// A regular (non-chaotic) double pendulum start, where the accelerations depend on the
/// velocities: the velocity Verlet variant must stay second order there. The reference is RK4
/// at dt = 1e-4, whose own error (~1e-15) is far below every error measured.
#[test]
fn orders_on_the_double_pendulum() -> Result<(), Error> {
    let dp = DoublePendulum::new(1.0, 1.0, 1.0, 1.0, 9.81)?;
    let start = State::new(0.0, [0.6, -0.4], [0.5, 1.0]);
    let fine = Rk4.integrate(&dp, &start, 1e-4, 10_000)?;
    let r = [fine.q[0], fine.q[1], fine.qd[0], fine.qd[1]];
    measured_order::<ExplicitEuler, _, 2>(&dp, &start, &r, &halvings(1e-3))?;
    measured_order::<SemiImplicitEuler, _, 2>(&dp, &start, &r, &halvings(1e-3))?;
    measured_order::<VelocityVerlet, _, 2>(&dp, &start, &r, &halvings(1e-2))?;
    measured_order::<Rk4, _, 2>(&dp, &start, &r, &halvings(4e-2))?;
    Ok(())
}
