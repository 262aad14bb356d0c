//! `cargo xtask bench --contacts` (which runs this bench, optimised): what a step with
//! contacts costs, beside a free RK4 step of the same mechanism and beside rapier2d.
//!
//! Scenes, each in `f32` and `f64`:
//!
//! - `ragdoll`: the thrown ragdoll of `examples/ragdoll.rs` (the adult body, its 13 floor
//!   points and 9 joint limits, e = 0.3, rest speed 0.3 m/s, friction 0.8), dt = 1/240 s,
//!   6 s.
//! - `double_pendulum`: the repository's double pendulum on the floor
//!   (`tests/tests/double_pendulum_floor.rs`: floor 0.8 m below the pivot, bend within
//!   +-2.5 rad, e = 0.8, no friction), dt = 1e-3 s, 10 s.
//! - `ball`: a 1 kg `FallingParticle` dropped from 1 m, e = 0.5, rest speed 0.05 m/s,
//!   dt = 1e-3 s, 5 s (it is at rest well before).
//! - `ragdoll_throws`: the same ragdoll thrown sixteen other ways ([`throws`]), the
//!   time-stepping stepper only: each figure over the throws (the mean step averaged, the
//!   worst the worst of any; the note gives the throws' range). No goal reads it; it says
//!   how far one throw's figures carry.
//!
//! Steppers: `time_stepping` is `ImpulseStepper` with `SemiImplicitEuler` inside, slop 2 mm
//! and at most 4 rounds for a step's plastic solve ([`scenes::SLOP`], [`scenes::MAX_ITERATIONS`]: a game's
//! budget; the slop is what a contact may rest below zero, so its depth is that by design);
//! `event` is `ContactStepper` with `Rk4` inside; `rapier2d` is the peer ([`peer`]), in the
//! `f32` ragdoll rows only (rapier2d computes in `f32`; its `f64` build is another crate),
//! with its bodies kept awake (lagrange's steppers do not sleep); the Markdown also times it
//! with sleeping allowed, as rapier comes (`rapier2d_sleeping`, not a row of the CSV).
//! `free_rk4_ns` is plain `Rk4` on the same mechanism from the same start, no contacts.
//!
//! **Timing.** Every candidate of a scene (free RK4, the steppers, rapier) is run in the same
//! process, round after round (one warm-up round first, not counted), so that a change in
//! the machine's load falls on all of them. In each round each candidate makes two whole
//! runs from the start: one timed as a whole (`mean_ns` is its time over its steps; no clock
//! is read inside it, as a reading costs about 20 ns, a fifth of a double pendulum's free
//! step) and one with every step timed (for the worst step). Reported (CSV, and the goals'
//! verdicts): `mean_ns` the fastest round's mean; `worst_ns` the slowest step of the
//! per-step minima over the rounds (each step at its fastest: the runs are deterministic,
//! step `k` does the same work in every round, so this is the work of the worst step);
//! `free_rk4_ns` the free step's fastest round's mean. Minima rather than medians because
//! the machine this was written on is shared (load 6 to 8 on 2 cores): a whole run's median
//! moved by 2x from one invocation to the next and a run's slowest step was a preemption
//! (milliseconds) in most rounds, whereas the minima held within a few percent. The
//! Markdown gives the medians beside them: the median over rounds of a round's mean, of a
//! round's slowest step, and of the per-round ratio to the free step.
//!
//! **Depth.** `max_penetration`: the deepest negative gap of a floor row at the end of any
//! step, m (zero when none); the joint limits' depth (rad) is in the Markdown. For rapier,
//! the deepest penetration in its contact manifolds after each step (`dist` of the points;
//! they describe the poses at the start of each step, its collision detection running
//! first), with the capsules' exact depth at the end of each step beside it in the Markdown.
//!
//! **Energy gain.** `max_energy_gain`: over the steps the contacts changed (the stepper's end
//! state differs from the free step's, the inner method's step from the same state with no
//! contact), the largest `E(end) - max(E(start), E(free))` with `E = T + V`, J: the energy
//! the contact handling created. Negative: every such step ended below both. For rapier the
//! free step is a copy of its world with the ground disabled and the joint limits removed,
//! stepped once; `T + V` sums `m |v|^2 / 2 + I w^2 / 2 + m g y` over its links, in `f64` from
//! its `f32` state. In `f32` the energies themselves round at about 3e-5 J (the ragdoll's
//! ~500 J at 6e-8).
//!
//! Output under `target/lagrange-bench/`: `contacts.csv`
//! (`scene,stepper,scalar,mean_ns,worst_ns,free_rk4_ns,max_penetration,max_energy_gain`) and
//! `contacts.md` (the table, the goals and whether each is met), the table printed too.
//! `--quick`: one round of 1.5 s of each scene (2 s for the others), a smoke run.
//!
//! The peer, rapier2d (a dev-dependency of this crate only), is built with its default
//! features (`dim2`, `f32`, `std`, `block-solver`) in the bench profile (release, thin LTO,
//! one codegen unit). Its README's performance advice: SIMD is always on since 0.35 (the
//! `simd-stable` feature is gone), and `parallel` (rayon) for multithreading, which is not
//! enabled: one ragdoll is one small island, and lagrange's steppers run on one thread.

