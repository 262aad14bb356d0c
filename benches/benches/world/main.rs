//! `cargo xtask bench --world` (which runs this bench, optimised): what a step of a
//! `lagrange_world::World` costs, beside rapier2d stepping the same scene (issue 34's cost
//! table).
//!
//! Scenes, each a lagrange `World` in `f32` and `f64` and the same scene built in rapier2d
//! ([`peer`]: the same bodies, masses, inertias, shapes, surfaces, walls and start), all
//! stepped at 60 Hz, slop 5 mm, 8 sweeps of lagrange's impulse solve:
//!
//! - `pyramid_55`, `pyramid_210`: 10 and 20 rows of 1 kg boxes of 1 m on the floor, 5 cm
//!   apart in a row (the stacking test of `tests/tests/world.rs`: no rebound, friction 0.6),
//!   5 s.
//! - `balls_1000`: 1,000 balls (0.1 m, 1 kg) poured from rows of 20 up to 12.75 m into a pit
//!   5.2 m wide (a floor and two walls: half-planes in lagrange, slabs in rapier2d),
//!   restitution 0.1, friction 0.5, 4 s: they land, heap and settle.
//! - `ragdolls_10`, `ragdolls_50`: adult ragdolls with capsules on their links and their
//!   joint limits (`CoordinateLimits`, solved with the contacts; rapier2d: multibodies with
//!   limited revolute joints) thrown into a pit (the pile of `tests/tests/world_pile.rs`:
//!   restitution 0.2, friction 0.6; but 2.8 m apart, so that no two start overlapping, and
//!   fifty in five columns of ten in a wider pit), 5 s.
//! - `ragdolls_10_asleep`, `ragdolls_50_asleep`: the same piles with sleeping on (lagrange:
//!   every rate below 0.05 for 0.5 s, the pile test's; rapier2d: its own defaults), stepped
//!   untimed until every body is asleep (at most 60 s), then timed for 2 s.
//!
//! In the awake scenes sleeping is off in both engines, so that every step does the
//! whole work (`awake` = `bodies`). rapier2d computes in `f32` (its `f64` build is
//! another crate, `rapier2d-f64`, not a dependency here): its rows are `f32` only, and the
//! goals compare lagrange's `f32` with it (lagrange's `f64` beside it, for information).
//!
//! **Timing.** Every candidate of a scene (lagrange in `f32` and `f64`, rapier2d) is run in
//! the same process, round after round (one warm-up round first, not counted), so that a
//! change in the machine's load falls on all of them. In each round each candidate's world
//! is built anew (not timed) and stepped through the scene as a whole run, timed as a whole
//! (no clock read inside it); an asleep scene's world is built and settled once, and each
//! round steps it on (asleep, every step is the same work). `ns_per_step`: the fastest
//! round's time over its steps; the Markdown gives the median over rounds beside it. Minima
//! because the machine this was written on is shared (2 cores, other builds running): the
//! medians move with its load, the minima much less (see the contacts bench's notes).
//!
//! **Figures.** After the timed rounds, one more untimed run of each candidate measures:
//! `awake`, the mean over the scene's steps of the bodies awake after each step;
//! `max_penetration`, the deepest overlap after any step, m. For lagrange, found again
//! after each step from outside: every shape placed at its body's state, boxed, paired by
//! the crate's public `BroadPhase` and collided with its public `collide` and
//! `collide_half_plane` (two shapes of different bodies, or a shape and a wall; a ragdoll's
//! own links overlap at its joints by design). For rapier2d, the deepest `dist` in its
//! contact manifolds (the poses its collision detection saw, those at the step's start: the
//! previous step's end).
//!
//! **Where lagrange's time goes.** In the untimed run each lagrange world is given a clock
//! (`World::set_clock`, nanoseconds since the bench started) and its own profile
//! (`WorldReport::profile`: free, broad, narrow, solve, drift, sleep) is averaged over the
//! steps; the Markdown gives the means a step, with the mean contacts and islands. The timed
//! rounds read no clock inside a step.
//!
//! Output under `target/lagrange-bench/`: `world.csv`
//! (`scene,engine,scalar,bodies,awake,ns_per_step,max_penetration`) and `world.md` (the
//! table, the goals and whether each is met), the Markdown printed too. `--quick`: one
//! round of a few steps of each scene and a settling capped at 10 s, a smoke run.
//!
//! [`WorldReport`]: lagrange_world::WorldReport

