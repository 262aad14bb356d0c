//! The bench's output: `bench.csv` (every point), `report.md` (summary, budgets, stability
//! limits, every point) and the SVG work-precision plots.

use super::budgets::{Rk4Ratio, RK4_BUDGET};
use super::chain_cost::ChainCost;
use super::engine_overhead::Overhead;
use super::method::{Origin, Tableau};
use super::stability::{Limit, STABLE_ENERGY_ERROR};
use super::sweep::{Row, Sweeps};
use super::timing::Budget;
use super::work_precision::{curves, time_at, Reach};
use lagrange_plot::{Panel, Scale, Series};
use std::fmt::Write;
use std::path::Path;

/// How the run went, for the report's header.
pub struct Context {
    /// A `--quick` smoke run.
    pub quick: bool,
    /// SciPy ran too (`--peers`).
    pub peers: bool,
    /// Wall time of the whole bench, s.
    pub elapsed: f64,
    /// 1-minute load average before and after.
    pub load: (Option<f64>, Option<f64>),
    /// Timing budget per point.
    pub budget: Budget,
}

/// Error levels of the f64 summary tables and of the comparison with `ode_solvers`.
pub const F64_LEVELS: [f64; 2] = [1e-6, 1e-10];
/// Error level of the f32 summary table (f32 rounding floors most problems near 1e-6).
pub const F32_LEVEL: f64 = 1e-4;

/// Writes every output file into `dir` and returns their names.
pub fn write(
    dir: &Path,
    context: &Context,
    sweeps: &Sweeps,
    ratios: &[Rk4Ratio],
    chain: &ChainCost,
    overhead: &Overhead,
    limits: &[Limit],
) -> Result<Vec<String>, String> {
    let mut files = Vec::new();
    let mut put = |name: String, text: String| -> Result<(), String> {
        let path = dir.join(&name);
        std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))?;
        files.push(name);
        Ok(())
    };
    put("bench.csv".into(), csv(&sweeps.rows))?;
    let plots = plots(&sweeps.rows).map_err(|e| e.to_string())?;
    let names: Vec<String> = plots.iter().map(|(n, _)| n.clone()).collect();
    for (name, svg) in plots {
        put(name, svg)?;
    }
    put(
        "report.md".into(),
        markdown(context, sweeps, ratios, chain, overhead, limits, &names),
    )?;
    Ok(files)
}

/// Every point as CSV.
fn csv(rows: &[Row]) -> String {
    let mut s = String::from(
        "problem,precision,method,origin,kind,param,t_end,steps,evals,jacobians,final_error,\
         energy_error,seconds,seconds_per_simulated_second,ns_per_step,runs,failure\n",
    );
    // RFC 4180: a field holding a comma or a quote is quoted, its quotes doubled.
    let field = |text: &str| {
        if text.contains([',', '"']) {
            format!("\"{}\"", text.replace('"', "\"\""))
        } else {
            text.to_string()
        }
    };
    for r in rows {
        let _ = writeln!(
            s,
            "{},{},{},{},{:?},{:e},{},{},{},{},{:e},{:e},{:e},{:e},{:.2},{},{}",
            r.problem,
            r.precision,
            field(r.method),
            r.origin.label(),
            r.kind,
            r.param,
            r.t_end,
            r.steps,
            r.evals,
            r.jacobians,
            r.final_error,
            r.energy_error,
            r.seconds,
            r.per_simulated_second(),
            r.ns_per_step(),
            r.runs,
            field(r.failure.as_deref().unwrap_or(""))
        );
    }
    s
}

/// Size of a work-precision plot, pixels.
const PLOT_SIZE: (u32, u32) = (900, 540);

/// One kind of work-precision plot: wall time per simulated second against an error.
struct WorkPlot {
    /// End of its file names.
    file: &'static str,
    /// The error, for its title.
    what: &'static str,
    /// Its x axis's label.
    x_label: &'static str,
    /// The error of a row.
    x: fn(&Row) -> f64,
}