mod peer;
#[path = "../shared/rapier_ragdoll.rs"]
mod rapier_ragdoll;
mod report;
mod run;
mod scenes;
mod throws;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use lagrange_benches::timing::median;

/// The free step's name among the candidates (it is not a row of the CSV).
pub const FREE: &str = "free_rk4";

/// The event-driven stepper's name (`ContactStepper`).
pub const EVENT: &str = "event";

/// One way of stepping a scene.
pub struct Candidate {
    /// `free_rk4`, `time_stepping`, `event` or `rapier2d`.
    pub stepper: &'static str,
    /// A whole run from the start: with `true` the ns of every step, with `false` one entry,
    /// the ns of the whole run.
    pub run: Box<dyn FnMut(bool) -> Result<Vec<f64>, String>>,
    /// The untimed run that measures depth and energy (none for the free step).
    pub figures: Option<Box<dyn FnMut() -> Result<Measured, String>>>,
}

/// What the untimed run of a stepper measured.
#[derive(Debug, Clone)]
pub struct Measured {
    /// Deepest floor penetration, m.
    pub depth: f64,
    /// Deepest joint-limit violation, rad (none for rapier).
    pub limit_depth: Option<f64>,
    /// Largest energy gain of a step the contacts changed, J.
    pub energy_gain: f64,
    /// Steps the contacts changed.
    pub contact_steps: usize,
    /// Anything else to say.
    pub note: String,
}

/// One row of the report.
#[derive(Debug, Clone)]
pub struct Row {
    /// Scene name.
    pub scene: &'static str,
    /// Stepper name.
    pub stepper: &'static str,
    /// `"f32"` or `"f64"`.
    pub scalar: &'static str,
    /// The fastest round's mean step, ns (the CSV's `mean_ns`).
    pub mean_ns: Option<f64>,
    /// The median over rounds of a round's mean step, ns.
    pub median_mean_ns: Option<f64>,
    /// The slowest of the steps' fastest times over the rounds, ns (the CSV's `worst_ns`).
    pub worst_ns: Option<f64>,
    /// The median over rounds of a round's slowest step, ns.
    pub median_worst_ns: Option<f64>,
    /// The free RK4 step's fastest round's mean, ns (none for rapier).
    pub free_rk4_ns: Option<f64>,
    /// The free RK4 step's median mean, ns.
    pub free_median_ns: Option<f64>,
    /// `mean_ns / free_rk4_ns`.
    pub mean_ratio: Option<f64>,
    /// The median over rounds of a round's mean / the free step's mean in the same round.
    pub median_ratio: Option<f64>,
    /// Rounds timed.
    pub rounds: usize,
    /// Depth and energy.
    pub measured: Option<Measured>,
    /// Why the row has no figures, if it has none.
    pub failure: Option<String>,
}

/// How much to run.
#[derive(Debug, Clone, Copy)]
pub struct Plan {
    /// Timed rounds (after one warm-up round, which the quick run skips).
    pub rounds: usize,
    /// Whether to warm up.
    pub warm_up: bool,
    /// Simulated seconds of the ragdoll, the double pendulum and the ball.
    pub seconds: [f64; 3],
}

