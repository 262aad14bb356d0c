//! The origin's pendulum (L = 1 m, g = 9.81 m/s^2, released at rest from 30 degrees, 10 s)
//! with every integrator of the library against the exact (Jacobi elliptic) solution: the
//! state along the run, the final error and the cost per step at two step sizes, the adaptive
//! pairs against their tolerance, and a plot of angle and energy error.
//!
//! `cargo run --release --example origin_pendulum` (writes `target/lagrange-demo/pendulum.svg`)

use lagrange_examples::{median_ns, ns_per_step, state_error, write_plot};
use lagrange_integrators::prelude::*;
use lagrange_integrators::{
    BackwardEuler, Dop853Pair, Dopri5Pair, EmbeddedPair, EmbeddedRungeKutta, ExplicitEuler,
    ImplicitMidpoint, RadauIIA2, SemiImplicitEuler, Stop, VelocityVerlet,
};
use lagrange_plot::{Scale, Series};
use lagrange_systems::exact::{pendulum_from_rest, pendulum_period};
use lagrange_systems::SimplePendulum;
use std::hint::black_box;

const G: f64 = 9.81;
const TH0: f64 = std::f64::consts::FRAC_PI_6;
const T_END: f64 = 10.0;
/// Times at which the state is tabulated.
const TABLE_TIMES: [f64; 4] = [2.5, 5.0, 7.5, 10.0];
/// Points kept per run for the plot.
const PLOT_POINTS: u64 = 1000;

type Pendulum = SimplePendulum<f64>;

/// The exact `(th, th')` at `t`.
fn exact(t: f64) -> Result<[f64; 2], Error> {
    pendulum_from_rest(TH0, G.sqrt(), t).map(|(th, thd)| [th, thd])
}

/// One integrator's run at one step size: samples for the table and the plot, and its figures.
struct Run {
    name: &'static str,
    order: u32,
    /// `(state, relative energy error)` every few steps, the start included.
    samples: Vec<(State<f64, 1>, f64)>,
    end: Result<State<f64, 1>, Error>,
    ns_per_step: f64,
}

/// `integrator` over 10 s at `dt`, sampled, then timed unobserved.
fn run<I: Integrator<f64, 1, Pendulum> + Clone>(p: &Pendulum, integrator: I, dt: f64) -> Run {
    let start = State::at_rest([TH0]);
    let steps = (T_END / dt).round() as u64;
    let e0 = p.energy(&start);
    let scale = e0 - p.energy(&State::at_rest([0.0]));
    let stride = (steps / PLOT_POINTS).max(1);
    let mut samples = vec![(start, 0.0)];
    let mut n = 0u64;
    let end = integrator
        .clone()
        .integrate_with(p, &start, dt, steps, |s| {
            n += 1;
            if n % stride == 0 {
                samples.push((*s, ((p.energy(s) - e0) / scale).abs()));
            }
        });
    Run {
        name: I::NAME,
        order: I::ORDER,
        samples,
        end: end.map_err(Error::from),
        ns_per_step: ns_per_step(integrator, p, &start, dt, steps),
    }
}

/// Every fixed-step method at `dt`.
fn every_method(p: &Pendulum, dt: f64) -> Vec<Run> {
    vec![
        run(p, ExplicitEuler, dt),
        run(p, SemiImplicitEuler, dt),
        run(p, VelocityVerlet, dt),
        run(p, StormerVerlet::default(), dt),
        run(p, Rk4, dt),
        run(p, Yoshida4::<StormerVerlet<f64, 1>>::default(), dt),
        run(p, ImplicitMidpoint::default(), dt),
        run(p, GaussLegendre2::default(), dt),
        run(p, BackwardEuler::default(), dt),
        run(p, RadauIIA2::default(), dt),
        run(p, VariationalMidpoint::default(), dt),
        run(p, Yoshida4::<VariationalMidpoint<f64, 1>>::default(), dt),
    ]
}

/// The state along the run for the first four methods, beside the exact one.
fn print_trajectories(runs: &[Run], dt: f64) -> Result<(), Error> {
    println!("\nThe origin's pendulum, dt = {dt:e} s: th (deg) along the run");
    print!("{:<22}", "integrator");
    for t in TABLE_TIMES {
        print!(" {:>12}", format!("th({t})"));
    }
    println!();
    print!("{:<22}", "exact (Jacobi sn)");
    for t in TABLE_TIMES {
        print!(" {:>12.6}", exact(t)?[0].to_degrees());
    }
    println!();
    for run in runs.iter().take(5) {
        print!("{:<22}", run.name);
        for t in TABLE_TIMES {
            let near = run
                .samples
                .iter()
                .min_by(|a, b| (a.0.t - t).abs().total_cmp(&(b.0.t - t).abs()));
            match near {
                Some((s, _)) => print!(" {:>12.6}", s.q[0].to_degrees()),
                None => print!(" {:>12}", "-"),
            }
        }
        println!();
    }
    Ok(())
}

