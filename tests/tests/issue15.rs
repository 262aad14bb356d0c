//! Issue 15, class by class: each of its reproducers (and a few of their kin) as a test, so
//! that what the redesign fixed and what this issue fixed stays fixed. Calls that once hung run
//! on a thread of their own under a deadline.

use lagrange_core::constraints::{Holonomic, HolonomicConstraints};
use lagrange_core::nalgebra::{SVector, Vector1};
use lagrange_core::{
    Constrained, Error, EulerLagrange, Lagrangian, Mechanism, Real, Scalar, Stabilization, State,
};
use lagrange_integrators::{
    AdaptiveSettings, Clock, DormandPrince54, DormandPrince853, ExplicitEuler, FixedTimestep,
    Integrator, Rk4, StormerVerlet, Yoshida4,
};
use lagrange_systems::exact::{
    damped_oscillator, jacobi_sn_cn, kepler_orbit, pendulum_from_rest, pendulum_period,
};
use lagrange_systems::{
    BeadOnRotatingHoop, CartesianPendulum, FallingParticle, FourBarLinkage, NLinkPendulum,
    SimplePendulum,
};
use lagrange_tests::for_f32_and_f64;
use std::sync::mpsc;
use std::time::Duration;

/// How long a call that once hung may take here (it takes microseconds).
const DEADLINE: Duration = Duration::from_secs(20);

/// `f()` run on a thread of its own; a failed assertion if it does not return within
/// [`DEADLINE`].
fn within<R: Send + 'static>(what: &str, f: impl FnOnce() -> R + Send + 'static) -> R {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    let answer = rx.recv_timeout(DEADLINE);
    assert!(
        answer.is_ok(),
        "{what}: no answer within {DEADLINE:?} (a hang)"
    );
    match answer {
        Ok(r) => r,
        Err(_) => unreachable!(),
    }
}

/// `Err(InvalidParameter { name, .. })` with exactly this name.
fn refuses<V: core::fmt::Debug>(result: Result<V, Error>, expected: &str) {
    assert!(
        matches!(result, Err(Error::InvalidParameter { name, .. }) if name == expected),
        "expected InvalidParameter {{ name: {expected} }}, got {result:?}"
    );
}

// ---------------------------------------------------------------------------------------------
// 1. Adaptive pairs: bounded step growth, no hangs.

/// The reproducer in the redesigned API: a pendulum at rest at its equilibrium (a zero
/// error estimate), 3000 steps of each kind. The step grows tenfold per step only up to the
/// end time: every state is finite, every step size finite, and each run lands on its end.
fn equilibrium_at_rest<T: Real + Send>() -> Result<(), Error> {
    let m = SimplePendulum::new(T::one(), T::one(), T::from_f64(9.81), T::zero())?;
    let settings = AdaptiveSettings::new(T::from_f64(1e-5), T::from_f64(1e-9))?;
    let rest = State::at_rest([T::zero()]);
    // Landings of one second: the internal steps run ahead, no further than needed.
    let mut dp = DormandPrince54::new(settings);
    let mut s = rest;
    for _ in 0..3000 {
        s = dp.step(&m, &s, T::one())?;
        assert!(s.is_finite() && dp.step_size().is_finite());
    }
    assert_eq!(s.t, T::from_f64(3000.0));
    // One step at a time towards an end time near the largest finite time: the step grows to
    // it and stops there.
    let far = T::MAX / T::from_f64(4.0);
    let mut dp = DormandPrince853::new(settings);
    let mut s = rest;
    for _ in 0..3000 {
        s = dp.next_step(&m, &s, far)?;
        assert!(s.is_finite() && dp.step_size().is_finite());
        if s.t == far {
            break;
        }
    }
    assert_eq!(s.t, far, "the end time is reached");
    assert_eq!(s.q[0], T::zero());
    // A whole run there in one call.
    let end = within("integrate_to near T::MAX", move || {
        DormandPrince54::new(settings).integrate_to(&m, &rest, far)
    })?;
    assert_eq!((end.t, end.q[0]), (far, T::zero()));
    Ok(())
}

