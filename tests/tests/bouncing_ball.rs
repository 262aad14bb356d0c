//! A ball dropped on the ground: bounce heights `e^(2n) h0`, rest in finite simulated time
//! (no Zeno), no penetration, no energy gained at any impact.

use lagrange_core::nalgebra::SVector;
use lagrange_core::State;
use lagrange_core::{Error, Holonomic, HolonomicConstraints, Lagrangian, Projection, Real, Scalar};
use lagrange_integrators::{ContactModel, ContactStepper, Rk4};
use lagrange_systems::FallingParticle;
use lagrange_tests::{for_f32_and_f64, pick};

/// The ground at `y = 0`: gap `g = y`.
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
