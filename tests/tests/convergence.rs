//! Measured order of convergence of every fixed-step integrator: the slope of log(error)
//! against log(dt) must be within 0.2 of the stated order (f64).

use lagrange_core::{Error, EulerLagrange, Lagrangian, Mechanism, State};
use lagrange_integrators::{
    BackwardEuler, ExplicitEuler, GaussLegendre2, ImplicitMidpoint, Integrator, RadauIIA2, Rk4,
    SemiImplicitEuler, StormerVerlet, VariationalMidpoint, VelocityVerlet, Yoshida4,
};
use lagrange_systems::exact::pendulum_from_rest;
use lagrange_systems::{CartPole, DoublePendulum, SimplePendulum};
use lagrange_tests::{fitted_order, state_error};

/// Allowed distance of the measured from the stated order.
const ORDER_TOLERANCE: f64 = 0.2;
/// Horizon of each run, s.
const T_END: f64 = 1.0;

/// The final-state error of `I` at each step size against `reference`, and the fitted order.
fn measured_order<I: Integrator<f64, N, M> + Default, M: Mechanism<f64, N>, const N: usize>(
    m: &M,
    start: &State<f64, N>,
    reference: &[f64],
    dts: &[f64],
) -> Result<f64, Error> {
    order_of(I::NAME, I::ORDER, reference, dts, |dt, steps| {
        Ok(I::default().integrate(m, start, dt, steps)?)
    })
}

/// The fitted order of `run(dt, steps)` (the state at `T_END`) against `reference`, asserted
/// within [`ORDER_TOLERANCE`] of `stated`.
fn order_of<const N: usize>(
    name: &str,
    stated: u32,
    reference: &[f64],
    dts: &[f64],
    mut run: impl FnMut(f64, u64) -> Result<State<f64, N>, Error>,
) -> Result<f64, Error> {
    let mut errs = Vec::new();
    for &dt in dts {
        let end = run(dt, (T_END / dt).round() as u64)?;
        errs.push(state_error(&end, reference));
    }
    let order = fitted_order(dts, &errs);
    println!(
        "{name:<20} errors {:?} -> order {order:.3} (stated {stated})",
        errs.iter().map(|e| format!("{e:.3e}")).collect::<Vec<_>>()
    );
    assert!(
        (order - f64::from(stated)).abs() < ORDER_TOLERANCE,
        "{name}: measured order {order}, stated {stated}"
    );
    Ok(order)
}

/// The variational integrator's order: it needs the Lagrangian, so it runs on the automatic
/// path of the same mechanism.
fn variational_order<L: Lagrangian<f64, N>, const N: usize>(
    l: L,
    start: &State<f64, N>,
    reference: &[f64],
    dts: &[f64],
) -> Result<f64, Error> {
    let m = EulerLagrange::new(l);
    order_of("variational midpoint", 2, reference, dts, |dt, steps| {
        Ok(VariationalMidpoint::default().integrate(&m, start, dt, steps)?)
    })
}

/// The orders of the symmetric, implicit and variational methods.
fn structure_preserving_orders<L, const N: usize>(
    l: L,
    start: &State<f64, N>,
    r: &[f64],
    dt2: f64,
    dt4: f64,
) -> Result<(), Error>
where
    L: Lagrangian<f64, N> + Mechanism<f64, N> + Copy,
{
    measured_order::<StormerVerlet<f64, N>, _, N>(&l, start, r, &halvings(dt2))?;
    measured_order::<Yoshida4<StormerVerlet<f64, N>>, _, N>(&l, start, r, &halvings(dt4))?;
    measured_order::<ImplicitMidpoint<f64>, _, N>(&l, start, r, &halvings(dt2))?;
    measured_order::<GaussLegendre2<f64>, _, N>(&l, start, r, &halvings(dt4))?;
    measured_order::<BackwardEuler<f64>, _, N>(&l, start, r, &halvings(1e-3))?;
    measured_order::<RadauIIA2<f64>, _, N>(&l, start, r, &halvings(dt4))?;
    variational_order(l, start, r, &halvings(dt2))?;
    // Composed, and stepping the hand-derived mechanism's own Lagrangian: order 4, symplectic
    // for any Lagrangian.
    measured_order::<Yoshida4<VariationalMidpoint<f64, N>>, _, N>(&l, start, r, &halvings(dt4))?;
    Ok(())
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
    structure_preserving_orders(p, &start, &r, 1e-2, 5e-2)
}

/// The cart-pole (mass matrix depending on the pole's angle) from a swing below the top: the
/// variational integrator and its Yoshida composition, which are symplectic for it where
/// the others are not. Reference: RK4 at dt = 1e-4 (error ~1e-15).
#[test]
fn orders_on_the_cart_pole() -> Result<(), Error> {
    let cp = CartPole::new(1.0, 0.1, 0.5, 9.8)?;
    let start = State::new(0.0, [0.0, 2.0], [0.3, -1.0]);
    let fine = Rk4.integrate(&cp, &start, 1e-4, 10_000)?;
    let r = [fine.q[0], fine.q[1], fine.qd[0], fine.qd[1]];
    order_of(
        "variational midpoint",
        2,
        &r,
        &halvings(1e-2),
        |dt, steps| Ok(VariationalMidpoint::default().integrate(&cp, &start, dt, steps)?),
    )?;
    measured_order::<Yoshida4<VariationalMidpoint<f64, 2>>, _, 2>(
        &cp,
        &start,
        &r,
        &halvings(4e-2),
    )?;
    measured_order::<Yoshida4<StormerVerlet<f64, 2>>, _, 2>(&cp, &start, &r, &halvings(4e-2))?;
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
    structure_preserving_orders(dp, &start, &r, 1e-2, 4e-2)
}