/// A falling particle: RK methods are exact on its polynomial motion, so its error estimate
/// is zero too; with no minimum step the step still stays bounded, and a run far out either
/// lands or overflows into an error, never a non-finite `Ok` (issue class 4, last case).
fn falling_particle_without_minimum_step<T: Real + Send>() -> Result<(), Error> {
    let m = FallingParticle::new(T::one(), T::from_f64(9.81))?;
    let settings = AdaptiveSettings::new(T::from_f64(1e-5), T::from_f64(1e-9))?
        .with_step_bounds(T::zero(), T::INFINITY)?
        .with_max_steps(5000)?;
    let start = State::at_rest([T::zero()]);
    let mut dp = DormandPrince54::new(settings);
    let mut s = start;
    for _ in 0..3000 {
        let next = dp.step(&m, &s, T::one());
        assert!(
            matches!(next, Ok(n) if n.is_finite()),
            "a finite fall of 3000 s: {next:?}"
        );
        if let Ok(n) = next {
            s = n;
        }
    }
    // Far out the motion itself overflows (y = -g t^2 / 2 with t near T::MAX): an error.
    let far = T::MAX / T::from_f64(2.0);
    let r = within("a fall to T::MAX / 2", move || {
        DormandPrince54::new(settings).integrate_to(&m, &start, far)
    });
    match r {
        Ok(end) => assert!(end.is_finite()),
        Err(f) => assert!(
            matches!(
                f.error,
                Error::NonFiniteState | Error::StepSizeUnderflow | Error::TooManySteps { .. }
            ),
            "{f}"
        ),
    }
    Ok(())
}

/// `integrate_to` an end an ulp (or a few) after a start at `2^50` (f64) or `2^22` (f32),
/// where an ulp of time is a quarter (a half) of a second: it returns at once. A slow
/// pendulum (period 200 s) lands there, in steps of whole ulps of time; a fast one (period
/// 2 s), whose tolerance Dormand-Prince 5(4) cannot meet in steps that long, fails with
/// `StepSizeUnderflow`.
fn end_a_few_ulps_away<T: Real + Send>() -> Result<(), Error> {
    let settings = AdaptiveSettings::new(T::from_f64(1e-5), T::from_f64(1e-9))?;
    let t0 = T::from_f64(if T::EPSILON.to_f64() < 1e-10 {
        1_125_899_906_842_624.0
    } else {
        4_194_304.0
    });
    let ulp = t0 * T::EPSILON;
    for (length, lands) in [(1e4, true), (1.0, false)] {
        let m = SimplePendulum::new(T::one(), T::from_f64(length), T::from_f64(9.81), T::zero())?;
        for k in [1.0, 2.0, 3.0, 10.0] {
            let start = State::new(t0, [T::HALF], [T::zero()]);
            let t_end = t0 + ulp * T::from_f64(k);
            let (run, one) = within("integrate_to a few ulps", move || {
                (
                    DormandPrince54::new(settings).integrate_to(&m, &start, t_end),
                    DormandPrince853::new(settings).next_step(&m, &start, t_end),
                )
            });
            if lands {
                let end = run?;
                assert_eq!(end.t, t_end);
                assert!(end.is_finite());
                let s = one?;
                assert!(s.t > t0 && s.t <= t_end && s.is_finite());
            } else {
                // Dormand-Prince 5(4) cannot meet the tolerance in steps of an ulp of time;
                // DOP853, of order 8, may.
                assert_eq!(run.map_err(|f| f.error), Err(Error::StepSizeUnderflow));
                match one {
                    Ok(s) => assert!(s.t > t0 && s.t <= t_end && s.is_finite()),
                    Err(e) => assert_eq!(e, Error::StepSizeUnderflow),
                }
            }
        }
    }
    Ok(())
}