/// The plots drawn per problem and precision.
const WORK_PLOTS: [WorkPlot; 2] = [
    WorkPlot {
        file: "error",
        what: "final error",
        x_label: "final error max |y(T) - y_ref(T)|",
        x: |r| r.final_error,
    },
    WorkPlot {
        file: "energy",
        what: "energy error",
        x_label: "max relative energy error max_t |E(t) - E(0)| / |E(0)|",
        x: |r| r.energy_error,
    },
];

/// One error plot and one energy plot per problem and precision: log-log, a line with a dot
/// per point for each method.
fn plots(rows: &[Row]) -> Result<Vec<(String, String)>, lagrange_plot::Error> {
    let all = curves(rows);
    let mut keys: Vec<(&str, &str)> = Vec::new();
    for c in &all {
        if let Some(f) = c.first() {
            if !keys.contains(&(f.problem, f.precision)) {
                keys.push((f.problem, f.precision));
            }
        }
    }
    let mut out = Vec::new();
    for (problem, precision) in keys {
        let mine: Vec<&Vec<&Row>> = all
            .iter()
            .filter(|c| {
                c.first()
                    .is_some_and(|f| f.problem == problem && f.precision == precision)
            })
            .collect();
        let series = |x: fn(&Row) -> f64| -> Vec<Series> {
            mine.iter()
                .filter_map(|c| {
                    let first = c.first()?;
                    Some(Series {
                        name: first.method.to_string(),
                        points: c
                            .iter()
                            .filter(|r| r.ok())
                            .map(|r| (x(r), r.per_simulated_second()))
                            .collect(),
                    })
                })
                .collect()
        };
        for plot in WORK_PLOTS {
            let lines = series(plot.x);
            let title = format!("{problem} ({precision}): work against {}", plot.what);
            let panel = Panel::new(&title, &lines)
                .x_axis(plot.x_label, Scale::Log)
                .y_axis("wall time per simulated second (s)", Scale::Log)
                .with_markers();
            out.push((
                format!("wp-{problem}-{precision}-{}.svg", plot.file),
                lagrange_plot::svg(&[panel], PLOT_SIZE.0, PLOT_SIZE.1)?,
            ));
        }
    }
    Ok(out)
}

/// A duration, human-readable.
fn time(s: f64) -> String {
    if !s.is_finite() {
        "-".into()
    } else if s < 1e-3 {
        format!("{:.3} µs", s * 1e6)
    } else if s < 1.0 {
        format!("{:.3} ms", s * 1e3)
    } else {
        format!("{s:.3} s")
    }
}

/// A reach, for a table cell.
fn cell(reach: Reach) -> String {
    match reach {
        Reach::Interpolated(t) => time(t),
        Reach::AtMost(t) => format!("≤ {}", time(t)),
        Reach::NotReached { best } if best.is_finite() => format!("— ({best:.0e})"),
        Reach::NotReached { .. } => "— (failed)".into(),
    }
}

/// Problem ids in first-seen order.
fn problem_ids(rows: &[Row]) -> Vec<&'static str> {
    let mut ids = Vec::new();
    for r in rows {
        if !ids.contains(&r.problem) {
            ids.push(r.problem);
        }
    }
    ids
}

/// Method names (with origin and tableau) in first-seen order.
fn method_names(rows: &[Row]) -> Vec<(&'static str, Origin, Option<Tableau>)> {
    let mut names = Vec::new();
    for r in rows {
        if !names.iter().any(|(n, _, _)| *n == r.method) {
            names.push((r.method, r.origin, r.tableau));
        }
    }
    names
}

/// The curve of one method on one problem in one precision.
fn curve<'a>(rows: &'a [Row], problem: &str, precision: &str, method: &str) -> Vec<&'a Row> {
    rows.iter()
        .filter(|r| r.problem == problem && r.precision == precision && r.method == method)
        .collect()
}

