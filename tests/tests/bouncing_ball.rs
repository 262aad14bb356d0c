//! A ball dropped on the ground: bounce heights `e^(2n) h0`, rest in finite simulated time
//! (no Zeno), no penetration, no energy gained at any impact.

use lagrange_core::nalgebra::SVector;
use lagrange_core::State;
use lagrange_core::{Error, Holonomic, HolonomicConstraints, Lagrangian, Projection, Real, Scalar};
use lagrange_integrators::{ContactModel, ContactStepper, Integrator, Method, Rk4};
use lagrange_systems::FallingParticle;
use lagrange_tests::{for_f32_and_f64, pick};

/// The ground at `y = 0`: gap `g = y`.
#[derive(Clone, Copy)]
struct Ground;

impl<T: Real> HolonomicConstraints<T, 1, 1> for Ground {
    fn phi<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 1>) -> SVector<S, 1> {
        *q
    }
}

const G: f64 = 9.81;
const H0: f64 = 1.0;
const E: f64 = 0.8;
/// 5 g dt: a bounce slower than this lasts under ten steps.
const REST_SPEED: f64 = 0.05;
const DT: f64 = 1e-3;

/// Dropped from 1 m with e = 0.8, RK4 at dt = 1e-3 (exact for the parabolas between impacts),
/// impacts located to 1e-10 s (f64) or 1e-6 s (f32: below that the bisection meets the
/// resolution of t ~ 1 s).
///
/// - Apex after impact n (highest sampled `y` between impacts) against `e^(2n) h0`: the
///   sampling misses the apex by at most `g dt^2 / 8 = 1.2e-6 m` (measured worst 1.2e-6 m in
///   f64); bound 2e-6 m. In f32 an impact located up to 1e-6 s early, at a gap `d` of up to
///   4e-6 m, also shifts the next apex by `d (1 - e^2)` (measured worst 1.1e-6 m); bound
///   5e-6 m.
/// - Rest: the rebound falls below 0.05 m/s after 20 bounces; the ball rests after
///   `t0 (1 + 2 (e + ... + e^20)) = 4.022 s` (`t0 = sqrt(2 h0 / g)`), measured 4.023 s;
///   asserted: resting before 4.1 s and still resting, at `y = 0` and `y' = 0` to the
///   projection's tolerance, at 6 s; 21 impacts in all.
/// - Depth: `y` never below `-1e-12 m` (f64) or `-1e-6 m` (f32), the projection tolerance.
/// - Energy: kinetic energy after each impact at most `e^2` times the one before, to
///   rounding (8 ulps).
fn ball_bounces_to_rest<T: Real>() -> Result<(), Error> {
    let ball = FallingParticle::new(T::one(), T::from_f64(G))?;
    let tol = T::from_f64(pick::<T>(1e-6, 1e-12));
    let model = ContactModel::new(
        T::from_f64(E),
        T::from_f64(REST_SPEED),
        T::from_f64(pick::<T>(1e-6, 1e-10)),
    )?;
    let mut stepper =
        ContactStepper::new(Rk4, Holonomic::new(Ground), model, Projection::new(tol, 4)?);
    let mut s = State::at_rest([T::from_f64(H0)]);
    let mut apexes: Vec<f64> = Vec::new();
    // The highest y since the last impact (none before the first).
    let mut since_impact: Option<f64> = None;
    let (mut deepest, mut rest_time) = (f64::INFINITY, None);
    let mut worst_energy_ratio = f64::NEG_INFINITY;
    for _ in 0..6000 {
        let mut impacted = false;
        s = stepper.step_observed(&ball, &s, T::from_f64(DT), |impact| {
            impacted = true;
            let before = ball.kinetic_energy(&impact.state_before()).to_f64();
            let after = ball.kinetic_energy(&impact.state_after()).to_f64();
            worst_energy_ratio = worst_energy_ratio.max(after / before);
        })?;
        let y = s.q[0].to_f64();
        if impacted {
            apexes.extend(since_impact);
            since_impact = Some(y);
        }
        since_impact = since_impact.map(|h| h.max(y));
        deepest = deepest.min(y);
        if rest_time.is_none() && stepper.resting()[0] {
            rest_time = Some(s.t.to_f64());
        }
    }
    let worst_height = apexes
        .iter()
        .zip(1..)
        .map(|(h, n)| (h - E.powi(2 * n) * H0).abs())
        .fold(0.0, f64::max);
    println!(
        "ball: {} impacts, {} apexes, worst apex error {worst_height:.2e} m, rest at {:?} s, \
         deepest {deepest:.2e} m, max KE ratio {worst_energy_ratio:.6} (e^2 = {})",
        stepper.impacts(),
        apexes.len(),
        rest_time,
        E * E
    );
    assert_eq!(apexes.len(), 20, "{apexes:?}");
    assert!(worst_height < pick::<T>(5e-6, 2e-6), "{worst_height:e}");
    assert!(rest_time.is_some_and(|t| t < 4.1), "{rest_time:?}");
    assert_eq!(stepper.impacts(), 21);
    assert!(stepper.resting()[0]);
    assert!(s.q[0].abs() <= tol && s.qd[0].abs() <= tol, "{s:?}");
    assert!(deepest >= -tol.to_f64(), "{deepest:e}");
    assert!(
        worst_energy_ratio <= E * E * (1.0 + 8.0 * T::EPSILON.to_f64()),
        "{worst_energy_ratio}"
    );
    Ok(())
}

