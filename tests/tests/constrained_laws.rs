//! The generic constrained mechanism's own hooks against their definitions, on the Cartesian
//! pendulum (mass 2 kg, length 1.5 m, at 0.7 rad with a swing, constraint rows unit length):
//! the force its law applies, the jump an impulse gives, and its settings as given.

use lagrange_core::constraints::Stabilization;
use lagrange_core::nalgebra::Vector2;
use lagrange_core::{Constrained, Constraints, Error, Mechanism, Projection, State};
use lagrange_systems::CartesianPendulum;

/// Rounding of forces and velocities of order 10 (a few hundred ulps at most).
const ROUNDING: f64 = 1e-12;

/// The constrained pendulum.
type Rod = Constrained<f64, 1, CartesianPendulum<f64>>;

fn pendulum() -> Result<(Rod, State<f64, 2>), Error> {
    let (l, th, thd) = (1.5, 0.7_f64, 1.3);
    let q = [l * th.sin(), -l * th.cos()];
    let qd = [l * thd * th.cos(), l * thd * th.sin()];
    Ok((
        Constrained::new(CartesianPendulum::new(2.0, l, 9.81)?),
        State::new(0.0, q, qd),
    ))
}

/// The force of the law besides `f` is what the accelerations say it is, `M q'' - f`: the
/// extra force plus the rod's tension `J^T lambda` (not minus it).
#[test]
fn law_force_is_m_qdd_minus_f() -> Result<(), Error> {
    let (p, s) = pendulum()?;
    let push = |_: &State<f64, 2>| Vector2::new(3.0, -1.0);
    let qdd = p.acceleration_with(&s, &push)?;
    let expected = p.mass_matrix(&s) * qdd - p.rhs(&s);
    let force = p.law_force(&s, &push)?;
    assert!(
        (force - expected).amax() < ROUNDING,
        "{force} against {expected}"
    );
    Ok(())
}

/// An impulse `p` on the bob jumps its velocity by the part of `p / m` along the circle: the
/// rod takes the radial part, `dq' = (p - j (j . p)) / m` with `j` the unit row, and the jump
/// keeps `J q' = 0`.
#[test]
fn velocity_jump_keeps_the_rod() -> Result<(), Error> {
    let (p, s) = pendulum()?;
    let impulse = Vector2::new(0.8, 2.5);
    let jump = p.velocity_jump(&s, &impulse)?;
    let j = p.jacobian(&s.q).transpose();
    let expected = (impulse - j * j.dot(&impulse)) / 2.0;
    assert!(
        (jump - expected).amax() < ROUNDING,
        "{jump} against {expected}"
    );
    assert!((p.jacobian(&s.q) * jump)[0].abs() < ROUNDING);
    Ok(())
}

/// Settings read back as given.
#[test]
fn settings_read_back() -> Result<(), Error> {
    let (p, _) = pendulum()?;
    let drift = Stabilization::critical(7.0)?;
    assert_eq!(p.with_stabilization(drift).stabilization(), drift);
    assert_eq!(Projection::new(1e-9, 7)?.max_iterations(), 7);
    assert_eq!(Projection::new(1e-9, 7)?.tolerance(), 1e-9);
    Ok(())
}
