//! The impact law ([`Impacts::impact`]) on a body whose two contacts are coupled through its
//! mass matrix: which rows take an impulse, which let go, which rest afterwards, and the
//! friction impulse of a body heavier than one kilogram. Each case has a closed-form answer,
//! worked out in its docs; the bounds are rounding (a few ulps of velocities of order 1).

use lagrange_core::constraints::contact::{drop_dependent_contacts, ActiveRows, Impacts};
use lagrange_core::nalgebra::{Matrix2, Matrix3, SMatrix, SVector, Vector2, Vector3};
use lagrange_core::{
    Constraints, Error, EulerLagrange, Lagrangian, Mechanism, Real, Scalar, State,
};
use lagrange_integrators::{ContactModel, Contacts};

/// Rounding of velocities of order 1 after a 2x2 solve.
const ROUNDING: f64 = 1e-14;

/// A point in a corner with the mass matrix `[[m, c], [c, m]]` (a sheared body: a push along
/// one coordinate moves the other), no forces.
struct Sheared {
    m: f64,
    c: f64,
}

impl Lagrangian<f64, 2> for Sheared {
    fn kinetic<S: Scalar<Real = f64>>(&self, _t: S, _q: &SVector<S, 2>, v: &SVector<S, 2>) -> S {
        let (m, c) = (S::from_f64(self.m), S::from_f64(self.c));
        (m * (v[0] * v[0] + v[1] * v[1]) + c * v[0] * v[1] * S::from_f64(2.0)) * S::from_f64(0.5)
    }
    fn potential<S: Scalar<Real = f64>>(&self, _t: S, _q: &SVector<S, 2>) -> S {
        S::from_f64(0.0)
    }
}

/// The walls `q0 >= 0` (row 0, sliding along q1) and `q1 >= 0` (row 1, sliding along q0).
struct Corner;

impl Constraints<f64, 2, 2> for Corner {
    fn position_residual(&self, q: &Vector2<f64>) -> Vector2<f64> {
        *q
    }
    fn jacobian(&self, _q: &Vector2<f64>) -> SMatrix<f64, 2, 2> {
        Matrix2::identity()
    }
    fn velocity_product(&self, _q: &Vector2<f64>, _qd: &Vector2<f64>) -> Vector2<f64> {
        Vector2::zeros()
    }
}

impl Contacts<f64, 2, 2> for Corner {
    fn tangent_jacobian(&self, _q: &Vector2<f64>) -> Option<SMatrix<f64, 2, 2>> {
        Some(Matrix2::new(0.0, 1.0, 1.0, 0.0))
    }
}

/// The impact at the corner from `qd`, with `struck` and `resting` rows: the velocities after
/// and the resting rows after.
fn impact(
    body: Sheared,
    model: &ContactModel<f64>,
    qd: [f64; 2],
    struck: [bool; 2],
    mut resting: [bool; 2],
) -> Result<(Vector2<f64>, [bool; 2]), Error> {
    let body = EulerLagrange::new(body);
    let s = State::new(0.0, [0.0, 0.0], qd);
    let (after, _) =
        Impacts::new(&Corner, model, [false; 2]).impact(&body, &s, struck, &mut resting)?;
    let gain = body.kinetic_energy(&after) - body.kinetic_energy(&s);
    assert!(gain <= ROUNDING, "the impact added {gain:e} J");
    Ok((after.qd, resting))
}

fn plastic() -> Result<ContactModel<f64>, Error> {
    ContactModel::new(0.0, 1e-3, 1e-10)
}

/// Row 1 strikes at 1 m/s while row 0 rests. With `M = [[2, -1], [-1, 2]]` both rows held
/// would need `p = M (0, 1) = (-1, 2)`: row 0 would pull, so it lets go and row 1 alone
/// stops: `p1 = 1 / (M^-1)_11 = 1.5`, `q'+ = (0, -1) + M^-1 (0, 1) 1.5 = (0.5, 0)`. The body
/// leaves the wall of row 0, which no longer rests.
#[test]
fn a_resting_row_that_would_pull_lets_go() -> Result<(), Error> {
    let body = Sheared { m: 2.0, c: -1.0 };
    let (after, resting) = impact(body, &plastic()?, [0.0, -1.0], [false, true], [true, false])?;
    assert!(
        (after - Vector2::new(0.5, 0.0)).amax() < ROUNDING,
        "{after}"
    );
    assert_eq!(resting, [false, true]);
    Ok(())
}

