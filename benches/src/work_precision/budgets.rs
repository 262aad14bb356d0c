//! The first budget of issue 5: the library's RK4 against the hand-written loop on the same
//! problem, step and precision, timed in interleaved pairs.

use super::method::{HandRk4, Library, Method, Param, Rk4Family};
use super::problem::{state_error, Problem, ProblemVisitor};
use super::real::{narrow, widen, BenchReal};
use super::timing::interleaved;
use super::Options;
use lagrange_core::State;
use std::hint::black_box;

/// The budget: the library's RK4 step within this factor of the hand-written loop's.
pub const RK4_BUDGET: f64 = 1.1;

/// One comparison.
#[derive(Debug, Clone)]
pub struct Rk4Ratio {
    /// Problem id.
    pub problem: &'static str,
    /// `"f32"` or `"f64"`.
    pub precision: &'static str,
    /// Step, s.
    pub dt: f64,
    /// Steps per solve.
    pub steps: u64,
    /// Library: median ns per step.
    pub library_ns: f64,
    /// Hand-written loop: median ns per step.
    pub hand_ns: f64,
    /// Library: fastest run's ns per step.
    pub library_min_ns: f64,
    /// Hand-written loop: fastest run's ns per step.
    pub hand_min_ns: f64,
    /// Median over the pairs of (library time / hand time).
    pub ratio: f64,
    /// Pairs timed.
    pub pairs: usize,
    /// Largest difference between the two final states (same arithmetic up to the order of
    /// operations, so rounding-level).
    pub max_difference: f64,
}

/// Every problem with a hand-written loop, f64 and f32.
pub fn rk4_against_hand(opts: &Options) -> Vec<Rk4Ratio> {
    let mut v = Compare {
        opts,
        out: Vec::new(),
    };
    super::problems::for_each(&mut v);
    v.out
}

/// Visits the problems.
struct Compare<'a> {
    opts: &'a Options,
    out: Vec<Rk4Ratio>,
}

impl ProblemVisitor for Compare<'_> {
    fn visit<P: Problem<N, N2>, const N: usize, const N2: usize>(&mut self, p: &P) {
        if !self.opts.selected(p.id())
            || !(self.opts.method_selected("RK4") || self.opts.method_selected("hand-written RK4"))
        {
            return;
        }
        for ratio in [
            self.compare::<f64, P, N, N2>(p),
            self.compare::<f32, P, N, N2>(p),
        ]
        .into_iter()
        .flatten()
        {
            println!(
                "   RK4 {} {}: library {:.1} ns/step, hand-written {:.1} ns/step, ratio {:.3} \
                 (median of {} pairs; budget {RK4_BUDGET})",
                ratio.problem,
                ratio.precision,
                ratio.library_ns,
                ratio.hand_ns,
                ratio.ratio,
                ratio.pairs
            );
            self.out.push(ratio);
        }
    }
}

impl Compare<'_> {
    /// Library RK4 against the hand loop on `p` in `T`; `None` without a hand loop.
    fn compare<T: BenchReal, P: Problem<N, N2>, const N: usize, const N2: usize>(
        &self,
        p: &P,
    ) -> Option<Rk4Ratio> {
        let start: State<T, N> = narrow(&p.start());
        let steps: u64 = if self.opts.quick { 10_000 } else { 100_000 };
        let pairs = if self.opts.quick { 5 } else { 41 };
        let dt = p.t_end() / steps as f64;
        let param = Param::Step { dt, steps };
        let t_end = T::real(p.t_end());
        let mech = p.mechanism::<T>().ok()?;
        let library = || {
            Library(Rk4Family)
                .solve(p, &mech, black_box(&start), t_end, param, None)
                .map(|r| r.map(|o| o.end))
        };
        let hand = || {
            HandRk4
                .solve(p, &mech, black_box(&start), t_end, param, None)
                .map(|r| r.map(|o| o.end))
        };
        let a = library()?.ok()?;
        let b = hand()?.ok()?;
        let max_difference = state_error(&widen(&a), &widen(&b));
        let (lib, hand_t, ratio) = interleaved(pairs, library, hand);
        let per_step = |s: f64| s * 1e9 / steps as f64;
        Some(Rk4Ratio {
            problem: p.id(),
            precision: T::LABEL,
            dt,
            steps,
            library_ns: per_step(lib.median),
            hand_ns: per_step(hand_t.median),
            library_min_ns: per_step(lib.min),
            hand_min_ns: per_step(hand_t.min),
            ratio,
            pairs,
            max_difference,
        })
    }
}