/// The summary table at `level` in `precision`: methods down, problems across.
fn summary_table(s: &mut String, rows: &[Row], precision: &str, level: f64) {
    let ids = problem_ids(rows);
    let _ = write!(s, "| method |");
    for id in &ids {
        let _ = write!(s, " {id} |");
    }
    let _ = write!(s, "\n|---|");
    for _ in &ids {
        let _ = write!(s, "---:|");
    }
    s.push('\n');
    for (method, _, _) in method_names(rows) {
        let mut line = format!("| {method} |");
        let mut any = false;
        for id in &ids {
            let c = curve(rows, id, precision, method);
            if c.is_empty() {
                line.push_str(" n/a |");
            } else {
                any = true;
                let _ = write!(line, " {} |", cell(time_at(&c, level)));
            }
        }
        if any {
            s.push_str(&line);
            s.push('\n');
        }
    }
}

/// The fastest method of `origin` that reaches `level` on `problem` (f64): (method, reach).
fn best_of(
    rows: &[Row],
    problem: &str,
    origin: Origin,
    level: f64,
) -> Option<(&'static str, Reach)> {
    method_names(rows)
        .into_iter()
        .filter(|(_, o, _)| *o == origin)
        .filter_map(|(m, _, _)| {
            let reach = time_at(&curve(rows, problem, "f64", m), level);
            reach.time().map(|t| (m, t, reach))
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(m, _, reach)| (m, reach))
}

/// The method of `origin` with `tableau` that ran on `problem` (f64), and how it reaches
/// `level`, reached or not.
fn with_tableau(
    rows: &[Row],
    problem: &str,
    origin: Origin,
    tableau: Tableau,
    level: f64,
) -> Option<(&'static str, Reach)> {
    method_names(rows)
        .into_iter()
        .find(|(m, o, t)| {
            *o == origin && *t == Some(tableau) && !curve(rows, problem, "f64", m).is_empty()
        })
        .map(|(m, _, _)| (m, time_at(&curve(rows, problem, "f64", m), level)))
}

/// One row of a peer table: the library's side against the peer's at one level.
fn peer_row(
    s: &mut String,
    (problem, level, pairing): (&str, f64, &str),
    lib: Option<(&str, Reach)>,
    peer: Option<(&str, Reach)>,
) {
    let show = |side: Option<(&str, Reach)>| {
        side.map_or(("not reached".to_string(), "-".to_string()), |(m, r)| {
            (m.to_string(), cell(r))
        })
    };
    let ((lm, lt), (pm, pt)) = (show(lib), show(peer));
    let factor = match (
        lib.and_then(|(_, r)| r.time()),
        peer.and_then(|(_, r)| r.time()),
    ) {
        (Some(a), Some(b)) => format!("{:.2}x", b / a),
        _ => "-".into(),
    };
    let _ = writeln!(
        s,
        "| {problem} | {level:.0e} | {pairing} | {lm} | {lt} | {pm} | {pt} | {factor} |"
    );
}

/// The library against a peer at equal final error, per problem and level: the best method of
/// each side, then each tableau both sides have, like for like.
fn peer_table(s: &mut String, rows: &[Row], peer: Origin, label: &str) {
    let _ = write!(
        s,
        "\n### The library against {label} at equal final error (f64)\n\n\
         | problem | final error | pairing | lagrange method | time / sim s | {label} method | \
         time / sim s | lagrange faster by |\n|---|---:|---|---|---:|---|---:|---:|\n"
    );
    for id in problem_ids(rows) {
        if !rows.iter().any(|r| r.problem == id && r.origin == peer) {
            continue;
        }
        for level in F64_LEVELS {
            peer_row(
                s,
                (id, level, "best against best"),
                best_of(rows, id, Origin::Library, level),
                best_of(rows, id, peer, level),
            );
            for tableau in Tableau::ALL {
                let lib = with_tableau(rows, id, Origin::Library, tableau, level);
                let other = with_tableau(rows, id, peer, tableau, level);
                if lib.is_some() && other.is_some() {
                    peer_row(s, (id, level, "like for like"), lib, other);
                }
            }
        }
    }
    let _ = writeln!(
        s,
        "\nBest against best: the fastest of all the library's methods against the fastest of \
         {label}'s at that error. Like for like: the same Butcher tableau on both sides \
         (Dormand-Prince 5(4), Dormand-Prince 8(5,3)), each with its own step-size controller. \
         `lagrange faster by` is {label}'s time over lagrange's: below 1, {label} is faster. {}",
        if peer == Origin::SciPy {
            "SciPy calls a Python right-hand side (the same equations, written in Python) once \
             per evaluation, as the origin's script did."
        } else {
            "Both call the same `Mechanism::acceleration`."
        }
    );
}

/// The engine's own cost per evaluation against `ode_solvers`', and the N-body through the
/// automatic path (issue 17).
fn overhead_summary(s: &mut String, o: &Overhead) {
    if o.rows.is_empty() && o.automatic.is_empty() {
        return;
    }
    s.push_str(
        "\n## Summary (f64): the engine's own cost per evaluation against `ode_solvers`\n\n",
    );
    let mut rows: Vec<_> = o.rows.iter().collect();
    rows.sort_by_key(|r| r.n);
    let rounds = rows.first().map_or(0, |r| r.rounds);
    let _ = write!(
        s,
        "Goal (issue 17): beyond the right-hand side, the library's cost per evaluation is at \
         most `ode_solvers`' for every N from 1 to 40. Both solve the problem from its start to \
         its end with the same tableau at rtol = atol = tol, each on a right-hand side written \
         by hand (the library on the problem's mechanism, `ode_solvers` on the same equations \
         written on plain arrays); `overhead = (solve - evals x rhs) / evals`, with `rhs` timed \
         over the states the library's solve evaluates at (each library its own call). The \
         four timings are taken in turn, round after round; medians of {rounds} rounds. `ratio`: \
         the library's solve time per evaluation over `ode_solvers`'. A negative overhead means \
         the right-hand side ran faster inside the solve than in the loop that timed it: the \
         overhead there is below the timing's resolution.\n\n\
         | problem | N | tableau | tol | evals lagrange / ode_solvers | rhs ns lagrange / ode_solvers | solve ns per eval lagrange / ode_solvers | ratio | overhead ns per eval lagrange | overhead ns per eval ode_solvers | lagrange's overhead at most ode_solvers' |\n\
         |---|---:|---|---:|---:|---:|---:|---:|---:|---:|---|\n",
    );
    for r in &rows {
        let (lo, oo) = (r.lib_overhead_ns(), r.ode_overhead_ns());
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.0e} | {} / {} | {:.1} / {:.1} | {:.1} / {:.1} | {:.2} | {:.1} | {:.1} | {} |",
            r.problem,
            r.n,
            match r.tableau {
                Tableau::DormandPrince54 => "DP 5(4)",
                Tableau::DormandPrince853 => "DP 8(5,3)",
            },
            r.tol,
            r.lib_evals,
            r.ode_evals,
            r.lib_rhs_ns,
            r.ode_rhs_ns,
            r.lib_solve * 1e9 / r.lib_evals as f64,
            r.ode_solve * 1e9 / r.ode_evals as f64,
            r.per_eval_ratio(),
            lo,
            oo,
            if lo <= oo.max(0.0) { "yes" } else { "**no**" }
        );
    }
    if !o.automatic.is_empty() {
        s.push_str(
            "\n### The N-body through the automatic path\n\n\
             The same mechanism three ways: its law written by hand (a `Mechanism`), and its \
             `Lagrangian` through `EulerLagrange`, declaring `CONSTANT_MASS` (the mass matrix \
             factored once, `T` never differentiated) or not. One acceleration timed over the \
             states of the hand law's DOP853 solve at 1e-6; whole DOP853 solves.\n\n\
             | problem | equations | ns per acceleration | x law by hand | DOP853 solves (tol: evals, time) | x law by hand |\n\
             |---|---|---:|---:|---|---|\n",
        );
        for r in &o.automatic {
            let hand = o
                .automatic
                .iter()
                .find(|h| h.problem == r.problem)
                .unwrap_or(r);
            let solves: Vec<String> = r
                .solves
                .iter()
                .map(|(tol, evals, t)| format!("{tol:.0e}: {evals}, {}", time(*t)))
                .collect();
            let ratios: Vec<String> = r
                .solves
                .iter()
                .filter_map(|(tol, _, t)| {
                    let h = hand.solves.iter().find(|x| x.0 == *tol)?;
                    Some(format!("{tol:.0e}: {:.1}x", t / h.2))
                })
                .collect();
            let _ = writeln!(
                s,
                "| {} | {} | {:.0} | {:.1}x | {} | {} |",
                r.problem,
                r.variant,
                r.ns_per_eval,
                r.ns_per_eval / hand.ns_per_eval,
                if solves.is_empty() {
                    "not timed (seconds per solve)".into()
                } else {
                    solves.join("; ")
                },
                ratios.join("; ")
            );
        }
    }
}

