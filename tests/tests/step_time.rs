//! A step's own time: every fixed-step method's `step` (and `run_step`, the step of a run)
//! returns the state at `t + dt`, exactly where `t + dt` is exact (0.25 + 0.125), in f32 and
//! f64. The runs keep the time by their own clock, so only a single step shows a method's.

use lagrange_core::{Error, Real, State};
use lagrange_integrators::{
    BackwardEuler, ExplicitEuler, GaussLegendre2, ImplicitMidpoint, Integrator, RadauIIA2, Rk4,
    SemiImplicitEuler, StormerVerlet, SymmetricBase, VariationalMidpoint, VelocityVerlet, Yoshida4,
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

/// Where the time cannot move: at `t = 1` a step of `1e-16` rounds to `t` going up (half an
/// ulp above 1 is 1.1e-16) though not going down (half an ulp below is 5.5e-17): a single
/// step, and a run of one step, is refused as too small; the step of a run is taken.
#[test]
fn a_step_that_rounds_away_is_refused() -> Result<(), Error> {
    let m = SimplePendulum::new(1.0, 1.0, 9.81, 0.1)?;
    let s = State::new(1.0f64, [0.4], [-0.3]);
    let tiny = 1e-16;
    assert_eq!(Rk4.step(&m, &s, tiny), Err(Error::StepSizeUnderflow));
    assert_eq!(
        Rk4.integrate(&m, &s, tiny, 1).map_err(|f| f.error),
        Err(Error::StepSizeUnderflow)
    );
    let next = Rk4.run_step(&m, &s, tiny)?;
    assert_eq!(next.t, 1.0);
    Ok(())
}

/// Far out in `f32` (t = 1e30, an ulp of 7.6e22), steps of 1e10 s round away but are finite:
/// the steps of a run, forwards and (a symmetric base's substep) backwards, are taken, with
/// the time where it was; so are huge steps from near `-MAX` whose end is finite; a substep of
/// zero or NaN is refused by name.
#[test]
fn steps_of_a_run_far_out_are_taken() -> Result<(), Error> {
    let m = SimplePendulum::new(1.0f32, 1.0, 9.81, 0.0)?;
    let s = State::new(1e30f32, [0.4], [0.0]);
    let dt = 1e10f32;
    for next in [
        ExplicitEuler.run_step(&m, &s, dt)?,
        SemiImplicitEuler.run_step(&m, &s, dt)?,
        Rk4.run_step(&m, &s, dt)?,
        StormerVerlet::default().run_step(&m, &s, dt)?,
        StormerVerlet::default().signed_run_step(&m, &s, dt)?,
        StormerVerlet::default().signed_run_step(&m, &s, -dt)?,
    ] {
        assert_eq!(next.t, 1e30);
        assert!(next.is_finite() && next.qd != s.qd, "{next:?}");
    }
    // Near the bottom of the range, a pendulum at rest at its bottom (it stays there) takes
    // steps of 0.2 MAX from -0.9 MAX: the end, -0.7 MAX, is finite.
    let bottom = State::new(-0.9 * f32::MAX, [0.0], [0.0]);
    let huge = 0.2 * f32::MAX;
    for next in [
        Rk4.run_step(&m, &bottom, huge)?,
        StormerVerlet::default().signed_run_step(&m, &bottom, huge)?,
    ] {
        assert_eq!(next.t, bottom.t + huge);
        assert_eq!((next.q, next.qd), (bottom.q, bottom.qd));
    }
    for bad in [0.0, f32::NAN] {
        assert!(matches!(
            StormerVerlet::default().signed_run_step(&m, &s, bad),
            Err(Error::InvalidParameter { name: "h", .. })
        ));
    }
    Ok(())
}