/// Final error and cost of every method at two step sizes.
fn print_errors(coarse: &[Run], fine: &[Run]) -> Result<(), Error> {
    let reference = exact(T_END)?;
    println!(
        "\nEvery fixed-step integrator (f64): final error max(|th|, |th'|) at 10 s against the \
         exact solution, and ns per step"
    );
    println!(
        "{:<24} {:>5} {:>12} {:>9} {:>12} {:>9} {:>7}",
        "integrator", "order", "err dt=1e-2", "ns/step", "err dt=1e-3", "ns/step", "slope"
    );
    for (a, b) in coarse.iter().zip(fine) {
        print!("{:<24} {:>5}", a.name, a.order);
        let mut errs = Vec::new();
        for r in [a, b] {
            match &r.end {
                Ok(s) => {
                    let e = state_error(s, &reference);
                    errs.push(e);
                    print!(" {e:>12.3e} {:>9.1}", r.ns_per_step);
                }
                Err(e) => print!(" {:>22}", format!("failed: {e}")),
            }
        }
        match errs[..] {
            [x, y] => println!(" {:>7.2}", (x / y).log10()),
            _ => println!(),
        }
    }
    println!(
        "(The slope over a decade of dt is the order until the error meets rounding, ~1e-13.)"
    );
    Ok(())
}

/// One adaptive pair: error against tolerance, work, and the first crossing of th = 0.
fn adaptive<const S: usize, const R: usize, P: EmbeddedPair<S, R>>(
    p: &Pendulum,
    rtols: &[f64],
) -> Result<(), Error> {
    let start = State::at_rest([TH0]);
    let quarter = 0.25 * pendulum_period(TH0, G.sqrt())?;
    for &rtol in rtols {
        let settings = AdaptiveSettings::new(rtol, rtol * 1e-2)?;
        let mut pair = EmbeddedRungeKutta::<f64, 1, S, R, P>::new(settings);
        let end = pair.integrate_to(p, &start, T_END)?;
        let work = pair.statistics();
        let us = median_ns(1, || {
            EmbeddedRungeKutta::<f64, 1, S, R, P>::new(settings).integrate_to(
                black_box(p),
                &start,
                T_END,
            )
        }) / 1e3;
        let mut events = EmbeddedRungeKutta::<f64, 1, S, R, P>::new(settings);
        let miss =
            match events.integrate_until_event(p, &start, T_END, |s: &State<f64, 1>| s.q[0])? {
                Stop::Event(s) => format!("{:>10.1e}", s.t - quarter),
                Stop::End(_) => format!("{:>10}", "none"),
            };
        println!(
            "{:<24} {rtol:>7.0e} {:>12.3e} {:>7} {:>5} {:>7} {:>9.1} {miss}",
            P::NAME,
            state_error(&end, &exact(T_END)?),
            work.accepted,
            work.rejected,
            work.evaluations,
            us,
        );
    }
    Ok(())
}

/// Plot lines of `(t, f(sample))` for each run.
fn series(runs: &[Run], f: impl Fn(&(State<f64, 1>, f64)) -> f64) -> Vec<Series> {
    runs.iter()
        .map(|r| Series {
            name: r.name.to_string(),
            points: r.samples.iter().map(|s| (s.0.t, f(s))).collect(),
        })
        .collect()
}

fn main() -> Result<(), String> {
    let text = |e: Error| e.to_string();
    let p = SimplePendulum::new(1.0, 1.0, G, 0.0).map_err(text)?;
    let coarse = every_method(&p, 1e-2);
    let fine = every_method(&p, 1e-3);
    print_trajectories(&fine, 1e-3).map_err(text)?;
    print_errors(&coarse, &fine).map_err(text)?;

    println!(
        "\nAdaptive pairs (atol = rtol / 100): final error at 10 s, work, microseconds per \
         run, and the miss of the first crossing of th = 0 (a quarter period)"
    );
    println!(
        "{:<24} {:>7} {:>12} {:>7} {:>5} {:>7} {:>9} {:>10}",
        "integrator", "rtol", "err(10)", "steps", "rej", "evals", "us/run", "event s"
    );
    adaptive::<7, 1, Dopri5Pair>(&p, &[1e-4, 1e-6, 1e-8, 1e-10, 1e-12]).map_err(text)?;
    adaptive::<16, 4, Dop853Pair>(&p, &[1e-6, 1e-8, 1e-10, 1e-12, 1e-13]).map_err(text)?;

    // The plot: the four classic methods' angle beside the exact one, and their energy error.
    let classic = &fine[..5];
    let mut angle = series(classic, |s| s.0.q[0]);
    angle.push(Series {
        name: "exact".into(),
        points: (0..=1000)
            .filter_map(|i| {
                let t = T_END * f64::from(i) / 1000.0;
                exact(t).ok().map(|[th, _]| (t, th))
            })
            .collect(),
    });
    let energy = series(&fine, |s| s.1.max(1e-17));
    write_plot(
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
        ],
    )
}
