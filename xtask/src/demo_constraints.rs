//! `cargo xtask demo`, constraints and impacts: the Cartesian pendulum under three kinds of
//! drift control and a four-bar linkage (residual and energy over time), a bouncing ball and a
//! double pendulum falling onto a floor (heights, energy, gaps), with the cost of a
//! constrained step against the unconstrained one and SVG plots.

use crate::demo::{ns_per_step, TIMING_RUNS};
use crate::plots;
use lagrange_core::nalgebra::{SVector, Vector4};
use lagrange_core::{
    Constrained, Constraints, Error, Holonomic, HolonomicConstraints, Lagrangian, Mechanism,
    Projection, Real, Scalar, Stabilization, State,
};
use lagrange_integrators::{ContactModel, ContactStepper, Integrator, Projected, Rk4};
use lagrange_plot::{Scale, Series};
use lagrange_systems::{
    Branch, CartesianPendulum, DoublePendulum, FallingParticle, FourBarLinkage, SimplePendulum,
};

const G: f64 = 9.81;
const DT: f64 = 1e-3;
/// The origin's 30 degrees.
const TH0: f64 = std::f64::consts::FRAC_PI_6;
/// Steps of the residual runs: 10^5, 100 s.
const LONG: u64 = 100_000;
/// Points kept per run for the plots.
const PLOT_POINTS: u64 = 1000;

/// One run's samples `(t, position residual, velocity residual, relative energy error)` and
/// its largest values.
struct Trace {
    name: String,
    samples: Vec<[f64; 4]>,
    worst: [f64; 3],
}

/// Steps `integrator` on `m` from `start`, tracing `constraints`' residuals and the energy
/// error relative to `scale`.
fn trace<I, M, K, const N: usize, const C: usize>(
    name: &str,
    mut integrator: I,
    m: &M,
    constraints: &K,
    start: &State<f64, N>,
    steps: u64,
    scale: f64,
) -> Result<Trace, Error>
where
    I: Integrator<f64, N>,
    M: Mechanism<f64, N>,
    K: Constraints<f64, N, C>,
{
    let e0 = m.energy(start);
    let stride = (steps / PLOT_POINTS).max(1);
    let mut out = Trace {
        name: name.into(),
        samples: Vec::new(),
        worst: [0.0; 3],
    };
    let mut n = 0;
    integrator.integrate_with(m, start, DT, steps, |s| {
        n += 1;
        let r = constraints.residual(s);
        let row = [r.position, r.velocity, (m.energy(s) - e0).abs() / scale];
        for (w, x) in out.worst.iter_mut().zip(row) {
            *w = w.max(x);
        }
        if n % stride == 0 {
            out.samples.push([s.t, row[0], row[1], row[2]]);
        }
    })?;
    Ok(out)
}

/// Plot lines of sample column `k` against time.
fn lines(traces: &[Trace], k: usize) -> Vec<Series> {
    traces
        .iter()
        .map(|t| Series {
            name: t.name.clone(),
            points: t.samples.iter().map(|s| (s[0], s[k])).collect(),
        })
        .collect()
}

/// The Cartesian pendulum three ways and the four-bar linkage with projection.
fn drift() -> Result<(Vec<Trace>, Trace), Error> {
    let free = Constrained::new(CartesianPendulum::new(1.0, 1.0, G)?);
    let baumgarte = free.with_stabilization(Stabilization::critical(3.0)?);
    let start = free.parts().state_from_angle(0.0, TH0, 0.0);
    // Energy relative to the swing's energy above the rest position.
    let scale = free.energy(&start) - free.energy(&free.parts().state_from_angle(0.0, 0.0, 0.0));
    let projection = Projection::new(1e-13, 4)?;
    let traces = vec![
        trace("RK4, none", Rk4, &free, &free, &start, LONG, scale)?,
        trace(
            "RK4, Baumgarte 3/s",
            Rk4,
            &baumgarte,
            &free,
            &start,
            LONG,
            scale,
        )?,
        trace(
            "RK4 + projection",
            Projected::new(Rk4, free, projection),
            &free,
            &free,
            &start,
            LONG,
            scale,
        )?,
    ];
    let linkage = four_bar()?;
    let s0 = linkage.parts().assemble(0.0, 0.0, 12.0, Branch::Right)?;
    let kinetic = linkage.kinetic_energy(&s0);
    let bar = trace(
        "four-bar, RK4 + projection",
        Projected::new(Rk4, linkage, projection),
        &linkage,
        &linkage,
        &s0,
        10_000,
        kinetic,
    )?;
    Ok((traces, bar))
}