mod peer;
#[path = "../shared/rapier_ragdoll.rs"]
mod rapier_ragdoll;
mod report;
mod scenes;

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use lagrange_benches::timing::median;
use lagrange_core::Real;
use scenes::{Probe, Sim};

/// Builds a candidate's world (settled, for an asleep scene), with a note on how.
type Build = Box<dyn Fn() -> Result<(Box<dyn Sim>, String), String>>;

/// One engine in one precision on one scene.
pub struct Candidate {
    /// `lagrange` or `rapier2d`.
    pub engine: &'static str,
    /// `f32` or `f64`.
    pub scalar: &'static str,
    /// Builds its world.
    pub build: Build,
}

/// One row of the report.
#[derive(Debug, Clone)]
pub struct Row {
    /// Scene name.
    pub scene: &'static str,
    /// `lagrange` or `rapier2d`.
    pub engine: &'static str,
    /// `f32` or `f64`.
    pub scalar: &'static str,
    /// Bodies (a ragdoll is one body).
    pub bodies: usize,
    /// Mean over the steps of the bodies awake after each step.
    pub awake: Option<f64>,
    /// The fastest round's ns per step.
    pub ns_per_step: Option<f64>,
    /// The median over rounds of a round's ns per step.
    pub median_ns: Option<f64>,
    /// Rounds timed.
    pub rounds: usize,
    /// Deepest overlap after any step, m.
    pub depth: Option<f64>,
    /// Means over the steps of what the probe found besides (lagrange only).
    pub probe: Probe,
    /// How the world was built (the settling of an asleep scene).
    pub note: String,
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
    /// Steps of the pyramids, the balls, the piles, the asleep piles.
    pub steps: [usize; 4],
    /// Steps an asleep scene may take to fall asleep, at most.
    pub settle: usize,
}

/// The plan of a full run and of a quick one.
fn plan(quick: bool) -> Plan {
    if quick {
        Plan {
            rounds: 1,
            warm_up: false,
            steps: [20, 20, 20, 20],
            settle: 600,
        }
    } else {
        Plan {
            rounds: 7,
            warm_up: true,
            steps: [300, 240, 300, 120],
            settle: 3600,
        }
    }
}

/// A whole run of `steps` steps of `sim`, timed as a whole, ns.
fn timed(sim: &mut dyn Sim, steps: usize) -> Result<f64, String> {
    let clock = Instant::now();
    for _ in 0..steps {
        sim.step()?;
    }
    Ok(clock.elapsed().as_nanos() as f64)
}

/// The untimed run: `steps` steps, the world probed after each, its parts timed.
fn figures(sim: &mut dyn Sim, steps: usize) -> Result<(f64, f64, Probe), String> {
    sim.time_parts();
    let (mut awake, mut depth) = (0.0, 0.0_f64);
    let mut sums = Probe::default();
    let add = |sum: &mut Option<f64>, x: Option<f64>| {
        if let Some(x) = x {
            *sum = Some(sum.unwrap_or(0.0) + x);
        }
    };
    for _ in 0..steps {
        sim.step()?;
        awake += sim.awake() as f64;
        let p = sim.probe();
        depth = depth.max(p.depth);
        add(&mut sums.contacts, p.contacts);
        add(&mut sums.islands, p.islands);
        if let Some(parts) = p.parts_ns {
            let sum = sums.parts_ns.get_or_insert([0.0; 6]);
            for (s, x) in sum.iter_mut().zip(parts) {
                *s += x;
            }
        }
    }
    let n = steps.max(1) as f64;
    let mean = |x: Option<f64>| x.map(|x| x / n);
    Ok((
        awake / n,
        depth,
        Probe {
            depth,
            contacts: mean(sums.contacts),
            islands: mean(sums.islands),
            parts_ns: sums.parts_ns.map(|p| p.map(|x| x / n)),
        },
    ))
}