/// Issue 17's targets at equal final error: how many times faster the library's fastest
/// method is than `ode_solvers`' fastest, per problem, at both f64 levels.
const EQUAL_ERROR_TARGETS: [(&str, f64); 5] = [
    ("P1", 3.0),
    ("P2", 3.0),
    ("P3-N5", 2.0),
    ("P3-N20", 2.0),
    ("P4", 2.0),
];

/// The equal-error targets: per problem and level, the factor, the library method that gives
/// it, and whether the target is met.
fn equal_error_goals(s: &mut String, rows: &[Row]) {
    let _ = write!(
        s,
        "**The fastest at equal error**: the library's fastest method against `ode_solvers`' \
         fastest, f64, at each final error (`ode_solvers`' time over the library's; details \
         under \"The library against `ode_solvers`\").\n\n\
         | problem | target | at {:.0e} | met | at {:.0e} | met |\n|---|---:|---|---|---|---|\n",
        F64_LEVELS[0], F64_LEVELS[1]
    );
    for (id, target) in EQUAL_ERROR_TARGETS {
        if !rows
            .iter()
            .any(|r| r.problem == id && r.origin == Origin::OdeSolvers)
        {
            continue;
        }
        let mut line = format!("| {id} | {target:.0}x |");
        for level in F64_LEVELS {
            let lib = best_of(rows, id, Origin::Library, level);
            let peer = best_of(rows, id, Origin::OdeSolvers, level);
            let time = |side: Option<(&str, Reach)>| side.and_then(|(_, r)| r.time());
            let (cell, met) = match (lib, time(lib), time(peer)) {
                (Some((m, _)), Some(a), Some(b)) => {
                    let factor = b / a;
                    let met = if factor >= target { "yes" } else { "**no**" };
                    (format!("{factor:.2}x ({m})"), met)
                }
                (_, Some(_), None) => ("`ode_solvers` does not reach it".into(), "yes"),
                (_, None, Some(_)) => ("the library does not reach it".into(), "**no**"),
                _ => ("neither reaches it".into(), "-"),
            };
            let _ = write!(line, " {cell} | {met} |");
        }
        s.push_str(&line);
        s.push('\n');
    }
}