/// The Grashof crank-rocker of the tests: ground 1 m, crank 0.3 m, coupler 1 m, rocker 0.8 m.
fn four_bar<T: Real>() -> Result<Constrained<T, 2, FourBarLinkage<T>>, Error> {
    Ok(Constrained::new(FourBarLinkage::new(
        [1.0, 0.3, 1.0, 0.8].map(T::from_f64),
        [0.5, 1.0, 0.8].map(T::from_f64),
        T::from_f64(G),
    )?))
}

/// Nanoseconds per step in `T`: `[simple pendulum RK4, Cartesian RK4, Cartesian RK4 +
/// Baumgarte, Cartesian RK4 + projection, double pendulum RK4, four-bar RK4, four-bar RK4 +
/// projection]`.
fn costs<T: Real>() -> Result<[f64; 7], Error> {
    let (one, g, dt) = (T::one(), T::from_f64(G), T::from_f64(DT));
    let th0 = T::from_f64(TH0);
    let steps = 10_000;
    let simple = SimplePendulum::new(one, one, g, T::zero())?;
    let free = Constrained::new(CartesianPendulum::new(one, one, g)?);
    let baumgarte = free.with_stabilization(Stabilization::critical(T::from_f64(3.0))?);
    let start = free.parts().state_from_angle(T::zero(), th0, T::zero());
    let tol = T::from_f64(if T::EPSILON.to_f64() > 1e-10 {
        1e-5
    } else {
        1e-13
    });
    let projection = Projection::new(tol, 4)?;
    let double = DoublePendulum::new(one, one, one, one, g)?;
    let linkage = four_bar::<T>()?;
    let s0 = linkage
        .parts()
        .assemble(T::zero(), T::zero(), T::from_f64(12.0), Branch::Right)?;
    Ok([
        ns_per_step(Rk4, &simple, &State::at_rest([th0]), dt, steps),
        ns_per_step(Rk4, &free, &start, dt, steps),
        ns_per_step(Rk4, &baumgarte, &start, dt, steps),
        ns_per_step(
            Projected::new(Rk4, free, projection),
            &free,
            &start,
            dt,
            steps,
        ),
        ns_per_step(Rk4, &double, &State::at_rest([th0; 2]), dt, steps),
        ns_per_step(Rk4, &linkage, &s0, dt, steps),
        ns_per_step(
            Projected::new(Rk4, linkage, projection),
            &linkage,
            &s0,
            dt,
            steps,
        ),
    ])
}

/// The ground at `y = 0` for a particle with `q = [y]`.
#[derive(Clone, Copy)]
struct Ground;

impl<T: Real> HolonomicConstraints<T, 1, 1> for Ground {
    fn phi<S: Scalar<Real = T>>(&self, q: &SVector<S, 1>) -> SVector<S, 1> {
        *q
    }
}

/// A floor 0.8 m below the double pendulum's pivot under both masses, and joint limits
/// `|th2 - th1| <= 2.5`.
#[derive(Clone, Copy)]
struct FloorAndLimits;

impl<T: Real> HolonomicConstraints<T, 2, 4> for FloorAndLimits {
    fn phi<S: Scalar<Real = T>>(&self, q: &SVector<S, 2>) -> SVector<S, 4> {
        let (floor, bend) = (S::from_f64(0.8), S::from_f64(2.5));
        let y1 = -q[0].cos();
        let y2 = y1 - q[1].cos();
        let relative = q[1] - q[0];
        Vector4::new(y1 + floor, y2 + floor, bend - relative, bend + relative)
    }
}

/// The contact model of both scenes: resting below 0.05 m/s, events to 1e-10 s.
fn contact_model(restitution: f64) -> Result<ContactModel<f64>, Error> {
    ContactModel::new(restitution, 0.05, 1e-10)
}

