//! The step clock against the exact time: `t0 + n dt`, summed without drift, is the exact
//! value rounded once (within half an ulp, and a little: see [`BOUND_ULPS`]) at every tick, over
//! blocks of ticks, across a change of step, and near the top of the range, where products
//! overflow though the time does not. And the frame clock beyond its cap: the whole steps
//! dropped, the fraction of a step kept, and the limit past which all of it is dropped.

use lagrange_core::{Error, Real, State};
use lagrange_integrators::{Clock, FixedTimestep, FrameClock, Integrator, Rk4, StormerVerlet};
use lagrange_systems::SimplePendulum;
use lagrange_tests::for_f32_and_f64;

/// The time is formed exactly and rounded once, up to the rounding of a small correction
/// term before it: measured worst 0.5 ulp in `f32` and `f64` over these runs.
/// A lost bit of the exact product or of its split costs a whole ulp or more.
const BOUND_ULPS: f64 = 0.51;

/// `a + b = s + e` exactly in `f64`.
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// A time as an unevaluated sum `hi + lo` of `f64`s, exact for these runs.
#[derive(Clone, Copy)]
struct Exact(f64, f64);

impl Exact {
    /// Plus `n` steps of `dt`: `n dt` exactly by a fused multiply-add, then summed in a pair.
    fn plus(self, n: u64, dt: f64) -> Self {
        let n = n as f64;
        let p = n * dt;
        let pe = n.mul_add(dt, -p);
        let (s, e) = two_sum(self.0, p);
        let (s, e2) = two_sum(s, e + pe + self.1);
        Self(s, e2)
    }
}

/// `|got - exact|` in ulps of `T` at the exact value.
fn ulps<T: Real>(got: T, exact: Exact) -> f64 {
    ulps_of::<T>(got.to_f64(), exact)
}

/// [`ulps`] of a time given as an `f64` (scaled by a power of two, exactly).
fn ulps_of<T: Real>(got: f64, exact: Exact) -> f64 {
    let error = (got - exact.0) - exact.1;
    let ulp = 2f64.powi(exact.0.abs().log2().floor() as i32) * T::EPSILON.to_f64();
    error.abs() / ulp
}

/// Ticks from several starts at several steps (`f32`: five blocks of 4096 ticks, where the
/// block's base is formed again), each time checked.
fn ticks_are_the_exact_time_rounded<T: Real>() -> Result<(), Error> {
    let mut worst = 0.0f64;
    for (t0, dt) in [
        (0.0, 1.0 / 120.0),
        (1000.25, 0.01),
        (-3.0, 0.1),
        (12345.678, 1e-3),
    ] {
        let (t0, dt) = (T::from_f64(t0), T::from_f64(dt));
        let mut clock = Clock::new(t0);
        assert_eq!(clock.time(), t0);
        let start = Exact(t0.to_f64(), 0.0);
        for n in 1..=20_000u64 {
            clock.tick(dt);
            let e = ulps(clock.time(), start.plus(n, dt.to_f64()));
            worst = worst.max(e);
            assert!(
                e <= BOUND_ULPS,
                "{e} ulps at tick {n} of {dt:?} from {t0:?}"
            );
        }
    }
    println!("worst {worst} ulps");
    Ok(())
}

/// Steps of one size, then another, then the first again: each change starts a new origin
/// at the time reached, exact to twice the precision, so the time stays the exact sum.
fn a_change_of_step_keeps_the_time<T: Real>() -> Result<(), Error> {
    let (a, b) = (T::from_f64(1.0 / 60.0), T::from_f64(0.003));
    let t0 = T::from_f64(10.5);
    let mut clock = Clock::new(t0);
    let mut exact = Exact(t0.to_f64(), 0.0);
    for (n, dt) in [(5000u64, a), (7000, b), (4500, a), (1, b), (3, a)] {
        for _ in 0..n {
            clock.tick(dt);
        }
        exact = exact.plus(n, dt.to_f64());
        let e = ulps(clock.time(), exact);
        assert!(e <= BOUND_ULPS, "{e} ulps after {n} of {dt:?}");
    }
    Ok(())
}