/// The plan of a full run and of a quick one.
fn plan(quick: bool) -> Plan {
    if quick {
        Plan {
            rounds: 1,
            warm_up: false,
            seconds: [1.5, 2.0, 2.0],
        }
    } else {
        Plan {
            rounds: 21,
            warm_up: true,
            seconds: [6.0, 10.0, 5.0],
        }
    }
}

/// Times the candidates of one scene round after round and measures their figures.
fn measure(
    scene: &'static str,
    scalar: &'static str,
    steps: usize,
    mut candidates: Vec<Candidate>,
    plan: Plan,
) -> Vec<Row> {
    let n = candidates.len();
    let mut means: Vec<Vec<f64>> = vec![Vec::new(); n];
    let mut worsts: Vec<Vec<f64>> = vec![Vec::new(); n];
    let mut fastest: Vec<Vec<f64>> = vec![vec![f64::INFINITY; steps]; n];
    let mut failures: Vec<Option<String>> = vec![None; n];
    let rounds = plan.rounds + usize::from(plan.warm_up);
    for round in 0..rounds {
        let counted = !plan.warm_up || round > 0;
        for (i, c) in candidates.iter_mut().enumerate() {
            if failures[i].is_some() {
                continue;
            }
            let whole = (c.run)(false);
            let each = whole.and_then(|w| (c.run)(true).map(|e| (w, e)));
            match each {
                Ok((whole, each)) if counted => {
                    means[i].push(whole[0] / steps as f64);
                    worsts[i].push(each.iter().copied().fold(0.0, f64::max));
                    for (f, &t) in fastest[i].iter_mut().zip(&each) {
                        *f = f.min(t);
                    }
                }
                Ok(_) => {}
                Err(e) => failures[i] = Some(e),
            }
        }
    }
    let free = candidates
        .iter()
        .position(|c| c.stepper == FREE)
        .filter(|&f| failures[f].is_none());
    let free_min = free.map(|f| fastest_of(&means[f]));
    let free_median = free.map(|f| median(means[f].clone()));
    let mut rows = Vec::new();
    for (i, c) in candidates.iter_mut().enumerate() {
        if c.stepper == FREE {
            continue;
        }
        let measured = c.figures.as_mut().map(|f| f());
        let (measured, figure_failure) = match measured {
            Some(Ok(m)) => (Some(m), None),
            Some(Err(e)) => (None, Some(e)),
            None => (None, None),
        };
        let timed = failures[i].is_none();
        let peer = c.stepper.starts_with("rapier");
        let mean = timed.then(|| fastest_of(&means[i]));
        let against = |x: Option<f64>| x.filter(|_| timed && !peer);
        rows.push(Row {
            scene,
            stepper: c.stepper,
            scalar,
            mean_ns: mean,
            median_mean_ns: timed.then(|| median(means[i].clone())),
            worst_ns: timed.then(|| fastest[i].iter().copied().fold(0.0, f64::max)),
            median_worst_ns: timed.then(|| median(worsts[i].clone())),
            free_rk4_ns: if peer { None } else { free_min },
            free_median_ns: if peer { None } else { free_median },
            mean_ratio: against(mean.zip(free_min).map(|(a, b)| a / b)),
            median_ratio: against(
                free.map(|f| median(means[i].iter().zip(&means[f]).map(|(a, b)| a / b).collect())),
            ),
            rounds: plan.rounds,
            measured,
            failure: failures[i].clone().or(figure_failure),
        });
    }
    rows
}

/// The smallest of `xs`.
fn fastest_of(xs: &[f64]) -> f64 {
    xs.iter().copied().fold(f64::INFINITY, f64::min)
}

/// The peer with its bodies allowed to fall asleep (rapier's default), in the Markdown only:
/// what a game using rapier as it comes would pay once the ragdoll rests.
pub const RAPIER_SLEEPING: &str = "rapier2d_sleeping";

/// rapier2d with sleeping allowed: timed only.
fn rapier_sleeping(steps: usize) -> Candidate {
    let start = scenes::thrown();
    let dt = scenes::RAGDOLL_DT;
    Candidate {
        stepper: RAPIER_SLEEPING,
        run: Box::new(move |per_step| peer::timed_run(&start, dt, steps, true, per_step)),
        figures: None,
    }
}

