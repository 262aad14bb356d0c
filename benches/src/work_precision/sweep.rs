//! The work-precision sweeps: every method of the table on every problem, f64 and f32, over a
//! range of step sizes or tolerances; one [`Row`] per point.

use super::counting::Counting;
use super::method::{self, Kind, Method, MethodVisitor, Origin, Param, Tableau};
use super::outcome::Outcome;
use super::problem::{energy, state_error, Problem, ProblemVisitor, Reference};
use super::real::{narrow, same_bits, widen, BenchReal};
use super::timing::{median_of_runs, Budget};
use super::Options;
use lagrange_core::{Real, State};
use std::hint::black_box;

/// One point of one sweep.
#[derive(Debug, Clone)]
pub struct Row {
    /// Problem id.
    pub problem: &'static str,
    /// `"f32"` or `"f64"`.
    pub precision: &'static str,
    /// Method name.
    pub method: &'static str,
    /// Whose method.
    pub origin: Origin,
    /// Fixed step or adaptive.
    pub kind: Kind,
    /// Its Butcher tableau, where solvers of other origins share it.
    pub tableau: Option<Tableau>,
    /// `dt` (s) or tolerance.
    pub param: f64,
    /// Final time of the problem, s.
    pub t_end: f64,
    /// Steps taken.
    pub steps: u64,
    /// Acceleration evaluations.
    pub evals: u64,
    /// Jacobian evaluations (implicit methods).
    pub jacobians: u64,
    /// `max_i |y_i(T) - y_ref,i(T)|`.
    pub final_error: f64,
    /// `max_t |E(t) - E(0)| / |E(0)|` over every step.
    pub energy_error: f64,
    /// Median wall time of one whole solve, s.
    pub seconds: f64,
    /// Timed runs behind the median.
    pub runs: usize,
    /// Why the solve failed, when it did.
    pub failure: Option<String>,
}

impl Row {
    /// Wall time per simulated second.
    pub fn per_simulated_second(&self) -> f64 {
        self.seconds / self.t_end
    }
    /// Wall time per step, ns.
    pub fn ns_per_step(&self) -> f64 {
        self.seconds * 1e9 / self.steps.max(1) as f64
    }
    /// True for a solve that finished.
    pub fn ok(&self) -> bool {
        self.failure.is_none()
    }
}

/// What a problem's reference was, for the report.
#[derive(Debug, Clone)]
pub struct ReferenceInfo {
    /// Problem id.
    pub problem: &'static str,
    /// Its one-line description.
    pub title: &'static str,
    /// Mechanism simulated and caveats.
    pub mechanism: &'static str,
    /// Final time, s.
    pub t_end: f64,
    /// Reference source.
    pub source: String,
    /// Reference error (stated or estimated).
    pub error: f64,
    /// Energy at the start, under the report's convention.
    pub e0: f64,
}

/// Everything the sweeps produced.
#[derive(Default)]
pub struct Sweeps {
    /// One per problem.
    pub references: Vec<ReferenceInfo>,
    /// One per point.
    pub rows: Vec<Row>,
    /// Problems that could not be set up, with why.
    pub failures: Vec<String>,
}

/// Runs every sweep selected by `opts`.
pub fn run(opts: &Options) -> Sweeps {
    let mut v = SweepProblems {
        opts,
        out: Sweeps::default(),
    };
    super::problems::for_each(&mut v);
    v.out
}

/// Visits each problem, then each method on it.
struct SweepProblems<'a> {
    opts: &'a Options,
    out: Sweeps,
}

impl ProblemVisitor for SweepProblems<'_> {
    fn visit<P: Problem<N, N2>, const N: usize, const N2: usize>(&mut self, p: &P) {
        if !self.opts.selected(p.id()) {
            return;
        }
        if self.opts.quick && NOT_SWEPT_QUICK.contains(&p.id()) {
            println!(
                "\n== {}: swept only without --quick (its overhead and RK4 budgets are measured)",
                p.id()
            );
            return;
        }
        println!("\n== {}: {}", p.id(), p.title());
        println!("   mechanism: {}", p.mechanism_note());
        let (reference, m64) = match (p.reference(), p.mechanism::<f64>()) {
            (Ok(r), Ok(m)) => (r, m),
            (Err(e), _) => {
                return self
                    .out
                    .failures
                    .push(format!("{}: reference: {e}", p.id()))
            }
            (_, Err(e)) => {
                return self
                    .out
                    .failures
                    .push(format!("{}: mechanism: {e}", p.id()))
            }
        };
        let datum = p.energy_datum();
        let e0 = energy(&m64, datum.as_ref(), &p.start());
        // Whatever its source, the reference is held in f64: half an ulp of its largest
        // component is part of its error.
        let rounding = 0.5
            * f64::EPSILON
            * reference
                .state
                .q
                .iter()
                .chain(reference.state.qd.iter())
                .fold(0.0f64, |m, x| m.max(x.abs()));
        let reference_error = reference.error.max(rounding);
        println!(
            "   reference: {} (its error {reference_error:.1e}); E(0) = {e0}",
            reference.source
        );
        self.out.references.push(ReferenceInfo {
            problem: p.id(),
            title: p.title(),
            mechanism: p.mechanism_note(),
            t_end: p.t_end(),
            source: reference.source.clone(),
            error: reference_error,
            e0,
        });
        let mut v = SweepMethods {
            problem: p,
            reference: &reference,
            m64: &m64,
            datum: datum.as_ref(),
            opts: self.opts,
            rows: &mut self.out.rows,
        };
        method::for_each(&mut v);
    }
}

