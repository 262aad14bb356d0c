//! `cargo xtask demo`, second part: every integrator on the origin's pendulum, final error
//! and cost per step at two step sizes, and the adaptive integrators' error against their
//! tolerance and event location.

use crate::demo::TIMING_RUNS;
use lagrange_core::{Error, EulerLagrange, State};
use lagrange_integrators::{
    AdaptiveSettings, BackwardEuler, EmbeddedPair, EmbeddedRungeKutta, ExplicitEuler,
    GaussLegendre2, ImplicitMidpoint, Integrator, RadauIIA2, Rk4, SemiImplicitEuler, Stop,
    StormerVerlet, VariationalMidpoint, VelocityVerlet, Yoshida4,
};
use lagrange_systems::exact::{pendulum_from_rest, pendulum_period};
use lagrange_systems::SimplePendulum;
use std::hint::black_box;
use std::time::Instant;

/// The origin's pendulum: L = 1 m, g = 9.81 m/s^2, released at rest from 30 degrees, 10 s.
const G: f64 = 9.81;
const TH0: f64 = std::f64::consts::FRAC_PI_6;
const T_END: f64 = 10.0;

/// The median over [`TIMING_RUNS`] of the wall time of `run`, in nanoseconds per `per`.
pub fn median_ns<R>(per: u64, mut run: impl FnMut() -> R) -> f64 {
    let mut times: Vec<f64> = (0..TIMING_RUNS)
        .map(|_| {
            let clock = Instant::now();
            black_box(run());
            clock.elapsed().as_secs_f64() * 1e9 / per as f64
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[TIMING_RUNS / 2]
}

/// `max(|th - th_exact|, |th' - th'_exact|)` at `T_END`.
fn final_error(s: &State<f64, 1>) -> Result<f64, Error> {
    let (th, thd) = pendulum_from_rest(TH0, G.sqrt(), T_END)?;
    Ok((s.q[0] - th).abs().max((s.qd[0] - thd).abs()))
}

/// One method's row: name, stated order, and per step size the final error and ns/step.
struct Row {
    name: &'static str,
    order: u32,
    cells: Vec<Result<(f64, f64), Error>>,
}

/// A fixed-step [`Integrator`] at each step size.
fn fixed<I: Integrator<f64, 1> + Default>(dts: &[f64]) -> Row {
    let start = State::at_rest([TH0]);
    let cells = dts
        .iter()
        .map(|&dt| {
            let p = SimplePendulum::new(1.0, 1.0, G, 0.0)?;
            let steps = (T_END / dt).round() as u64;
            let end = I::default().integrate(&p, &start, dt, steps)?;
            let ns = median_ns(steps, || {
                I::default().integrate(black_box(&p), &start, dt, steps)
            });
            Ok((final_error(&end)?, ns))
        })
        .collect();
    Row {
        name: I::NAME,
        order: I::ORDER,
        cells,
    }
}

/// The variational integrator (on the automatic path of the same pendulum).
fn variational(dts: &[f64]) -> Row {
    let start = State::at_rest([TH0]);
    let cells = dts
        .iter()
        .map(|&dt| {
            let p = EulerLagrange::new(SimplePendulum::new(1.0, 1.0, G, 0.0)?);
            let steps = (T_END / dt).round() as u64;
            let end = VariationalMidpoint::default().integrate(&p, &start, dt, steps)?;
            let ns = median_ns(steps, || {
                VariationalMidpoint::default().integrate(black_box(&p), &start, dt, steps)
            });
            Ok((final_error(&end)?, ns))
        })
        .collect();
    Row {
        name: "variational midpoint",
        order: 2,
        cells,
    }
}

/// The fixed-step table.
fn fixed_step_table() {
    let dts = [1e-2, 1e-3];
    let rows = [
        fixed::<ExplicitEuler>(&dts),
        fixed::<SemiImplicitEuler>(&dts),
        fixed::<VelocityVerlet>(&dts),
        fixed::<StormerVerlet<f64, 1>>(&dts),
        fixed::<Rk4>(&dts),
        fixed::<Yoshida4<StormerVerlet<f64, 1>>>(&dts),
        fixed::<ImplicitMidpoint<f64>>(&dts),
        fixed::<GaussLegendre2<f64>>(&dts),
        fixed::<BackwardEuler<f64>>(&dts),
        fixed::<RadauIIA2<f64>>(&dts),
        variational(&dts),
    ];
    println!(
        "\nEvery fixed-step integrator on the origin's pendulum (30 deg at rest, 10 s, f64): \
         final error max(|th|, |th'|) against the exact solution, and ns per step"
    );
    println!(
        "{:<22} {:>5} {:>12} {:>9} {:>12} {:>9} {:>14}",
        "integrator", "order", "err dt=1e-2", "ns/step", "err dt=1e-3", "ns/step", "slope 1e-2:-3"
    );
    for row in &rows {
        print!("{:<22} {:>5}", row.name, row.order);
        for cell in &row.cells {
            match cell {
                Ok((err, ns)) => print!(" {err:>12.3e} {ns:>9.1}"),
                Err(e) => print!(" {:>22}", format!("failed: {e}")),
            }
        }
        match (&row.cells[0], &row.cells[1]) {
            (Ok((a, _)), Ok((b, _))) => println!(" {:>14.2}", (a / b).log10()),
            _ => println!(),
        }
    }
    println!(
        "(The slope over one decade is the order until the error meets rounding, ~1e-13: \
         the order-4 methods' slopes at dt = 1e-3 are limited by it.)"
    );
}

/// One adaptive pair (the engine behind the aliases `DormandPrince54` and
/// `DormandPrince853`): error against tolerance, work, and the crossing of th = 0.
fn adaptive<const S: usize, const R: usize, P: EmbeddedPair<S, R>>(
    rtols: &[f64],
) -> Result<(), Error> {
    let p = SimplePendulum::new(1.0, 1.0, G, 0.0)?;
    let start = State::at_rest([TH0]);
    let quarter = 0.25 * pendulum_period(TH0, G.sqrt())?;
    for &rtol in rtols {
        let settings = AdaptiveSettings::new(rtol, rtol * 1e-2)?;
        let mut i = EmbeddedRungeKutta::<f64, 1, S, R, P>::new(settings, &p, &start)?;
        let end = i.integrate_to(&p, T_END)?;
        let st = i.statistics();
        let us = median_ns(1, || {
            EmbeddedRungeKutta::<f64, 1, S, R, P>::new(settings, black_box(&p), &start)
                .and_then(|mut i| i.integrate_to(&p, T_END))
        }) / 1e3;
        let mut e = EmbeddedRungeKutta::<f64, 1, S, R, P>::new(settings, &p, &start)?;
        let miss = match e.integrate_until_event(&p, T_END, |s: &State<f64, 1>| s.q[0])? {
            Stop::Event(s) => format!("{:>10.1e}", s.t - quarter),
            Stop::End(_) => format!("{:>10}", "none"),
        };
        println!(
            "{:<22} {rtol:>7.0e} {:>12.3e} {:>7} {:>5} {:>7} {:>9.1} {:>9.1} {miss}",
            P::NAME,
            final_error(&end)?,
            st.accepted,
            st.rejected,
            st.evaluations,
            us,
            us * 1e3 / st.accepted as f64,
        );
    }
    Ok(())
}

/// The adaptive table.
fn adaptive_table() -> Result<(), Error> {
    println!(
        "\nAdaptive integrators on the same pendulum (atol = rtol / 100): final error at 10 s, \
         work, and the miss of the first crossing of th = 0 (exact: a quarter period)"
    );
    println!(
        "{:<22} {:>7} {:>12} {:>7} {:>5} {:>7} {:>9} {:>9} {:>10}",
        "integrator", "rtol", "err(10)", "steps", "rej", "evals", "us/run", "ns/step", "event s"
    );
    adaptive::<7, 1, lagrange_integrators::Dopri5Pair>(&[1e-4, 1e-6, 1e-8, 1e-10, 1e-12])?;
    adaptive::<16, 4, lagrange_integrators::Dop853Pair>(&[1e-6, 1e-8, 1e-10, 1e-12, 1e-13])?;
    Ok(())
}

/// Runs this part of the demo.
pub fn run() -> Result<(), String> {
    fixed_step_table();
    adaptive_table().map_err(|e| e.to_string())
}
