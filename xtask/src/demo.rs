//! `cargo xtask demo`: the origin's pendulum and a chaotic double pendulum with every
//! integrator, against exact or reference answers, with an SVG plot.

use crate::plots;
use lagrange_core::{Error, Mechanism, Real, State};
use lagrange_integrators::{ExplicitEuler, Integrator, Rk4, SemiImplicitEuler, VelocityVerlet};
use lagrange_plot::{Scale, Series};
use lagrange_systems::exact::pendulum_from_rest;
use lagrange_systems::{DoublePendulum, SimplePendulum};
use std::hint::black_box;

/// The origin's pendulum: L = 1 m, g = 9.81 m/s^2, released at rest from 30 degrees.
const G: f64 = 9.81;
const TH0: f64 = std::f64::consts::FRAC_PI_6;
const T_END: f64 = 10.0;
/// Times at which the state is tabulated.
const TABLE_TIMES: [f64; 4] = [2.5, 5.0, 7.5, 10.0];
/// Points kept per run for the plot.
const PLOT_POINTS: u64 = 1000;
/// Timing: the median of this many whole runs.
pub(crate) const TIMING_RUNS: usize = 5;

/// Problem P2 of shared/BENCH_PROBLEMS.md: both angles pi/2 at rest, T = 10 s; its state at
/// T from a 1e-27 reference solve (th1, th2, th1', th2').
#[allow(clippy::excessive_precision)] // the digits as published
const P2_REFERENCE: [f64; 4] = [
    -0.568_474_664_015_950_2,
    -0.526_393_727_932_404_7,
    6.078_384_885_761_965,
    -9.681_360_681_708_879,
];

/// Median wall time per step of `steps` steps, over `TIMING_RUNS` whole runs.
pub(crate) fn ns_per_step<T, I, M, const N: usize>(
    mut integrator: I,
    mechanism: &M,
    start: &State<T, N>,
    dt: T,
    steps: u64,
) -> f64
where
    T: Real,
    I: Integrator<T, N>,
    M: Mechanism<T, N>,
{
    crate::demo_integrators::median_ns(steps, || {
        integrator.integrate(black_box(mechanism), black_box(start), dt, steps)
    })
}

/// RK4's cost per step on the pendulum and the double pendulum in `T`.
fn rk4_cost<T: Real>() -> Result<(f64, f64), Error> {
    let (one, g, dt) = (T::one(), T::from_f64(G), T::from_f64(1e-3));
    let p = SimplePendulum::new(one, one, g, T::zero())?;
    let dp = DoublePendulum::new(one, one, one, one, g)?;
    Ok((
        ns_per_step(Rk4, &p, &State::at_rest([T::from_f64(TH0)]), dt, 10_000),
        ns_per_step(Rk4, &dp, &State::at_rest([T::from_f64(TH0); 2]), dt, 10_000),
    ))
}

/// One integrator's run: samples for the table and plot, and its figures.
struct Run<const N: usize> {
    name: &'static str,
    /// `(state, relative energy error)` every `stride` steps, the start included.
    samples: Vec<(State<f64, N>, f64)>,
    last: Result<State<f64, N>, Error>,
    max_energy_error: f64,
    ns_per_step: f64,
}

/// Integrates `mechanism` from `start` over `steps` steps of `dt`, sampling, then times the
/// same run without sampling. Energy error is relative to `start`'s energy above `rest`.
fn simulate<I, M, const N: usize>(
    mut integrator: I,
    mechanism: &M,
    start: State<f64, N>,
    dt: f64,
    steps: u64,
    rest: &State<f64, N>,
) -> Run<N>
where
    I: Integrator<f64, N> + Copy,
    M: Mechanism<f64, N>,
{
    let e0 = mechanism.energy(&start);
    let scale = (e0 - mechanism.energy(rest)).abs();
    let rel = |s: &State<f64, N>| (mechanism.energy(s) - e0).abs() / scale;
    let stride = (steps / PLOT_POINTS).max(1);
    let mut samples = vec![(start, 0.0)];
    let mut max_energy_error: f64 = 0.0;
    let mut n = 0u64;
    let last = integrator.integrate_with(mechanism, &start, dt, steps, |s| {
        n += 1;
        let e = rel(s);
        max_energy_error = max_energy_error.max(e);
        if n % stride == 0 {
            samples.push((*s, e));
        }
    });

    Run {
        name: I::NAME,
        samples,
        last,
        max_energy_error,
        ns_per_step: ns_per_step(integrator, mechanism, &start, dt, steps),
    }
}

/// The four integrators on one problem.
fn all_integrators<M: Mechanism<f64, N>, const N: usize>(
    m: &M,
    start: State<f64, N>,
    dt: f64,
    rest: &State<f64, N>,
) -> [Run<N>; 4] {
    let steps = (T_END / dt).round() as u64;
    [
        simulate(ExplicitEuler, m, start, dt, steps, rest),
        simulate(SemiImplicitEuler, m, start, dt, steps, rest),
        simulate(VelocityVerlet, m, start, dt, steps, rest),
        simulate(Rk4, m, start, dt, steps, rest),
    ]
}

/// The sampled state nearest to time `t`.
fn at<const N: usize>(run: &Run<N>, t: f64) -> Option<&State<f64, N>> {
    run.samples
        .iter()
        .map(|(s, _)| s)
        .min_by(|a, b| (a.t - t).abs().total_cmp(&(b.t - t).abs()))
}

