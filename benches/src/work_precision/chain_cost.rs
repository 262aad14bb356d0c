//! The third budget of issue 5: the chain's cost per step against its length N, with the
//! fitted exponent, split into assembling `M` and `f` and solving `M q'' = f`.

use super::problems::p3_chain::chain;
use super::timing::{median_of_runs, Budget};
use super::work_precision::log_log_slope;
use super::Options;
use lagrange_core::{solve_spd, EulerLagrange, Mechanism, State};
use lagrange_integrators::{Integrator, Rk4};
use std::hint::black_box;

/// The cost at one N.
#[derive(Debug, Clone, Copy)]
pub struct ChainPoint {
    /// Links.
    pub n: usize,
    /// One RK4 step, ns (median).
    pub ns_per_step: f64,
    /// Assembling `M` and `f` once, ns.
    pub ns_assembly: f64,
    /// Solving `M x = f` once by the library's fixed-size Cholesky, ns.
    pub ns_solve: f64,
    /// One RK4 step through the automatic Euler-Lagrange path on the chain's Lagrangian, ns.
    pub ns_per_step_automatic: f64,
}

/// The costs and their fitted exponents.
#[derive(Debug, Clone)]
pub struct ChainCost {
    /// Which mechanism was timed.
    pub mechanism: &'static str,
    /// One point per N.
    pub points: Vec<ChainPoint>,
    /// Slope of log(cost per step) against log N, over all points.
    pub exponent_step: f64,
    /// The same over N >= 8 (where fixed per-step overheads no longer dominate).
    pub exponent_step_large: f64,
    /// Slope for the assembly alone.
    pub exponent_assembly: f64,
    /// Slope for the solve alone.
    pub exponent_solve: f64,
    /// Slope for the automatic path's step.
    pub exponent_automatic: f64,
}

/// Times the chain at N = 2 ... 20.
pub fn measure(opts: &Options) -> ChainCost {
    if !opts.selected("P3") || !opts.method_selected("RK4") {
        return ChainCost {
            mechanism: "",
            points: Vec::new(),
            exponent_step: f64::NAN,
            exponent_step_large: f64::NAN,
            exponent_assembly: f64::NAN,
            exponent_solve: f64::NAN,
            exponent_automatic: f64::NAN,
        };
    }
    let b = if opts.quick {
        Budget {
            seconds: 0.01,
            min_runs: 3,
            max_runs: 5,
        }
    } else {
        Budget {
            seconds: 0.1,
            min_runs: 5,
            max_runs: 21,
        }
    };
    let points = vec![
        point::<2>(b),
        point::<3>(b),
        point::<4>(b),
        point::<5>(b),
        point::<6>(b),
        point::<8>(b),
        point::<10>(b),
        point::<12>(b),
        point::<16>(b),
        point::<20>(b),
    ];
    let slope = |f: fn(&ChainPoint) -> f64, min_n: usize| {
        let pts: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| p.n >= min_n)
            .map(|p| (p.n as f64, f(p)))
            .collect();
        log_log_slope(&pts)
    };
    let cost = ChainCost {
        mechanism: "NLinkPendulum (hand-derived: its acceleration solves for the rod tensions, \
                    a tridiagonal system, in O(N); the assembly and solve columns time the \
                    general route, M and f in O(N^2) and a fixed-size Cholesky solve)",
        exponent_step: slope(|p| p.ns_per_step, 2),
        exponent_step_large: slope(|p| p.ns_per_step, 8),
        exponent_assembly: slope(|p| p.ns_assembly, 2),
        exponent_solve: slope(|p| p.ns_solve, 2),
        exponent_automatic: slope(|p| p.ns_per_step_automatic, 2),
        points,
    };
    println!(
        "   chain cost per RK4 step ~ N^{:.2} (N >= 8: N^{:.2}); assembly ~ N^{:.2}, solve ~ \
         N^{:.2}; automatic path ~ N^{:.2}",
        cost.exponent_step,
        cost.exponent_step_large,
        cost.exponent_assembly,
        cost.exponent_solve,
        cost.exponent_automatic
    );
    cost
}

/// The chain of `N` links at 45 degrees, moving (so no term vanishes).
fn chain_state<const N: usize>() -> State<f64, N> {
    State::new(0.0, [std::f64::consts::FRAC_PI_4; N], [0.3; N])
}

/// Costs at one `N` (`NaN` where the chain could not be built, which its fixed parameters
/// rule out).
fn point<const N: usize>(b: Budget) -> ChainPoint {
    let ns = |secs: f64, count: u64| secs * 1e9 / count as f64;
    let Ok(m) = chain::<f64, N>() else {
        return ChainPoint {
            n: N,
            ns_per_step: f64::NAN,
            ns_assembly: f64::NAN,
            ns_solve: f64::NAN,
            ns_per_step_automatic: f64::NAN,
        };
    };
    let s = chain_state::<N>();
    // About 1 ms per timed run at any N: fewer steps for longer chains.
    let steps = (100_000 / (N * N) as u64).max(20);
    let (step, _) = median_of_runs(b, || Rk4.integrate(&m, black_box(&s), 1e-3, steps));
    let reps = steps * 4;
    let (assembly, _) = median_of_runs(b, || {
        for _ in 0..reps {
            black_box((m.mass_matrix(black_box(&s)), m.rhs(black_box(&s))));
        }
    });
    let (mm, f) = (m.mass_matrix(&s), m.rhs(&s));
    let (solve, _) = median_of_runs(b, || {
        for _ in 0..reps {
            let _ = black_box(solve_spd(black_box(&mm), black_box(&f)));
        }
    });
    // The automatic path costs O(N^3) and more per evaluation: fewer steps still.
    let auto = EulerLagrange::new(m);
    let auto_steps = (steps / N as u64).max(4);
    let (automatic, _) =
        median_of_runs(b, || Rk4.integrate(&auto, black_box(&s), 1e-3, auto_steps));
    ChainPoint {
        n: N,
        ns_per_step: ns(step.median, steps),
        ns_assembly: ns(assembly.median, reps),
        ns_solve: ns(solve.median, reps),
        ns_per_step_automatic: ns(automatic.median, auto_steps),
    }
}