/// A finite state whose acceleration is finite but whose scale makes Hairer's initial step
/// estimate overflow: the first step falls back to a small one and the run goes on.
fn initial_step_estimate_overflow<T: Real>() -> Result<(), Error> {
    let m = FallingParticle::new(T::one(), T::from_f64(9.81))?;
    let settings = AdaptiveSettings::new(T::from_f64(1e-5), T::from_f64(1e-9))?;
    let big = T::MAX / T::from_f64(16.0);
    let start = State::new(T::zero(), [big], [-big]);
    assert!(m.acceleration(&start)?[0].is_finite());
    let mut dp = DormandPrince54::new(settings);
    let s = dp.next_step(&m, &start, T::from_f64(1e-6))?;
    assert!(s.is_finite());
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// 2. Time that does not advance; exact long-run time.

/// A step that cannot move the clock is `StepSizeUnderflow`: an f32 game clock after hours
/// at 1/120 s, an f64 clock at large times; and every fixed-step method says so.
#[test]
fn a_step_that_cannot_advance_the_time_is_an_error() -> Result<(), Error> {
    let p32 = SimplePendulum::new(1.0f32, 1.0, 9.81, 0.0)?;
    // 2^21 s (24 days): the f32 ulp is 0.25 s, and 1/120 s rounds away.
    let late = State::new(2_097_152.0f32, [0.1], [0.0]);
    let dt = 1.0f32 / 120.0;
    assert_eq!(Rk4.step(&p32, &late, dt), Err(Error::StepSizeUnderflow));
    assert_eq!(
        ExplicitEuler.step(&p32, &late, dt),
        Err(Error::StepSizeUnderflow)
    );
    assert_eq!(
        StormerVerlet::<f32, 1>::default().step(&p32, &late, dt),
        Err(Error::StepSizeUnderflow)
    );
    assert_eq!(
        Rk4.integrate(&p32, &late, dt, 10).map_err(|f| f.error),
        Err(Error::StepSizeUnderflow)
    );
    let p64 = SimplePendulum::new(1.0f64, 1.0, 9.81, 0.0)?;
    let late = State::new(2f64.powi(60), [0.1], [0.0]);
    assert_eq!(Rk4.step(&p64, &late, 1e-3), Err(Error::StepSizeUnderflow));
    // And one that would carry the clock past the largest finite time is not finite.
    let end = State::new(f64::MAX, [0.1], [0.0]);
    assert_eq!(Rk4.step(&p64, &end, f64::MAX), Err(Error::NonFiniteState));
    Ok(())
}

/// The exact clock: 10^7 ticks of 1/120 s in f32 end within an ulp of `n dt` (a plain
/// sum is off by thousands of ulps).
#[test]
fn the_clock_keeps_time() {
    let dt = 1.0f32 / 120.0;
    let n = 10_000_000u64;
    let mut clock = Clock::new(0.0f32);
    let mut plain = 0.0f32;
    for _ in 0..n {
        clock.tick(dt);
        plain += dt;
    }
    let exact = (n as f64 * f64::from(dt)) as f32;
    let ulp = exact * f32::EPSILON;
    assert!(
        (clock.time() - exact).abs() <= ulp,
        "{} vs {exact}",
        clock.time()
    );
    assert!((plain - exact).abs() > 100.0 * ulp, "the plain sum drifts");
}

/// 10^8 f32 steps of 1/120 s (about 9.6 days): the state's time is within an ulp of `n dt`,
/// through `integrate` and through `FixedTimestep` (release: `cargo xtask ci` runs it).
#[test]
#[ignore = "10^8 steps: run in release by cargo xtask ci"]
fn a_long_f32_run_keeps_time() -> Result<(), Error> {
    let m = FallingParticle::new(1.0f32, 0.0)?;
    let dt = 1.0f32 / 120.0;
    let n = 100_000_000u64;
    let start = State::at_rest([0.0f32]);
    let end = ExplicitEuler.integrate(&m, &start, dt, n)?;
    let exact = (n as f64 * f64::from(dt)) as f32;
    assert!(
        (end.t - exact).abs() <= exact * f32::EPSILON,
        "{} vs {exact}",
        end.t
    );
    let mut sim = FixedTimestep::new(ExplicitEuler, dt, 1, start)?;
    for _ in 0..n {
        sim.advance(&m, dt)?;
    }
    let t = sim.current().t;
    assert!((t - exact).abs() <= exact * f32::EPSILON, "{t} vs {exact}");
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// 3. FixedTimestep: no frame time can corrupt it.

/// A huge frame time (the largest finite one, a pause in a debugger) is dropped whole and
/// reported finite; frames of exactly `dt` then take one step each. Negative and non-finite
/// frame times are refused and change nothing.
fn fixed_timestep_survives_any_frame_time<T: Real>() -> Result<(), Error> {
    let m = SimplePendulum::new(T::one(), T::one(), T::from_f64(9.81), T::zero())?;
    let dt = T::from_f64(1.0 / 120.0);
    let mut sim = FixedTimestep::new(StormerVerlet::default(), dt, 4, State::at_rest([T::HALF]))?;
    for huge in [T::MAX, T::from_f64(3600.0), T::MAX / T::from_f64(3.0)] {
        let frame = sim.advance(&m, huge)?;
        assert_eq!(frame.steps, 4);
        assert!(frame.dropped.is_finite() && frame.dropped > T::zero());
        for _ in 0..100 {
            let frame = sim.advance(&m, dt)?;
            assert_eq!((frame.steps, frame.dropped), (1, T::zero()));
        }
    }
    let before = *sim.current();
    let alpha = sim.alpha();
    for bad in [-dt, T::from_f64(f64::NAN), T::INFINITY, -T::INFINITY] {
        refuses(sim.advance(&m, bad), "frame_time");
        assert_eq!((*sim.current(), sim.alpha()), (before, alpha));
    }
    Ok(())
}

/// A frame whose step fails is refused whole: states, time and accumulated time as before.
fn a_failing_frame_changes_nothing<T: Real>() -> Result<(), Error> {
    // A spring so stiff that explicit Euler blows up within a frame of many steps.
    let m = EulerLagrange::new(Stiff(T::from_f64(1e30)));
    let dt = T::from_f64(0.1);
    let mut sim = FixedTimestep::new(ExplicitEuler, dt, 64, State::at_rest([T::one()]))?;
    let before = (*sim.current(), *sim.previous(), sim.alpha());
    assert!(sim.advance(&m, T::from_f64(6.4)).is_err());
    assert_eq!((*sim.current(), *sim.previous(), sim.alpha()), before);
    Ok(())
}

/// `T = q'^2 / 2`, `V = k q^2 / 2`: a unit mass on a spring of stiffness `k`.
struct Stiff<T>(T);

impl<T: Real> Lagrangian<T, 1> for Stiff<T> {
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, _q: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
        qd[0] * qd[0] * T::HALF
    }
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 1>) -> S {
        q[0] * q[0] * (T::HALF * self.0)
    }
}

