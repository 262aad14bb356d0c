//! Bad input to constraints and impacts gives a specific error: parameters out of range,
//! inconsistent initial states, redundant or singular constraints, non-finite states.

use lagrange_core::constraints::Stabilization;
use lagrange_core::nalgebra::{SVector, Vector2};
use lagrange_core::{
    Constrained, Error, EulerLagrange, Holonomic, HolonomicConstraints, Mechanism, Projection,
    Real, Scalar, State,
};
use lagrange_integrators::{ContactModel, ContactStepper, Integrator, Projected, Rk4};
use lagrange_systems::{Branch, CartesianPendulum, FallingParticle, FourBarLinkage, RollingDisk};
use lagrange_tests::for_f32_and_f64;

/// `Err(InvalidParameter { name, .. })` with exactly this name.
fn refuses<V: core::fmt::Debug>(result: Result<V, Error>, expected: &str) {
    assert!(
        matches!(result, Err(Error::InvalidParameter { name, .. }) if name == expected),
        "expected InvalidParameter {{ name: {expected} }}, got {result:?}"
    );
}

fn parameters_are_checked<T: Real>() -> Result<(), Error> {
    let (one, nan, inf) = (T::one(), T::from_f64(f64::NAN), T::INFINITY);
    let small = T::from_f64(1e-3);
    for e in [-T::from_f64(0.1), T::from_f64(1.1), nan, inf] {
        refuses(ContactModel::new(e, small, small), "restitution");
    }
    ContactModel::new(T::zero(), small, small)?;
    ContactModel::new(one, small, small)?;
    for bad in [T::zero(), -one, nan, inf] {
        refuses(ContactModel::new(T::HALF, bad, small), "rest_speed");
        refuses(ContactModel::new(T::HALF, small, bad), "time_tolerance");
        refuses(Projection::new(bad, 4), "tolerance");
        refuses(Stabilization::critical(bad), "rate");
        refuses(Stabilization::for_step(bad), "dt");
        refuses(CartesianPendulum::new(bad, one, one), "mass");
        refuses(CartesianPendulum::new(one, bad, one), "length");
        refuses(
            FourBarLinkage::new([one, one, bad, one], [one; 3], one),
            "lengths[2]",
        );
        refuses(
            FourBarLinkage::new([one; 4], [one, bad, one], one),
            "masses[1]",
        );
        refuses(RollingDisk::new(bad, one), "mass");
        refuses(RollingDisk::new(one, bad), "radius");
    }
    for bad in [-one, nan, inf] {
        refuses(
            ContactModel::new(T::HALF, small, small)?.with_friction(bad),
            "friction",
        );
        refuses(Stabilization::baumgarte(bad, one), "alpha");
        refuses(Stabilization::baumgarte(one, bad), "beta");
        refuses(CartesianPendulum::new(one, one, bad), "gravity");
        refuses(FourBarLinkage::new([one; 4], [one; 3], bad), "gravity");
    }
    // Gains whose products the equation forms (2 alpha, beta^2, rate^2) must not overflow.
    let root = T::MAX.sqrt();
    refuses(Stabilization::baumgarte(T::MAX, T::zero()), "alpha");
    refuses(Stabilization::baumgarte(T::zero(), root * T::TWO), "beta");
    refuses(Stabilization::critical(root * T::TWO), "rate");
    refuses(Stabilization::for_step(T::from_f64(0.01) / root), "dt");
    Stabilization::baumgarte(T::MAX / T::from_f64(4.0), root / T::TWO)?;
    Stabilization::critical(root / T::TWO)?;
    refuses(Projection::new(small, 0), "max_iterations");
    refuses(Projection::new(small, 1001), "max_iterations");
    refuses(Projection::new(small, u32::MAX), "max_iterations");
    Projection::new(small, 1000)?;
    Stabilization::baumgarte(T::zero(), T::zero())?;
    Ok(())
}

