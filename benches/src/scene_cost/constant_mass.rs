//! The constant-mass skip: ns per acceleration of a spring chain through the automatic path
//! with the skip (mass matrix factored once, `T` not differentiated) and without.

use lagrange_benches::timing::{median_of_runs, Budget};
use lagrange_cases::SpringChain;
use lagrange_core::{Error, EulerLagrange, Mechanism, Real, State};
use std::hint::black_box;

/// One chain length's figures.
#[derive(Debug, Clone)]
pub struct Skip {
    /// Masses in the chain.
    pub n: usize,
    /// `"f32"` or `"f64"`.
    pub scalar: &'static str,
    /// ns per acceleration with the skip.
    pub with: f64,
    /// ns per acceleration without it.
    pub without: f64,
    /// The largest difference of the two accelerations over the sampled states, in ulps of
    /// the acceleration's size.
    pub ulps: f64,
}

/// States evaluated per timed run.
const STATES: usize = 64;

/// The chain's masses and stiffnesses: all different, so no term cancels.
fn chain<T: Real, const N: usize, const CLAIM: bool>() -> SpringChain<T, N, CLAIM> {
    SpringChain {
        masses: core::array::from_fn(|i| T::from_f64(0.5 + 0.1 * i as f64)),
        stiffnesses: core::array::from_fn(|i| T::from_f64(2.0 + 0.7 * i as f64)),
    }
}

/// Deterministic, varied states.
fn states<T: Real, const N: usize>() -> Vec<State<T, N>> {
    (0..STATES)
        .map(|k| {
            let x = |i: usize, s: f64| T::from_f64(((k * 7 + i * 13) as f64 * s).sin());
            State::new(
                T::zero(),
                core::array::from_fn(|i| x(i, 0.37)),
                core::array::from_fn(|i| x(i, 0.91)),
            )
        })
        .collect()
}

/// ns per acceleration of `m` over `states`.
fn ns_per_acceleration<T: Real, const N: usize, M: Mechanism<T, N>>(
    budget: Budget,
    m: &M,
    states: &[State<T, N>],
) -> f64 {
    let (timing, _) = median_of_runs(budget, || {
        for s in states {
            let _ = black_box(m.acceleration(black_box(s)));
        }
    });
    timing.median * 1e9 / states.len() as f64
}

/// The figures for one `N` in one precision.
fn one<T: Real, const N: usize>(budget: Budget) -> Result<Skip, Error> {
    let skip = EulerLagrange::new(chain::<T, N, true>());
    let full = EulerLagrange::new(chain::<T, N, false>());
    let states = states::<T, N>();
    let mut ulps = 0.0f64;
    for s in &states {
        let (a, b) = (skip.acceleration(s)?, full.acceleration(s)?);
        let size = a.iter().fold(0.0f64, |m, x| m.max(x.abs().to_f64()));
        for (x, y) in a.iter().zip(b.iter()) {
            ulps = ulps.max((*x - *y).abs().to_f64() / (size * T::EPSILON.to_f64()));
        }
    }
    let out = Skip {
        n: N,
        scalar: lagrange_benches::precision::<T>(),
        with: ns_per_acceleration(budget, &skip, &states),
        without: ns_per_acceleration(budget, &full, &states),
        ulps,
    };
    println!(
        "N = {:>2} {}: {:>8.1} ns with the skip, {:>8.1} ns without ({:.1}x), {} ulps apart",
        out.n,
        out.scalar,
        out.with,
        out.without,
        out.without / out.with,
        out.ulps
    );
    Ok(out)
}

/// Every chain length in both precisions.
pub fn measure(budget: Budget) -> Result<Vec<Skip>, Error> {
    Ok(vec![
        one::<f64, 2>(budget)?,
        one::<f64, 5>(budget)?,
        one::<f64, 10>(budget)?,
        one::<f32, 2>(budget)?,
        one::<f32, 5>(budget)?,
        one::<f32, 10>(budget)?,
    ])
}
