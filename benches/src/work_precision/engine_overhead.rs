//! The engine's own cost per evaluation (issue 17): for each problem, the library's adaptive
//! pairs against `ode_solvers`' on the same tableau, each on a right-hand side written by hand
//! (the library's on the problem's mechanism, `ode_solvers` on [`Problem::hand`]):
//!
//! ```text
//! overhead per evaluation = (solve time - evaluations x cost of one right-hand side) / evaluations
//! ```
//!
//! with the cost of one right-hand side timed over the very states the library's solve
//! evaluates at, each library's own way (`Mechanism::acceleration`; `ode_solvers`' `System`
//! call, which also copies the rates). The four timings (two solves, two passes over the
//! states) are taken in turn, round after round, and each is the median over the rounds.
//!
//! And the N-body of P6 through the automatic path: the same mechanism's `Lagrangian` in
//! `EulerLagrange`, with its declared constant mass matrix and without the declaration.

use super::method::Tableau;
use super::ode_peer::{self, Peer, Sys};
use super::problem::{Problem, ProblemVisitor};
use super::problems::p6_nbody;
use super::timing::{median, once};
use super::Options;
use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{
    Error, EulerLagrange, GeneralizedForce, Jacobian, Lagrangian, Mechanism, Real, Scalar, State,
};
use lagrange_integrators::{
    AdaptiveSettings, Dop853Pair, Dopri5Pair, EmbeddedPair, EmbeddedRungeKutta,
};
use ode_solvers::System;
use std::cell::RefCell;
use std::hint::black_box;

/// The tolerances (relative = absolute) at which the overhead is measured.
pub const TOLERANCES: [f64; 2] = [1e-6, 1e-10];

/// The library's pair against `ode_solvers`' on one problem at one tolerance.
#[derive(Debug, Clone)]
pub struct OverheadRow {
    /// Problem id.
    pub problem: &'static str,
    /// Coordinates.
    pub n: usize,
    /// The tableau both sides step with.
    pub tableau: Tableau,
    /// Relative and absolute tolerance.
    pub tol: f64,
    /// The library's evaluations per solve.
    pub lib_evals: u64,
    /// `ode_solvers`' evaluations per solve.
    pub ode_evals: u64,
    /// The library's solve, s (median).
    pub lib_solve: f64,
    /// `ode_solvers`' solve, s (median).
    pub ode_solve: f64,
    /// One library right-hand side (`Mechanism::acceleration`), ns.
    pub lib_rhs_ns: f64,
    /// One `ode_solvers` right-hand side (its `System` call on the hand-written equations), ns.
    pub ode_rhs_ns: f64,
    /// Rounds timed.
    pub rounds: usize,
}

impl OverheadRow {
    /// The library's own cost per evaluation, ns.
    pub fn lib_overhead_ns(&self) -> f64 {
        overhead_ns(self.lib_solve, self.lib_evals, self.lib_rhs_ns)
    }
    /// `ode_solvers`' own cost per evaluation, ns.
    pub fn ode_overhead_ns(&self) -> f64 {
        overhead_ns(self.ode_solve, self.ode_evals, self.ode_rhs_ns)
    }
    /// The library's solve time over `ode_solvers`', per evaluation.
    pub fn per_eval_ratio(&self) -> f64 {
        (self.lib_solve / self.lib_evals as f64) / (self.ode_solve / self.ode_evals as f64)
    }
}

/// `(solve - evals rhs) / evals`, ns.
fn overhead_ns(solve: f64, evals: u64, rhs_ns: f64) -> f64 {
    (solve * 1e9 - evals as f64 * rhs_ns) / evals as f64
}

/// One way of writing the N-body, through one tolerance.
#[derive(Debug, Clone)]
pub struct AutomaticRow {
    /// Problem id.
    pub problem: &'static str,
    /// How its equations are formed.
    pub variant: &'static str,
    /// One acceleration at the states of the hand-written law's solve, ns (median).
    pub ns_per_eval: f64,
    /// DOP853 solves at [`TOLERANCES`]: (evaluations, s), where timed.
    pub solves: Vec<(f64, u64, f64)>,
}

/// Everything measured.
#[derive(Debug, Clone, Default)]
pub struct Overhead {
    /// One per problem, pair and tolerance.
    pub rows: Vec<OverheadRow>,
    /// The N-body three ways.
    pub automatic: Vec<AutomaticRow>,
}