/// Visits each method on one problem.
struct SweepMethods<'a, P: Problem<N, N2>, const N: usize, const N2: usize> {
    problem: &'a P,
    reference: &'a Reference<N>,
    m64: &'a P::Mech<f64>,
    datum: Option<&'a State<f64, N>>,
    opts: &'a Options,
    rows: &'a mut Vec<Row>,
}

impl<P: Problem<N, N2>, const N: usize, const N2: usize> MethodVisitor
    for SweepMethods<'_, P, N, N2>
{
    fn visit<X: Method>(&mut self, m: &X) {
        if !self.opts.method_selected(m.name()) {
            return;
        }
        for precision in [Precision::F64, Precision::F32] {
            let before = self.rows.len();
            match precision {
                Precision::F64 => self.sweep::<f64, X>(m),
                Precision::F32 => self.sweep::<f32, X>(m),
            }
            summarize(&self.rows[before..]);
        }
    }
}

/// The two precisions.
#[derive(Clone, Copy)]
enum Precision {
    F64,
    F32,
}

/// Prints one line for a finished sweep.
fn summarize(rows: &[Row]) {
    let Some(first) = rows.first() else { return };
    let ok: Vec<&Row> = rows.iter().filter(|r| r.ok()).collect();
    let best = ok
        .iter()
        .map(|r| r.final_error)
        .fold(f64::INFINITY, f64::min);
    println!(
        "   {:<22} {} {:>2} points ({} failed), best error {:>8.1e}, {:>8.2e} .. {:>8.2e} s/sim s",
        first.method,
        first.precision,
        rows.len(),
        rows.len() - ok.len(),
        best,
        ok.iter()
            .map(|r| r.per_simulated_second())
            .fold(f64::INFINITY, f64::min),
        ok.iter()
            .map(|r| r.per_simulated_second())
            .fold(0.0, f64::max),
    );
}

/// The sweep's points, coarsest first: step sizes halving from the problem's coarsest, or
/// tolerances falling by decades to what the precision can honour.
fn params<T: BenchReal>(kind: Kind, coarsest_dt: f64, t_end: f64) -> Vec<Param> {
    match kind {
        Kind::FixedStep => (0..40)
            .map(|k| {
                let steps = (t_end / (coarsest_dt * 0.5f64.powi(k))).ceil().max(1.0) as u64;
                Param::Step {
                    dt: t_end / steps as f64,
                    steps,
                }
            })
            .collect(),
        Kind::Adaptive => {
            let tightest = if T::LABEL == "f32" { 7 } else { 14 };
            (3..=tightest)
                .map(|k| Param::Tolerance(10f64.powi(-k)))
                .collect()
        }
    }
}

