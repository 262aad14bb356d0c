//! `cargo xtask bench --automatic` (which runs this binary, optimised): what one automatic
//! acceleration (`EulerLagrange::new(lagrangian).acceleration(&s)`) costs against the
//! hand-derived one of the same system, issue 16's table.
//!
//! For the double pendulum, the cart-pole, the acrobot and the chain (`NLinkPendulum`,
//! N = 2, 5, 10, 20): ns per acceleration of the hand-derived law, of the automatic path as it
//! was before issue 16 (frozen in [`before`]) and of the automatic path now, the three timed
//! in turn, round after round, over the same states; the ratios are medians of the per-round
//! ratios, robust to a load that changes during the run on a shared machine. Also the largest
//! relative difference of each automatic path from the hand-derived accelerations.
//!
//! Output under `target/lagrange-bench/`: `automatic.csv` and `automatic.md`. `--quick` for a
//! smoke run, `--only NAME` for the rows whose name contains `NAME`.

mod before;

use lagrange_benches::timing::{median, once};
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, EulerLagrange, Mechanism, State};
use lagrange_systems::{Acrobot, CartPole, DoublePendulum, NLinkPendulum};
use std::fmt::Write;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// States evaluated per timed run.
const STATES: usize = 64;

/// One system's figures.
#[derive(Debug, Clone)]
struct Row {
    /// The system.
    name: String,
    /// ns per acceleration: hand-derived, automatic before issue 16, automatic now.
    hand: f64,
    before: f64,
    after: f64,
    /// Medians of the per-round ratios before / hand and after / hand.
    before_ratio: f64,
    after_ratio: f64,
    /// The goal for after / hand, when it sets one.
    goal: Option<f64>,
    /// Largest difference from the hand-derived accelerations, relative to the largest
    /// acceleration of the state plus one.
    before_error: f64,
    after_error: f64,
}

/// Deterministic, varied states: angles over (-pi, pi), rates over (-2, 2).
fn states<const N: usize>() -> Vec<State<f64, N>> {
    (0..STATES)
        .map(|k| {
            let x = |i: usize, s: f64| ((k * 7 + i * 13) as f64 * s).sin();
            State::new(
                0.0,
                core::array::from_fn(|i| 3.1 * x(i, 0.37)),
                core::array::from_fn(|i| 2.0 * x(i, 0.91)),
            )
        })
        .collect()
}

/// `|a - b|_inf / (|b|_inf + 1)`.
fn relative<const N: usize>(a: &SVector<f64, N>, b: &SVector<f64, N>) -> f64 {
    (a - b).amax() / (b.amax() + 1.0)
}

/// Times `runs` in turn, `rounds` times after one warm-up each, and returns each one's median
/// seconds per run and the median of each one's per-round ratio to the first.
fn rounds<const K: usize>(rounds: usize, runs: &mut [&mut dyn FnMut(); K]) -> ([f64; K], [f64; K]) {
    for run in runs.iter_mut() {
        once(run);
    }
    let mut times: [Vec<f64>; K] = core::array::from_fn(|_| Vec::new());
    let mut ratios: [Vec<f64>; K] = core::array::from_fn(|_| Vec::new());
    for _ in 0..rounds {
        let t: [f64; K] = core::array::from_fn(|i| once(&mut runs[i]));
        for i in 0..K {
            times[i].push(t[i]);
            ratios[i].push(t[i] / t[0]);
        }
    }
    (times.map(median), ratios.map(median))
}