/// The ratios of issue 17's goals in one place: the library against `ode_solvers` at equal
/// error, the engine's own cost per evaluation against `ode_solvers`' for each N, and the RK4
/// step against the hand-written loop for each problem.
fn goals_summary(s: &mut String, rows: &[Row], ratios: &[Rk4Ratio], o: &Overhead) {
    if ratios.is_empty() && o.rows.is_empty() && rows.is_empty() {
        return;
    }
    s.push_str("\n## Summary: the goals of issue 17 (speed)\n\n");
    if rows.iter().any(|r| r.origin == Origin::OdeSolvers) {
        equal_error_goals(s, rows);
        s.push('\n');
    }
    if !o.rows.is_empty() {
        s.push_str(
            "**Overhead that does not grow with N**: the library's own cost per evaluation \
             (solve time per evaluation minus one right-hand side) at most `ode_solvers`' for \
             every N. Per N, over its problems and both tolerances (details in the next \
             section): the largest difference `lagrange - ode_solvers`, ns per evaluation, and \
             the median ratio of the solve times per evaluation.\n\n\
             | N | problems | overhead ns lagrange (range) | overhead ns ode_solvers (range) | largest difference ns | solve per eval ratio (median) | at most ode_solvers' |\n\
             |---:|---|---:|---:|---:|---:|---|\n",
        );
        let mut ns: Vec<usize> = o.rows.iter().map(|r| r.n).collect();
        ns.sort_unstable();
        ns.dedup();
        for n in ns {
            let rows: Vec<_> = o.rows.iter().filter(|r| r.n == n).collect();
            let mut problems: Vec<&str> = rows.iter().map(|r| r.problem).collect();
            problems.dedup();
            let range = |f: &dyn Fn(&&super::engine_overhead::OverheadRow) -> f64| {
                let v: Vec<f64> = rows.iter().map(f).collect();
                let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                format!("{lo:.0}..{hi:.0}")
            };
            let worst = rows
                .iter()
                .map(|r| r.lib_overhead_ns() - r.ode_overhead_ns())
                .fold(f64::NEG_INFINITY, f64::max);
            let mut per_eval: Vec<f64> = rows.iter().map(|r| r.per_eval_ratio()).collect();
            per_eval.sort_by(f64::total_cmp);
            let met = rows
                .iter()
                .all(|r| r.lib_overhead_ns() <= r.ode_overhead_ns().max(0.0));
            let _ = writeln!(
                s,
                "| {n} | {} | {} | {} | {worst:+.1} | {:.2} | {} |",
                problems.join(", "),
                range(&|r| r.lib_overhead_ns()),
                range(&|r| r.ode_overhead_ns()),
                per_eval[per_eval.len() / 2],
                if met { "yes" } else { "**no**" }
            );
        }
    }
    if !ratios.is_empty() {
        let _ = write!(
            s,
            "\n**The RK4 step**: the library's RK4 within {RK4_BUDGET}x of the hand-written loop \
             (the goal is for f32; f64 shown too). Median of the per-pair ratios; details under \
             Budgets.\n\n| problem | f32 ratio | f32 within {RK4_BUDGET}x | f64 ratio |\n|---|---:|---|---:|\n"
        );
        let mut problems: Vec<&str> = ratios.iter().map(|r| r.problem).collect();
        problems.dedup();
        for p in problems {
            let of = |precision: &str| {
                ratios
                    .iter()
                    .find(|r| r.problem == p && r.precision == precision)
            };
            let (f32r, f64r) = (of("f32"), of("f64"));
            let _ = writeln!(
                s,
                "| {p} | {} | {} | {} |",
                f32r.map_or("-".into(), |r| format!("{:.3}", r.ratio)),
                f32r.map_or("-", |r| if r.ratio <= RK4_BUDGET {
                    "yes"
                } else {
                    "**no**"
                }),
                f64r.map_or("-".into(), |r| format!("{:.3}", r.ratio)),
            );
        }
    }
}