/// Measures every selected problem, then the N-body's automatic path.
pub fn measure(opts: &Options) -> Overhead {
    let pairs =
        |name: &str, peer: Peer| opts.method_selected(name) || opts.method_selected(peer.name());
    let mut v = Visit {
        opts,
        dp54: pairs(Dopri5Pair::NAME, Peer::Dopri5),
        dop853: pairs(Dop853Pair::NAME, Peer::Dop853),
        out: Overhead::default(),
    };
    if v.dp54 || v.dop853 {
        println!("\n== engine overhead per evaluation (f64; library against ode_solvers, hand-written right-hand sides)");
        super::problems::for_each(&mut v);
    }
    if v.dop853 {
        if let Ok(m) = Problem::mechanism::<f64>(&p6_nbody::Pleiades) {
            if opts.selected(Problem::id(&p6_nbody::Pleiades)) {
                v.out
                    .automatic
                    .extend(automatic_rows(&p6_nbody::Pleiades, &m, opts));
            }
        }
        if let Ok(m) = Problem::mechanism::<f64>(&p6_nbody::StarAndPlanets) {
            if opts.selected(Problem::id(&p6_nbody::StarAndPlanets)) {
                v.out
                    .automatic
                    .extend(automatic_rows(&p6_nbody::StarAndPlanets, &m, opts));
            }
        }
    }
    v.out
}

/// Rounds of timing per point.
fn rounds(opts: &Options) -> usize {
    if opts.quick {
        9
    } else {
        41
    }
}

/// Visits the problems.
struct Visit<'a> {
    opts: &'a Options,
    dp54: bool,
    dop853: bool,
    out: Overhead,
}

impl ProblemVisitor for Visit<'_> {
    fn visit<P: Problem<N, N2>, const N: usize, const N2: usize>(&mut self, p: &P) {
        if !self.opts.selected(p.id()) {
            return;
        }
        let Ok(m) = p.mechanism::<f64>() else {
            return;
        };
        for tol in TOLERANCES {
            if self.dp54 {
                self.push(compare::<P, _, 7, 1, Dopri5Pair, N, N2>(
                    p,
                    &m,
                    Tableau::DormandPrince54,
                    Peer::Dopri5,
                    tol,
                    rounds(self.opts),
                ));
            }
            if self.dop853 {
                self.push(compare::<P, _, 16, 4, Dop853Pair, N, N2>(
                    p,
                    &m,
                    Tableau::DormandPrince853,
                    Peer::Dop853,
                    tol,
                    rounds(self.opts),
                ));
            }
        }
    }
}

impl Visit<'_> {
    /// Prints and keeps a row, or says why there is none.
    fn push(&mut self, row: Result<OverheadRow, String>) {
        match row {
            Ok(r) => {
                println!(
                    "   {:<7} N = {:>2} {:?} tol {:.0e}: library {} evals {:.3} ms (rhs {:.1} ns), \
                     ode_solvers {} evals {:.3} ms (rhs {:.1} ns); overhead per evaluation \
                     {:.1} ns against {:.1} ns",
                    r.problem,
                    r.n,
                    r.tableau,
                    r.tol,
                    r.lib_evals,
                    r.lib_solve * 1e3,
                    r.lib_rhs_ns,
                    r.ode_evals,
                    r.ode_solve * 1e3,
                    r.ode_rhs_ns,
                    r.lib_overhead_ns(),
                    r.ode_overhead_ns()
                );
                self.out.rows.push(r);
            }
            Err(e) => println!("   {e}"),
        }
    }
}

/// A fresh library integrator on the pair `Pair` at `tol`.
fn integrator<const N: usize, const S: usize, const R: usize, Pair: EmbeddedPair<S, R>>(
    tol: f64,
) -> Result<EmbeddedRungeKutta<f64, N, S, R, Pair>, String> {
    AdaptiveSettings::new(tol, tol)
        .and_then(|s| s.with_max_steps(10_000_000))
        .map(EmbeddedRungeKutta::new)
        .map_err(|e| e.to_string())
}

/// One solve by the library: the end and the evaluations.
fn lib_solve<M, const N: usize, const S: usize, const R: usize, Pair>(
    m: &M,
    start: &State<f64, N>,
    t_end: f64,
    tol: f64,
) -> Result<(State<f64, N>, u64), String>
where
    M: Mechanism<f64, N>,
    Pair: EmbeddedPair<S, R>,
{
    let mut rk = integrator::<N, S, R, Pair>(tol)?;
    let end = rk
        .integrate_to(m, start, t_end)
        .map_err(|e| e.to_string())?;
    Ok((end, rk.statistics().evaluations))
}