/// A start state off the constraint (position or velocity) is refused by `Projected` and by
/// `check_state`, naming the row; a consistent one is accepted.
fn inconsistent_start_is_refused<T: Real>() -> Result<(), Error> {
    let p = Constrained::new(CartesianPendulum::new(
        T::one(),
        T::one(),
        T::from_f64(9.81),
    )?);
    let dt = T::from_f64(1e-3);
    let tol = T::from_f64(1e-5);
    let mut stepper = Projected::new(Rk4, Projection::new(tol, 4)?);
    let off_circle = State::new(T::zero(), [T::from_f64(1.1), T::zero()], [T::zero(); 2]);
    let radial_velocity = State::new(T::zero(), [T::one(), T::zero()], [T::HALF, T::zero()]);
    for bad in [off_circle, radial_velocity] {
        assert_eq!(
            stepper.step(&p, &bad, dt),
            Err(Error::ConstraintViolated { row: 0 })
        );
    }
    let good = p.parts().state_from_angle(T::zero(), T::HALF, T::one());
    let next = stepper.step(&p, &good, dt)?;
    stepper.step(&p, &next, dt)?;
    // The stepper's own last output continues unchecked; that output with its coordinates
    // or its velocities moved off the constraint is a new start, checked and refused.
    let last = stepper.step(&p, &next, dt)?;
    let mut moved = last;
    moved.q[0] += T::from_f64(0.1);
    let mut pushed = last;
    pushed.qd[0] += T::from_f64(0.1);
    for bad in [moved, pushed] {
        assert_eq!(
            stepper.step(&p, &bad, dt),
            Err(Error::ConstraintViolated { row: 0 })
        );
    }

    let linkage = Constrained::new(FourBarLinkage::new(
        [T::one(), T::from_f64(0.3), T::one(), T::from_f64(0.8)],
        [T::one(); 3],
        T::from_f64(9.81),
    )?);
    let mut s = linkage
        .parts()
        .assemble(T::zero(), T::HALF, T::one(), Branch::Right)?;
    s.q[2] += T::from_f64(0.01);
    let mut stepper = Projected::new(Rk4, Projection::new(tol, 4)?);
    assert!(matches!(
        stepper.step(&linkage, &s, dt),
        Err(Error::ConstraintViolated { .. })
    ));

    let nan = State::new(
        T::zero(),
        [T::from_f64(f64::NAN), -T::one()],
        [T::zero(); 2],
    );
    let mut stepper = Projected::new(Rk4, Projection::new(tol, 4)?);
    assert_eq!(stepper.step(&p, &nan, dt), Err(Error::NonFiniteState));
    Ok(())
}

/// The unit circle twice: the same constraint written as two rows.
struct Twice;

impl<T: Real> HolonomicConstraints<T, 2, 2> for Twice {
    fn phi<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 2>) -> SVector<S, 2> {
        let c = (q[0] * q[0] + q[1] * q[1] - S::one()) * S::from_f64(0.5);
        Vector2::new(c, c * S::from_f64(3.0))
    }
}

/// Redundant constraints (a row that is a multiple of another) and singular configurations
/// (the Cartesian pendulum's bob at its pivot; the square four-bar linkage folded flat, all
/// links in line) give `RedundantConstraints` naming the dependent row, from the solve and
/// the projection alike.
fn redundant_and_singular_constraints<T: Real>() -> Result<(), Error> {
    let p = CartesianPendulum::new(T::one(), T::one(), T::from_f64(9.81))?;
    let twice = EulerLagrange::new(p).held_by(Holonomic::new(Twice));
    let s = p.state_from_angle(T::zero(), T::HALF, T::one());
    assert_eq!(
        twice.acceleration(&s),
        Err(Error::RedundantConstraints { row: 1 })
    );
    assert_eq!(
        Projection::new(T::from_f64(1e-5), 4)?.project(&p, &Holonomic::new(Twice), &s),
        Err(Error::RedundantConstraints { row: 1 })
    );
    let at_pivot = State::new(T::zero(), [T::zero(); 2], [T::zero(); 2]);
    assert_eq!(
        Constrained::new(p).acceleration(&at_pivot),
        Err(Error::RedundantConstraints { row: 0 })
    );

    let square = Constrained::new(FourBarLinkage::new(
        [T::one(); 4],
        [T::one(); 3],
        T::from_f64(9.81),
    )?);
    let half_pi = T::from_f64(core::f64::consts::FRAC_PI_2);
    let flat = State::new(T::zero(), [half_pi; 3], [T::zero(); 3]);
    assert_eq!(
        square.acceleration(&flat),
        Err(Error::RedundantConstraints { row: 1 })
    );
    assert_eq!(
        Projection::new(T::from_f64(1e-5), 4)?.project(&square, &square, &flat),
        Err(Error::RedundantConstraints { row: 1 })
    );
    Ok(())
}

