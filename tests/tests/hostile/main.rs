//! The hostile-input campaign: every public entry point of lagrange-core,
//! lagrange-integrators (scenes and lanes included), lagrange-systems, the generated
//! mechanisms of lagrange-generated and lagrange-world's `World`, `f32` and `f64`, called
//! with drawn nasty values (NaN, infinities, the largest and smallest values, subnormals, signed zeros, tiny and huge
//! steps, tolerances at their edges) and classified: ok, a specific error, panic, hang, silent
//! non-finite (`Ok` holding NaN or an infinity), wrong parameter named, state changed on error,
//! inconsistent (a step and a one-step run disagree).
//!
//! Each family of entry points runs on a worker thread, each call under `catch_unwind`; a
//! watchdog notices a call running past the deadline, reports it as a hang and stops that
//! family. Findings are shrunk to simple argument values and printed as Rust. The last line is
//! `N calls, P panics, H hangs, S silent non-finite, W wrong parameter`; the exit code is 1
//! when any class but ok and error was seen.
//!
//! A test binary without the libtest harness (`harness = false`): `cargo test` runs a short
//! campaign (10^5 calls, a few seconds in release, well under 30 s in debug);
//! `cargo xtask fuzz [CALLS]` runs a long one in release. Settings:
//!
//! ```text
//! HOSTILE_CALLS    calls in all (default 100000)        or --calls N
//! HOSTILE_SEED     the seed (default 15)                 or --seed S
//! HOSTILE_DEADLINE a hang after this many seconds (default 10 in release, 60 unoptimised)
//! HOSTILE_FAMILY   only the families whose name contains this
//! ```

mod adaptive;
mod checks;
mod core;
mod drivers;
mod exact;
mod fixed_step;
mod harness;
mod ragdoll;
mod scenes;
mod systems;
mod values;
mod world;

use harness::Config;
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// The default deadline of a call, s: its slowest legitimate calls (an adaptive run of 10^5
/// steps) take a quarter of a second in release, some thirty times that unoptimised.
const DEADLINE: f64 = if cfg!(debug_assertions) { 60.0 } else { 10.0 };

/// A number from the command line (`--name N`) or the environment (`VAR`), or `default`.
fn setting(args: &[String], flag: &str, var: &str, default: f64) -> f64 {
    let from_args = args
        .iter()
        .position(|a| a == flag)
        .and_then(|i| args.get(i + 1))
        .cloned();
    from_args
        .or_else(|| std::env::var(var).ok())
        .and_then(|v| v.trim().parse::<f64>().ok())
        .unwrap_or(default)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().collect();
    // As a test target: nothing to list, and nothing here is #[ignore]d.
    if args.iter().any(|a| a == "--list" || a == "--ignored") {
        return ExitCode::SUCCESS;
    }
    let cfg = Config {
        seed: setting(&args, "--seed", "HOSTILE_SEED", 15.0) as u64,
        calls: setting(&args, "--calls", "HOSTILE_CALLS", 1e5) as u64,
        deadline: Duration::from_secs_f64(setting(
            &args,
            "--deadline",
            "HOSTILE_DEADLINE",
            DEADLINE,
        )),
        only: std::env::var("HOSTILE_FAMILY").ok(),
        reproducers: 2,
    };
    harness::quiet_panics();
    let started = Instant::now();
    println!(
        "hostile-input campaign: {} calls, seed {}, deadline {:?}",
        cfg.calls, cfg.seed, cfg.deadline
    );
    let families = vec![
        systems::family(),
        exact::family(),
        core::family(),
        fixed_step::family(),
        adaptive::family(),
        drivers::family(),
        scenes::family(),
        ragdoll::family(),
        world::family(),
    ];
    let reports = harness::run(families, &cfg);
    println!();
    println!("ran in {:.1} s", started.elapsed().as_secs_f64());
    let totals = harness::report(&reports, &cfg);
    let clean = harness::CLASSES
        .iter()
        .filter(|c| c.is_finding())
        .all(|&c| totals.get(c) == 0);
    if clean {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
