//! `--peers`: SciPy's `solve_ivp` (RK45, DOP853) and `odeint` (LSODA) on the problems whose
//! equations of motion are also written in Python ([`Problem::python_rhs`]), the way the
//! origin's pendulum script integrated. They run in a virtual environment that this module
//! creates under `target/lagrange-bench/scipy-venv` (with `pip install scipy`) when `python3`
//! is available; the script is `scipy_peer.py`. Their points join the sweeps as f64 rows of
//! origin [`Origin::SciPy`]; the energy error is not measured for them (SciPy's solves are
//! timed whole, with no observer).

/// Virtual environments under `target/`.
#[path = "venv.rs"]
mod venv;

use super::method::{Kind, Origin, Tableau};
use super::problem::{state_error, Problem, ProblemVisitor};
use super::sweep::{Row, Sweeps};
use super::Options;
use lagrange_core::State;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// The driver, run by the venv's Python with a job on stdin.
const SCRIPT: &str = include_str!("scipy_peer.py");

/// The methods the script runs, by the names it prints, with their tableaux.
const METHODS: [(&str, Option<Tableau>); 3] = [
    ("SciPy solve_ivp RK45", Some(Tableau::DormandPrince54)),
    ("SciPy solve_ivp DOP853", Some(Tableau::DormandPrince853)),
    ("SciPy odeint (LSODA)", None),
];

/// Tolerances (relative = absolute) of each SciPy sweep.
const TOLERANCES: [f64; 10] = [
    1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12,
];

/// A method's sweep ends after a solve slower than this, s (Python calls the right-hand side
/// once per evaluation: a Kepler run at 1e-12 takes seconds).
const MAX_SOLVE_SECONDS: f64 = 2.0;

/// Runs SciPy on every selected problem with a Python right-hand side and appends its rows.
///
/// # Errors
/// When `python3` is missing or the environment cannot be set up; a failing solve is a row
/// with its failure, not an error.
pub fn run(opts: &Options, venv: &Path, sweeps: &mut Sweeps) -> Result<(), String> {
    let python = environment(venv)?;
    let mut v = Peers {
        opts,
        python,
        rows: Vec::new(),
        failures: Vec::new(),
    };
    super::problems::for_each(&mut v);
    sweeps.rows.extend(v.rows);
    sweeps.failures.extend(v.failures);
    Ok(())
}

/// The venv's Python, after creating the venv and installing SciPy if needed (the same
/// environment maker as `cargo xtask derive`'s SymPy).
fn environment(venv: &Path) -> Result<PathBuf, String> {
    venv::Venv {
        dir: venv.to_path_buf(),
        packages: &["numpy", "scipy"],
        probe: "import scipy, numpy",
        user: "--peers",
    }
    .python()
}

/// Visits the problems.
struct Peers<'a> {
    opts: &'a Options,
    python: PathBuf,
    rows: Vec<Row>,
    failures: Vec<String>,
}

impl ProblemVisitor for Peers<'_> {
    fn visit<P: Problem<N, N2>, const N: usize, const N2: usize>(&mut self, p: &P) {
        let Some(rhs) = p.python_rhs() else { return };
        if !self.opts.selected(p.id()) || !METHODS.iter().any(|(m, _)| self.opts.method_selected(m))
        {
            return;
        }
        match self.solve(p, rhs) {
            Ok(rows) => {
                for r in &rows {
                    if let Some(why) = &r.failure {
                        println!("   {} {:.0e}: {why}", r.method, r.param);
                    }
                }
                println!("   SciPy on {}: {} points", p.id(), rows.len());
                self.rows.extend(rows);
            }
            Err(e) => self.failures.push(format!("{}: SciPy: {e}", p.id())),
        }
    }
}

impl Peers<'_> {
    /// Runs the script on `p` and turns its lines into rows.
    fn solve<P: Problem<N, N2>, const N: usize, const N2: usize>(
        &self,
        p: &P,
        rhs: &str,
    ) -> Result<Vec<Row>, String> {
        let reference = p.reference()?;
        let start = p.start();
        let y0: Vec<f64> = start.q.iter().chain(start.qd.iter()).copied().collect();
        let job = format!(
            "{{\"rhs\": {}, \"y0\": {y0:?}, \"t_end\": {:?}, \"tolerances\": {TOLERANCES:?}, \
             \"budget_seconds\": {:?}, \"min_runs\": {}, \"max_runs\": {}, \"max_solve\": {:?}}}",
            json_string(rhs),
            p.t_end(),
            self.opts.budget.seconds,
            self.opts.budget.min_runs,
            self.opts.budget.max_runs,
            MAX_SOLVE_SECONDS,
        );
        let mut child = Command::new(&self.python)
            .args(["-c", SCRIPT])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| e.to_string())?;
        child
            .stdin
            .take()
            .ok_or("no stdin")?
            .write_all(job.as_bytes())
            .map_err(|e| e.to_string())?;
        let out = child.wait_with_output().map_err(|e| e.to_string())?;
        if !out.status.success() {
            return Err(String::from_utf8_lossy(&out.stderr).into_owned());
        }
        String::from_utf8_lossy(&out.stdout)
            .lines()
            .filter(|l| self.opts.method_selected(l.split(',').next().unwrap_or("")))
            .map(|line| row(p, &reference.state, line))
            .collect()
    }
}

/// One printed line as a row: `method,tol,steps,evaluations,seconds,runs,failure,y...`.
fn row<P: Problem<N, N2>, const N: usize, const N2: usize>(
    p: &P,
    reference: &State<f64, N>,
    line: &str,
) -> Result<Row, String> {
    let bad = || format!("unreadable SciPy line `{line}`");
    let f: Vec<&str> = line.split(',').collect();
    if f.len() != 7 + 2 * N {
        return Err(bad());
    }
    let (method, tableau) = *METHODS.iter().find(|(m, _)| *m == f[0]).ok_or_else(bad)?;
    let num = |s: &str| s.parse::<f64>().map_err(|_| bad());
    let int = |s: &str| s.parse::<u64>().map_err(|_| bad());
    let y: Vec<f64> = f[7..].iter().map(|s| num(s)).collect::<Result<_, _>>()?;
    let end = State::<f64, N> {
        t: p.t_end(),
        q: lagrange_core::nalgebra::SVector::from_fn(|i, _| y[i]),
        qd: lagrange_core::nalgebra::SVector::from_fn(|i, _| y[N + i]),
    };
    let failure = (!f[6].is_empty()).then(|| f[6].to_string());
    Ok(Row {
        problem: p.id(),
        precision: "f64",
        method,
        origin: Origin::SciPy,
        kind: Kind::Adaptive,
        tableau,
        param: num(f[1])?,
        t_end: p.t_end(),
        steps: int(f[2])?,
        evals: int(f[3])?,
        jacobians: 0,
        final_error: if failure.is_some() {
            f64::NAN
        } else {
            state_error(&end, reference)
        },
        energy_error: f64::NAN,
        seconds: num(f[4])?,
        runs: usize::try_from(int(f[5])?).map_err(|_| bad())?,
        failure,
    })
}

/// `s` as a JSON string literal.
fn json_string(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}