// ---------------------------------------------------------------------------------------------
// 4. Ok with NaN or infinity from finite inputs.

/// Parameters whose products leave the range of `T` are refused, naming the responsible one.
#[test]
fn products_out_of_range_are_refused() {
    refuses(SimplePendulum::new(1.0, 5e-324, 9.81, 0.0), "length");
    refuses(SimplePendulum::new(1e300, 1e10, 9.81, 0.0), "mass");
    refuses(SimplePendulum::new(1e-10, 1.0, 9.81, 1e308), "damping");
    refuses(BeadOnRotatingHoop::new(1.0, 1.0, -f64::MAX, 9.81), "omega");
    refuses(BeadOnRotatingHoop::new(1.0f32, 1.0, 1e20, 9.81), "omega");
    refuses(SimplePendulum::new(1.0f32, 1e-30, 9.81, 0.0), "length");
    refuses(
        NLinkPendulum::new([1.0, 1.0, 1.0], [1.0, 1e-320, 1.0], 9.81),
        "lengths[1]",
    );
    refuses(Stabilization::<f64>::critical(1e200), "rate");
}

/// A user's Lagrangian, force or constraint that returns NaN is an error through every path:
/// the acceleration, the mass solve, the law and the constrained solve.
fn user_nan_is_an_error<T: Real>() -> Result<(), Error> {
    let nan = T::from_f64(f64::NAN);
    let s = State::new(T::zero(), [T::HALF], [T::one()]);
    // A Lagrangian with a NaN stiffness or mass.
    {
        let m = EulerLagrange::new(Stiff(nan));
        assert_eq!(m.acceleration(&s), Err(Error::NonFiniteState));
        assert_eq!(
            m.law(&s, &lagrange_core::NoForce),
            Err(Error::NonFiniteState)
        );
        assert!(m.solve_mass(&s, &Vector1::new(nan)).is_err());
        assert!(m.acceleration_jacobian(&s).is_err());
    }
    // A force that returns NaN.
    let p = SimplePendulum::new(T::one(), T::one(), T::from_f64(9.81), T::zero())?;
    let pushed = p.with_force(move |_: &State<T, 1>| Vector1::new(nan));
    assert_eq!(pushed.acceleration(&s), Err(Error::NonFiniteState));
    assert_eq!(
        pushed.law(&s, &lagrange_core::NoForce),
        Err(Error::NonFiniteState)
    );
    assert!(pushed.law_force(&s, &lagrange_core::NoForce).is_err());
    // A constraint that returns NaN.
    let held = EulerLagrange::new(Plane).held_by(Holonomic::new(NanCircle(nan)));
    let s2 = State::new(T::zero(), [T::one(), T::zero()], [T::zero(), T::one()]);
    assert!(held.acceleration(&s2).is_err());
    assert!(held.solve(&s2).is_err());
    Ok(())
}