/// `max_i |x_i - y_i|` over angles and rates.
fn state_error<const N: usize>(s: &State<f64, N>, reference: &[f64]) -> f64 {
    s.q.iter()
        .chain(s.qd.iter())
        .zip(reference)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

fn pendulum_table(dt: f64) -> Result<[Run<1>; 4], String> {
    let p = SimplePendulum::new(1.0, 1.0, G, 0.0).map_err(|e| e.to_string())?;
    let exact = |t: f64| pendulum_from_rest(TH0, G.sqrt(), t).map_err(|e| e.to_string());
    let runs = all_integrators(&p, State::at_rest([TH0]), dt, &State::at_rest([0.0]));

    println!(
        "\nThe origin's pendulum: L = 1 m, g = 9.81 m/s^2, 30 deg at rest, 10 s, dt = {dt:e} s"
    );
    print!("{:<20}", "integrator");
    for t in TABLE_TIMES {
        print!(" {:>12}", format!("th({t}) deg"));
    }
    println!(
        " {:>12} {:>11} {:>11} {:>8}",
        "th'(10) r/s", "err(10)", "max dE/E", "ns/step"
    );
    print!("{:<20}", "exact (Jacobi sn)");
    for t in TABLE_TIMES {
        print!(" {:>12.6}", exact(t)?.0.to_degrees());
    }
    println!(" {:>12.6}", exact(T_END)?.1);
    let (th_end, thd_end) = exact(T_END)?;
    for run in &runs {
        print!("{:<20}", run.name);
        for t in TABLE_TIMES {
            match at(run, t) {
                Some(s) => print!(" {:>12.6}", s.q[0].to_degrees()),
                None => print!(" {:>12}", "-"),
            }
        }
        match &run.last {
            Ok(s) => println!(
                " {:>12.6} {:>11.3e} {:>11.3e} {:>8.1}",
                s.qd[0],
                state_error(s, &[th_end, thd_end]),
                run.max_energy_error,
                run.ns_per_step
            ),
            Err(e) => println!(" failed: {e}"),
        }
    }
    Ok(runs)
}

fn double_pendulum_table(dt: f64) -> Result<[Run<2>; 4], String> {
    let dp = DoublePendulum::new(1.0, 1.0, 1.0, 1.0, G).map_err(|e| e.to_string())?;
    let half_pi = std::f64::consts::FRAC_PI_2;
    let runs = all_integrators(
        &dp,
        State::at_rest([half_pi, half_pi]),
        dt,
        &State::at_rest([0.0, 0.0]),
    );
    println!("\nChaotic double pendulum (P2): m = l = 1, both angles 90 deg at rest, 10 s, dt = {dt:e} s");
    println!(
        "{:<20} {:>10} {:>10} {:>10} {:>10} {:>11} {:>11} {:>8}",
        "integrator",
        "th1(10)",
        "th2(10)",
        "th1'(10)",
        "th2'(10)",
        "err(10)",
        "max dE/E",
        "ns/step"
    );
    let [a, b, c, d] = P2_REFERENCE;
    println!(
        "{:<20} {a:>10.6} {b:>10.6} {c:>10.6} {d:>10.6}",
        "reference"
    );
    for run in &runs {
        match &run.last {
            Ok(s) => println!(
                "{:<20} {:>10.6} {:>10.6} {:>10.6} {:>10.6} {:>11.3e} {:>11.3e} {:>8.1}",
                run.name,
                s.q[0],
                s.q[1],
                s.qd[0],
                s.qd[1],
                state_error(s, &P2_REFERENCE),
                run.max_energy_error,
                run.ns_per_step
            ),
            Err(e) => println!("{:<20} failed: {e}", run.name),
        }
    }
    Ok(runs)
}

/// Plot lines of `(t, f(sample))` for every run.
fn series<const N: usize>(
    runs: &[Run<N>],
    f: impl Fn(&(State<f64, N>, f64)) -> f64,
) -> Vec<Series> {
    runs.iter()
        .map(|r| Series {
            name: r.name.to_string(),
            points: r.samples.iter().map(|s| (s.0.t, f(s))).collect(),
        })
        .collect()
}

/// Runs the demo.
pub fn run() -> Result<(), String> {
    let coarse = pendulum_table(1e-2)?;
    let fine = pendulum_table(1e-3)?;
    let chaotic = double_pendulum_table(1e-3)?;
    drop(coarse);
    let (p32, dp32) = rk4_cost::<f32>().map_err(|e| e.to_string())?;
    let (p64, dp64) = rk4_cost::<f64>().map_err(|e| e.to_string())?;
    println!("\nRK4, ns per step (median of {TIMING_RUNS} runs of 10^4 steps):");
    println!("{:<20} {:>8} {:>8}", "", "f32", "f64");
    println!("{:<20} {p32:>8.1} {p64:>8.1}", "pendulum");
    println!("{:<20} {dp32:>8.1} {dp64:>8.1}", "double pendulum");

    let mut angle = series(&fine, |s| s.0.q[0]);
    angle.push(Series {
        name: "exact".into(),
        points: (0..=1000)
            .filter_map(|i| {
                let t = T_END * f64::from(i) / 1000.0;
                pendulum_from_rest(TH0, G.sqrt(), t)
                    .ok()
                    .map(|(th, _)| (t, th))
            })
            .collect(),
    });
    let energy = series(&fine, |s| s.1);
    let dp_energy = series(&chaotic, |s| s.1);
    println!();
    plots::write(
        "pendulum.svg",
        "t (s)",
        &[
            (
                "Origin's pendulum, dt = 1e-3: angle",
                "th (rad)",
                Scale::Linear,
                &angle,
            ),
            (
                "Origin's pendulum, dt = 1e-3: energy error",
                "|dE|/E",
                Scale::Log,
                &energy,
            ),
            (
                "Chaotic double pendulum, dt = 1e-3: energy error",
                "|dE|/E",
                Scale::Log,
                &dp_energy,
            ),
        ],
    )?;
    crate::demo_systems::run()?;
    crate::demo_integrators::run()?;
    crate::demo_constraints::run()
}
