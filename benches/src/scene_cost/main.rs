//! `cargo xtask bench --scene` (which runs this binary, optimised): what a frame of a scene
//! costs.
//!
//! - 1,000 damped `f32` pendulums at dt = 1/120 s with 100%, 50%, 10% and 1% of them awake
//!   (the rest asleep at the bottom), under Stormer-Verlet and RK4 ([`pendulums`]); with all
//!   awake, against the loops a scene replaces: one `FixedTimestep` per pendulum, and a hand
//!   loop over the same slots with one clock (ratios measured interleaved, pair by pair).
//! - A mixed scene ([`mixed`]): pendulums, double pendulums, cart-poles (some pushed), four-bar
//!   linkages and balls bouncing to rest on a floor, at its start (all awake) and once
//!   settled.
//! - Lanes ([`lanes`]): banks of 1,024 `f32` pendulums and of 1,024 double pendulums, all awake,
//!   stepped by RK4 in lanes against the same banks one by one (and the same by hand, without a
//!   bank).
//! - The constant-mass skip of the automatic path ([`constant_mass`]): ns per acceleration of
//!   a spring chain (N = 2, 5, 10) with the skip and without, and how far apart they are.
//!
//! Output under `target/lagrange-bench/`: `scene.csv`
//! (`scene,layout,instances,awake_fraction,integrator,scalar,ns_per_frame`) and `scene.md`.
//! `--quick` for a smoke run.

mod constant_mass;
mod frames;
mod lanes;
mod mixed;
mod pendulums;
mod report;

use lagrange_benches::timing::Budget;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// One measured scene: a row of `scene.csv`.
#[derive(Debug, Clone)]
pub struct Row {
    /// Which scene (and which loop, for the plain loops).
    pub scene: String,
    /// How its instances are stepped: `"lanes"` (side by side, a bank [`InLanes`]) or
    /// `"one_by_one"`.
    ///
    /// [`InLanes`]: lagrange_integrators::scene::InLanes
    pub layout: &'static str,
    /// Instances in it.
    pub instances: usize,
    /// Fraction of them awake while measured.
    pub awake_fraction: f64,
    /// The integrator's name.
    pub integrator: &'static str,
    /// `"f32"` or `"f64"`.
    pub scalar: &'static str,
    /// Median wall time of one frame, ns.
    pub ns_per_frame: f64,
}

/// A ratio of two frame costs measured interleaved, for the report.
#[derive(Debug, Clone)]
pub struct Ratio {
    /// What is compared with what.
    pub what: String,
    /// Median of the per-pair ratios.
    pub ratio: f64,
    /// The goal it is held against, as text.
    pub goal: &'static str,
    /// Whether it meets the goal.
    pub met: bool,
}

/// Timing budget per measured point.
fn budget(quick: bool) -> Budget {
    if quick {
        Budget {
            seconds: 0.05,
            min_runs: 3,
            max_runs: 9,
        }
    } else {
        Budget {
            seconds: 0.5,
            min_runs: 11,
            max_runs: 101,
        }
    }
}

/// The workspace root (the parent of this crate's manifest directory).
fn project_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("scene bench failed:\n{e}");
            ExitCode::FAILURE
        }
    }
}

/// Runs every measurement and writes the files.
fn run(args: &[String]) -> Result<(), String> {
    let mut quick = false;
    for arg in args {
        match arg.as_str() {
            "--quick" => quick = true,
            "--scene" => {}
            other => {
                return Err(format!(
                    "unknown flag `{other}`\nusage: cargo xtask bench --scene [--quick]"
                ))
            }
        }
    }
    let budget = budget(quick);
    let mut rows = Vec::new();
    let mut ratios = Vec::new();
    println!("== 1000 damped pendulums at 1/120 s");
    pendulums::measure(budget, &mut rows, &mut ratios).map_err(|e| e.to_string())?;
    println!("\n== lanes");
    lanes::measure(budget, &mut rows, &mut ratios).map_err(|e| e.to_string())?;
    println!("\n== mixed scene");
    mixed::measure(budget, &mut rows).map_err(|e| e.to_string())?;
    println!("\n== constant-mass skip");
    let skip = constant_mass::measure(budget).map_err(|e| e.to_string())?;

    let dir = project_root().join("target").join("lagrange-bench");
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    for (name, text) in [
        ("scene.csv", report::csv(&rows)),
        ("scene.md", report::markdown(quick, &rows, &ratios, &skip)),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