for_f32_and_f64!(ball_bounces_to_rest);

/// The ground written twice (two rows `y >= 0`, the same units so that the resting threshold
/// means the same on both): more contact rows than degrees of freedom, dependent.
struct GroundTwice;

impl HolonomicConstraints<f64, 1, 2> for GroundTwice {
    fn phi<S: Scalar<Real = f64> + 'static>(&self, q: &SVector<S, 1>) -> SVector<S, 2> {
        SVector::from([q[0], q[0]])
    }
}

/// Redundant contacts are no error: each impact and each resting phase leaves out the
/// dependent row, and the ball bounces exactly as on the single ground (the same 21 impacts and
/// the same states: measured identical; bound 1e-12 m).
#[test]
fn redundant_contacts_are_left_out() -> Result<(), Error> {
    let ball = FallingParticle::new(1.0, G)?;
    let model = ContactModel::new(E, REST_SPEED, 1e-10)?;
    let projection = Projection::new(1e-12, 4)?;
    let mut once = ContactStepper::new(Rk4, Holonomic::new(Ground), model, projection);
    let mut twice = ContactStepper::new(Rk4, Holonomic::new(GroundTwice), model, projection);
    let (mut a, mut b) = (State::at_rest([H0]), State::at_rest([H0]));
    let mut worst: f64 = 0.0;
    for _ in 0..6000 {
        a = lagrange_integrators::Integrator::step(&mut once, &ball, &a, DT)?;
        b = lagrange_integrators::Integrator::step(&mut twice, &ball, &b, DT)?;
        worst = worst.max((a.q[0] - b.q[0]).abs());
    }
    println!(
        "ground once vs twice: {} and {} impacts, largest difference {worst:.1e} m",
        once.impacts(),
        twice.impacts()
    );
    assert_eq!(once.impacts(), twice.impacts());
    assert!(worst < 1e-12, "{worst:e}");
    assert!(twice.resting().iter().any(|&r| r));
    Ok(())
}

/// The ball for the exact figures below: unit mass, `g = 2`, so that from 1 m at rest
/// `y = 1 - t^2` and `y' = -2 t`; RK4 is exact for the parabola, and at the dyadic times of a
/// bisection of a dyadic step every figure is a short binary fraction, exact in `f32` too.
fn dyadic_ball<T: Real>() -> Result<FallingParticle<T>, Error> {
    FallingParticle::new(T::one(), T::TWO)
}

/// Steps `stepper` once from `start` by `dt`, recording every impact: the end state and the
/// impacts (time, height and velocity before, velocity after).
fn step_recorded<T: Real, K: lagrange_integrators::Contacts<T, 1, C>, const C: usize>(
    stepper: &mut ContactStepper<T, 1, C, Rk4, K>,
    ball: &FallingParticle<T>,
    start: &State<T, 1>,
    dt: f64,
) -> (Result<State<T, 1>, Error>, Vec<[f64; 4]>) {
    let mut impacts = Vec::new();
    let end = stepper.step_observed(ball, start, T::from_f64(dt), |i| {
        impacts.push([
            i.t.to_f64(),
            i.q[0].to_f64(),
            i.before[0].to_f64(),
            i.after[0].to_f64(),
        ]);
    });
    (end, impacts)
}

