//! The fixed-timestep driver: variable frame times, whole steps of `dt`, the cap on steps per
//! frame, and the interpolated state for rendering.

use lagrange_core::{Error, Real, State};
use lagrange_integrators::{ExplicitEuler, FixedTimestep, Integrator, StormerVerlet};
use lagrange_systems::{SimplePendulum, SpringMassDamper};
use lagrange_tests::{for_f32_and_f64, pick, Rng};

/// `Err(InvalidParameter { name, .. })` with exactly this name.
fn refuses<V: core::fmt::Debug>(result: Result<V, Error>, expected: &str) {
    assert!(
        matches!(result, Err(Error::InvalidParameter { name, .. }) if name == expected),
        "expected InvalidParameter {{ name: {expected} }}, got {result:?}"
    );
}

/// Frames of 1/60 s stepped at 1/120 s: two steps every frame despite the rounding of the
/// accumulated time, and the very states of 1200 plain steps.
fn frames_of_two_steps<T: Real>() -> Result<(), Error> {
    let p = SimplePendulum::new(T::one(), T::one(), T::from_f64(9.81), T::zero())?;
    let start = State::at_rest([T::HALF]);
    let dt = T::from_f64(1.0 / 120.0);
    let mut sim = FixedTimestep::new(StormerVerlet::default(), dt, 4, start)?;
    for _ in 0..600 {
        let frame = sim.advance(&p, T::from_f64(1.0 / 60.0))?;
        assert_eq!(frame.steps, 2);
        assert_eq!(frame.dropped, T::zero());
    }
    let direct = StormerVerlet::default().integrate(&p, &start, dt, 1200)?;
    assert_eq!(sim.current(), &direct);
    Ok(())
}

/// Random frame times from 0 to 50 ms: the steps taken and `alpha` account for the elapsed
/// time, `alpha` stays in `[0, 1]`, and the drawn state lies between the last two steps, one
/// step behind the simulation clock.
fn variable_frames<T: Real>() -> Result<(), Error> {
    let p = SimplePendulum::new(T::one(), T::one(), T::from_f64(9.81), T::zero())?;
    let dt = T::from_f64(0.01);
    let mut sim = FixedTimestep::new(StormerVerlet::default(), dt, 10, State::at_rest([T::HALF]))?;
    let mut rng = Rng::new(5);
    let (mut elapsed, mut steps, mut worst) = (0.0f64, 0u64, 0.0f64);
    let one = T::one();
    for _ in 0..2000 {
        let frame_time: T = rng.uniform(0.0, 0.05);
        elapsed += frame_time.to_f64();
        let frame = sim.advance(&p, frame_time)?;
        steps += u64::from(frame.steps);
        assert_eq!(frame.dropped, T::zero());
        let a = sim.alpha();
        assert!(a >= T::zero() && a <= T::one());
        let drawn = sim.interpolated();
        let (prev, cur) = (sim.previous(), sim.current());
        assert!(drawn.t >= prev.t && drawn.t <= cur.t);
        let lo = prev.q[0].min(cur.q[0]);
        let hi = prev.q[0].max(cur.q[0]);
        assert!(drawn.q[0] >= lo && drawn.q[0] <= hi);
        // The bookkeeping: the elapsed time is the steps taken plus alpha of a step, to the
        // rounding of the accumulator over 2000 frames (measured worst 1.0e-6 s in f32,
        // 8.5e-14 s in f64). (The state's own `t`, summed step by step, drifts further in
        // f32.)
        let booked = (steps as f64 + a.to_f64()) * dt.to_f64();
        worst = worst.max((elapsed - booked).abs());
        assert!(
            (elapsed - booked).abs() < pick::<T>(3e-6, 3e-13),
            "{elapsed} vs {booked}"
        );
        // Drawn one step behind the simulation clock.
        let behind = cur.t - drawn.t - (one - a) * dt;
        assert!(behind.abs() < T::from_f64(4.0) * T::EPSILON * cur.t);
    }
    println!("worst bookkeeping error {worst:.1e} s");
    let whole = (elapsed / 0.01).floor() as u64;
    assert!(
        steps.abs_diff(whole) <= 1,
        "{steps} steps for {whole} whole steps"
    );
    Ok(())
}

/// A 1 s hitch at 10 ms steps with a cap of 5: 5 steps, 0.95 s dropped, nothing left over
/// beyond a fraction of a step; the next frames run normally.
fn the_cap_prevents_the_spiral<T: Real>() -> Result<(), Error> {
    let p = SimplePendulum::new(T::one(), T::one(), T::from_f64(9.81), T::zero())?;
    let dt = T::from_f64(0.01);
    let mut sim = FixedTimestep::new(StormerVerlet::default(), dt, 5, State::at_rest([T::HALF]))?;
    let frame = sim.advance(&p, T::one())?;
    assert_eq!(frame.steps, 5);
    assert!((frame.dropped.to_f64() - 0.95).abs() < pick::<T>(1e-5, 1e-12));
    assert!(sim.alpha() < T::one());
    assert!((sim.current().t.to_f64() - 0.05).abs() < pick::<T>(1e-6, 1e-14));
    let frame = sim.advance(&p, T::from_f64(0.02))?;
    assert_eq!(frame.steps, 2);
    assert_eq!(frame.dropped, T::zero());
    Ok(())
}

/// Bad parameters name themselves; a step that blows up is an error after which the driver
/// still holds the last good state.
fn bad_input_and_failed_steps<T: Real>() -> Result<(), Error> {
    let one = T::one();
    let p = SimplePendulum::new(one, one, T::from_f64(9.81), T::zero())?;
    let start = State::at_rest([T::HALF]);
    let nan = T::from_f64(f64::NAN);
    for bad in [T::zero(), -one, nan, T::INFINITY] {
        refuses(FixedTimestep::new(ExplicitEuler, bad, 4, start), "dt");
    }
    refuses(
        FixedTimestep::new(ExplicitEuler, one, 0, start),
        "max_steps_per_frame",
    );
    assert_eq!(
        FixedTimestep::new(ExplicitEuler, one, 4, State::at_rest([nan])).map(|_| ()),
        Err(Error::NonFiniteState)
    );
    let mut sim = FixedTimestep::new(ExplicitEuler, T::from_f64(0.01), 4, start)?;
    for bad in [-one, nan, T::INFINITY] {
        refuses(sim.advance(&p, bad), "frame_time");
    }
    // Explicit Euler on a stiff spring (h w = 100) overflows within a few hundred steps.
    let stiff = SpringMassDamper::new(one, T::from_f64(1e8), T::zero())?;
    let mut sim = FixedTimestep::new(
        ExplicitEuler,
        T::from_f64(0.01),
        1000,
        State::at_rest([one]),
    )?;
    assert_eq!(
        sim.advance(&stiff, T::from_f64(10.0)),
        Err(Error::NonFiniteState)
    );
    assert!(sim.current().is_finite() && sim.interpolated().is_finite());
    sim.reset(State::at_rest([one]))?;
    assert_eq!(sim.current().t, T::zero());
    Ok(())
}

for_f32_and_f64!(
    frames_of_two_steps,
    variable_frames,
    the_cap_prevents_the_spiral,
    bad_input_and_failed_steps
);