/// The library's pair `Pair` against `peer` on `p` at `tol`.
fn compare<P, M, const S: usize, const R: usize, Pair, const N: usize, const N2: usize>(
    p: &P,
    m: &M,
    tableau: Tableau,
    peer: Peer,
    tol: f64,
    rounds: usize,
) -> Result<OverheadRow, String>
where
    P: Problem<N, N2>,
    M: Mechanism<f64, N>,
    Pair: EmbeddedPair<S, R>,
{
    let fail = |what: &str, e: String| format!("{} {tableau:?} tol {tol:.0e}: {what}: {e}", p.id());
    let (start, t_end) = (p.start(), p.t_end());
    let hand = p.hand::<f64>();
    // The states the library's solve evaluates at, recorded by an untimed run.
    let recorder = Recording::new(m);
    lib_solve::<_, N, S, R, Pair>(&recorder, &start, t_end, tol).map_err(|e| fail("library", e))?;
    let states = recorder.states.into_inner();
    let ys: Vec<ode_solvers::SVector<f64, N2>> = states
        .iter()
        .map(|s| ode_solvers::SVector::from_fn(|i, _| if i < N { s.q[i] } else { s.qd[i - N] }))
        .collect();
    let sys = Sys::new(&hand);
    let mut lib = || lib_solve::<_, N, S, R, Pair>(m, black_box(&start), t_end, tol);
    let mut ode =
        || ode_peer::solve::<f64, _, N, N2>(peer, &hand, black_box(&start), t_end, tol, None);
    let mut lib_rhs = || {
        for s in &states {
            let _ = black_box(m.acceleration(black_box(s)));
        }
    };
    let mut ode_rhs = || {
        let mut dy = ode_solvers::SVector::<f64, N2>::zeros();
        for (y, s) in ys.iter().zip(&states) {
            sys.system(s.t, black_box(y), &mut dy);
            black_box(&mut dy);
        }
    };
    let (_, lib_evals) = lib().map_err(|e| fail("library", e))?;
    let ode_evals = ode()
        .map_err(|e| fail("ode_solvers", e))?
        .evals
        .unwrap_or(0);
    let mut t = [const { Vec::new() }; 4];
    for _ in 0..rounds.max(1) {
        t[0].push(once(&mut lib));
        t[1].push(once(&mut ode));
        t[2].push(once(&mut lib_rhs));
        t[3].push(once(&mut ode_rhs));
    }
    let [tl, to, rl, ro] = t.map(median);
    let per_state = |secs: f64| secs * 1e9 / states.len().max(1) as f64;
    Ok(OverheadRow {
        problem: p.id(),
        n: N,
        tableau,
        tol,
        lib_evals,
        ode_evals,
        lib_solve: tl,
        ode_solve: to,
        lib_rhs_ns: per_state(rl),
        ode_rhs_ns: per_state(ro),
        rounds,
    })
}

/// `inner`, recording the state of every evaluation of its law.
struct Recording<'a, M, const N: usize> {
    inner: &'a M,
    states: RefCell<Vec<State<f64, N>>>,
}

impl<'a, M, const N: usize> Recording<'a, M, N> {
    /// Wraps `inner`, nothing recorded.
    fn new(inner: &'a M) -> Self {
        Self {
            inner,
            states: RefCell::new(Vec::new()),
        }
    }
}

impl<M: Lagrangian<f64, N>, const N: usize> Lagrangian<f64, N> for Recording<'_, M, N> {
    const EXPLICIT_TIME: bool = M::EXPLICIT_TIME;
    const DRIVEN: bool = M::DRIVEN;
    const READS_TIME: bool = M::READS_TIME;
    fn kinetic<S: Scalar<Real = f64>>(&self, t: S, q: &SVector<S, N>, qd: &SVector<S, N>) -> S {
        self.inner.kinetic(t, q, qd)
    }
    fn potential<S: Scalar<Real = f64>>(&self, t: S, q: &SVector<S, N>) -> S {
        self.inner.potential(t, q)
    }
}

impl<M: Mechanism<f64, N>, const N: usize> Mechanism<f64, N> for Recording<'_, M, N> {
    fn mass_matrix(&self, s: &State<f64, N>) -> SMatrix<f64, N, N> {
        self.inner.mass_matrix(s)
    }
    fn rhs(&self, s: &State<f64, N>) -> SVector<f64, N> {
        self.inner.rhs(s)
    }
    fn law<F: GeneralizedForce<f64, N>>(
        &self,
        s: &State<f64, N>,
        extra: &F,
    ) -> Result<SVector<f64, N>, Error> {
        self.states.borrow_mut().push(*s);
        self.inner.law(s, extra)
    }
    fn law_jacobian<F: GeneralizedForce<f64, N>>(
        &self,
        s: &State<f64, N>,
        extra: &F,
    ) -> Result<(SVector<f64, N>, Jacobian<f64, N>), Error> {
        self.inner.law_jacobian(s, extra)
    }
    fn reads_velocities(&self) -> bool {
        self.inner.reads_velocities()
    }
}

