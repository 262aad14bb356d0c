//! `cargo xtask demo`: runs the examples of `examples/`, optimised, one after the other: the
//! origin's pendulum with every integrator, the chaotic double pendulum's energy, your own
//! mechanism, every standard mechanism, a mechanism SymPy derived (`cargo xtask derive`),
//! constraints, impacts, a game loop, a scene of sleeping lamps and a ragdoll thrown onto a floor (with its cost per step
//! beside a chain's). Their figures go to `target/lagrange-demo/`.

use crate::cmd;

/// The examples, in the order the demo runs them.
const EXAMPLES: [&str; 10] = [
    "origin_pendulum",
    "double_pendulum_energy",
    "own_mechanism",
    "mechanisms",
    "derived",
    "four_bar",
    "impacts",
    "game_loop",
    "scene",
    "ragdoll",
];

/// Runs every example; reports every failure at the end.
pub fn run() -> Result<(), String> {
    let failures: Vec<String> = EXAMPLES
        .iter()
        .filter_map(|name| {
            println!("\n=== cargo run --example {name}\n");
            cmd::run(cmd::cargo().args([
                "run",
                "--quiet",
                "--profile",
                "xtask",
                "-p",
                "lagrange-examples",
                "--example",
                name,
            ]))
            .err()
        })
        .collect();
    if failures.is_empty() {
        Ok(())
    } else {
        Err(failures.join("\n"))
    }
}