/// A four-bar linkage that cannot close at every crank angle: crank 0.6, coupler and rocker
/// 0.3 on a ground of 1 close only while the crank tip is within 0.6 of the rocker pivot.
fn linkage_that_cannot_close<T: Real>() -> Result<(), Error> {
    let l = FourBarLinkage::new(
        [
            T::one(),
            T::from_f64(0.6),
            T::from_f64(0.3),
            T::from_f64(0.3),
        ],
        [T::one(); 3],
        T::from_f64(9.81),
    )?;
    let half_pi = T::from_f64(core::f64::consts::FRAC_PI_2);
    l.assemble(T::zero(), half_pi, T::one(), Branch::Left)?;
    refuses(
        l.assemble(T::zero(), -half_pi, T::one(), Branch::Left),
        "crank",
    );
    refuses(
        l.assemble(T::zero(), T::from_f64(f64::NAN), T::one(), Branch::Left),
        "crank",
    );
    Ok(())
}

/// The ground at `y = 0`.
struct Ground;

impl<T: Real> HolonomicConstraints<T, 1, 1> for Ground {
    fn phi<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 1>) -> SVector<S, 1> {
        *q
    }
}

/// A contact start state below the ground beyond the tolerance is refused; so is a step that
/// is not positive and finite.
fn contact_start_and_step_are_checked<T: Real>() -> Result<(), Error> {
    let ball = FallingParticle::new(T::one(), T::from_f64(9.81))?;
    let small = T::from_f64(1e-3);
    let model = ContactModel::new(T::HALF, small, small)?;
    let mut stepper = ContactStepper::new(
        Rk4,
        Holonomic::new(Ground),
        model,
        Projection::new(small, 4)?,
    );
    let below = State::at_rest([-T::from_f64(0.01)]);
    assert_eq!(
        stepper.step(&ball, &below, small),
        Err(Error::ConstraintViolated { row: 0 })
    );
    let above = State::at_rest([T::one()]);
    for dt in [T::zero(), -small, T::from_f64(f64::NAN)] {
        refuses(stepper.step(&ball, &above, dt), "dt");
    }
    stepper.step(&ball, &above, small)?;
    Ok(())
}

for_f32_and_f64!(
    parameters_are_checked,
    inconsistent_start_is_refused,
    redundant_and_singular_constraints,
    linkage_that_cannot_close,
    contact_start_and_step_are_checked
);

/// Newton that cannot reach the tolerance in its iterations says so.
#[test]
fn projection_reports_no_convergence() -> Result<(), Error> {
    let p = Constrained::new(CartesianPendulum::new(1.0, 1.0, 9.81)?);
    let far = State::new(0.0, [3.0, 0.0], [0.0, 0.0]);
    assert_eq!(
        Projection::new(1e-12, 1)?.project(&p, &p, &far),
        Err(Error::NoConvergence { iterations: 1 })
    );
    let near = Projection::new(1e-12, 8)?.project(&p, &p, &far)?;
    assert!((near.q[0] - 1.0).abs() < 1e-12);
    Ok(())
}