/// Near the top of the range: from `-0.9 MAX` by steps of `0.6 MAX`, two ticks reach
/// `0.3 MAX` though `2 dt` overflows; a change of step there, and 8196 ticks from `-MAX`
/// across a block whose base `n dt` overflows, still give the exact time rounded. (The exact times are
/// formed at a sixteenth, which is exact, so that `f64` does not overflow either.)
fn huge_steps_across_zero<T: Real>() -> Result<(), Error> {
    let max = T::MAX.to_f64();
    let sixteenth = |x: T| x.to_f64() / 16.0;
    let t0 = T::from_f64(-0.9 * max);
    let dt = T::from_f64(0.6 * max);
    let mut clock = Clock::new(t0);
    clock.tick(dt);
    clock.tick(dt);
    let exact = Exact(sixteenth(t0), 0.0).plus(2, sixteenth(dt));
    assert!(clock.time().is_finite());
    let e = ulps_of::<T>(sixteenth(clock.time()), exact);
    assert!(e <= BOUND_ULPS, "{e} ulps after two huge ticks");
    let small = T::from_f64(0.01 * max);
    for _ in 0..3 {
        clock.tick(small);
    }
    let exact = exact.plus(3, sixteenth(small));
    let e = ulps_of::<T>(sixteenth(clock.time()), exact);
    assert!(e <= BOUND_ULPS, "{e} ulps after the change of step");
    // A change of step at a time whose pair has a low part (-0.9 MAX + 0.3 MAX rounds), then
    // huge steps again: two of 0.7 MAX overflow as a product, and the time takes the low
    // part at half scale.
    let mut clock = Clock::new(t0);
    let third = T::from_f64(0.3 * max);
    clock.tick(third);
    let wide = T::from_f64(0.7 * max);
    clock.tick(wide);
    clock.tick(wide);
    let exact = Exact(sixteenth(t0), 0.0)
        .plus(1, sixteenth(third))
        .plus(2, sixteenth(wide));
    let e = ulps_of::<T>(sixteenth(clock.time()), exact);
    assert!(e <= BOUND_ULPS, "{e} ulps after huge steps from a restart");
    // From -MAX by MAX / 4100 (small enough to split in f32): at 8192 ticks, a block's
    // base, n dt is nearly 2 MAX. (In f64 a block is 2^26 ticks, and a step small enough to
    // split, below MAX / 2^26, takes as many to overflow: the f32 run covers the same code.)
    if T::EPSILON.to_f64() < 1e-10 {
        return Ok(());
    }
    let t0 = -T::MAX;
    let dt = T::from_f64(max / 4100.0);
    let mut clock = Clock::new(t0);
    let mut exact = Exact(sixteenth(t0), 0.0);
    for block in 0..6 {
        for _ in 0..1366 {
            clock.tick(dt);
        }
        exact = exact.plus(1366, sixteenth(dt));
        let e = ulps_of::<T>(sixteenth(clock.time()), exact);
        assert!(e <= BOUND_ULPS, "{e} ulps in block {block}");
    }
    Ok(())
}

/// A run of 4096 steps of 0.01 s from 10^6 s in `f32`, each step below half an ulp of the
/// time (0.0625 there): the run is refused only when its end does not move, and its end is
/// `10^6 + 40.96` to the rounding of the time.
#[test]
fn steps_below_half_an_ulp_still_add_up() -> Result<(), Error> {
    let p = SimplePendulum::new(1.0f32, 1.0, 9.81, 0.0)?;
    let start = State::new(1e6f32, [0.1], [0.0]);
    let end = Rk4.integrate(&p, &start, 0.01, 4096)?;
    let exact = Exact(1e6, 0.0).plus(4096, f64::from(0.01f32));
    assert!(ulps(end.t, exact) <= BOUND_ULPS, "{}", end.t);
    Ok(())
}

