//! `lagrange_world::PlaneContacts` under the impulse stepper: a disk rolling down a slope at
//! the exact rolling law, and a crate dropped turned onto the floor coming to rest flat,
//! within the slop, never gaining energy over a step in contact. Both precisions.

use lagrange_core::{Constraints, Error, Lagrangian, Real, State};
use lagrange_integrators::{
    ContactModel, ImpulseSettings, ImpulseStepper, Integrator, SemiImplicitEuler, VelocityVerlet,
};
use lagrange_systems::RigidBody;
use lagrange_tests::{for_f32_and_f64, pick};
use lagrange_world::{HalfPlane, PlaneContacts, Shape};

const G: f64 = 9.81;

/// A uniform disk (radius 0.2 m, 1 kg) from rest on a 30 degree slope, friction 0.5 (rolling
/// needs `tan 30 / 3 = 0.19`): it rolls without slipping at `a = g sin a / (1 + I / m r^2) =
/// 2 g sin a / 3`, its angle turning by `-s / r`. The contact's force is constant, so velocity
/// Verlet is exact to rounding (1e-9 m in f64, 1e-3 in f32 over 480 steps); semi-implicit
/// Euler at its first order (within `a t dt` over 2 s at 240 Hz).
fn a_disk_rolls_down_a_slope<T: Real>() -> Result<(), Error> {
    let alpha = core::f64::consts::FRAC_PI_6;
    let (sa, ca) = alpha.sin_cos();
    let r = 0.2;
    let disk = RigidBody::disk(T::one(), T::from_f64(r), T::from_f64(G))?;
    let slope = HalfPlane::new([T::from_f64(-sa), T::from_f64(ca)], T::zero())?;
    let rows =
        PlaneContacts::<_, _, 3, 1>::new(disk, &[(0, Shape::circle(T::from_f64(r))?)], &[slope])?;
    let model = ContactModel::new(T::zero(), T::from_f64(0.1), T::one())?.with_friction(T::HALF)?;
    let settings = ImpulseSettings::new(T::from_f64(1e-4), 8)?;
    let start = State::at_rest([T::from_f64(-r * sa), T::from_f64(r * ca), T::zero()]);
    let a = 2.0 * G * sa / 3.0;
    let (t, dt) = (2.0, 1.0 / 240.0);
    let down =
        |s: &State<T, 3>| -((s.q[0].to_f64() + r * sa) * ca + (s.q[1].to_f64() - r * ca) * sa);
    let exact = a * t * t / 2.0;
    let mut verlet = ImpulseStepper::new(VelocityVerlet, rows, model, settings);
    let end = verlet.integrate(&disk, &start, T::from_f64(dt), 480)?;
    let tol = pick::<T>(1e-3, 1e-9);
    assert!(
        (down(&end) - exact).abs() < tol,
        "Verlet: {} against {exact}",
        down(&end)
    );
    // Rolling: the angle turns by the distance over the radius (clockwise going down-slope
    // to the left).
    assert!(
        (end.q[2].to_f64() - exact / r).abs() < tol / r,
        "angle {:?} against {}",
        end.q[2],
        exact / r
    );
    let mut euler = ImpulseStepper::new(SemiImplicitEuler, rows, model, settings);
    let end = euler.integrate(&disk, &start, T::from_f64(dt), 480)?;
    assert!(
        (down(&end) - exact).abs() < a * t * dt,
        "Euler: {} against {exact}",
        down(&end)
    );
    Ok(())
}