/// A unit point mass in the plane, no forces.
struct Plane;

impl<T: Real> Lagrangian<T, 2> for Plane {
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, _q: &SVector<S, 2>, v: &SVector<S, 2>) -> S {
        (v[0] * v[0] + v[1] * v[1]) * T::HALF
    }
    fn potential<S: Scalar<Real = T>>(&self, _t: S, _q: &SVector<S, 2>) -> S {
        S::zero()
    }
}

/// A circle whose radius is NaN.
struct NanCircle<T>(T);

impl<T: Real> HolonomicConstraints<T, 2, 1> for NanCircle<T> {
    fn phi<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 2>) -> SVector<S, 1> {
        Vector1::new((q[0] * q[0] + q[1] * q[1]) * self.0)
    }
}

/// The exact solutions return finite values or an error, for finite arguments.
#[test]
fn exact_solutions_are_finite_or_errors() {
    let r = damped_oscillator(1.0, 4.0, 1.0, 1.0, 0.0, f64::MIN);
    assert!(r.is_err(), "{r:?}");
    for (u, k) in [
        (f64::MAX, 0.5),
        (1e308, 0.9),
        (-f64::MAX, 0.0),
        (1e300, 0.999),
    ] {
        let r = jacobi_sn_cn(u, k);
        assert!(
            matches!(r, Ok((s, c)) if s.is_finite() && c.is_finite())
                || matches!(r, Err(Error::InvalidParameter { name: "u", .. })),
            "{r:?}"
        );
    }
    let near_pi = core::f64::consts::PI - 1e-14;
    for (theta0, omega) in [(3.0, 1e-308), (near_pi, 1.0), (1.0, 5e-324)] {
        let r = pendulum_period(theta0, omega);
        assert!(matches!(r, Ok(p) if p.is_finite()) || r.is_err(), "{r:?}");
    }
    for t in [f64::MAX, -f64::MAX, 1e300] {
        let r = pendulum_from_rest(1.0, 3.0, t);
        assert!(
            matches!(r, Ok((a, b)) if a.is_finite() && b.is_finite()) || r.is_err(),
            "{r:?}"
        );
        let r = kepler_orbit(1.0, 1.0, 0.5, t);
        assert!(matches!(r, Ok(s) if s.is_finite()) || r.is_err(), "{r:?}");
    }
    let r = kepler_orbit(1e300, 1e-200, 0.5, 1.0);
    assert!(matches!(r, Ok(s) if s.is_finite()) || r.is_err(), "{r:?}");
}

// ---------------------------------------------------------------------------------------------
// 5. Errors that name the caller's own parameter.

#[test]
fn errors_name_the_callers_parameters() {
    // The pendulum's phase omega t overflows: omega or t, never the internal u.
    let r = pendulum_from_rest(1.0, 2.0, f64::MAX);
    refuses(r, "t");
    let r = pendulum_from_rest(1.0, f64::MAX, 2.0);
    refuses(r, "omega");
    // An amplitude so close to pi that the modulus rounds to 1: theta0, never k.
    refuses(pendulum_period(3.141_592_5f32, 1.0), "theta0");
    refuses(pendulum_from_rest(3.141_592_5f32, 1.0, 0.5), "theta0");
    // An amplitude that is no amplitude.
    refuses(pendulum_period(1e15, 3.0), "theta0");
    // The mean anomaly n t overflows: t (or mu, semi_major_axis), never mean_anomaly.
    refuses(kepler_orbit(4.0, 1.0, 0.5, f64::MAX), "t");
    refuses(kepler_orbit(1e300, 1e-3, 0.5, 1e10), "mu");
    refuses(kepler_orbit(1.0, 1e-200, 0.5, 1.0), "semi_major_axis");
    // A step so small that the stabilisation rate overflows: dt, never rate; valid steps pass.
    refuses(Stabilization::<f64>::for_step(1e-300), "dt");
    assert!(Stabilization::<f64>::for_step(1e-6).is_ok());
    assert!(Stabilization::<f32>::for_step(1e-6).is_ok());
    // Array entries by index.
    refuses(
        NLinkPendulum::new([1.0; 3], [1.0, -1.0, 1.0], 9.81),
        "lengths[1]",
    );
    refuses(
        FourBarLinkage::new([1.0, 0.3, f64::NAN, 0.8], [1.0; 3], 9.81),
        "lengths[2]",
    );
    refuses(
        FourBarLinkage::new([1.0, 0.3, 1.0, 0.8], [1.0, 0.0, 1.0], 9.81),
        "masses[1]",
    );
}

