//! `cargo xtask bench` (which runs this binary, optimised): run time against error.
//!
//! Every method of the methods table ([`method::for_each`]: the library's integrators, a
//! hand-written RK4 loop, `ode_solvers`' Dopri5 and Dop853) on every problem of the problems
//! table ([`problems::for_each`]: P1-P5 of `shared/BENCH_PROBLEMS.md`), in f64 and f32, over a
//! sweep of step sizes or tolerances: final error against a reference, maximum relative energy
//! error, wall time per simulated second and per step (median of repeated whole solves),
//! acceleration evaluations. Then the budgets of issue 5 as measured ratios (the library's
//! RK4 against the hand-written loop; the best library method against `ode_solvers`' best at
//! equal error; the chain's cost per step against N) and the stability limit of each explicit
//! method. Output under `target/lagrange-bench/`: `bench.csv`, `report.md` and SVG
//! work-precision plots.
//!
//! Flags: `--quick` (a smoke run: small budgets, short sweeps), `--only P1,P3-N5` (problems
//! whose id starts with one of these), `--method RK4` (methods whose name contains this),
//! `--peers` (also SciPy's `solve_ivp` and `odeint` from a venv under `target/`, see
//! [`scipy_peer`]).

mod budgets;
mod chain_cost;
mod counting;
mod engine_overhead;
mod hand_rhs;
mod hand_rk4;
mod method;
mod ode_peer;
mod outcome;
mod problem;
mod problems;
mod real;
mod report;
mod scipy_peer;
mod stability;
mod sweep;

mod work_precision;

use lagrange_benches::timing::{self, Budget};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// What to run and how much time to spend on it.
pub struct Options {
    /// A smoke run.
    pub quick: bool,
    /// Problem id prefixes to run (all when empty).
    pub only: Vec<String>,
    /// Method name fragments to run (all when empty).
    pub methods: Vec<String>,
    /// Also run SciPy (`--peers`).
    pub peers: bool,
    /// Timing budget per point.
    pub budget: Budget,
    /// A sweep stops after a point whose solve takes longer than this, s.
    pub max_solve: f64,
    /// A fixed-step sweep stops before a point of more steps than this.
    pub max_steps: u64,
}

impl Options {
    /// Parses the arguments after `bench`.
    fn parse(args: &[String]) -> Result<Self, String> {
        let mut opts = Self {
            quick: false,
            only: Vec::new(),
            methods: Vec::new(),
            peers: false,
            budget: sweep::DEFAULT_BUDGET,
            max_solve: 0.2,
            max_steps: 20_000_000,
        };
        let mut it = args.iter();
        while let Some(arg) = it.next() {
            match arg.as_str() {
                "--quick" => {
                    opts.quick = true;
                    opts.budget = sweep::QUICK_BUDGET;
                    opts.max_solve = 0.02;
                    opts.max_steps = 1_000_000;
                }
                "--only" => opts.only = list(it.next())?,
                "--method" => opts.methods = list(it.next())?,
                "--peers" => opts.peers = true,
                other => return Err(format!("unknown bench flag `{other}`\n{USAGE}")),
            }
        }
        Ok(opts)
    }

    /// True when problem `id` is to run.
    pub fn selected(&self, id: &str) -> bool {
        self.only.is_empty() || self.only.iter().any(|p| id.starts_with(p.as_str()))
    }

    /// True when method `name` is to run.
    pub fn method_selected(&self, name: &str) -> bool {
        self.methods.is_empty() || self.methods.iter().any(|m| name.contains(m.as_str()))
    }
}

/// A comma-separated list argument.
fn list(arg: Option<&String>) -> Result<Vec<String>, String> {
    arg.map(|a| a.split(',').map(str::to_string).collect())
        .ok_or_else(|| format!("missing list after flag\n{USAGE}"))
}

/// Usage of `cargo xtask bench`.
const USAGE: &str =
    "usage: cargo xtask bench [--quick] [--only P1,P2,...] [--method NAME,...] [--peers]";

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
            eprintln!("bench failed:\n{e}");
            ExitCode::FAILURE
        }
    }
}

/// Runs the bench.
fn run(args: &[String]) -> Result<(), String> {
    let opts = Options::parse(args)?;
    let clock = Instant::now();
    let load_before = load_average();
    let mut sweeps = sweep::run(&opts);
    let dir = project_root().join("target").join("lagrange-bench");
    if opts.peers {
        println!("\n== SciPy (--peers)");
        if let Err(e) = scipy_peer::run(&opts, &dir.join("scipy-venv"), &mut sweeps) {
            sweeps.failures.push(format!("--peers: {e}"));
        }
    }
    println!("\n== budgets");
    let ratios = budgets::rk4_against_hand(&opts);
    let chain = chain_cost::measure(&opts);
    let overhead = engine_overhead::measure(&opts);
    println!("\n== stability limits");
    let limits = stability::scan(&opts);
    let elapsed = clock.elapsed().as_secs_f64();

    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let context = report::Context {
        quick: opts.quick,
        peers: opts.peers,
        elapsed,
        load: (load_before, load_average()),
        budget: opts.budget,
    };
    let files = report::write(&dir, &context, &sweeps, &ratios, &chain, &overhead, &limits)?;
    println!("\nwrote {} files under {}:", files.len(), dir.display());
    for f in files.iter().filter(|f| !f.ends_with(".svg")) {
        println!("  {f}");
    }
    if sweeps.failures.is_empty() {
        Ok(())
    } else {
        Err(sweeps.failures.join("\n"))
    }
}

/// The 1-minute load average, when the system reports one (the machine is shared: timings
/// taken under load are noisier).
fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}