/// With `M = [[2, 1], [1, 2]]` the resting row pushes (`p = M (0, 1) = (1, 2)`), so both stay
/// held and the body stops. A resting row drifting into its wall at 0.01 m/s is stopped too:
/// `w+ = 0` on every held row, `p = M (0.01, 1)`.
#[test]
fn held_rows_end_at_rest() -> Result<(), Error> {
    for drift in [0.0, -0.01] {
        let body = Sheared { m: 2.0, c: 1.0 };
        let (after, resting) = impact(
            body,
            &plastic()?,
            [drift, -1.0],
            [false, true],
            [true, false],
        )?;
        assert!(after.amax() < ROUNDING, "drift {drift}: {after}");
        assert_eq!(resting, [true, true]);
    }
    Ok(())
}

/// A diagonal mass matrix: the rows do not couple. Row 1 strikes fast enough to rebound at
/// e = 0.5; row 0 is struck at exactly zero speed (it crossed by acceleration alone) or
/// rests already. Row 0 takes no impulse (exactly zero), comes to rest (or stays resting),
/// and row 1 rebounds at half its speed: `q'+ = (0, 1)`.
#[test]
fn a_row_at_zero_speed_rests_beside_a_rebound() -> Result<(), Error> {
    let bouncy = ContactModel::new(0.5, 1e-3, 1e-10)?;
    for (struck, resting) in [
        ([true, true], [false, false]),
        ([false, true], [true, false]),
    ] {
        let body = Sheared { m: 1.0, c: 0.0 };
        let (after, resting) = impact(body, &bouncy, [0.0, -2.0], struck, resting)?;
        assert!(
            (after - Vector2::new(0.0, 1.0)).amax() < ROUNDING,
            "{after}"
        );
        assert_eq!(resting, [true, false], "struck {struck:?}");
    }
    Ok(())
}

/// Friction on a body of 2 kg sliding at 0.1 m/s along row 1's wall as it strikes at 1 m/s
/// (plastic, mu = 1): the normal impulse is `2 * 1 = 2` N s, the impulse that stops the
/// sliding `0.1 / (1/2) = 0.2` N s is within `mu * 2`, so the body stops dead.
#[test]
fn friction_stops_a_heavy_body_by_its_mass() -> Result<(), Error> {
    let model = plastic()?.with_friction(1.0)?;
    let body = Sheared { m: 2.0, c: 0.0 };
    let (after, resting) = impact(body, &model, [0.1, -1.0], [false, true], [false, false])?;
    assert!(after.amax() < ROUNDING, "{after}");
    assert_eq!(resting, [false, true]);
    Ok(())
}

/// Friction on a sheared body (`M = [[2, -1], [-1, 2]]`, `M^-1 = [[2, 1], [1, 2]] / 3`)
/// striking row 1 at 1 m/s while sliding at 0.5 m/s, plastic, mu = 0.3. The normal impulse
/// `1 / (2/3) = 1.5` gives `q' = (1, 0)`. The impulse that would stop the sliding,
/// `1 / (2/3) = 1.5`, is capped at `0.3 * 1.5 = 0.45`: `q' = (1, 0) - 0.45 (2, 1) / 3 =
/// (0.7, -0.15)`, which would push into the wall: the projection back onto the resting row
/// adds `0.15 (1, 2) / 2`, `q'+ = (0.775, 0)`.
#[test]
fn friction_keeps_a_resting_row_at_rest() -> Result<(), Error> {
    let model = plastic()?.with_friction(0.3)?;
    let body = Sheared { m: 2.0, c: -1.0 };
    let (after, resting) = impact(body, &model, [0.5, -1.0], [false, true], [false, false])?;
    assert!(
        (after - Vector2::new(0.775, 0.0)).amax() < ROUNDING,
        "{after}"
    );
    assert_eq!(resting, [false, true]);
    Ok(())
}