/// Measures `hand` against the automatic paths of its own Lagrangian.
fn measure<M, const N: usize>(
    name: &str,
    hand: M,
    goal: Option<f64>,
    quick: bool,
) -> Result<Row, Error>
where
    M: Mechanism<f64, N> + Clone,
{
    let automatic = EulerLagrange::new(hand.clone());
    let states = states::<N>();
    let (mut before_error, mut after_error) = (0.0f64, 0.0f64);
    for s in &states {
        let a = hand.acceleration(s)?;
        before_error = before_error.max(relative(&before::acceleration(&hand, s)?, &a));
        after_error = after_error.max(relative(&automatic.acceleration(s)?, &a));
    }
    // Aim for about a millisecond per run of the fastest, so that clock reads do not matter.
    let repeat = |mut f: &mut dyn FnMut()| {
        let t = once(&mut f);
        ((1e-3 / t.max(1e-9)).ceil() as usize).clamp(1, 10_000)
    };
    let mut hand_run = || {
        for s in &states {
            let _ = black_box(hand.acceleration(black_box(s)));
        }
    };
    let reps = repeat(&mut hand_run);
    let mut hand_run = || {
        for _ in 0..reps {
            hand_run();
        }
    };
    let mut before_run = || {
        for _ in 0..reps {
            for s in &states {
                let _ = black_box(before::acceleration(black_box(&hand), black_box(s)));
            }
        }
    };
    let mut after_run = || {
        for _ in 0..reps {
            for s in &states {
                let _ = black_box(automatic.acceleration(black_box(s)));
            }
        }
    };
    let n = if quick { 3 } else { 21 };
    let (t, r) = rounds(n, &mut [&mut hand_run, &mut before_run, &mut after_run]);
    let per = |x: f64| x * 1e9 / (reps * STATES) as f64;
    let row = Row {
        name: name.to_string(),
        hand: per(t[0]),
        before: per(t[1]),
        after: per(t[2]),
        before_ratio: r[1],
        after_ratio: r[2],
        goal,
        before_error,
        after_error,
    };
    println!(
        "{:<22} hand {:>9.1} ns  before {:>10.1} ns ({:>6.1}x)  after {:>9.1} ns ({:>5.2}x)  \
         differences {:.1e} {:.1e}",
        row.name,
        row.hand,
        row.before,
        row.before_ratio,
        row.after,
        row.after_ratio,
        row.before_error,
        row.after_error
    );
    Ok(row)
}

/// The chain of `N` links: masses and lengths all different, so that no term cancels.
fn chain<const N: usize>() -> Result<NLinkPendulum<f64, N>, Error> {
    NLinkPendulum::new(
        core::array::from_fn(|i| 0.5 + 0.1 * i as f64),
        core::array::from_fn(|i| 1.0 - 0.02 * i as f64),
        9.81,
    )
}

/// The classic cart-pole, pushed (so that its input enters).
fn pushed_cart_pole() -> Result<CartPole<f64>, Error> {
    let mut cp = CartPole::new(1.0, 0.1, 0.5, 9.81)?;
    cp.set_force(0.7)?;
    Ok(cp)
}

/// Spong's acrobot with a torque at its elbow.
fn driven_acrobot() -> Result<Acrobot<f64>, Error> {
    let mut a = Acrobot::spong();
    a.set_torque(0.3)?;
    Ok(a)
}

/// Measures one row: its name and goal in, the row out.
type Measure<'a> = &'a dyn Fn(&str, Option<f64>) -> Result<Row, Error>;

/// Every row of the table whose name contains `only`.
fn measure_all(quick: bool, only: &str) -> Result<Vec<Row>, Error> {
    let mut rows = Vec::new();
    let mut row = |name: &str, goal, f: Measure<'_>| {
        if name.contains(only) {
            rows.push(f(name, goal)?);
        }
        Ok::<(), Error>(())
    };
    row("double pendulum", Some(3.0), &|n, g| {
        measure(n, DoublePendulum::new(1.0, 0.8, 1.2, 0.9, 9.81)?, g, quick)
    })?;
    row("cart-pole", Some(3.0), &|n, g| {
        measure(n, pushed_cart_pole()?, g, quick)
    })?;
    row("acrobot", Some(3.0), &|n, g| {
        measure(n, driven_acrobot()?, g, quick)
    })?;
    row("chain N = 2", None, &|n, g| {
        measure(n, chain::<2>()?, g, quick)
    })?;
    row("chain N = 5", Some(5.0), &|n, g| {
        measure(n, chain::<5>()?, g, quick)
    })?;
    row("chain N = 10", None, &|n, g| {
        measure(n, chain::<10>()?, g, quick)
    })?;
    row("chain N = 20", Some(20.0), &|n, g| {
        measure(n, chain::<20>()?, g, quick)
    })?;
    Ok(rows)
}

