//! A step's own time: every fixed-step method's `step` (and `run_step`, the step of a run)
//! returns the state at `t + dt`, exactly where `t + dt` is exact (0.25 + 0.125), in f32 and
//! f64. The runs keep the time by their own clock, so only a single step shows a method's.

use lagrange_core::{Error, Real, State};
use lagrange_integrators::{
    BackwardEuler, ExplicitEuler, GaussLegendre2, ImplicitMidpoint, Integrator, RadauIIA2, Rk4,
    SemiImplicitEuler, StormerVerlet, VariationalMidpoint, VelocityVerlet, Yoshida4,
};
use lagrange_systems::SimplePendulum;
use lagrange_tests::for_f32_and_f64;

fn lands<T: Real, I: Integrator<T, 1, SimplePendulum<T>>>(
    name: &str,
    mut method: I,
) -> Result<(), Error> {
    let m = SimplePendulum::new(T::one(), T::one(), T::from_f64(9.81), T::from_f64(0.1))?;
    let s = State::new(T::from_f64(0.25), [T::from_f64(0.4)], [T::from_f64(-0.3)]);
    let dt = T::from_f64(0.125);
    let end = T::from_f64(0.375);
    let stepped = method.step(&m, &s, dt)?;
    assert!(
        stepped.t == end,
        "{name}: step ends at {:?}",
        stepped.t.to_f64()
    );
    let run = method.run_step(&m, &s, dt)?;
    assert!(
        run.t == end,
        "{name}: run_step ends at {:?}",
        run.t.to_f64()
    );
    assert!(stepped.q != s.q, "{name}: the step moved nothing");
    Ok(())
}

fn every_method<T: Real>() -> Result<(), Error> {
    lands::<T, _>("explicit Euler", ExplicitEuler)?;
    lands::<T, _>("semi-implicit Euler", SemiImplicitEuler)?;
    lands::<T, _>("velocity Verlet", VelocityVerlet)?;
    lands::<T, _>("Stormer-Verlet", StormerVerlet::default())?;
    lands::<T, _>("RK4", Rk4)?;
    lands::<T, _>("implicit midpoint", ImplicitMidpoint::default())?;
    lands::<T, _>("Gauss-Legendre 2", GaussLegendre2::default())?;
    lands::<T, _>("backward Euler", BackwardEuler::default())?;
    lands::<T, _>("Radau IIA 2", RadauIIA2::default())?;
    lands::<T, _>("variational midpoint", VariationalMidpoint::default())?;
    lands::<T, _>("Yoshida 4", Yoshida4::new(StormerVerlet::default()))?;
    Ok(())
}

for_f32_and_f64!(every_method);
