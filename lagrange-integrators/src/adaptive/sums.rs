//! Weighted sums of the stage derivatives, the arithmetic every adaptive pair's stages, error
//! estimate and dense output are made of.

use lagrange_core::nalgebra::SVector;
use lagrange_core::Real;

/// `x` in the integrator's scalar.
pub(super) fn real<T: Real>(x: f64) -> T {
    T::from_f64(x)
}

/// The cubic Hermite part of a dense output: `(y1 - y0, c3, c4)`.
pub(super) type Hermite<T, const N: usize> = [SVector<T, N>; 3];

/// `sum_j w_j k_ji` for component `i`, over the first `w.len()` stages with a non-zero
/// weight, in stage order: `((0 + k_0i w_0) + k_1i w_1) + ...`.
///
/// Always inlined: where `w` is a row of the pair's constant tableau at a constant index (the
/// stages of a step: `run_stages!` in `embedded.rs`), the loop over the stages unrolls and
/// the zero weights fold away, as in a hand-written stage; the callers' loops over the
/// components then vectorise, each sum staying in a register and each stage read once.
#[inline(always)]
pub(super) fn stage_sum<T: Real, const N: usize>(w: &[f64], k: &[SVector<T, N>], i: usize) -> T {
    let mut acc = T::zero();
    for (wj, kj) in w.iter().zip(k) {
        if *wj != 0.0 {
            acc += kj.as_slice()[i] * real::<T>(*wj);
        }
    }
    acc
}

/// `sum_j w_j k_j` over the first `w.len()` stages with a non-zero weight ([`stage_sum`] for
/// every component).
#[inline(always)]
pub(super) fn combine<T: Real, const N: usize>(w: &[f64], k: &[SVector<T, N>]) -> SVector<T, N> {
    let mut sum = SVector::<T, N>::zeros();
    for (i, s) in sum.as_mut_slice().iter_mut().enumerate() {
        *s = stage_sum(w, k, i);
    }
    sum
}

/// `out = y + (sum_j w_j k_j) h`, component by component, in place: the same arithmetic as
/// `y + combine(w, k) * h`, without the sum as a vector of its own. (A sum built as a vector,
/// through nalgebra's `from_fn` or by adding a whole stage at a time, and then added to `y`,
/// cost two thirds of a DOP853 step of a 14-coordinate N-body: the closure was not inlined
/// there, and stage by stage every partial sum went through memory.)
#[inline(always)]
pub(super) fn step_into<T: Real, const N: usize>(
    out: &mut SVector<T, N>,
    y: &SVector<T, N>,
    w: &[f64],
    k: &[SVector<T, N>],
    h: T,
) {
    for (i, (o, yi)) in out.as_mut_slice().iter_mut().zip(y.as_slice()).enumerate() {
        *o = *yi + stage_sum(w, k, i) * h;
    }
}