/// A slow approach (1e-4 m/s, a tenth of the rest speed of 1e-3 m/s) is still an approach: a
/// plastic impulse stops it, `q'+ = 0`, and the row rests. One far below the rest speed
/// (1e-7 m/s, under the noise threshold of a thousandth of it) is no approach: the row comes
/// to rest without an impulse (the projection at the end of the step takes the creep out).
#[test]
fn slow_approaches_stop_and_creep_settles() -> Result<(), Error> {
    let model = plastic()?;
    let unit = || Sheared { m: 1.0, c: 0.0 };
    let (after, resting) = impact(unit(), &model, [0.0, -1e-4], [false, true], [false; 2])?;
    assert!(after.abs().max() <= 1e-4 * ROUNDING, "{after:?}");
    assert_eq!(resting, [false, true]);
    let (after, resting) = impact(unit(), &model, [0.0, -1e-7], [false, true], [false; 2])?;
    assert_eq!(after, Vector2::new(0.0, -1e-7));
    assert_eq!(resting, [false, true]);
    Ok(())
}

/// A point in the corner of three walls `q_i >= 0` (row `i`, frictionless) with a constant
/// mass matrix, no forces.
struct Octant([[f64; 3]; 3]);

impl Lagrangian<f64, 3> for Octant {
    fn kinetic<S: Scalar<Real = f64>>(&self, _t: S, _q: &SVector<S, 3>, v: &SVector<S, 3>) -> S {
        let mut t = S::from_f64(0.0);
        for (i, row) in self.0.iter().enumerate() {
            for (j, m) in row.iter().enumerate() {
                t += v[i] * v[j] * (0.5 * m);
            }
        }
        t
    }
    fn potential<S: Scalar<Real = f64>>(&self, _t: S, _q: &SVector<S, 3>) -> S {
        S::from_f64(0.0)
    }
}

impl Constraints<f64, 3, 3> for Octant {
    fn position_residual(&self, q: &Vector3<f64>) -> Vector3<f64> {
        *q
    }
    fn jacobian(&self, _q: &Vector3<f64>) -> Matrix3<f64> {
        Matrix3::identity()
    }
    fn velocity_product(&self, _q: &Vector3<f64>, _qd: &Vector3<f64>) -> Vector3<f64> {
        Vector3::zeros()
    }
}

impl Contacts<f64, 3, 3> for Octant {}

/// Row 2 strikes at 1 m/s (plastic) while rows 0 and 1 rest, with
/// `M = [[2, 1, -0.2], [1, 2, -1], [-0.2, -1, 2]]` (`det = 4.32`). All three held would need
/// `p = M (0, 0, 1) = (-0.2, -1, 2)`: both resting rows pull, row 1 the harder. It lets go
/// alone, and with rows 0 and 2 held, `p = (0.3, 1.5)` (both push: row 0 pulled only because
/// row 1 did) and `q'+ = (0, 0.5, 0)`: row 0 still rests. Dropping the weaker puller first
/// leaves row 1 pulling, then nothing held but row 2: `q'+ = (-0.2, 0.6, 0)`, into wall 0.
#[test]
fn the_row_that_pulls_hardest_lets_go_first() -> Result<(), Error> {
    let m = [[2.0, 1.0, -0.2], [1.0, 2.0, -1.0], [-0.2, -1.0, 2.0]];
    let body = EulerLagrange::new(Octant(m));
    let s = State::new(0.0, [0.0; 3], [0.0, 0.0, -1.0]);
    let mut resting = [true, true, false];
    let (after, _) = Impacts::new(&Octant(m), &plastic()?, [false; 3]).impact(
        &body,
        &s,
        [false, false, true],
        &mut resting,
    )?;
    assert!(
        (after.qd - Vector3::new(0.0, 0.5, 0.0)).amax() < ROUNDING,
        "{}",
        after.qd
    );
    assert_eq!(resting, [true, false, true]);
    let gain = body.kinetic_energy(&after) - body.kinetic_energy(&s);
    assert!(gain <= ROUNDING, "the impact added {gain:e} J");
    Ok(())
}

/// The walls `q0 >= 0` twice (rows 0 and 1: a contact that depends on another) and
/// `q1 >= 0` (row 2).
struct DoubledWall;