impl<P: Problem<N, N2>, const N: usize, const N2: usize> SweepMethods<'_, P, N, N2> {
    /// One method in one precision over its sweep.
    fn sweep<T: BenchReal, X: Method>(&mut self, m: &X) {
        let p = self.problem;
        let mech = match p.mechanism::<T>() {
            Ok(mech) => mech,
            Err(e) => {
                println!("   {}: {} mechanism refused: {e}", m.name(), T::LABEL);
                return;
            }
        };
        let start: State<T, N> = narrow(&p.start());
        let e0 = energy(self.m64, self.datum, &widen(&start));
        let t_end = T::real(p.t_end());
        let (budget, max_solve, max_steps) =
            (self.opts.budget, self.opts.max_solve, self.opts.max_steps);
        let mut best = f64::INFINITY;
        let mut stale = 0;
        let mut failures = 0;
        for param in params::<T>(m.kind(), p.coarsest_dt(), p.t_end()) {
            if let Param::Step { steps, .. } = param {
                if steps > max_steps {
                    break;
                }
            }
            let counter = Counting::new(&mech);
            let mut max_de: f64 = 0.0;
            let mut observe = |s: &State<T, N>| {
                let de = (energy(self.m64, self.datum, &widen(s)) - e0).abs() / e0.abs();
                max_de = if de.is_nan() {
                    f64::NAN
                } else {
                    max_de.max(de)
                };
            };
            let Some(result) = m.solve(p, &counter, &start, t_end, param, Some(&mut observe))
            else {
                return;
            };
            let mut row = Row {
                problem: p.id(),
                precision: T::LABEL,
                method: m.name(),
                origin: m.origin(),
                kind: m.kind(),
                tableau: m.tableau(),
                param: param.value(),
                t_end: p.t_end(),
                steps: 0,
                evals: counter.calls(),
                jacobians: counter.jacobians(),
                final_error: f64::NAN,
                energy_error: max_de,
                seconds: f64::NAN,
                runs: 0,
                failure: None,
            };
            // The figures of a point are of one computation: the final error is measured on
            // the timed runs' end, which must be the observed run's to the bit (that run's
            // energy error and evaluation count are reported beside it).
            let measured = result.and_then(|out| {
                let (timing, timed) = median_of_runs(budget, || {
                    m.solve(p, &mech, black_box(&start), t_end, param, None)
                });
                let end = timed_end(&out.end, timed)?;
                Ok((out, timing, end))
            });
            match measured {
                Err(why) => {
                    row.failure = Some(why);
                    self.rows.push(row);
                    failures += 1;
                    // A coarse fixed step past the stability limit fails and a finer one may
                    // not; a loose tolerance may let a trial step leave the coordinates' domain
                    // where a tighter one does not. Three adaptive failures in a row end it.
                    let limit = if m.kind() == Kind::Adaptive { 3 } else { 12 };
                    if failures >= limit {
                        return;
                    }
                }
                Ok((out, timing, end)) => {
                    failures = 0;
                    row.steps = out.steps;
                    row.evals = out.evals.unwrap_or(row.evals);
                    // The wrapper counts calls of the law (and the value inside each
                    // Jacobian); a method that evaluates its mechanism otherwise (the
                    // variational integrator: the Lagrangian in dual numbers) has its own
                    // count, which the wrapper does not see. Where both exist they agree up
                    // to that value inside each Jacobian, which the wrapper adds.
                    if let Some((evals, jacobians)) = out.work {
                        row.evals = row.evals.max(evals);
                        row.jacobians = row.jacobians.max(jacobians);
                    }
                    row.final_error = state_error(&widen(&end), &self.reference.state);
                    row.seconds = timing.median;
                    row.runs = timing.runs;
                    let (err, secs) = (row.final_error, row.seconds);
                    self.rows.push(row);
                    // Stop when finer points only cost more: too slow, or no better than the
                    // best so far three times running (the rounding floor).
                    if secs > max_solve {
                        return;
                    }
                    stale = if err < best / 1.5 { 0 } else { stale + 1 };
                    best = best.min(err);
                    if stale >= 3 {
                        return;
                    }
                }
            }
        }
    }
}

/// The final state of a point's timed runs, given the observed run's: every timed run must
/// have finished, at the observed run's end to the bit.
///
/// # Errors
/// Which timed run failed or ended elsewhere.
fn timed_end<T: Real, const N: usize>(
    observed: &State<T, N>,
    timed: Vec<Option<Result<Outcome<T, N>, String>>>,
) -> Result<State<T, N>, String> {
    let mut end = *observed;
    for (i, run) in timed.into_iter().enumerate() {
        let out = run
            .unwrap_or_else(|| Err("the method did not apply".into()))
            .map_err(|e| format!("timed run {i} failed where the observed run did not: {e}"))?;
        if !same_bits(&out.end, observed) {
            return Err(format!(
                "timed run {i} ended at another state than the observed run"
            ));
        }
        end = out.end;
    }
    Ok(end)
}

/// The problems that `--quick` does not sweep: those added for the engine's overhead against N
/// (issue 17), whose sweeps of every method (the implicit ones with Jacobians of up to 40
/// coordinates by differences) took minutes each. The overhead and the RK4 budget still
/// measure them.
const NOT_SWEPT_QUICK: [&str; 4] = ["P3-N10", "P3-N40", "P6-N14", "P6-N28"];

/// For `--quick`: the budget of a smoke run.
pub const QUICK_BUDGET: Budget = Budget {
    seconds: 0.02,
    min_runs: 1,
    max_runs: 3,
};

/// The default budget per point.
pub const DEFAULT_BUDGET: Budget = Budget {
    seconds: 0.1,
    min_runs: 3,
    max_runs: 11,
};