/// A 0.5 m by 0.3 m crate dropped from 0.6 m turned by 0.4 rad, spinning, onto the floor
/// (restitution 0.3, friction 0.6, slop 2 mm) at 120 Hz for 4 s: no step in contact ends above
/// its start's energy (to 16 ulps of the terms), no corner deeper than the slop (to 2^-10 of it
/// and rounding), and at the end it rests on a face: still (under 1e-3 m/s and rad/s), its
/// angle a multiple of a quarter turn to what the slop allows (its two lowest corners rest
/// anywhere within the slop, at most 0.3 m apart: slop / 0.3 m = 6.7e-3 rad; measured 1.4e-3
/// rad, standing on its short side), its lowest corners on the floor within the slop.
fn a_crate_comes_to_rest_flat<T: Real>() -> Result<(), Error> {
    let body = RigidBody::rectangle(T::from_f64(2.0), T::HALF, T::from_f64(0.3), T::from_f64(G))?;
    let shape = Shape::rectangle(T::HALF, T::from_f64(0.3))?;
    let rows = PlaneContacts::<_, _, 3, 4>::new(body, &[(0, shape)], &[HalfPlane::floor()])?;
    let model = ContactModel::new(T::from_f64(0.3), T::from_f64(0.2), T::one())?
        .with_friction(T::from_f64(0.6))?;
    let slop = 2e-3;
    let mut stepper = ImpulseStepper::new(
        SemiImplicitEuler,
        rows,
        model,
        ImpulseSettings::new(T::from_f64(slop), 8)?,
    );
    let mut s = State::new(
        T::zero(),
        [T::zero(), T::from_f64(0.6), T::from_f64(0.4)],
        [T::HALF, T::zero(), T::from_f64(3.0)],
    );
    let deepest = slop * (1.0 + 1.0 / 1024.0) + 64.0 * T::EPSILON.to_f64() * 2.0;
    for step in 0..480 {
        let next = stepper.step(&body, &s, T::from_f64(1.0 / 120.0))?;
        if stepper.last_report().rows > 0 {
            let (e0, e1) = (body.energy(&s).to_f64(), body.energy(&next).to_f64());
            let v = body.potential_energy(&next).to_f64().abs();
            assert!(
                e1 <= e0 + 16.0 * T::EPSILON.to_f64() * (e0.abs() + e1.abs() + 2.0 * v),
                "step {step}: {e0} -> {e1}"
            );
        }
        let gaps = rows.position_residual(&next.q);
        assert!(
            gaps.iter().all(|g| -g.to_f64() <= deepest),
            "step {step}: {gaps:?}"
        );
        s = next;
    }
    assert!(
        s.qd.iter().all(|v| v.to_f64().abs() < 1e-3),
        "still moving: {s:?}"
    );
    let quarter = core::f64::consts::FRAC_PI_2;
    let angle = s.q[2].to_f64();
    assert!(
        (angle - quarter * (angle / quarter).round()).abs() <= slop / 0.3,
        "angle {angle}"
    );
    let gaps = rows.position_residual(&s.q);
    let lowest = gaps
        .iter()
        .map(|g| g.to_f64())
        .fold(f64::INFINITY, f64::min);
    assert!(lowest.abs() <= deepest, "lowest corner {lowest}");
    Ok(())
}

/// A shape on a link the mechanism does not have, or a row count that is not the vertices
/// times the planes, is refused by name.
fn bad_rows_are_refused<T: Real>() -> Result<(), Error> {
    let body = RigidBody::disk(T::one(), T::one(), T::from_f64(G))?;
    let ball = Shape::circle(T::one())?;
    let refused = |r: Result<PlaneContacts<T, RigidBody<T>, 3, 2>, Error>| {
        assert!(
            matches!(r, Err(Error::InvalidParameter { name: "shapes", .. })),
            "{r:?}"
        );
    };
    refused(PlaneContacts::new(
        body,
        &[(1, ball)],
        &[HalfPlane::floor(), HalfPlane::floor()],
    ));
    refused(PlaneContacts::new(
        body,
        &[(0, ball)],
        &[HalfPlane::floor()],
    ));
    assert!(PlaneContacts::<T, RigidBody<T>, 3, 2>::new(
        body,
        &[(0, ball)],
        &[HalfPlane::floor(), HalfPlane::floor()]
    )
    .is_ok());
    Ok(())
}

for_f32_and_f64!(
    a_disk_rolls_down_a_slope,
    a_crate_comes_to_rest_flat,
    bad_rows_are_refused
);