/// `automatic.csv`.
fn csv(rows: &[Row]) -> String {
    let mut out = String::from(
        "system,hand_ns,generated_ns,automatic_before_ns,automatic_after_ns,\
         before_over_hand,after_over_hand,before_difference,after_difference\n",
    );
    for r in rows {
        let _ = writeln!(
            out,
            "{},{:.1},,{:.1},{:.1},{:.3},{:.3},{:.2e},{:.2e}",
            r.name,
            r.hand,
            r.before,
            r.after,
            r.before_ratio,
            r.after_ratio,
            r.before_error,
            r.after_error
        );
    }
    out
}

/// `automatic.md`.
fn markdown(quick: bool, rows: &[Row]) -> String {
    let mut out = String::from("# One automatic acceleration against the hand-derived one\n\n");
    if quick {
        out.push_str("A `--quick` smoke run: few rounds, noisy figures.\n\n");
    }
    out.push_str(
        "ns per acceleration, f64, medians over rounds in which the three were timed in turn \
         over the same states; ratios are medians of the per-round ratios. The generated column \
         waits for `cargo xtask derive` (issue 16, part 1).\n\n\
         | system | hand | generated | automatic before | automatic after | before / hand | \
         after / hand | goal | met |\n|---|---:|---:|---:|---:|---:|---:|---:|---|\n",
    );
    for r in rows {
        let (goal, met) = match r.goal {
            Some(g) => (
                format!("{g:.0}x"),
                if r.after_ratio <= g { "yes" } else { "**no**" },
            ),
            None => ("-".into(), "-"),
        };
        let _ = writeln!(
            out,
            "| {} | {:.1} | - | {:.1} | {:.1} | {:.1}x | {:.2}x | {goal} | {met} |",
            r.name, r.hand, r.before, r.after, r.before_ratio, r.after_ratio
        );
    }
    out.push_str(
        "\nLargest difference from the hand-derived accelerations over the states, relative \
         to the largest acceleration plus one:\n\n| system | before | after |\n|---|---:|---:|\n",
    );
    for r in rows {
        let _ = writeln!(
            out,
            "| {} | {:.1e} | {:.1e} |",
            r.name, r.before_error, r.after_error
        );
    }
    out
}

/// The workspace root (the parent of this crate's manifest directory).
fn project_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
}

fn main() -> ExitCode {
    let (mut quick, mut only) = (false, String::new());
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--quick" => quick = true,
            "--automatic" => {}
            "--only" => only = args.next().unwrap_or_default(),
            other => {
                eprintln!(
                    "unknown flag `{other}`\nusage: cargo xtask bench --automatic [--quick] \
                     [--only NAME]"
                );
                return ExitCode::FAILURE;
            }
        }
    }
    let rows = match measure_all(quick, &only) {
        Ok(rows) => rows,
        Err(e) => {
            eprintln!("automatic bench failed: {e}");
            return ExitCode::FAILURE;
        }
    };
    let dir = project_root().join("target").join("lagrange-bench");
    if let Err(e) = std::fs::create_dir_all(&dir) {
        eprintln!("{}: {e}", dir.display());
        return ExitCode::FAILURE;
    }
    for (name, text) in [
        ("automatic.csv", csv(&rows)),
        ("automatic.md", markdown(quick, &rows)),
    ] {
        let path = dir.join(name);
        if let Err(e) = std::fs::write(&path, text) {
            eprintln!("{}: {e}", path.display());
            return ExitCode::FAILURE;
        }
        println!("wrote {}", path.display());
    }
    ExitCode::SUCCESS
}