/// The bisection stops when its bracket is no longer than the time tolerance, and the impact
/// is at the bracket's early end. The ball above from 1 m, one step of 1.25 s, tolerance
/// 0.078125 s (2^-4 + 2^-6: a bracket width the bisection of 1.25 s reaches): the brackets
/// are [0, 1.25], [0.625, 1.25], [0.9375, 1.25], [0.9375, 1.09375], [0.9375, 1.015625]
/// (crossing at 1 s), and the last, 0.078125 s long, ends it: the impact at t = 0.9375 s, where
/// `y = 0.12109375` and `y' = -1.875` (the contact open by `|y'|` times the tolerance at most),
/// rebounds at `e = 0.5` to 0.9375 m/s, and the 0.3125 s left take it to `y = 0.31640625`,
/// `y' = 0.3125`. Exact (dyadic figures), asserted to 4 ulps; one more halving would have put
/// the impact at 0.9765625 s, a bisection to the resolution of `T` at 1 s.
fn bisection_stops_at_the_time_tolerance<T: Real>() -> Result<(), Error> {
    let ball = dyadic_ball::<T>()?;
    let model = ContactModel::new(T::HALF, T::from_f64(0.05), T::from_f64(0.078125))?;
    let projection = Projection::new(T::from_f64(pick::<T>(1e-6, 1e-12)), 4)?;
    let mut stepper = ContactStepper::new(Rk4, Holonomic::new(Ground), model, projection);
    let (end, impacts) = step_recorded(&mut stepper, &ball, &State::at_rest([T::one()]), 1.25);
    let end = end?;
    let ulps = 4.0 * T::EPSILON.to_f64();
    assert_eq!(impacts.len(), 1, "{impacts:?}");
    for (got, want) in impacts[0].iter().zip([0.9375, 0.12109375, -1.875, 0.9375]) {
        assert!((got - want).abs() <= ulps, "{impacts:?}");
    }
    let (y, v) = (end.q[0].to_f64(), end.qd[0].to_f64());
    assert!(
        (y - 0.31640625).abs() <= ulps && (v - 0.3125).abs() <= ulps,
        "{end:?}"
    );
    assert_eq!(stepper.impacts(), 1);
    Ok(())
}

/// A time tolerance finer than the resolution of `T` (1e-30 s) still ends: the bisection
/// stops when the midpoint of its bracket rounds to one of its ends. The ball above, one
/// step of 1.25 s: the impact is at the crossing, t = 1 s, to the resolution of `T` (2 ulps
/// of 1), where the gap is at most the rounding of `y = 1 - t^2` (8 ulps of 1 m) and not
/// below zero.
fn a_time_tolerance_below_the_resolution_ends<T: Real>() -> Result<(), Error> {
    let ball = dyadic_ball::<T>()?;
    let model = ContactModel::new(T::HALF, T::from_f64(0.05), T::from_f64(1e-30))?;
    let projection = Projection::new(T::from_f64(pick::<T>(1e-6, 1e-12)), 4)?;
    let mut stepper = ContactStepper::new(Rk4, Holonomic::new(Ground), model, projection);
    let (end, impacts) = step_recorded(&mut stepper, &ball, &State::at_rest([T::one()]), 1.25);
    end?;
    let eps = T::EPSILON.to_f64();
    assert_eq!(impacts.len(), 1, "{impacts:?}");
    let [t, y, before, after] = impacts[0];
    assert!((t - 1.0).abs() <= 2.0 * eps, "{impacts:?}");
    assert!((0.0..=8.0 * eps).contains(&y), "{impacts:?}");
    assert!((before + 2.0).abs() <= 8.0 * eps && (after - 1.0).abs() <= 8.0 * eps);
    Ok(())
}

