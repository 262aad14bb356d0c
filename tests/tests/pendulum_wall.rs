//! A pendulum swinging into a wall loses exactly the fraction `1 - e^2` of its kinetic energy
//! at every impact: as one angle with a joint limit, and as Cartesian coordinates whose rod is
//! a bilateral row beside the wall's unilateral one.

use lagrange_core::nalgebra::{SVector, Vector2};
use lagrange_core::{
    Error, EulerLagrange, Holonomic, HolonomicConstraints, Mechanism, Projection, Real, Scalar,
    State,
};
use lagrange_integrators::{ContactModel, ContactStepper, Contacts, Integrator, Rk4};
use lagrange_systems::{CartesianPendulum, SimplePendulum};
use lagrange_tests::{for_f32_and_f64, pick};

const G: f64 = 9.81;
const TH0: f64 = 0.9;
/// The wall stops the swing at 0.3 rad to the right of the vertical: gravity pushes the
/// pendulum into it, so after its bounces it comes to rest against it.
const WALL: f64 = 0.3;
const E: f64 = 0.7;
const DT: f64 = 1e-3;

/// The joint limit `th >= WALL`.
struct JointLimit;

impl<T: Real> HolonomicConstraints<T, 1, 1> for JointLimit {
    fn phi<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 1>) -> SVector<S, 1> {
        SVector::from([q[0] - S::from_f64(WALL)])
    }
}

/// Row 0: the rod, `(x^2 + y^2 - l^2) / (2 l)` with l = 1; row 1: the wall
/// `x >= sin(WALL)`.
struct RodAndWall;

impl<T: Real> HolonomicConstraints<T, 2, 2> for RodAndWall {
    fn phi<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 2>) -> SVector<S, 2> {
        Vector2::new(
            (q[0] * q[0] + q[1] * q[1] - S::one()) * S::from_f64(0.5),
            q[0] - S::from_f64(WALL.sin()),
        )
    }
}

/// The contact model: e = 0.7, resting below 0.05 rad/s (or m/s), events to 1e-10 s (f64) or
/// 1e-6 s (f32).
fn model<T: Real>() -> Result<ContactModel<T>, Error> {
    ContactModel::new(
        T::from_f64(E),
        T::from_f64(0.05),
        T::from_f64(pick::<T>(1e-6, 1e-10)),
    )
}

/// Steps `stepper` on `m` from `start` for 8 s; the kinetic energy ratio after/before of
/// every impact with a rebound (the last, plastic one brings the pendulum to rest against the
/// wall and is left out), and the final state.
fn ratios<T, M, K, const N: usize, const C: usize>(
    m: &M,
    stepper: &mut ContactStepper<T, N, C, Rk4, K>,
    start: State<T, N>,
) -> Result<(Vec<f64>, State<T, N>), Error>
where
    T: Real,
    M: Mechanism<T, N>,
    K: Contacts<T, N, C>,
{
    let mut out = Vec::new();
    let mut s = start;
    for _ in 0..8000 {
        s = stepper.step_observed(m, &s, T::from_f64(DT), |impact| {
            let before = m.kinetic_energy(&impact.state_before()).to_f64();
            let after = m.kinetic_energy(&impact.state_after()).to_f64();
            if !impact.resting.iter().any(|&r| r) {
                out.push(after / before);
            }
        })?;
    }
    Ok((out, s))
}

/// `|ratio - e^2|` over all impacts, after checking there were `at_least` of them.
fn worst_ratio_error(ratios: &[f64], at_least: usize) -> f64 {
    assert!(ratios.len() >= at_least, "{ratios:?}");
    ratios.iter().map(|r| (r - E * E).abs()).fold(0.0, f64::max)
}