/// What the ball's run measured.
struct BallRun {
    /// `(t, y)` every step.
    path: Vec<(f64, f64)>,
    /// The highest `y` between successive impacts.
    apexes: Vec<f64>,
    impacts: u64,
    /// When the contact became resting.
    rest: Option<f64>,
}

/// A ball dropped from 1 m with e = 0.8 for 6 s.
fn ball() -> Result<BallRun, Error> {
    let ball = FallingParticle::new(1.0, G)?;
    let mut stepper = ContactStepper::new(
        Rk4,
        Holonomic::new(Ground),
        contact_model(0.8)?,
        Projection::new(1e-12, 4)?,
    );
    let mut s = State::at_rest([1.0]);
    let (mut path, mut apexes) = (vec![(0.0, 1.0)], Vec::new());
    let (mut since, mut rest) = (None::<f64>, None);
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
    Ok(BallRun {
        path,
        apexes,
        impacts: stepper.impacts(),
        rest,
    })
}

/// What the double pendulum's run measured.
struct FloorRun {
    /// `(t, E, gap 1, gap 2)` every 20 steps.
    samples: Vec<[f64; 4]>,
    impacts: u64,
    /// The lowest gap of any contact row after any step.
    deepest: f64,
    /// The largest change of kinetic energy across an impact (negative: always a loss).
    gain: f64,
}

/// The double pendulum thrown onto the floor (e = 0.8) for 20 s.
fn double_on_floor() -> Result<FloorRun, Error> {
    let dp = DoublePendulum::new(1.0, 1.0, 1.0, 1.0, G)?;
    let contacts = Holonomic::new(FloorAndLimits);
    let mut stepper = ContactStepper::new(
        Rk4,
        contacts,
        contact_model(0.8)?,
        Projection::new(1e-10, 6)?,
    );
    let mut s = State::new(0.0, [1.6, 2.2], [2.0, -6.0]);
    let (mut out, mut deepest, mut gain) = (Vec::new(), f64::INFINITY, f64::NEG_INFINITY);
    for n in 0..20_000 {
        s = stepper.step_observed(&dp, &s, DT, |impact| {
            let k0 = dp.kinetic_energy(&impact.state_before());
            gain = gain.max(dp.kinetic_energy(&impact.state_after()) - k0);
        })?;
        let gaps = contacts.position_residual(&s.q);
        deepest = gaps.iter().fold(deepest, |d, &g| d.min(g));
        if n % 20 == 0 {
            out.push([s.t, dp.energy(&s), gaps[0], gaps[1]]);
        }
    }
    Ok(FloorRun {
        samples: out,
        impacts: stepper.impacts(),
        deepest,
        gain,
    })
}

/// Nanoseconds per step of the ball's and the double pendulum's contact runs (events and
/// resting included) and of the same mechanisms without contacts.
fn contact_costs() -> Result<[f64; 4], Error> {
    let ball = FallingParticle::new(1.0, G)?;
    let dp = DoublePendulum::new(1.0, 1.0, 1.0, 1.0, G)?;
    let ball_stepper = ContactStepper::new(
        Rk4,
        Holonomic::new(Ground),
        contact_model(0.8)?,
        Projection::new(1e-12, 4)?,
    );
    let floor_stepper = ContactStepper::new(
        Rk4,
        Holonomic::new(FloorAndLimits),
        contact_model(0.8)?,
        Projection::new(1e-10, 6)?,
    );
    let b0 = State::at_rest([1.0]);
    let d0 = State::new(0.0, [1.6, 2.2], [2.0, -6.0]);
    Ok([
        ns_per_step(Rk4, &ball, &b0, DT, 6000),
        ns_per_step(ball_stepper, &ball, &b0, DT, 6000),
        ns_per_step(Rk4, &dp, &d0, DT, 20_000),
        ns_per_step(floor_stepper, &dp, &d0, DT, 20_000),
    ])
}