/// A four-bar linkage whose longest link is longer than the other three together closes at
/// no crank angle: refused by `new`, naming that link. One that can close is accepted and
/// assembles somewhere.
#[test]
fn a_linkage_that_cannot_close_is_refused() -> Result<(), Error> {
    refuses(
        FourBarLinkage::new([10.0, 1.0, 2.0, 3.0], [1.0; 3], 9.81),
        "lengths[0]",
    );
    refuses(
        FourBarLinkage::new([1.0, 0.5, 5.0, 1.0], [1.0; 3], 9.81),
        "lengths[2]",
    );
    let ok = FourBarLinkage::new([1.0, 0.3, 1.0, 0.8], [1.0; 3], 9.81)?;
    assert!(ok
        .assemble(0.0, 0.5, 0.0, lagrange_systems::Branch::Right)
        .is_ok());
    Ok(())
}

/// A Cartesian pendulum with its bob at the pivot: row 0 is singular, and the message says
/// so (no row comes before it).
#[test]
fn a_singular_first_row_is_reported_as_singular() -> Result<(), Error> {
    let c = Constrained::new(CartesianPendulum::new(1.0, 1.0, 9.81)?);
    let at_pivot = State::new(0.0, [0.0, 0.0], [0.0, 0.0]);
    let e = c.acceleration(&at_pivot);
    assert_eq!(e, Err(Error::RedundantConstraints { row: 0 }));
    let text = Error::RedundantConstraints { row: 0 }.to_string();
    assert!(!text.contains("before"), "{text}");
    assert!(text.contains("singular"), "{text}");
    assert!(Error::RedundantConstraints { row: 2 }
        .to_string()
        .contains("before"));
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// 6. Consistent acceptance.

/// Yoshida's `integrate` accepts what its `step` accepts, and a run of no steps checks `dt`
/// and the state as a step does.
fn acceptance_is_consistent<T: Real>() -> Result<(), Error> {
    let m = SimplePendulum::new(T::one(), T::one(), T::from_f64(9.81), T::zero())?;
    let s = State::at_rest([T::HALF]);
    for dt in [
        T::from_f64(1e-3),
        T::from_f64(0.7),
        T::from_f64(1e-30),
        T::EPSILON,
    ] {
        let mut a = Yoshida4::<StormerVerlet<T, 1>>::default();
        let mut b = Yoshida4::<StormerVerlet<T, 1>>::default();
        let three_steps = a
            .step(&m, &s, dt)
            .and_then(|x| a.step(&m, &x, dt))
            .and_then(|x| a.step(&m, &x, dt));
        let run = b.integrate(&m, &s, dt, 3).map_err(|f| f.error);
        assert_eq!(three_steps.is_ok(), run.is_ok(), "dt = {dt:?}");
    }
    for bad in [T::zero(), -T::one(), T::from_f64(f64::NAN), T::INFINITY] {
        refuses(Rk4.integrate(&m, &s, bad, 0).map_err(|f| f.error), "dt");
        refuses(
            Yoshida4::<StormerVerlet<T, 1>>::default()
                .integrate(&m, &s, bad, 0)
                .map_err(|f| f.error),
            "dt",
        );
    }
    let nan = State::new(T::zero(), [T::from_f64(f64::NAN)], [T::zero()]);
    assert_eq!(
        Rk4.integrate(&m, &nan, T::from_f64(1e-3), 0)
            .map_err(|f| f.error),
        Err(Error::NonFiniteState)
    );
    Ok(())
}

for_f32_and_f64!(
    equilibrium_at_rest,
    falling_particle_without_minimum_step,
    end_a_few_ulps_away,
    initial_step_estimate_overflow,
    fixed_timestep_survives_any_frame_time,
    a_failing_frame_changes_nothing,
    user_nan_is_an_error,
    acceptance_is_consistent,
);
