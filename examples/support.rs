//! What the examples share: timing by medians of whole runs, the error of a state against a
//! reference, and writing their figures under `target/lagrange-demo/`.
//!
//! Run an example with `cargo run --release --example NAME`; `cargo xtask demo` runs them all.

use lagrange_core::{Real, State};
use lagrange_integrators::Integrator;
use lagrange_plot::{Panel, Scale, Series};
use std::hint::black_box;
use std::path::PathBuf;
use std::time::Instant;

/// Timing: the median of this many whole runs.
pub const TIMING_RUNS: usize = 5;

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

/// Median wall time per step of `steps` steps of `integrator` on `mechanism` from `start`.
pub fn ns_per_step<T, M, I, const N: usize>(
    mut integrator: I,
    mechanism: &M,
    start: &State<T, N>,
    dt: T,
    steps: u64,
) -> f64
where
    T: Real,
    M: lagrange_core::Mechanism<T, N>,
    I: Integrator<T, N, M>,
{
    median_ns(steps, || {
        integrator.integrate(black_box(mechanism), black_box(start), dt, steps)
    })
}

/// `max_i |x_i - y_i|` over the coordinates, then the velocities, of `s` against `reference`.
pub fn state_error<T: Real, const N: usize>(s: &State<T, N>, reference: &[f64]) -> f64 {
    s.q.iter()
        .chain(s.qd.iter())
        .zip(reference)
        .map(|(a, b)| (a.to_f64() - b).abs())
        .fold(0.0, f64::max)
}

/// Width of a figure, pixels.
const WIDTH: u32 = 820;
/// Height of each of its panels, pixels.
const PANEL_HEIGHT: u32 = 360;

/// The directory the examples write their figures to: `target/lagrange-demo/`.
#[must_use]
pub fn output_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join("target")
        .join("lagrange-demo")
}

/// Writes `target/lagrange-demo/<name>`: one panel per `(title, y label, y scale, series)`,
/// stacked, each over a linear x axis labelled `x_label`; prints where.
///
/// # Errors
/// The plot's or the file system's, as text.
pub fn write_plot(
    name: &str,
    x_label: &str,
    panels: &[(&str, &str, Scale, &[Series])],
) -> Result<(), String> {
    let panels: Vec<Panel<'_>> = panels
        .iter()
        .map(|&(title, y_label, scale, series)| {
            Panel::new(title, series)
                .x_axis(x_label, Scale::Linear)
                .y_axis(y_label, scale)
        })
        .collect();
    let doc = lagrange_plot::svg(&panels, WIDTH, PANEL_HEIGHT).map_err(|e| e.to_string())?;
    let dir = output_dir();
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let path = dir.join(name);
    std::fs::write(&path, doc).map_err(|e| e.to_string())?;
    println!("Plot: {}", path.display());
    Ok(())
}