impl Constraints<f64, 2, 3> for DoubledWall {
    fn position_residual(&self, q: &Vector2<f64>) -> Vector3<f64> {
        Vector3::new(q[0], q[0], q[1])
    }
    fn jacobian(&self, _q: &Vector2<f64>) -> SMatrix<f64, 3, 2> {
        SMatrix::<f64, 3, 2>::new(1.0, 0.0, 1.0, 0.0, 0.0, 1.0)
    }
    fn velocity_product(&self, _q: &Vector2<f64>, _qd: &Vector2<f64>) -> Vector3<f64> {
        Vector3::zeros()
    }
}

impl Contacts<f64, 2, 3> for DoubledWall {}

/// Between events (`ActiveRows`): a unit point at rest in the corner, pushed by
/// `F = (-1, 1)`, into wall 0 and away from wall 2, with every row resting. Row 1 repeats row
/// 0: a contact that depends on the others carries no force of its own and is left out, not
/// reported. Row 2 would pull (`lambda = -F_1 = -1`) and lets go: the rows still in force are
/// 0 alone, and the point accelerates at `(0, 1)` along wall 0. Pushed by `(-1, 0)`, row 2
/// carries exactly no force and stays in force (only a pulling row lets go).
/// `drop_dependent_contacts` leaves the repeated row out before any solve. The same repeated
/// row held as bilateral is the user's error: `RedundantConstraints`, naming it.
#[test]
fn rows_in_force_leave_out_pulling_and_repeated_contacts() -> Result<(), Error> {
    let point = EulerLagrange::new(Sheared { m: 1.0, c: 0.0 })
        .with_force(|_: &State<f64, 2>| Vector2::new(-1.0, 1.0));
    let s = State::at_rest([0.0, 0.0]);
    let model = plastic()?;
    let rows = ActiveRows::new(&point, &DoubledWall, &model, &[false; 3], &[true; 3]);
    assert_eq!(rows.still_in_force(&s)?, [true, false, false]);
    let a = rows.acceleration(&s)?;
    assert!((a - Vector2::new(0.0, 1.0)).amax() < ROUNDING, "{a}");
    // Pushed into wall 0 only, row 2 carries exactly no force: it stays in force.
    let pressed = EulerLagrange::new(Sheared { m: 1.0, c: 0.0 })
        .with_force(|_: &State<f64, 2>| Vector2::new(-1.0, 0.0));
    let resting = ActiveRows::new(&pressed, &DoubledWall, &model, &[false; 3], &[true; 3]);
    assert_eq!(resting.still_in_force(&s)?, [true, false, true]);
    // The same choice before any solve: the repeated contact is left out.
    let mut active = [true; 3];
    drop_dependent_contacts(&point, &DoubledWall, &s, &mut active, &[false; 3])?;
    assert_eq!(active, [true, false, true]);
    let mut held = [true; 3];
    assert_eq!(
        drop_dependent_contacts(&point, &DoubledWall, &s, &mut held, &[true, true, false]),
        Err(Error::RedundantConstraints { row: 1 })
    );
    let held = ActiveRows::new(
        &point,
        &DoubledWall,
        &model,
        &[true, true, false],
        &[false; 3],
    );
    assert_eq!(
        held.acceleration(&s),
        Err(Error::RedundantConstraints { row: 1 })
    );
    Ok(())
}

