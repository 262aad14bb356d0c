//! Wall-clock timing of the hot paths that validation must not slow down, without criterion:
//! RK4 steps and runs of the pendulum and the double pendulum (f32 and f64), a DOP853 solve, and
//! DOP853 landings from a fixed-timestep loop. Each figure is the median of repeated whole runs.
//!
//! `cargo run --release -p lagrange-tests --example step_timing [repeats]`
//!
//! It prints one line per case, `name  median unit  (min .. max)`: run it before and after a
//! change on the same machine, alternately, and compare the medians.

use lagrange_core::{Error, Mechanism, Real, State};
use lagrange_integrators::{AdaptiveSettings, DormandPrince853, Integrator, Rk4};
use lagrange_systems::{DoublePendulum, SimplePendulum};
use std::hint::black_box;
use std::time::Instant;

/// Steps per timed run of a fixed-step case.
const STEPS: u64 = 2_000_000;

/// Whole runs per case (the median is reported); the first argument overrides it.
const DEFAULT_REPEATS: usize = 15;

/// `(median, min, max)` of `repeats` timings of `f`, each divided by `per` (ns per unit).
fn timed(
    repeats: usize,
    per: f64,
    mut f: impl FnMut() -> Result<(), Error>,
) -> Result<(f64, f64, f64), Error> {
    let mut ns = Vec::with_capacity(repeats);
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        f()?;
        ns.push(start.elapsed().as_nanos() as f64 / per);
    }
    ns.sort_by(f64::total_cmp);
    Ok((ns[ns.len() / 2], ns[0], ns[ns.len() - 1]))
}

/// Prints one case in `unit`.
fn report(name: &str, unit: &str, (median, min, max): (f64, f64, f64)) {
    println!("{name:<42} {median:9.2} {unit}  ({min:.2} .. {max:.2})");
}

/// RK4 steps chained from `start`, each from the last one's result.
fn rk4<T: Real, M: Mechanism<T, N>, const N: usize>(
    name: &str,
    repeats: usize,
    m: &M,
    start: State<T, N>,
) -> Result<(), Error> {
    let dt = T::from_f64(1e-4);
    let times = timed(repeats, STEPS as f64, || {
        let mut s = start;
        for _ in 0..STEPS {
            s = Rk4.step(black_box(m), &s, dt)?;
        }
        black_box(s);
        Ok(())
    })?;
    report(name, "ns", times);
    Ok(())
}

/// RK4 runs (`integrate`, the run's clock included) of `STEPS` steps from `start`.
fn rk4_run<T: Real, M: Mechanism<T, N>, const N: usize>(
    name: &str,
    repeats: usize,
    m: &M,
    start: State<T, N>,
) -> Result<(), Error> {
    let dt = T::from_f64(1e-4);
    let times = timed(repeats, STEPS as f64, || {
        black_box(Rk4.integrate(black_box(m), &start, dt, STEPS)?);
        Ok(())
    })?;
    report(name, "ns", times);
    Ok(())
}

fn main() -> Result<(), Error> {
    let repeats = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(DEFAULT_REPEATS);
    let p64 = SimplePendulum::new(1.0_f64, 1.0, 9.81, 0.0)?;
    let p32 = SimplePendulum::new(1.0_f32, 1.0, 9.81, 0.0)?;
    let d64 = DoublePendulum::new(1.0_f64, 1.0, 1.0, 1.0, 9.81)?;
    let d32 = DoublePendulum::new(1.0_f32, 1.0, 1.0, 1.0, 9.81)?;
    rk4(
        "rk4 step, pendulum f64",
        repeats,
        &p64,
        State::at_rest([0.5]),
    )?;
    rk4(
        "rk4 step, pendulum f32",
        repeats,
        &p32,
        State::at_rest([0.5]),
    )?;
    let swing = [1.0, -0.5];
    rk4(
        "rk4 step, double pendulum f64",
        repeats,
        &d64,
        State::at_rest(swing),
    )?;
    rk4(
        "rk4 step, double pendulum f32",
        repeats,
        &d32,
        State::at_rest([1.0, -0.5]),
    )?;
    rk4_run(
        "rk4 integrate, pendulum f64",
        repeats,
        &p64,
        State::at_rest([0.5]),
    )?;
    rk4_run(
        "rk4 integrate, pendulum f32",
        repeats,
        &p32,
        State::at_rest([0.5]),
    )?;
    let start = State::at_rest([1.0, -0.5]);
    rk4_run("rk4 integrate, double pendulum f32", repeats, &d32, start)?;

    // A DOP853 solve: the chaotic double pendulum over 100 s at rtol = atol = 1e-10.
    let settings = AdaptiveSettings::new(1e-10, 1e-10)?;
    let start = State::at_rest([2.0, -1.0]);
    let solves = 20;
    let times = timed(repeats, f64::from(solves), || {
        for _ in 0..solves {
            let mut dop = DormandPrince853::new(settings);
            black_box(dop.integrate_to(black_box(&d64), &start, 100.0)?);
        }
        Ok(())
    })?;
    let us = (times.0 / 1e3, times.1 / 1e3, times.2 / 1e3);
    report("dop853 solve, double pendulum 100 s", "us", us);

    // DOP853 driven by a frame loop: landings at 1/120 s, most by dense output alone.
    let frames = 100_000u64;
    let loose = AdaptiveSettings::new(1e-8, 1e-8)?;
    let times = timed(repeats, frames as f64, || {
        let mut dop = DormandPrince853::new(loose);
        let mut s = State::at_rest([0.5, 0.2]);
        for _ in 0..frames {
            s = dop.step(black_box(&d64), &s, 1.0 / 120.0)?;
        }
        black_box(s);
        Ok(())
    })?;
    report("dop853 landing per frame, double pendulum", "ns", times);
    Ok(())
}
