//! Constraints that coordinates cannot absorb: a four-bar linkage (three angles tied by a
//! loop closure) stepped by RK4 and projected back onto its constraints after every step, and
//! the origin's pendulum written in Cartesian coordinates with a rod, under each kind of drift
//! control: none, Baumgarte, projection. Prints the residuals, the energy error and the cost
//! of a constrained step.
//!
//! `cargo run --release --example four_bar` (writes `target/lagrange-demo/constraints.svg`)

use lagrange_examples::{ns_per_step, write_plot, TIMING_RUNS};
use lagrange_integrators::prelude::*;
use lagrange_plot::{Scale, Series};
use lagrange_systems::{Branch, CartesianPendulum, DoublePendulum, FourBarLinkage, SimplePendulum};

const G: f64 = 9.81;
const DT: f64 = 1e-3;
/// The origin's 30 degrees.
const TH0: f64 = std::f64::consts::FRAC_PI_6;
/// Steps of the pendulum's runs: 10^5, 100 s.
const LONG: u64 = 100_000;
/// Points kept per run for the plots.
const PLOT_POINTS: u64 = 1000;

/// The Grashof crank-rocker of the tests: ground 1 m, crank 0.3 m, coupler 1 m, rocker 0.8 m.
fn four_bar<T: Real>() -> Result<Constrained<T, 2, FourBarLinkage<T>>, Error> {
    Ok(Constrained::new(FourBarLinkage::new(
        [1.0, 0.3, 1.0, 0.8].map(T::from_f64),
        [0.5, 1.0, 0.8].map(T::from_f64),
        T::from_f64(G),
    )?))
}

/// One run's samples `(t, position residual, velocity residual, relative energy error)` and
/// its largest values.
struct Trace {
    name: String,
    samples: Vec<[f64; 4]>,
    worst: [f64; 3],
}

/// Steps `integrator` on `m` from `start`, tracing the residuals of `m`'s rows and the energy
/// error relative to `scale`.
fn trace<I, M, const N: usize, const C: usize>(
    name: &str,
    mut integrator: I,
    m: &M,
    start: &State<f64, N>,
    steps: u64,
    scale: f64,
) -> Result<Trace, Error>
where
    I: Integrator<f64, N, M>,
    M: Mechanism<f64, N> + Constraints<f64, N, C>,
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
        let r = m.residual(s);
        let row = [r.position, r.velocity, (m.energy(s) - e0).abs() / scale];
        for (w, x) in out.worst.iter_mut().zip(row) {
            *w = w.max(x);
        }
        if n % stride == 0 {
            out.samples
                .push([s.t, row[0].max(1e-17), row[1], row[2].max(1e-17)]);
        }
    })?;
    Ok(out)
}

/// The Cartesian pendulum three ways, and the four-bar linkage with projection.
fn drift() -> Result<(Vec<Trace>, Trace), Error> {
    let free = Constrained::new(CartesianPendulum::new(1.0, 1.0, G)?);
    let baumgarte = free.with_stabilization(Stabilization::critical(3.0)?);
    let start = free.parts().state_from_angle(0.0, TH0, 0.0);
    // Energy relative to the swing's energy above the rest position.
    let scale = free.energy(&start) - free.energy(&free.parts().state_from_angle(0.0, 0.0, 0.0));
    let projection = Projection::new(1e-13, 4)?;
    let traces = vec![
        trace("RK4, none", Rk4, &free, &start, LONG, scale)?,
        trace("RK4, Baumgarte 3/s", Rk4, &baumgarte, &start, LONG, scale)?,
        trace(
            "RK4 + projection",
            Projected::new(Rk4, projection),
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
        Projected::new(Rk4, projection),
        &linkage,
        &s0,
        10_000,
        kinetic,
    )?;
    Ok((traces, bar))
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
    let tolerance = if T::EPSILON.to_f64() > 1e-10 {
        1e-5
    } else {
        1e-13
    };
    let projection = Projection::new(T::from_f64(tolerance), 4)?;
    let double = DoublePendulum::new(one, one, one, one, g)?;
    let linkage = four_bar::<T>()?;
    let s0 = linkage
        .parts()
        .assemble(T::zero(), T::zero(), T::from_f64(12.0), Branch::Right)?;
    Ok([
        ns_per_step(Rk4, &simple, &State::at_rest([th0]), dt, steps),
        ns_per_step(Rk4, &free, &start, dt, steps),
        ns_per_step(Rk4, &baumgarte, &start, dt, steps),
        ns_per_step(Projected::new(Rk4, projection), &free, &start, dt, steps),
        ns_per_step(Rk4, &double, &State::at_rest([th0; 2]), dt, steps),
        ns_per_step(Rk4, &linkage, &s0, dt, steps),
        ns_per_step(Projected::new(Rk4, projection), &linkage, &s0, dt, steps),
    ])
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

fn main() -> Result<(), String> {
    let text = |e: Error| e.to_string();
    let (traces, bar) = drift().map_err(text)?;
    println!(
        "Cartesian pendulum (q = [x, y], x^2 + y^2 = l^2): l = 1 m, 30 deg at rest, RK4 at \
         dt = 1e-3 s for 100 s (10^5 steps); four-bar linkage: 10 s, crank at 12 rad/s"
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
    println!("(four-bar: dE relative to its initial kinetic energy)");

    let (c64, c32) = (costs::<f64>().map_err(text)?, costs::<f32>().map_err(text)?);
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
    write_plot(
        "constraints.svg",
        "t (s)",
        &[
            (
                "Cartesian pendulum, RK4 dt = 1e-3: constraint residual",
                "|phi| (m)",
                Scale::Log,
                &lines(&traces, 1),
            ),
            (
                "Cartesian pendulum, RK4 dt = 1e-3: energy error",
                "|dE| / E",
                Scale::Log,
                &lines(&traces, 3),
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