/// A step that ends exactly on the ground has not crossed it (a crossing is a gap below
/// zero): the ball above from 1 m, one step of 1 s ends at `y = 0`, `y' = -2` (exact) with no
/// impact. The next step finds the crossing at its start: the impact at t = 1 s, `y = 0`,
/// from -2 m/s to 1 m/s (`e = 0.5`).
fn ending_on_the_ground_is_no_crossing<T: Real>() -> Result<(), Error> {
    let ball = dyadic_ball::<T>()?;
    let model = ContactModel::new(
        T::HALF,
        T::from_f64(0.05),
        T::from_f64(pick::<T>(1e-6, 1e-10)),
    )?;
    let projection = Projection::new(T::from_f64(pick::<T>(1e-6, 1e-12)), 4)?;
    let mut stepper = ContactStepper::new(Rk4, Holonomic::new(Ground), model, projection);
    let (end, impacts) = step_recorded(&mut stepper, &ball, &State::at_rest([T::one()]), 1.0);
    let end = end?;
    assert!(impacts.is_empty(), "{impacts:?}");
    assert_eq!((end.q[0].to_f64(), end.qd[0].to_f64()), (0.0, -2.0));
    assert_eq!(stepper.impacts(), 0);
    let (_, impacts) = step_recorded(&mut stepper, &ball, &end, 0.25);
    assert_eq!(impacts, vec![[1.0, 0.0, -2.0, 1.0]]);
    Ok(())
}

/// Two walls, at `x = 0` and `x = 1`: rows `x >= 0` and `1 - x >= 0`.
#[derive(Clone, Copy)]
struct Walls;

impl<T: Real> HolonomicConstraints<T, 1, 2> for Walls {
    fn phi<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 1>) -> SVector<S, 2> {
        SVector::from([q[0], S::one() - q[0]])
    }
}

/// A free particle (no gravity) between the walls, elastic (`e = 1`), from `x = 0.25` at
/// `v` m/s for one step of 1 s: `v` impacts in the step (one at each whole metre travelled).
/// With two rows a step takes at most `4 C + 8 = 16` events: at 16 m/s the step is taken and
/// ends where the walls' reflections put it, `x = 0.25`, `v = 16` (16 reflections; each
/// impact located up to the time tolerance early shifts the path by at most twice `v` times
/// it: 16 x 32 x 1e-10 m in f64, x 1e-6 m in f32); at 17 m/s the 17th impact is an error,
/// `NoConvergence` with 17 iterations, after the observer saw 17 impacts, and the stepper is
/// as it was (no impact counted).
fn events_beyond_the_cap_are_an_error<T: Real>() -> Result<(), Error> {
    let particle = FallingParticle::new(T::one(), T::zero())?;
    let tolerance = pick::<T>(1e-6, 1e-10);
    let model = ContactModel::new(T::one(), T::from_f64(0.05), T::from_f64(tolerance))?;
    let projection = Projection::new(T::from_f64(pick::<T>(1e-6, 1e-12)), 4)?;
    let mut stepper = ContactStepper::new(Rk4, Holonomic::new(Walls), model, projection);
    let start = State::new(T::zero(), [T::from_f64(0.25)], [T::from_f64(16.0)]);
    let (end, impacts) = step_recorded(&mut stepper, &particle, &start, 1.0);
    let end = end?;
    assert_eq!(impacts.len(), 16);
    assert_eq!(stepper.impacts(), 16);
    let shift = 16.0 * 32.0 * tolerance + 64.0 * T::EPSILON.to_f64();
    assert!((end.q[0].to_f64() - 0.25).abs() <= shift, "{end:?}");
    assert!(
        (end.qd[0].to_f64() - 16.0).abs() <= 64.0 * T::EPSILON.to_f64(),
        "{end:?}"
    );
    let mut fresh = ContactStepper::new(Rk4, Holonomic::new(Walls), model, projection);
    let start = State::new(T::zero(), [T::from_f64(0.25)], [T::from_f64(17.0)]);
    let (end, impacts) = step_recorded(&mut fresh, &particle, &start, 1.0);
    assert_eq!(end, Err(Error::NoConvergence { iterations: 17 }));
    assert_eq!(impacts.len(), 17);
    assert_eq!(fresh.impacts(), 0);
    Ok(())
}