/// A frame of 1.0049 s at 10 ms steps with a cap of 5: five steps, 0.95 s of whole steps
/// dropped, the 4.9 ms left over kept (alpha 0.49), and the next frame of 5.6 ms takes one
/// step with it (alpha 0.05).
fn beyond_the_cap_the_fraction_is_kept<T: Real>() -> Result<(), Error> {
    let dt = T::from_f64(0.01);
    let mut clock = FrameClock::new(dt, 5, T::zero())?;
    assert_eq!(clock.dt(), dt);
    let mut times = Vec::new();
    let frame = clock.advance(T::from_f64(1.0049), |t| {
        times.push(t);
        Ok(())
    })?;
    assert_eq!(frame.steps, 5);
    assert_eq!(times.len(), 5);
    assert_eq!(times[4], clock.time());
    // The accumulator's rounding over five subtractions: a few ulps of 1 s.
    let tol = 16.0 * T::EPSILON.to_f64();
    assert!(
        (frame.dropped.to_f64() - 0.95).abs() < tol,
        "{:?}",
        frame.dropped
    );
    assert!(
        (clock.alpha().to_f64() - 0.49).abs() < 100.0 * tol,
        "{:?}",
        clock.alpha()
    );
    let frame = clock.advance(T::from_f64(0.0056), |_| Ok(()))?;
    assert_eq!((frame.steps, frame.dropped), (1, T::zero()));
    assert!((clock.alpha().to_f64() - 0.05).abs() < 100.0 * tol);
    // A reset starts again at its time with nothing accumulated.
    clock.reset(T::from_f64(5.0))?;
    assert_eq!((clock.time(), clock.alpha()), (T::from_f64(5.0), T::zero()));
    let frame = clock.advance(T::from_f64(0.015), |_| Ok(()))?;
    assert_eq!(frame.steps, 1);
    assert_eq!(clock.time(), T::from_f64(5.0) + dt);
    Ok(())
}

/// At exactly 2^22 whole steps beyond the cap the accumulator is cleared (below, the
/// fraction of a step is kept): a frame of (2^22 + 5.5) steps of 0.25 s, capped at 5,
/// drops all of what is left, 2^22 + 0.5 steps, exactly.
fn at_the_limit_all_is_dropped<T: Real>() -> Result<(), Error> {
    let dt = T::from_f64(0.25);
    let mut clock = FrameClock::new(dt, 5, T::zero())?;
    let frame = clock.advance(T::from_f64((4_194_304.0 + 5.5) * 0.25), |_| Ok(()))?;
    assert_eq!(frame.steps, 5);
    assert_eq!(frame.dropped, T::from_f64((4_194_304.0 + 0.5) * 0.25));
    assert_eq!(clock.alpha(), T::zero());
    // One step fewer beyond the cap, and the half step is kept.
    let mut clock = FrameClock::new(dt, 5, T::zero())?;
    let frame = clock.advance(T::from_f64((4_194_303.0 + 5.5) * 0.25), |_| Ok(()))?;
    assert_eq!(frame.dropped, T::from_f64(4_194_303.0 * 0.25));
    assert_eq!(clock.alpha(), T::HALF);
    Ok(())
}

/// A fixed-timestep driver reset mid-frame starts at the new state's time with nothing
/// accumulated, and reports its step.
fn a_reset_driver_starts_over<T: Real>() -> Result<(), Error> {
    let p = SimplePendulum::new(T::one(), T::one(), T::from_f64(9.81), T::zero())?;
    let dt = T::from_f64(0.01);
    let mut sim = FixedTimestep::new(StormerVerlet::default(), dt, 4, State::at_rest([T::HALF]))?;
    assert_eq!(sim.dt(), dt);
    sim.advance(&p, T::from_f64(0.025))?;
    assert!(sim.alpha() > T::zero());
    let restart = State::new(T::from_f64(5.0), [T::from_f64(0.2)], [T::zero()]);
    sim.reset(restart)?;
    assert_eq!(sim.alpha(), T::zero());
    assert_eq!((sim.current(), sim.previous()), (&restart, &restart));
    let frame = sim.advance(&p, T::from_f64(0.015))?;
    assert_eq!(frame.steps, 1);
    assert_eq!(sim.current().t, T::from_f64(5.0) + dt);
    Ok(())
}

for_f32_and_f64!(
    beyond_the_cap_the_fraction_is_kept,
    at_the_limit_all_is_dropped,
    a_reset_driver_starts_over,
    ticks_are_the_exact_time_rounded,
    a_change_of_step_keeps_the_time,
    huge_steps_across_zero
);
