//! [`Mixing`]: the secant step (Anderson mixing of depth one) between the rounds of a step's
//! solve, on the friction tangents' impulses.
//!
//! A round of [`Problem::solve`](super::solve::Problem::solve) maps the tangents it starts
//! from to the ones its sweep ends with: a fixed-point iteration whose fixed point is the
//! solve's answer. Where two sticking contacts couple their normals and tangents strongly
//! (a ragdoll landing on both feet) it converges linearly and slowly: each round shrank a
//! landing's change by 0.84 only, and such steps ended at any cap unsettled (12 rounds
//! allowed, 12 taken; 50 allowed, 50 taken). Solving the tangents exactly each round did
//! not help (the slow mode is the coupling of the two blocks, not the sweep), nor did one
//! exact solve of the normals and tangents together with the cone's bounds taken from the
//! round before (its rows doubled, each round cost several times as much, and the bounds
//! still moved from round to round).
//!
//! The secant step removes the slowest mode from the last two rounds' changes: with `x` the
//! tangents a round started from, `g` those it ended with and `f = g - x` its change, the
//! next round starts from `g - gamma (g - g_before)`, `gamma` the least-squares fit of `f`
//! by `f - f_before` (weighted in speed: each change times its row's inverse mass, as the
//! settle test measures them), clamped into the cone of the round's normals. For a mode
//! that shrinks by `rho` a round, `gamma = rho / (rho - 1)` and the step lands on its
//! limit. It costs `4 F` multiply-adds a round (`F` tangents); the rounds still end as
//! before (the cap, or a round whose first sweep changes nothing), so the answer is the
//! same fixed point and its guarantees (the cone, no energy gained) are untouched.
//! Measured on the example's thrown ragdoll and 17 other throws of it (1/240 s, 6 s
//! each): steps left unsettled 3,705 -> 2,302 in f64 (f32 3,699 -> 2,253) with 4 rounds a
//! solve, 1,871 -> 607 (1,771 -> 538) with 12; the example's throw alone 304 -> 209 with 4
//! and 172 -> 12 (177 -> 21) with 12. The mean step over the throws moved by at most 8%
//! either way (f64 at 4 rounds 1.69 -> 1.72 free RK4 steps; at 12, 1.89 -> 1.74).

use super::rows::{within, Direction};
use lagrange_core::Real;

/// `gamma`'s range: `rho / (rho - 1)` for a mode shrinking by `rho` in `(-1, 16 / 17)`
/// (down to -16: the slowest modes measured shrank by 0.84 a round, -5.25; up to 0.5: a
/// mode that flips sign each round). Beyond it a round's change is no contraction a secant
/// can be trusted with, and the step stops at the bound.
const GAMMA: (f64, f64) = (-16.0, 0.5);

/// The last round's tangents and their change in it, in speed (see the module's docs).
#[derive(Debug, Clone, Copy)]
pub(super) struct Mixing<T, const C: usize> {
    last: Option<([T; C], [T; C])>,
}

impl<T: Real, const C: usize> Mixing<T, C> {
    /// No round yet.
    pub(super) fn new() -> Self {
        Self { last: None }
    }

    /// A round started from the tangents `start` and its sweep ended at `end` (over the rows
    /// `listed`, their directions in `tangent`, each bounded by `bound(i)`): `end` replaced by
    /// the secant step from the round before, where there was one.
    pub(super) fn step<const N: usize>(
        &mut self,
        start: &[T; C],
        end: &mut [T; C],
        listed: &[usize],
        tangent: &[Option<Direction<T, N>>; C],
        bound: impl Fn(usize) -> T,
    ) {
        let rows = || {
            listed
                .iter()
                .map(|&i| within::<C>(i))
                .filter_map(|i| tangent[i].as_ref().map(|t| (i, t)))
        };
        let mut change = [T::zero(); C];
        for (i, t) in rows() {
            change[i] = (end[i] - start[i]) / t.inverse;
        }
        let ended = *end;
        if let Some((before, was)) = &self.last {
            let (mut fit, mut size) = (T::zero(), T::zero());
            for (i, _) in rows() {
                let d = change[i] - was[i];
                fit += d * change[i];
                size += d * d;
            }
            if size > T::zero() {
                let gamma = (fit / size)
                    .max(T::from_f64(GAMMA.0))
                    .min(T::from_f64(GAMMA.1));
                for (i, _) in rows() {
                    let b = bound(i);
                    end[i] = (ended[i] - gamma * (ended[i] - before[i])).max(-b).min(b);
                }
            }
        }
        self.last = Some((ended, change));
    }
}

#[cfg(test)]
mod tests {
    use super::{Direction, Mixing};
    use lagrange_core::nalgebra::SVector;

    /// Rounds that map the tangents `x -> rho x + c` (a mode that shrinks by `rho` a round):
    /// the first round has nothing to fit and is left alone; from the second the secant step
    /// lands on the limit `c / (1 - rho)`, to the rounding of a few operations on numbers
    /// of size 1 (1e-14), for a landing's slow mode (0.84), a fast one (0.3) and one that
    /// flips sign (-0.5); a bound below the limit stops it there.
    #[test]
    fn the_secant_step_lands_on_a_linear_modes_limit() {
        let direction = Direction {
            j: SVector::<f64, 1>::new(1.0),
            b: SVector::<f64, 1>::new(0.5),
            inverse: 2.0,
        };
        let tangent = [Some(direction), Some(direction), None];
        let c = [0.2, -0.1, 0.0];
        for (rho, bound) in [(0.84, 10.0), (0.3, 10.0), (-0.5, 10.0), (0.84, 0.5)] {
            let round = |x: &[f64; 3]| [rho * x[0] + c[0], rho * x[1] + c[1], 0.0];
            let mut mixing = Mixing::<f64, 3>::new();
            let start = [0.0; 3];
            let mut end = round(&start);
            let swept = end;
            mixing.step(&start, &mut end, &[0, 1], &tangent, |_| bound);
            assert_eq!(end, swept);
            let start = end;
            let mut end = round(&start);
            mixing.step(&start, &mut end, &[0, 1], &tangent, |_| bound);
            for i in 0..2 {
                let limit = (c[i] / (1.0 - rho)).clamp(-bound, bound);
                assert!(
                    (end[i] - limit).abs() <= 1e-14,
                    "rho {rho}, bound {bound}: {end:?}"
                );
            }
            assert_eq!(end[2], 0.0);
        }
    }
}
