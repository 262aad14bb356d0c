//! The measured stability limit of each explicit fixed-step method on the problems where it is
//! sharp: the largest `dt` for which a whole solve finishes with bounded energy.

use super::method::{self, Kind, Method, MethodVisitor, Origin, Param};
use super::problem::{energy, Problem, ProblemVisitor};
use super::real::widen;
use super::Options;
use lagrange_core::State;

/// Problems scanned (P3's fastest modes make its limit a property of N; with the automatic
/// path its scan costs minutes).
const PROBLEMS: [&str; 4] = ["P1", "P2", "P4", "P5"];

/// A run is stable when it finishes and its relative energy error stays at or below this.
///
/// Large on purpose: near its linear limit `h w -> 2` a symplectic method's energy error is
/// large but bounded (Stormer-Verlet on an oscillator conserves a modified energy, and `E`
/// swings by the factor `1 / (1 - (h w / 2)^2)`), while past any limit the growth is
/// exponential. 10 puts the limit of Verlet on an oscillator at `h w = 1.91` of 2, and is
/// crossed within a few steps by a blow-up.
pub const STABLE_ENERGY_ERROR: f64 = 10.0;

/// One method's limit on one problem.
#[derive(Debug, Clone)]
pub struct Limit {
    /// Problem id.
    pub problem: &'static str,
    /// Method name.
    pub method: &'static str,
    /// The fastest natural frequency of the problem, rad/s.
    pub omega: f64,
    /// Largest stable `dt` found, s (`None`: not stable even at the smallest `dt` tried).
    pub largest_stable: Option<f64>,
    /// Smallest unstable `dt` found, s (`None`: stable up to the largest tried).
    pub smallest_unstable: Option<f64>,
    /// Smallest `dt` tried, s.
    pub smallest_tried: f64,
    /// The method's `h w` limit on a linear oscillator.
    pub linear_limit: Option<f64>,
    /// How the first unstable run ended: an error, or a bounded energy error exceeded.
    pub outcome: String,
}

/// Scans every library fixed-step method on [`PROBLEMS`], in f64.
pub fn scan(opts: &Options) -> Vec<Limit> {
    let mut v = ScanProblems {
        opts,
        out: Vec::new(),
    };
    super::problems::for_each(&mut v);
    v.out
}

/// Visits the problems.
struct ScanProblems<'a> {
    opts: &'a Options,
    out: Vec<Limit>,
}

impl ProblemVisitor for ScanProblems<'_> {
    fn visit<P: Problem<N, N2>, const N: usize, const N2: usize>(&mut self, p: &P) {
        if !self.opts.selected(p.id()) || !PROBLEMS.contains(&p.id()) {
            return;
        }
        let mut v = ScanMethods {
            problem: p,
            opts: self.opts,
            out: &mut self.out,
        };
        method::for_each(&mut v);
    }
}

/// Visits the methods on one problem.
struct ScanMethods<'a, P, const N: usize, const N2: usize> {
    problem: &'a P,
    opts: &'a Options,
    out: &'a mut Vec<Limit>,
}

impl<P: Problem<N, N2>, const N: usize, const N2: usize> MethodVisitor
    for ScanMethods<'_, P, N, N2>
{
    fn visit<X: Method>(&mut self, m: &X) {
        if m.kind() != Kind::FixedStep
            || m.origin() != Origin::Library
            || !m.explicit()
            || !self.opts.method_selected(m.name())
        {
            return;
        }
        let Some(limit) = self.limit(m) else { return };
        let w = limit.omega;
        let shown =
            |dt: Option<f64>| dt.map_or("-".to_string(), |d| format!("{d:.4e} (h w {:.3})", d * w));
        println!(
            "   {} {:<20} largest stable dt {}, first unstable {}: {}",
            limit.problem,
            limit.method,
            shown(limit.largest_stable),
            shown(limit.smallest_unstable),
            limit.outcome
        );
        self.out.push(limit);
    }
}

impl<P: Problem<N, N2>, const N: usize, const N2: usize> ScanMethods<'_, P, N, N2> {
    /// `Ok` when a whole solve at (about) `dt` finishes with bounded energy, else why not.
    fn stable<X: Method>(&self, m: &X, mech: &P::Mech<f64>, dt: f64) -> Result<(), String> {
        let p = self.problem;
        let datum = p.energy_datum();
        let start = p.start();
        let e0 = energy(mech, datum.as_ref(), &start);
        let steps = (p.t_end() / dt).ceil().max(1.0) as u64;
        let param = Param::Step {
            dt: p.t_end() / steps as f64,
            steps,
        };
        let mut max_de: f64 = 0.0;
        let mut observe = |s: &State<f64, N>| {
            let de = (energy(mech, datum.as_ref(), &widen(s)) - e0).abs() / e0.abs();
            max_de = if de.is_nan() {
                f64::NAN
            } else {
                max_de.max(de)
            };
        };
        match m.solve(p, mech, &start, p.t_end(), param, Some(&mut observe)) {
            None => Err("not applicable".into()),
            Some(Err(e)) => Err(format!("error: {e}")),
            Some(Ok(_)) if max_de <= STABLE_ENERGY_ERROR => Ok(()),
            Some(Ok(_)) => Err(format!("finished, energy error {max_de:.1e}")),
        }
    }

    /// Scans `dt` upwards by doublings from `T / max_steps` to the first unstable run, then
    /// bisects (geometrically) between the last stable and the first unstable step.
    fn limit<X: Method>(&self, m: &X) -> Option<Limit> {
        let p = self.problem;
        let mech = p.mechanism::<f64>().ok()?;
        let (max_steps, bisections) = if self.opts.quick {
            (20_000.0, 4)
        } else {
            (200_000.0, 8)
        };
        let smallest = p.t_end() / max_steps;
        let largest = p.t_end() / 4.0;
        let mut good = None;
        let mut bad = None;
        let mut outcome = "stable at every step tried".to_string();
        let mut dt = smallest;
        while dt <= largest {
            match self.stable(m, &mech, dt) {
                Ok(()) => good = Some(dt),
                Err(e) if e == "not applicable" => return None,
                Err(e) => {
                    bad = Some(dt);
                    outcome = e;
                    break;
                }
            }
            dt *= 2.0;
        }
        if let (Some(mut g), Some(mut b)) = (good, bad) {
            for _ in 0..bisections {
                let mid = (g * b).sqrt();
                match self.stable(m, &mech, mid) {
                    Ok(()) => g = mid,
                    Err(e) => {
                        b = mid;
                        outcome = e;
                    }
                }
            }
            good = Some(g);
            bad = Some(b);
        }
        Some(Limit {
            problem: p.id(),
            method: m.name(),
            omega: p.fastest_frequency(),
            largest_stable: good,
            smallest_unstable: bad,
            smallest_tried: smallest,
            linear_limit: m.linear_stability_limit(),
            outcome,
        })
    }
}
