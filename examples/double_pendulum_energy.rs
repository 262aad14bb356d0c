//! The chaotic double pendulum (problem P2: unit masses and rods, both arms horizontal at rest,
//! 10 s) with every fixed-step integrator at dt = 1e-3: its state at 10 s against a 1e-27
//! reference, and its energy error, which the symmetric and symplectic methods keep bounded
//! where RK4 and the dissipative methods drift.
//!
//! `cargo run --release --example double_pendulum_energy` (writes
//! `target/lagrange-demo/double_pendulum.svg`)

use lagrange_examples::{ns_per_step, state_error, write_plot};
use lagrange_integrators::prelude::*;
use lagrange_integrators::{
    BackwardEuler, ExplicitEuler, ImplicitMidpoint, RadauIIA2, SemiImplicitEuler, VelocityVerlet,
};
use lagrange_plot::{Scale, Series};
use lagrange_systems::DoublePendulum;

const DT: f64 = 1e-3;
const STEPS: u64 = 10_000;
/// Points kept per run for the plot.
const PLOT_POINTS: u64 = 500;

/// P2's state at 10 s (th1, th2, th1', th2') from a 1e-27 reference solve
/// (shared/BENCH_PROBLEMS.md).
#[allow(clippy::excessive_precision)] // the digits as published
const REFERENCE: [f64; 4] = [
    -0.568_474_664_015_950_2,
    -0.526_393_727_932_404_7,
    6.078_384_885_761_965,
    -9.681_360_681_708_879,
];

/// One method's figures, and its energy error along the run for the plot.
struct Row {
    name: &'static str,
    error: Result<f64, Error>,
    max_energy_error: f64,
    ns_per_step: f64,
    energy: Series,
}

/// `integrator` on `dp` from P2's start.
fn row<I: Integrator<f64, 2, DoublePendulum<f64>> + Clone>(
    dp: &DoublePendulum<f64>,
    integrator: I,
) -> Row {
    let half_pi = std::f64::consts::FRAC_PI_2;
    let start = State::at_rest([half_pi, half_pi]);
    // Energy from the hanging rest state, where P2 starts at 3 g exactly.
    let rest = dp.energy(&State::at_rest([0.0, 0.0]));
    let e0 = dp.energy(&start) - rest;
    let (mut max, mut n, mut points) = (0.0f64, 0u64, Vec::new());
    let end = integrator
        .clone()
        .integrate_with(dp, &start, DT, STEPS, |s| {
            n += 1;
            let e = ((dp.energy(s) - rest - e0) / e0).abs();
            max = max.max(e);
            if n % (STEPS / PLOT_POINTS) == 0 {
                points.push((s.t, e.max(1e-17)));
            }
        });
    Row {
        name: I::NAME,
        error: end
            .map(|s| state_error(&s, &REFERENCE))
            .map_err(Error::from),
        max_energy_error: max,
        ns_per_step: ns_per_step(integrator, dp, &start, DT, STEPS),
        energy: Series {
            name: I::NAME.to_string(),
            points,
        },
    }
}

fn main() -> Result<(), String> {
    let dp = DoublePendulum::new(1.0, 1.0, 1.0, 1.0, 9.81).map_err(|e| e.to_string())?;
    let rows = [
        row(&dp, ExplicitEuler),
        row(&dp, SemiImplicitEuler),
        row(&dp, VelocityVerlet),
        row(&dp, StormerVerlet::default()),
        row(&dp, Rk4),
        row(&dp, Yoshida4::<StormerVerlet<f64, 2>>::default()),
        row(&dp, ImplicitMidpoint::default()),
        row(&dp, GaussLegendre2::default()),
        row(&dp, BackwardEuler::default()),
        row(&dp, RadauIIA2::default()),
        row(&dp, VariationalMidpoint::default()),
        row(&dp, Yoshida4::<VariationalMidpoint<f64, 2>>::default()),
    ];
    println!(
        "Chaotic double pendulum (P2), 10 s at dt = 1e-3 (f64): error of the state at 10 s \
         against the reference, largest relative energy error, ns per step"
    );
    println!(
        "{:<26} {:>11} {:>11} {:>9}",
        "integrator", "err(10)", "max dE/E", "ns/step"
    );
    for r in &rows {
        let error = r
            .error
            .as_ref()
            .map_or_else(|e| format!("failed: {e}"), |e| format!("{e:.3e}"));
        println!(
            "{:<26} {error:>11} {:>11.3e} {:>9.1}",
            r.name, r.max_energy_error, r.ns_per_step
        );
    }
    println!(
        "(A perturbation grows about 140x over these 10 s, so the state error is the method's \
         error times that; the energy error is the method's own.)"
    );
    let energy: Vec<Series> = rows.into_iter().map(|r| r.energy).collect();
    write_plot(
        "double_pendulum.svg",
        "t (s)",
        &[(
            "Chaotic double pendulum, dt = 1e-3: energy error",
            "|dE|/E",
            Scale::Log,
            &energy,
        )],
    )
}