/// A start state is checked: a contact deeper than the projection's tolerance is refused
/// (`ConstraintViolated`, row 0), one within it is not; a bilateral row must hold in position
/// and in velocity, each to the tolerance. A stepper turned bilateral by `with_bilateral`
/// forgets the state it would continue from, and checks the next start: the ball that fell
/// freely for half a second from 0.765625 m is 0.515625 m off the row it is now held to.
fn start_states_are_checked<T: Real>() -> Result<(), Error> {
    let ball = dyadic_ball::<T>()?;
    let tol = pick::<T>(1e-6, 1e-12);
    let model = ContactModel::new(
        T::HALF,
        T::from_f64(0.05),
        T::from_f64(pick::<T>(1e-6, 1e-10)),
    )?;
    let projection = Projection::new(T::from_f64(tol), 4)?;
    let unilateral = ContactStepper::new(Rk4, Holonomic::new(Ground), model, projection);
    let bilateral = unilateral.with_bilateral([true]);
    let at = |y: f64, v: f64| State::new(T::zero(), [T::from_f64(y)], [T::from_f64(v)]);
    let dt = T::from_f64(0.125);
    let refused = Err(Error::ConstraintViolated { row: 0 });
    // A step of a fresh copy of `stepper` from `y`, `v`.
    let first = |mut stepper: ContactStepper<T, 1, 1, Rk4, _>, y: f64, v: f64| {
        stepper.step(&ball, &at(y, v), dt)
    };
    assert_eq!(first(unilateral, -2.0 * tol, 0.0), refused);
    assert!(first(unilateral, -0.5 * tol, 0.0).is_ok());
    assert_eq!(first(bilateral, 2.0 * tol, 0.0), refused);
    assert_eq!(first(bilateral, 0.0, 2.0 * tol), refused);
    let held = first(bilateral, 0.5 * tol, 0.5 * tol)?;
    assert!(
        held.q[0].to_f64().abs() <= tol && held.qd[0].to_f64().abs() <= tol,
        "{held:?}"
    );
    let mut stepper = unilateral;
    let fallen = stepper.step(&ball, &at(0.765625, 0.0), T::HALF)?;
    assert_eq!(fallen.q[0].to_f64(), 0.515625);
    let mut stepper = stepper.with_bilateral([true]);
    assert_eq!(stepper.step(&ball, &fallen, dt), refused);
    Ok(())
}

/// A contact below zero (within the tolerance) that does not go deeper has not crossed: a
/// particle with no gravity at rest at `y = -tol / 2` steps with no impact, and stays there
/// (RK4 of no motion: the same bits).
fn resting_within_the_tolerance_is_no_crossing<T: Real>() -> Result<(), Error> {
    let particle = FallingParticle::new(T::one(), T::zero())?;
    let tol = pick::<T>(1e-6, 1e-12);
    let model = ContactModel::new(
        T::HALF,
        T::from_f64(0.05),
        T::from_f64(pick::<T>(1e-6, 1e-10)),
    )?;
    let projection = Projection::new(T::from_f64(tol), 4)?;
    let mut stepper = ContactStepper::new(Rk4, Holonomic::new(Ground), model, projection);
    let start = State::at_rest([T::from_f64(-0.5 * tol)]);
    let (end, impacts) = step_recorded(&mut stepper, &particle, &start, 0.125);
    let end = end?;
    assert!(impacts.is_empty(), "{impacts:?}");
    assert_eq!(stepper.impacts(), 0);
    assert!(
        (-tol..=0.0).contains(&end.q[0].to_f64()) && end.qd[0] == T::zero(),
        "{end:?}"
    );
    Ok(())
}

/// The work of a step is the inner integrator's last step's: RK4's four evaluations in one
/// step, after a step in free flight.
fn last_step_is_the_inner_methods<T: Real>() -> Result<(), Error> {
    let ball = dyadic_ball::<T>()?;
    let model = ContactModel::new(
        T::HALF,
        T::from_f64(0.05),
        T::from_f64(pick::<T>(1e-6, 1e-10)),
    )?;
    let projection = Projection::new(T::from_f64(pick::<T>(1e-6, 1e-12)), 4)?;
    let mut stepper = ContactStepper::new(Rk4, Holonomic::new(Ground), model, projection);
    stepper.step(&ball, &State::at_rest([T::one()]), T::from_f64(0.125))?;
    let work = Method::last_step(&stepper);
    assert_eq!(work, Method::last_step(&Rk4));
    assert_eq!((work.evaluations, work.steps), (4, 1));
    Ok(())
}

for_f32_and_f64!(
    bisection_stops_at_the_time_tolerance,
    a_time_tolerance_below_the_resolution_ends,
    ending_on_the_ground_is_no_crossing,
    events_beyond_the_cap_are_an_error,
    start_states_are_checked,
    resting_within_the_tolerance_is_no_crossing,
    last_step_is_the_inner_methods
);