/// A Lagrangian with its claim of a constant mass matrix withdrawn: the automatic path's
/// general route for the same physics.
struct General<L>(L);

impl<T: Real, const N: usize, L: Lagrangian<T, N>> Lagrangian<T, N> for General<L> {
    fn kinetic<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>, qd: &SVector<S, N>) -> S {
        self.0.kinetic(t, q, qd)
    }
    fn potential<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>) -> S {
        self.0.potential(t, q)
    }
}

/// Seconds of one acceleration of `m` at each of `states`.
fn pass<M: Mechanism<f64, N>, const N: usize>(m: &M, states: &[State<f64, N>]) -> f64 {
    once(&mut || {
        for s in states {
            let _ = black_box(m.acceleration(black_box(s)));
        }
    })
}

/// The N-body `hand` of `p` three ways: ns per acceleration over the states of the hand law's
/// DOP853 solve at the looser tolerance, and whole DOP853 solves (the general automatic path's
/// only where N <= 14: at N = 28 one solve takes seconds).
fn automatic_rows<P, const B: usize, const N: usize, const N2: usize>(
    p: &P,
    hand: &p6_nbody::NBody<f64, B, N>,
    opts: &Options,
) -> Vec<AutomaticRow>
where
    P: Problem<N, N2>,
{
    let constant = EulerLagrange::new(*hand);
    let general = EulerLagrange::new(General(*hand));
    let (start, t_end) = (p.start(), p.t_end());
    let recorder = Recording::new(hand);
    if lib_solve::<_, N, 16, 4, Dop853Pair>(&recorder, &start, t_end, TOLERANCES[0]).is_err() {
        return Vec::new();
    }
    let states = recorder.states.into_inner();
    let mut t = [const { Vec::new() }; 3];
    for _ in 0..rounds(opts).min(5) {
        t[0].push(pass(hand, &states));
        t[1].push(pass(&constant, &states));
        t[2].push(pass(&general, &states));
    }
    let ns = t.map(|v| median(v) * 1e9 / states.len().max(1) as f64);
    let solves = |m: &dyn Fn(f64) -> Result<(State<f64, N>, u64), String>, every: bool| {
        TOLERANCES
            .iter()
            .filter(|_| every)
            .filter_map(|&tol| {
                let mut run = || m(tol);
                let (_, evals) = run().ok()?;
                let times: Vec<f64> = (0..rounds(opts).min(5)).map(|_| once(&mut run)).collect();
                Some((tol, evals, median(times)))
            })
            .collect::<Vec<_>>()
    };
    let rows = vec![
        AutomaticRow {
            problem: p.id(),
            variant: "law by hand (Mechanism)",
            ns_per_eval: ns[0],
            solves: solves(
                &|tol| lib_solve::<_, N, 16, 4, Dop853Pair>(hand, &start, t_end, tol),
                true,
            ),
        },
        AutomaticRow {
            problem: p.id(),
            variant: "automatic, CONSTANT_MASS (M factored once)",
            ns_per_eval: ns[1],
            solves: solves(
                &|tol| lib_solve::<_, N, 16, 4, Dop853Pair>(&constant, &start, t_end, tol),
                true,
            ),
        },
        AutomaticRow {
            problem: p.id(),
            variant: "automatic, general (M and T's derivatives every evaluation)",
            ns_per_eval: ns[2],
            solves: solves(
                &|tol| lib_solve::<_, N, 16, 4, Dop853Pair>(&general, &start, t_end, tol),
                N <= 14,
            ),
        },
    ];
    for r in &rows {
        println!(
            "   {} {}: {:.0} ns per acceleration ({:.1}x the law by hand){}",
            r.problem,
            r.variant,
            r.ns_per_eval,
            r.ns_per_eval / ns[0],
            r.solves
                .iter()
                .map(|(tol, evals, s)| format!(
                    "; DOP853 tol {tol:.0e}: {evals} evals, {:.3} ms",
                    s * 1e3
                ))
                .collect::<String>()
        );
    }
    rows
}