/// The rapier2d candidate: the thrown ragdoll, `steps` steps of 1/240 s.
fn rapier(steps: usize) -> Candidate {
    let start = scenes::thrown();
    let dt = scenes::RAGDOLL_DT;
    Candidate {
        stepper: "rapier2d",
        run: Box::new(move |per_step| peer::timed_run(&start, dt, steps, false, per_step)),
        figures: Some(Box::new(move || {
            let f = peer::figures(&start, dt, steps)?;
            Ok(Measured {
                depth: f.manifold_depth,
                limit_depth: None,
                energy_gain: f.energy_gain,
                contact_steps: f.contact_steps,
                note: format!(
                    "capsules' exact depth after each step {:.2} mm",
                    f.geometric_depth * 1e3
                ),
            })
        })),
    }
}

/// Every scene in `T`, measured.
fn scenes_in<T: lagrange_core::Real>(plan: Plan, rows: &mut Vec<Row>) -> Result<(), String> {
    let scalar = lagrange_benches::precision::<T>();
    let e = |e: lagrange_core::Error| e.to_string();
    let [ragdoll_s, pendulum_s, ball_s] = plan.seconds;

    let scene = scenes::ragdoll::<T>(ragdoll_s).map_err(e)?;
    let steps = scene.steps;
    let mut c = scenes::candidates(scene).map_err(e)?;
    if scalar == "f32" {
        c.push(rapier(steps));
        c.push(rapier_sleeping(steps));
    }
    println!("== ragdoll, {scalar}: {steps} steps");
    rows.extend(measure("ragdoll", scalar, steps, c, plan));

    let starts = scenes::other_throws();
    println!("== {}, {scalar}: {} throws", throws::SCENE, starts.len());
    let mut each = Vec::new();
    for start in &starts {
        let scene = scenes::ragdoll_from::<T>(ragdoll_s, start).map_err(e)?;
        let steps = scene.steps;
        let mut c = scenes::candidates(scene).map_err(e)?;
        c.retain(|c| c.stepper != EVENT);
        each.extend(measure(throws::SCENE, scalar, steps, c, plan));
    }
    rows.extend(throws::spread(&each));

    let scene = scenes::double_pendulum::<T>(pendulum_s).map_err(e)?;
    let steps = scene.steps;
    println!("== double_pendulum, {scalar}: {steps} steps");
    rows.extend(measure(
        "double_pendulum",
        scalar,
        steps,
        scenes::candidates(scene).map_err(e)?,
        plan,
    ));

    let scene = scenes::ball::<T>(ball_s).map_err(e)?;
    let steps = scene.steps;
    println!("== ball, {scalar}: {steps} steps");
    rows.extend(measure(
        "ball",
        scalar,
        steps,
        scenes::candidates(scene).map_err(e)?,
        plan,
    ));
    Ok(())
}

/// The workspace's root.
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
            eprintln!("contacts bench: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Parses the flags, measures, writes and prints the report.
fn run(args: &[String]) -> Result<(), String> {
    let mut quick = false;
    for arg in args {
        match arg.as_str() {
            "--quick" => quick = true,
            // `cargo bench` passes `--bench`; xtask passes its own flag on.
            "--bench" | "--contacts" => {}
            other => {
                return Err(format!(
                    "unknown flag `{other}`\nusage: cargo xtask bench --contacts [--quick]"
                ))
            }
        }
    }
    let clock = std::time::Instant::now();
    let plan = plan(quick);
    let start = scenes::thrown();
    let agreement = peer::free_flight_agreement(&start, scenes::RAGDOLL_DT, 60)?;
    println!(
        "rapier2d's ragdoll against lagrange's in free flight (no ground, 60 steps of \
         1/240 s): centres of mass within {:.2} mm",
        agreement * 1e3
    );
    let mut rows = Vec::new();
    scenes_in::<f32>(plan, &mut rows)?;
    scenes_in::<f64>(plan, &mut rows)?;
    let seconds = clock.elapsed().as_secs_f64();
    let markdown = report::markdown(quick, &rows, agreement, seconds);
    let dir = project_root().join("target").join("lagrange-bench");
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    for (name, text) in [
        ("contacts.csv", report::csv(&rows)),
        ("contacts.md", markdown.clone()),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    println!("\n{markdown}");
    println!("wrote {}", dir.join("contacts.csv").display());
    println!("wrote {}", dir.join("contacts.md").display());
    Ok(())
}