/// Times the candidates of one scene round after round, then measures their figures. An
/// asleep scene (`keep`) is built once and stepped on; an awake one anew each round.
fn measure(
    scene: &'static str,
    bodies: usize,
    steps: usize,
    keep: bool,
    candidates: Vec<Candidate>,
    plan: Plan,
) -> Vec<Row> {
    let n = candidates.len();
    let mut ns: Vec<Vec<f64>> = vec![Vec::new(); n];
    let mut failures: Vec<Option<String>> = vec![None; n];
    let mut notes = vec![String::new(); n];
    let mut kept: Vec<Option<Box<dyn Sim>>> = (0..n).map(|_| None).collect();
    if keep {
        for (i, c) in candidates.iter().enumerate() {
            match (c.build)() {
                Ok((sim, note)) => {
                    kept[i] = Some(sim);
                    notes[i] = note;
                }
                Err(e) => failures[i] = Some(e),
            }
        }
    }
    let rounds = plan.rounds + usize::from(plan.warm_up);
    for round in 0..rounds {
        let counted = !plan.warm_up || round > 0;
        for (i, c) in candidates.iter().enumerate() {
            if failures[i].is_some() {
                continue;
            }
            let run = match kept[i].as_mut() {
                Some(sim) => timed(sim.as_mut(), steps),
                None => (c.build)().and_then(|(mut sim, note)| {
                    notes[i] = note;
                    timed(sim.as_mut(), steps)
                }),
            };
            match run {
                Ok(t) if counted => ns[i].push(t / steps as f64),
                Ok(_) => {}
                Err(e) => failures[i] = Some(e),
            }
        }
    }
    let mut rows = Vec::new();
    for (i, c) in candidates.iter().enumerate() {
        let measured = if failures[i].is_some() {
            None
        } else {
            let run = match kept[i].as_mut() {
                Some(sim) => figures(sim.as_mut(), steps),
                None => (c.build)().and_then(|(mut sim, _)| figures(sim.as_mut(), steps)),
            };
            match run {
                Ok(m) => Some(m),
                Err(e) => {
                    failures[i] = Some(e);
                    None
                }
            }
        };
        let timed = !ns[i].is_empty() && failures[i].is_none();
        let row = Row {
            scene,
            engine: c.engine,
            scalar: c.scalar,
            bodies,
            awake: measured.as_ref().map(|m| m.0),
            ns_per_step: timed.then(|| ns[i].iter().copied().fold(f64::INFINITY, f64::min)),
            median_ns: timed.then(|| median(ns[i].clone())),
            rounds: plan.rounds,
            depth: measured.as_ref().map(|m| m.1),
            probe: measured.map(|m| m.2).unwrap_or_default(),
            note: notes[i].clone(),
            failure: failures[i].clone(),
        };
        println!(
            "  {} {}: {} ns/step, awake {}, depth {} mm{}",
            row.engine,
            row.scalar,
            row.ns_per_step.map_or("-".into(), |x| format!("{x:.0}")),
            row.awake.map_or("-".into(), |x| format!("{x:.1}")),
            row.depth.map_or("-".into(), |x| format!("{:.2}", x * 1e3)),
            row.failure
                .as_ref()
                .map_or(String::new(), |f| format!(" FAILED: {f}")),
        );
        rows.push(row);
    }
    rows
}

/// A lagrange candidate in `T`.
fn lagrange<T: Real, S: Sim + 'static>(
    make: impl Fn() -> Result<S, lagrange_core::Error> + 'static,
) -> Candidate {
    Candidate {
        engine: "lagrange",
        scalar: lagrange_benches::precision::<T>(),
        build: Box::new(move || {
            let sim = make().map_err(|e| e.to_string())?;
            Ok((Box::new(sim) as Box<dyn Sim>, String::new()))
        }),
    }
}

/// The rapier2d candidate (f32).
fn rapier<S: Sim + 'static>(make: impl Fn() -> Result<S, String> + 'static) -> Candidate {
    Candidate {
        engine: "rapier2d",
        scalar: "f32",
        build: Box::new(move || Ok((Box::new(make()?) as Box<dyn Sim>, String::new()))),
    }
}

/// `c` with its world stepped (untimed) until no body is awake, `settle` steps at most;
/// the note says how long it took, or that it did not.
fn settled(mut c: Candidate, settle: usize) -> Candidate {
    let build = c.build;
    c.build = Box::new(move || {
        let (mut sim, _) = build()?;
        for k in 1..=settle {
            sim.step()?;
            if sim.awake() == 0 {
                let note = format!("asleep after {k} steps ({:.1} s)", k as f64 * scenes::DT);
                return Ok((sim, note));
            }
        }
        Ok((
            sim,
            format!(
                "NOT all asleep after {settle} steps ({:.0} s): timed as it is",
                settle as f64 * scenes::DT
            ),
        ))
    });
    c
}