/// Between events, the three walls and `M = [[2, 1, -0.2], [1, 2, -1], [-0.2, -1, 2]]` of
/// [`the_row_that_pulls_hardest_lets_go_first`], at rest, all three rows resting, pushed by
/// `F = -M (0, 0, 1)`: held together the rows would need `lambda = -F = (-0.2, -1, 2)`, rows 0
/// and 1 pulling, row 1 the harder. It lets go alone; then row 0 pushes (`A lambda =
/// (0, 1)` over rows 0 and 2, `lambda = (0.3, 1.5)`), and `q'' = (0, 0.5, 0)`. Pushed by
/// `F = (1, 0, -1) M`-free `(0, 0, -1)` instead... (see below) a row with exactly no force
/// stays in force. `drop_dependent_contacts` leaves the repeated wall out.
#[test]
fn between_events_the_hardest_puller_lets_go_first() -> Result<(), Error> {
    let m = [[2.0, 1.0, -0.2], [1.0, 2.0, -1.0], [-0.2, -1.0, 2.0]];
    let f = Vector3::new(0.2, 1.0, -2.0);
    let body = EulerLagrange::new(Octant(m)).with_force(move |_: &State<f64, 3>| f);
    let s = State::at_rest([0.0; 3]);
    let model = plastic()?;
    let walls = Octant(m);
    let rows = ActiveRows::new(&body, &walls, &model, &[false; 3], &[true; 3]);
    assert_eq!(rows.still_in_force(&s)?, [true, false, true]);
    let a = rows.acceleration(&s)?;
    assert!((a - Vector3::new(0.0, 0.5, 0.0)).amax() < ROUNDING, "{a}");
    Ok(())
}

/// A floor `q2 >= 0` (row 0, a contact) and a rail `q1 = 0` (row 1, bilateral), both with
/// the tangent along `q0`.
struct Rail;

impl Constraints<f64, 3, 2> for Rail {
    fn position_residual(&self, q: &Vector3<f64>) -> Vector2<f64> {
        Vector2::new(q[2], q[1])
    }
    fn jacobian(&self, _q: &Vector3<f64>) -> SMatrix<f64, 2, 3> {
        SMatrix::<f64, 2, 3>::new(0.0, 0.0, 1.0, 0.0, 1.0, 0.0)
    }
    fn velocity_product(&self, _q: &Vector3<f64>, _qd: &Vector3<f64>) -> Vector2<f64> {
        Vector2::zeros()
    }
}

impl Contacts<f64, 3, 2> for Rail {
    fn tangent_jacobian(&self, _q: &Vector3<f64>) -> Option<SMatrix<f64, 2, 3>> {
        Some(SMatrix::<f64, 2, 3>::new(1.0, 0.0, 0.0, 1.0, 0.0, 0.0))
    }
}

/// Between events, sliding friction acts at resting contacts only: a unit point sliding at
/// 1 m/s (far above the slip speed) along a floor it rests on (normal force g) and a rail it
/// is pressed against (the rail's force 1 N, positive), mu = 0.5: `q'' = (-mu g, 0, 0)`. The
/// rail is bilateral: it holds without friction (with it, `-mu (g + 1)`).
#[test]
fn sliding_friction_acts_at_resting_contacts_only() -> Result<(), Error> {
    const G: f64 = 9.81;
    let body = EulerLagrange::new(Octant([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]))
        .with_force(|_: &State<f64, 3>| Vector3::new(0.0, -1.0, -G));
    let s = State::new(0.0, [0.0; 3], [1.0, 0.0, 0.0]);
    let model = plastic()?.with_friction(0.5)?;
    let rows = ActiveRows::new(&body, &Rail, &model, &[false, true], &[true, false]);
    let a = rows.acceleration(&s)?;
    assert!(
        (a - Vector3::new(-0.5 * G, 0.0, 0.0)).amax() < ROUNDING,
        "{a}"
    );
    Ok(())
}

/// A model gives back the figures it was made with, exactly (its accessors store and return,
/// with no arithmetic between), in `f32` and `f64`; the event-location tolerance among them,
/// which the stepper's crossing search stops at.
fn a_model_keeps_its_figures<T: Real>() -> Result<(), Error> {
    let (e, rest, tol, mu) = (
        T::from_f64(0.25),
        T::from_f64(0.3),
        T::from_f64(1e-6),
        T::from_f64(0.7),
    );
    let m = ContactModel::new(e, rest, tol)?.with_friction(mu)?;
    assert!(
        m.restitution() == e
            && m.rest_speed() == rest
            && m.time_tolerance() == tol
            && m.friction() == mu,
        "{m:?}"
    );
    Ok(())
}

#[test]
fn a_model_keeps_its_figures_f32() -> Result<(), Error> {
    a_model_keeps_its_figures::<f32>()
}

#[test]
fn a_model_keeps_its_figures_f64() -> Result<(), Error> {
    a_model_keeps_its_figures::<f64>()
}