/// The constrained scene: tables and `constraints.svg`.
fn constrained_scene() -> Result<(), String> {
    let (traces, bar) = drift().map_err(|e| e.to_string())?;
    println!(
        "\nCartesian pendulum (q = [x, y], x^2 + y^2 = l^2): l = 1 m, 30 deg at rest, RK4 at \
         dt = 1e-3 s for 100 s (10^5 steps)"
    );
    println!(
        "{:<28} {:>12} {:>12} {:>12}",
        "drift control", "max |phi| m", "max |Jq'|", "max dE/E"
    );
    for t in traces.iter().chain([&bar]) {
        println!(
            "{:<28} {:>12.2e} {:>12.2e} {:>12.2e}",
            t.name, t.worst[0], t.worst[1], t.worst[2]
        );
    }
    println!(
        "(four-bar linkage: 10 s, crank at 12 rad/s, dE relative to its initial kinetic energy)"
    );

    let c64 = costs::<f64>().map_err(|e| e.to_string())?;
    let c32 = costs::<f32>().map_err(|e| e.to_string())?;
    println!(
        "\nCost of a constrained step, ns per step (median of {TIMING_RUNS} runs of 10^4 steps):"
    );
    println!("{:<40} {:>8} {:>8}", "", "f32", "f64");
    let names = [
        "simple pendulum, RK4 (1 angle)",
        "Cartesian pendulum, RK4 (2 + 1 rows)",
        "  + Baumgarte",
        "  + projection",
        "double pendulum, RK4 (2 angles)",
        "four-bar, RK4 (3 angles + 2 rows)",
        "  + projection",
    ];
    for (i, name) in names.iter().enumerate() {
        println!("{name:<40} {:>8.1} {:>8.1}", c32[i], c64[i]);
    }

    let residual = lines(&traces, 1);
    let energy = lines(&traces, 3);
    let bar_lines = vec![
        Series {
            name: "|dE| / KE0".into(),
            points: bar.samples.iter().map(|s| (s[0], s[3])).collect(),
        },
        Series {
            name: "|phi| (m)".into(),
            points: bar.samples.iter().map(|s| (s[0], s[1])).collect(),
        },
    ];
    plots::write(
        "constraints.svg",
        "t (s)",
        &[
            (
                "Cartesian pendulum, RK4 dt = 1e-3: constraint residual",
                "|phi| (m)",
                Scale::Log,
                &residual,
            ),
            (
                "Cartesian pendulum, RK4 dt = 1e-3: energy error",
                "|dE| / E",
                Scale::Log,
                &energy,
            ),
            (
                "Four-bar linkage, RK4 + projection: energy error and residual",
                "",
                Scale::Log,
                &bar_lines,
            ),
        ],
    )
}

/// The colliding scene: tables and `impacts.svg`.
fn colliding_scene() -> Result<(), String> {
    let BallRun {
        path,
        apexes,
        impacts,
        rest,
    } = ball().map_err(|e| e.to_string())?;
    println!(
        "\nBall dropped from 1 m on the ground, e = 0.8, RK4 at dt = 1e-3 s, contacts located \
         to 1e-10 s: {impacts} impacts, at rest from t = {} s",
        rest.map_or_else(|| "-".to_string(), |t| format!("{t:.3}"))
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

    let FloorRun {
        samples: dp,
        impacts: dp_impacts,
        deepest,
        gain,
    } = double_on_floor().map_err(|e| e.to_string())?;
    println!(
        "\nDouble pendulum thrown onto a floor 0.8 m below its pivot, joint limits |th2 - th1| \
         <= 2.5, e = 0.8, 20 s: {dp_impacts} impacts, deepest gap {deepest:.1e} m, largest \
         kinetic energy change at an impact {gain:.1e} J (never a gain)"
    );
    let [ball_free, ball_contact, dp_free, dp_contact] =
        contact_costs().map_err(|e| e.to_string())?;
    println!("\nCost with contacts, ns per step (f64, whole runs, events and resting included):");
    println!("{:<28} {:>10} {:>14}", "", "RK4", "RK4 + contacts");
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
        points: dp.iter().map(|r| (r[0], r[1])).collect(),
    }];
    let gaps = vec![
        Series {
            name: "mass 1".into(),
            points: dp.iter().map(|r| (r[0], r[2])).collect(),
        },
        Series {
            name: "mass 2".into(),
            points: dp.iter().map(|r| (r[0], r[3])).collect(),
        },
    ];
    plots::write(
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
}

/// Runs both scenes.
pub fn run() -> Result<(), String> {
    constrained_scene()?;
    colliding_scene()
}