/// The angle with a joint limit: one row, one degree of freedom, so each impact reverses
/// `th'` times `e` and the kinetic energy ratio is `e^2` to rounding. Measured: 11 rebounds
/// before the pendulum rests against the wall (resting then holds it at the limit); worst
/// `|ratio - e^2|` 2.2e-16 (f64), 2.2e-7 (f32); bound 8 ulps.
fn joint_limit_keeps_e_squared<T: Real>() -> Result<(), Error> {
    let p = SimplePendulum::new(T::one(), T::one(), T::from_f64(G), T::zero())?;
    let tol = T::from_f64(pick::<T>(1e-6, 1e-12));
    let mut stepper = ContactStepper::new(
        Rk4,
        Holonomic::new(JointLimit),
        model()?,
        Projection::new(tol, 4)?,
    );
    let (r, end) = ratios(&p, &mut stepper, State::at_rest([T::from_f64(TH0)]))?;
    let worst = worst_ratio_error(&r, 5);
    println!(
        "joint limit: {} rebounds, worst |KE+/KE- - e^2| {worst:.1e}",
        r.len()
    );
    assert!(worst <= 8.0 * T::EPSILON.to_f64(), "{worst:e}");
    assert!(stepper.resting()[0] && (end.q[0] - T::from_f64(WALL)).abs() <= tol);
    Ok(())
}

/// The same pendulum in Cartesian coordinates: the free particle (`EulerLagrange` of
/// `CartesianPendulum`'s Lagrangian), the rod a bilateral row, the wall a unilateral one.
/// The impulse acts through both rows; the motion has one degree of freedom, so the ratio is
/// again `e^2`. Measured: 10 rebounds (the resting threshold is now on `x'`, not `th'`);
/// worst `|ratio - e^2|` 1.2e-15 (f64), 3.2e-7 (f32); bound 16 ulps (the 2x2 Schur solve and
/// the projection of the rod row add a few roundings).
fn rod_and_wall_keep_e_squared<T: Real>() -> Result<(), Error> {
    let cp = CartesianPendulum::new(T::one(), T::one(), T::from_f64(G))?;
    let particle = EulerLagrange::new(cp);
    let tol = T::from_f64(pick::<T>(1e-6, 1e-12));
    let mut stepper = ContactStepper::new(
        Rk4,
        Holonomic::new(RodAndWall),
        model()?,
        Projection::new(tol, 4)?,
    )
    .with_bilateral([true, false]);
    let start = cp.state_from_angle(T::zero(), T::from_f64(TH0), T::zero());
    let (r, end) = ratios(&particle, &mut stepper, start)?;
    let worst = worst_ratio_error(&r, 5);
    let (th, _) = cp.angle(&end);
    println!(
        "rod and wall: {} rebounds, worst |KE+/KE- - e^2| {worst:.1e}, rests at {th}",
        r.len()
    );
    assert!(worst <= 16.0 * T::EPSILON.to_f64(), "{worst:e}");
    assert!(stepper.resting()[1] && (th - T::from_f64(WALL)).abs() <= T::from_f64(10.0) * tol);
    Ok(())
}

for_f32_and_f64!(joint_limit_keeps_e_squared, rod_and_wall_keep_e_squared);

/// Both formulations give the same motion: the angle of the Cartesian one against the joint
/// limit's over 2 s (three impacts), RK4 at dt = 1e-3 with impacts located to 1e-10 s.
/// Measured largest difference 3.5e-13 rad (the two RK4 truncation patterns); bound 2e-12 rad.
#[test]
fn both_formulations_agree() -> Result<(), Error> {
    let p = SimplePendulum::new(1.0, 1.0, G, 0.0)?;
    let cp = CartesianPendulum::new(1.0, 1.0, G)?;
    let particle = EulerLagrange::new(cp);
    let projection = Projection::new(1e-13, 4)?;
    let mut angle = ContactStepper::new(Rk4, Holonomic::new(JointLimit), model()?, projection);
    let mut cartesian = ContactStepper::new(Rk4, Holonomic::new(RodAndWall), model()?, projection)
        .with_bilateral([true, false]);
    let mut a = State::at_rest([TH0]);
    let mut c = cp.state_from_angle(0.0, TH0, 0.0);
    let mut worst: f64 = 0.0;
    for _ in 0..2000 {
        a = angle.step(&p, &a, DT)?;
        c = cartesian.step(&particle, &c, DT)?;
        worst = worst.max((cp.angle(&c).0 - a.q[0]).abs());
    }
    println!(
        "angle vs Cartesian through {} impacts: {worst:.2e} rad",
        angle.impacts()
    );
    assert!(angle.impacts() >= 3 && angle.impacts() == cartesian.impacts());
    assert!(worst < 2e-12, "{worst:e}");
    Ok(())
}