/// The whole Markdown report.
fn markdown(
    context: &Context,
    sweeps: &Sweeps,
    ratios: &[Rk4Ratio],
    chain: &ChainCost,
    overhead: &Overhead,
    limits: &[Limit],
    plots: &[String],
) -> String {
    let rows = &sweeps.rows;
    let mut s = String::from("# lagrange: run time against error\n\n");
    let cores = std::thread::available_parallelism().map_or(0, usize::from);
    let load = |l: Option<f64>| l.map_or("?".into(), |v| format!("{v:.2}"));
    let _ = writeln!(
        s,
        "Written by `cargo xtask bench{}` in {:.0} s on {cores} cores (1-minute load average {} \
         before, {} after). Each time is the median of {}..{} whole solves over [0, T] (as \
         many as fit about {} s per point), f64 and f32 alike; errors and energies are \
         computed in f64. A point's final error is measured on its timed solves' end state, \
         and its energy error and evaluation count on an untimed solve that must end at the \
         same state bit for bit (else the point is reported failed). The machine may be shared: compare ratios and orders of magnitude, \
         not the last digit.\n",
        match (context.quick, context.peers) {
            (true, true) => " --quick --peers",
            (true, false) => " --quick",
            (false, true) => " --peers",
            (false, false) => "",
        },
        context.elapsed,
        load(context.load.0),
        load(context.load.1),
        context.budget.min_runs,
        context.budget.max_runs,
        context.budget.seconds
    );

    goals_summary(&mut s, rows, ratios, overhead);
    s.push_str("\n## Problems and references\n\n");
    s.push_str("| id | problem | T (s) | mechanism simulated | reference | its error | E(0) |\n|---|---|---:|---|---|---:|---:|\n");
    for r in &sweeps.references {
        let _ = writeln!(
            s,
            "| {} | {} | {:.6} | {} | {} | {:.1e} | {:.6} |",
            r.problem, r.title, r.t_end, r.mechanism, r.source, r.error, r.e0
        );
    }
    s.push_str(
        "\nFinal error: `max_i |y_i(T) - y_ref,i(T)|` over angles (rad, unwrapped) and rates. \
         Energy error: `max_t |E(t) - E(0)| / |E(0)|` over every step, with `V = 0` at the \
         hanging rest state for pendulums and chains (`BENCH_PROBLEMS.md`).\n",
    );

    for level in F64_LEVELS {
        let _ = writeln!(
            s,
            "\n## Summary (f64): wall time per simulated second at final error {level:.0e}\n"
        );
        summary_table(&mut s, rows, "f64", level);
    }
    let _ = writeln!(
        s,
        "\n## Summary (f32): wall time per simulated second at final error {F32_LEVEL:.0e}\n"
    );
    summary_table(&mut s, rows, "f32", F32_LEVEL);
    s.push_str(
        "\nInterpolated log-log between the two sweep points around the level; `≤ t`: the \
         coarsest point of the sweep is already below the level; `— (e)`: the sweep never gets \
         there, `e` its best error (rounding floor, stability, or the time cap per point).\n",
    );
    overhead_summary(&mut s, overhead);

    s.push_str("\n## Budgets\n\n### The library's RK4 against a hand-written RK4 loop\n\n");
    s.push_str(
        "Same problem, step and precision; whole solves timed in interleaved pairs; the ratio \
         is the median of the per-pair ratios.\n\n\
         | problem | precision | dt | steps | library ns/step | hand-written ns/step | ratio | ratio of fastest runs | within 1.1x | max difference of final states |\n\
         |---|---|---:|---:|---:|---:|---:|---:|---|---:|\n",
    );
    for r in ratios {
        let _ = writeln!(
            s,
            "| {} | {} | {:.0e} | {} | {:.1} | {:.1} | {:.3} | {:.3} | {} | {:.1e} |",
            r.problem,
            r.precision,
            r.dt,
            r.steps,
            r.library_ns,
            r.hand_ns,
            r.ratio,
            r.library_min_ns / r.hand_min_ns,
            if r.ratio <= RK4_BUDGET {
                "yes"
            } else {
                "**no**"
            },
            r.max_difference
        );
    }

    for (peer, label) in [
        (Origin::OdeSolvers, "`ode_solvers`"),
        (Origin::SciPy, "SciPy"),
    ] {
        if rows.iter().any(|r| r.origin == peer) {
            peer_table(&mut s, rows, peer, label);
        }
    }

    s.push_str("\n### The chain's cost per step against N\n\n");
    if chain.points.is_empty() {
        s.push_str("Not measured (P3 not selected).\n");
    } else {
        let _ = writeln!(
            s,
            "Mechanism: {}. One RK4 step (4 evaluations), one assembly of `M` and `f`, one \
             fixed-size Cholesky solve, f64; and one RK4 step through the automatic \
             Euler-Lagrange path on the same chain's Lagrangian.\n\n\
             | N | ns per RK4 step | ns per assembly | ns per solve | ns per RK4 step, automatic path |\n\
             |---:|---:|---:|---:|---:|",
            chain.mechanism
        );
        for p in &chain.points {
            let _ = writeln!(
                s,
                "| {} | {:.0} | {:.0} | {:.0} | {:.0} |",
                p.n, p.ns_per_step, p.ns_assembly, p.ns_solve, p.ns_per_step_automatic
            );
        }
        let _ = writeln!(
            s,
            "\nFitted exponents (least squares of log cost on log N): step **{:.2}** over \
             N = 2..20, {:.2} over N = 8..20; assembly {:.2}; solve {:.2}; automatic path \
             {:.2}. The budget is O(N^2) plus the fixed-size solve (O(N^3) with a small \
             constant).",
            chain.exponent_step,
            chain.exponent_step_large,
            chain.exponent_assembly,
            chain.exponent_solve,
            chain.exponent_automatic
        );
    }

    let _ = writeln!(
        s,
        "\n## Stability limits (f64)\n\nLargest `dt` for which a whole solve over [0, T] finishes \
         with relative energy error at most {STABLE_ENERGY_ERROR}: scanned upwards by doublings \
         from T / (max steps), then bisected geometrically. `w`: the problem's fastest \
         small-oscillation frequency; `h w` is comparable with the linear limit of each method \
         (the extent of its stability region along the imaginary axis).\n\n\
         | problem | method | w (rad/s) | largest stable dt | h w | first unstable dt | linear limit h w | how the first unstable run ended |\n\
         |---|---|---:|---:|---:|---:|---:|---|"
    );
    for l in limits {
        let stable = l
            .largest_stable
            .map_or(format!("< {:.2e}", l.smallest_tried), |d| {
                format!("{d:.4e}")
            });
        let hw = l
            .largest_stable
            .map_or("-".into(), |d| format!("{:.3}", d * l.omega));
        let unstable = l
            .smallest_unstable
            .map_or("-".into(), |d| format!("{d:.4e}"));
        let theory = l.linear_limit.map_or("-".into(), |v| {
            if v == 0.0 {
                "0 (none)".into()
            } else {
                format!("{v:.3}")
            }
        });
        let _ = writeln!(
            s,
            "| {} | {} | {:.3} | {stable} | {hw} | {unstable} | {theory} | {} |",
            l.problem, l.method, l.omega, l.outcome
        );
    }

    s.push_str("\n## Plots\n\n");
    for p in plots {
        let _ = writeln!(s, "- [{p}]({p})");
    }

    s.push_str("\n## Every point\n");
    for id in problem_ids(rows) {
        let _ = writeln!(
            s,
            "\n### {id}\n\n| method | precision | dt or tol | steps | evals | Jacobians | final error | energy error | time / sim s | ns/step | runs | failure |\n\
             |---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|"
        );
        for r in rows.iter().filter(|r| r.problem == id) {
            let _ = writeln!(
                s,
                "| {} | {} | {:.3e} | {} | {} | {} | {:.2e} | {:.2e} | {} | {:.1} | {} | {} |",
                r.method,
                r.precision,
                r.param,
                r.steps,
                r.evals,
                r.jacobians,
                r.final_error,
                r.energy_error,
                time(r.per_simulated_second()),
                r.ns_per_step(),
                r.runs,
                r.failure.as_deref().unwrap_or("")
            );
        }
    }
    if !sweeps.failures.is_empty() {
        s.push_str("\n## Problems that could not run\n\n");
        for f in &sweeps.failures {
            let _ = writeln!(s, "- {f}");
        }
    }
    s
}
