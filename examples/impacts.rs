//! Impacts and resting contact: a ball dropped on the ground (its apex heights against
//! `e^(2n) h0`, and when it comes to rest), and a double pendulum thrown onto a floor with joint
//! limits (it never gains energy at an impact, and never sinks into the floor), with the cost
//! of stepping through contacts.
//!
//! `cargo run --release --example impacts` (writes `target/lagrange-demo/impacts.svg`)

use lagrange_core::nalgebra::Vector4;
use lagrange_core::{Holonomic, HolonomicConstraints};
use lagrange_examples::{ns_per_step, write_plot};
use lagrange_integrators::prelude::*;
use lagrange_integrators::{ContactModel, ContactStepper};
use lagrange_plot::{Scale, Series};
use lagrange_systems::{DoublePendulum, FallingParticle};

const G: f64 = 9.81;
const DT: f64 = 1e-3;

/// The ground at `y = 0` for a particle with `q = [y]`.
#[derive(Clone, Copy)]
struct Ground;

impl<T: Real> HolonomicConstraints<T, 1, 1> for Ground {
    fn phi<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 1>) -> SVector<S, 1> {
        *q
    }
}

/// A floor 0.8 m below the double pendulum's pivot under both masses, and the joint limits
/// `|th2 - th1| <= 2.5`.
#[derive(Clone, Copy)]
struct FloorAndLimits;

impl HolonomicConstraints<f64, 2, 4> for FloorAndLimits {
    fn phi<S: Scalar<Real = f64> + 'static>(&self, q: &SVector<S, 2>) -> SVector<S, 4> {
        let y1 = -q[0].cos();
        let y2 = y1 - q[1].cos();
        let relative = q[1] - q[0];
        Vector4::new(y1 + 0.8, y2 + 0.8, -relative + 2.5, relative + 2.5)
    }
}

/// Restitution `e`; resting below 0.05 m/s; contacts located to 1e-10 s.
fn model(restitution: f64) -> Result<ContactModel<f64>, Error> {
    ContactModel::new(restitution, 0.05, 1e-10)
}

fn main() -> Result<(), Error> {
    // The ball.
    let ball = FallingParticle::new(1.0, G)?;
    let ground = || -> Result<_, Error> {
        Ok(ContactStepper::new(
            Rk4,
            Holonomic::new(Ground),
            model(0.8)?,
            Projection::new(1e-12, 4)?,
        ))
    };
    let mut stepper = ground()?;
    let b0 = State::at_rest([1.0]);
    let mut s = b0;
    let (mut path, mut apexes, mut since, mut rest) =
        (vec![(0.0, 1.0)], Vec::new(), None::<f64>, None);
    for _ in 0..6000 {
        let mut hit = false;
        s = stepper.step_observed(&ball, &s, DT, |_| hit = true)?;
        if hit {
            apexes.extend(since);
            since = Some(s.q[0]);
        }
        since = since.map(|h| h.max(s.q[0]));
        path.push((s.t, s.q[0]));
        if rest.is_none() && stepper.resting()[0] {
            rest = Some(s.t);
        }
    }
    println!(
        "Ball dropped from 1 m on the ground, e = 0.8, RK4 at dt = 1e-3 s, contacts located to \
         1e-10 s: {} impacts, at rest from t = {}",
        stepper.impacts(),
        rest.map_or_else(|| "-".to_string(), |t| format!("{t:.3} s"))
    );
    println!(
        "{:>4} {:>14} {:>14} {:>10}",
        "n", "apex (m)", "e^(2n) h0", "error"
    );
    for (n, h) in (1..).zip(&apexes) {
        if n <= 5 || n == apexes.len() {
            let exact = 0.8f64.powi(2 * i32::try_from(n).unwrap_or(i32::MAX));
            println!("{n:>4} {h:>14.9} {exact:>14.9} {:>10.1e}", h - exact);
        }
    }

    // The double pendulum.
    let dp = DoublePendulum::new(1.0, 1.0, 1.0, 1.0, G)?;
    let contacts = Holonomic::new(FloorAndLimits);
    let floor = || -> Result<_, Error> {
        Ok(ContactStepper::new(
            Rk4,
            contacts,
            model(0.8)?,
            Projection::new(1e-10, 6)?,
        ))
    };
    let mut stepper = floor()?;
    let d0 = State::new(0.0, [1.6, 2.2], [2.0, -6.0]);
    let mut s = d0;
    let (mut samples, mut deepest, mut gain) = (Vec::new(), f64::INFINITY, f64::NEG_INFINITY);
    for n in 0..20_000 {
        s = stepper.step_observed(&dp, &s, DT, |impact| {
            let before = dp.kinetic_energy(&impact.state_before());
            gain = gain.max(dp.kinetic_energy(&impact.state_after()) - before);
        })?;
        let gaps = contacts.position_residual(&s.q);
        deepest = gaps.iter().fold(deepest, |d, &g| d.min(g));
        if n % 20 == 0 {
            samples.push([s.t, dp.energy(&s), gaps[0], gaps[1]]);
        }
    }
    println!(
        "\nDouble pendulum thrown onto a floor 0.8 m below its pivot, joint limits |th2 - th1| \
         <= 2.5, e = 0.8, 20 s: {} impacts, deepest gap {deepest:.1e} m, largest kinetic \
         energy change at an impact {gain:.1e} J (never a gain)",
        stepper.impacts()
    );

    println!("\nCost with contacts, ns per step (f64, whole runs, events and resting included):");
    println!("{:<28} {:>10} {:>14}", "", "RK4", "RK4 + contacts");
    let (ball_free, ball_contact) = (
        ns_per_step(Rk4, &ball, &b0, DT, 6000),
        ns_per_step(ground()?, &ball, &b0, DT, 6000),
    );
    let (dp_free, dp_contact) = (
        ns_per_step(Rk4, &dp, &d0, DT, 20_000),
        ns_per_step(floor()?, &dp, &d0, DT, 20_000),
    );
    println!(
        "{:<28} {ball_free:>10.1} {ball_contact:>14.1}",
        "ball (6 s)"
    );
    println!(
        "{:<28} {dp_free:>10.1} {dp_contact:>14.1}",
        "double pendulum (20 s)"
    );

    let height = vec![Series {
        name: "y".into(),
        points: path.iter().step_by(5).copied().collect(),
    }];
    let energy = vec![Series {
        name: "E".into(),
        points: samples.iter().map(|r| (r[0], r[1])).collect(),
    }];
    let gaps = vec![
        Series {
            name: "mass 1".into(),
            points: samples.iter().map(|r| (r[0], r[2])).collect(),
        },
        Series {
            name: "mass 2".into(),
            points: samples.iter().map(|r| (r[0], r[3])).collect(),
        },
    ];
    write_plot(
        "impacts.svg",
        "t (s)",
        &[
            (
                "Ball on the ground, e = 0.8: height",
                "y (m)",
                Scale::Linear,
                &height,
            ),
            (
                "Double pendulum onto a floor: energy (falls only at impacts)",
                "E (J)",
                Scale::Linear,
                &energy,
            ),
            (
                "Double pendulum onto a floor: height of each mass above it",
                "gap (m)",
                Scale::Linear,
                &gaps,
            ),
        ],
    )
    .map_err(|_| Error::NonFiniteState)
}