/// Every scene, measured.
fn all_scenes(plan: Plan) -> Vec<Row> {
    use scenes::{lagrange_balls, lagrange_pile, lagrange_pyramid};
    let [pyramid_steps, ball_steps, pile_steps, asleep_steps] = plan.steps;
    let mut rows = Vec::new();
    let mut scene = |name: &'static str, bodies: usize, steps: usize, keep: bool, c| {
        println!("== {name}: {bodies} bodies, {steps} steps");
        rows.extend(measure(name, bodies, steps, keep, c, plan));
    };
    scene(
        "pyramid_55",
        55,
        pyramid_steps,
        false,
        vec![
            lagrange::<f32, _>(|| lagrange_pyramid::<f32, 64, 512>(10)),
            lagrange::<f64, _>(|| lagrange_pyramid::<f64, 64, 512>(10)),
            rapier(|| Ok(peer::pyramid(10))),
        ],
    );
    scene(
        "pyramid_210",
        210,
        pyramid_steps,
        false,
        vec![
            lagrange::<f32, _>(|| lagrange_pyramid::<f32, 256, 2048>(20)),
            lagrange::<f64, _>(|| lagrange_pyramid::<f64, 256, 2048>(20)),
            rapier(|| Ok(peer::pyramid(20))),
        ],
    );
    scene(
        "balls_1000",
        1000,
        ball_steps,
        false,
        vec![
            lagrange::<f32, _>(|| lagrange_balls::<f32, 1024, 8192>(1000)),
            lagrange::<f64, _>(|| lagrange_balls::<f64, 1024, 8192>(1000)),
            rapier(|| Ok(peer::balls(1000))),
        ],
    );
    scene(
        "ragdolls_10",
        10,
        pile_steps,
        false,
        vec![
            lagrange::<f32, _>(|| lagrange_pile::<f32, 16, 160, 1024>(10, false)),
            lagrange::<f64, _>(|| lagrange_pile::<f64, 16, 160, 1024>(10, false)),
            rapier(|| peer::pile(10, false)),
        ],
    );
    scene(
        "ragdolls_50",
        50,
        pile_steps,
        false,
        vec![
            lagrange::<f32, _>(|| lagrange_pile::<f32, 64, 640, 4096>(50, false)),
            lagrange::<f64, _>(|| lagrange_pile::<f64, 64, 640, 4096>(50, false)),
            rapier(|| peer::pile(50, false)),
        ],
    );
    let s = plan.settle;
    scene(
        "ragdolls_10_asleep",
        10,
        asleep_steps,
        true,
        vec![
            settled(
                lagrange::<f32, _>(|| lagrange_pile::<f32, 16, 160, 1024>(10, true)),
                s,
            ),
            settled(
                lagrange::<f64, _>(|| lagrange_pile::<f64, 16, 160, 1024>(10, true)),
                s,
            ),
            settled(rapier(|| peer::pile(10, true)), s),
        ],
    );
    scene(
        "ragdolls_50_asleep",
        50,
        asleep_steps,
        true,
        vec![
            settled(
                lagrange::<f32, _>(|| lagrange_pile::<f32, 64, 640, 4096>(50, true)),
                s,
            ),
            settled(
                lagrange::<f64, _>(|| lagrange_pile::<f64, 64, 640, 4096>(50, true)),
                s,
            ),
            settled(rapier(|| peer::pile(50, true)), s),
        ],
    );
    rows
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
            eprintln!("world bench: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Parses the flags, measures (on a thread with a big stack: a world of 1,000 balls or 50
/// ragdolls is megabytes, and its step keeps a copy of its bodies), writes and prints the
/// report.
fn run(args: &[String]) -> Result<(), String> {
    let mut quick = false;
    for arg in args {
        match arg.as_str() {
            "--quick" => quick = true,
            // `cargo bench` passes `--bench`; xtask passes its own flag on.
            "--bench" | "--world" => {}
            other => {
                return Err(format!(
                    "unknown flag `{other}`\nusage: cargo xtask bench --world [--quick]"
                ))
            }
        }
    }
    let clock = Instant::now();
    let plan = plan(quick);
    let rows = std::thread::Builder::new()
        .stack_size(512 << 20)
        .spawn(move || all_scenes(plan))
        .map_err(|e| format!("could not start the bench's thread: {e}"))?
        .join()
        .map_err(|_| "the bench's thread panicked".to_string())?;
    let seconds = clock.elapsed().as_secs_f64();
    let markdown = report::markdown(quick, &rows, seconds);
    let dir = project_root().join("target").join("lagrange-bench");
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    for (name, text) in [
        ("world.csv", report::csv(&rows)),
        ("world.md", markdown.clone()),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    println!("\n{markdown}");
    println!("wrote {}", dir.join("world.csv").display());
    println!("wrote {}", dir.join("world.md").display());
    Ok(())
}
