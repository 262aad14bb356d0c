//! `cargo xtask fuzz [CALLS] [--seed S]`: the long hostile-input campaign, in release.
//!
//! The campaign itself is the `hostile` test of `lagrange-tests` (`tests/tests/hostile`), whose
//! short run (10^5 calls) is part of every `cargo test`; this runs it optimised with many more
//! calls, 10^7 by default. It prints a table per family of entry points, the findings shrunk to
//! Rust reproducers, and ends with `N calls, P panics, H hangs, S silent non-finite, W wrong
//! parameter`; it fails when any call panicked, hung, returned a silent non-finite value, named
//! a wrong parameter, changed a stateful API's state on an error or was inconsistent.
//!
//! The count and the seed may also come from `HOSTILE_CALLS` and `HOSTILE_SEED`.

use crate::cmd;

/// The default number of calls of the long run.
const DEFAULT_CALLS: &str = "10000000";

/// Runs the campaign with the count and seed of `args` (or the environment, or the defaults).
pub fn run(args: &[String]) -> Result<(), String> {
    let mut calls = std::env::var("HOSTILE_CALLS").unwrap_or_else(|_| DEFAULT_CALLS.into());
    let mut seed = std::env::var("HOSTILE_SEED").ok();
    let mut rest = args.iter();
    while let Some(a) = rest.next() {
        match a.as_str() {
            "--seed" => seed = rest.next().cloned(),
            n if n.parse::<f64>().is_ok() => calls = n.to_string(),
            other => {
                return Err(format!(
                    "fuzz: unknown argument `{other}` (usage: cargo xtask fuzz [CALLS] [--seed S])"
                ))
            }
        }
    }
    let mut command = cmd::cargo();
    command
        .args([
            "test",
            "--quiet",
            "--release",
            "-p",
            "lagrange-tests",
            "--test",
            "hostile",
        ])
        .env("HOSTILE_CALLS", &calls);
    if let Some(seed) = seed {
        command.env("HOSTILE_SEED", seed);
    }
    cmd::run(&mut command)
}
