//! Newton's method shared by every implicit integrator: unknowns in `S` blocks of `N`, a dense
//! LU factorisation with partial pivoting of the `S N` equations, simplified Newton with a
//! Jacobian refreshed when convergence slows, and a fixed-point start where that converges.

use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{all_finite, Error, Real};

/// How an implicit method iterates to solve its step equations.
///
/// The iteration stops when every unknown's update is at most `tolerance` times that
/// unknown's scale (its own size plus the size of the step's motion in it, as each method
/// documents), or when a Newton matrix factorised at most one iteration earlier no longer
/// halves an update that is already below `tolerance^(2/3)`: that is the rounding floor of
/// the residual, where the updates only bounce (nothing more can be had). After
/// `max_iterations` without either, the step fails with [`Error::NoConvergence`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct NewtonSettings<T> {
    tolerance: T,
    max_iterations: u32,
    /// `tolerance^(2/3)`, the largest update accepted as the rounding floor.
    floor: T,
}

/// Most iterations a caller may allow: beyond this a step that has not converged never will.
const MAX_ITERATIONS_CAP: u32 = 1000;

/// The default iteration limit: simplified Newton converges linearly with a rate of order
/// `h` times the change of the Jacobian over the step, a few iterations in practice.
const DEFAULT_MAX_ITERATIONS: u32 = 20;

/// The default tolerance, in machine epsilons: converged to rounding.
const DEFAULT_TOLERANCE_EPS: f64 = 8.0;

/// No unknown's scale is taken below this fraction of the largest one: an unknown that is
/// exactly zero still receives rounding from the others through the Newton matrix.
const WEIGHT_FLOOR: f64 = 1.0 / 1_048_576.0;

/// A contraction rate above this (the update shrinking by less than half) switches a
/// fixed-point iteration to Newton; for Newton with a fresh matrix it means the updates only
/// bounce (the rounding floor).
const SLOW_RATE: f64 = 0.5;

/// A Newton contraction rate above this with a matrix factorised in an earlier iteration
/// makes Newton factorise it anew at the current iterate (simplified Newton gone stale).
const REFRESH_RATE: f64 = 0.25;

/// Simplified Newton whose rate, kept up, would still need more than this many iterations to
/// reach the tolerance factorises its matrix anew too: a slow but steady contraction (a large
/// step over a law whose Jacobian changes fast along it) costs more iterations than a fresh
/// matrix, which restores Newton's quadratic convergence.
const STALE_ITERATIONS: i32 = 4;

/// Iterations Newton takes from where a fixed-point iteration gives way to it: a fixed point
/// too slow to converge with this many iterations to spare switches.
const NEWTON_ITERATIONS: u32 = 3;

impl<T: Real> NewtonSettings<T> {
    /// Relative `tolerance` (at least `EPSILON`, below 1) and at most `max_iterations`
    /// iterations per step (1 to 1000).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `tolerance` or `max_iterations` when out of range.
    pub fn new(tolerance: T, max_iterations: u32) -> Result<Self, Error> {
        if !(tolerance.is_finite() && tolerance >= T::EPSILON && tolerance < T::one()) {
            return Err(Error::InvalidParameter {
                name: "tolerance",
                reason: "must be at least machine epsilon and below 1",
            });
        }
        if !(1..=MAX_ITERATIONS_CAP).contains(&max_iterations) {
            return Err(Error::InvalidParameter {
                name: "max_iterations",
                reason: "must be from 1 to 1000",
            });
        }
        Ok(Self::unchecked(tolerance, max_iterations))
    }

    /// The settings, with the floor derived from the tolerance.
    fn unchecked(tolerance: T, max_iterations: u32) -> Self {
        Self {
            tolerance,
            max_iterations,
            floor: tolerance.powf(T::from_f64(2.0 / 3.0)),
        }
    }

    /// The relative tolerance.
    #[must_use]
    pub fn tolerance(&self) -> T {
        self.tolerance
    }

    /// The iteration limit per step.
    #[must_use]
    pub fn max_iterations(&self) -> u32 {
        self.max_iterations
    }
}

impl<T: Real> Default for NewtonSettings<T> {
    /// Tolerance `8 EPSILON` (converged to rounding), at most 20 iterations.
    fn default() -> Self {
        Self::unchecked(
            T::from_f64(DEFAULT_TOLERANCE_EPS) * T::EPSILON,
            DEFAULT_MAX_ITERATIONS,
        )
    }
}

/// The unknowns of an implicit step: `S` vectors of `N` (stages, or one vector).
pub(crate) type Blocks<T, const N: usize, const S: usize> = [SVector<T, N>; S];

/// An `S N x S N` matrix stored as `S x S` blocks of `N x N`, so that its size needs no
/// arithmetic on const generics.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BlockMatrix<T: Real, const N: usize, const S: usize>(
    pub [[SMatrix<T, N, N>; S]; S],
);

impl<T: Real, const N: usize, const S: usize> BlockMatrix<T, N, S> {
    /// The matrix whose block `(i, j)` is `f(i, j)`.
    pub fn from_blocks(mut f: impl FnMut(usize, usize) -> SMatrix<T, N, N>) -> Self {
        Self(core::array::from_fn(|i| core::array::from_fn(|j| f(i, j))))
    }

    /// Entry `(r, c)` of the flattened matrix (`r, c < S N`).
    ///
    /// The block indices are taken `% S`, a no-op for indices in range, so that the optimiser
    /// sees them in bounds and drops the checks (the panic-free firmware image links only
    /// without them); likewise in [`flat`] and [`Lu::solve`].
    fn at(&self, r: usize, c: usize) -> T {
        self.0[(r / N) % S][(c / N) % S][(r % N, c % N)]
    }

    /// Entry `(r, c)` of the flattened matrix, to write.
    fn at_mut(&mut self, r: usize, c: usize) -> &mut T {
        &mut self.0[(r / N) % S][(c / N) % S][(r % N, c % N)]
    }
}

/// `x[r]` of the flattened unknowns.
fn flat<T: Real, const N: usize, const S: usize>(x: &Blocks<T, N, S>, r: usize) -> T {
    x[(r / N) % S][r % N]
}

/// `x[r]` of the flattened unknowns, to write.
fn flat_mut<T: Real, const N: usize, const S: usize>(x: &mut Blocks<T, N, S>, r: usize) -> &mut T {
    &mut x[(r / N) % S][r % N]
}

/// The largest absolute entry.
pub(crate) fn max_abs<T: Real, const N: usize, const S: usize>(x: &Blocks<T, N, S>) -> T {
    x.iter()
        .flat_map(|v| v.iter())
        .fold(T::zero(), |m, v| m.max(v.abs()))
}

/// `max_i |dx_i| / w_i`, each weight floored at [`WEIGHT_FLOOR`] times the largest and at
/// `MIN_POSITIVE / EPSILON`: an unknown decaying into the subnormal range (a damped stiff
/// mode) has no relative precision left, and an update there counts as converged.
fn weighted_size<T: Real, const N: usize, const S: usize>(
    dx: &Blocks<T, N, S>,
    w: &Blocks<T, N, S>,
) -> T {
    let floor = (max_abs(w) * T::from_f64(WEIGHT_FLOOR)).max(T::MIN_POSITIVE / T::EPSILON);
    dx.iter()
        .flat_map(|v| v.iter())
        .zip(w.iter().flat_map(|v| v.iter()))
        .fold(T::zero(), |m, (d, wi)| m.max(d.abs() / wi.abs().max(floor)))
}

/// True unless `x <= limit`: NaN exceeds every limit.
fn exceeds<T: Real>(x: T, limit: T) -> bool {
    !matches!(
        x.partial_cmp(&limit),
        Some(core::cmp::Ordering::Less | core::cmp::Ordering::Equal)
    )
}

/// True when every entry is finite.
fn all_blocks_finite<T: Real, const N: usize, const S: usize>(x: &Blocks<T, N, S>) -> bool {
    x.iter().all(|v| all_finite(v.as_slice()))
}

/// An LU factorisation `P A = L U` with partial pivoting.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Lu<T: Real, const N: usize, const S: usize> {
    lu: BlockMatrix<T, N, S>,
    /// The row swapped with row `k` at elimination step `k`, flattened like the unknowns.
    pivots: [[usize; N]; S],
}

impl<T: Real, const N: usize, const S: usize> Lu<T, N, S> {
    /// Factorises `a`.
    ///
    /// # Errors
    /// [`Error::NonFiniteState`] when `a` holds NaN or infinity; [`Error::SingularJacobian`]
    /// when a pivot column is zero.
    pub fn factor(mut a: BlockMatrix<T, N, S>) -> Result<Self, Error> {
        let n = N * S;
        if !a.0.iter().flatten().all(|b| all_finite(b.as_slice())) {
            return Err(Error::NonFiniteState);
        }
        let mut pivots = [[0; N]; S];
        for k in 0..n {
            let mut p = k;
            let mut best = a.at(k, k).abs();
            for r in k + 1..n {
                let v = a.at(r, k).abs();
                if v > best {
                    best = v;
                    p = r;
                }
            }
            if best == T::zero() {
                return Err(Error::SingularJacobian);
            }
            pivots[k / N][k % N] = p;
            if p != k {
                for c in 0..n {
                    let tmp = a.at(k, c);
                    *a.at_mut(k, c) = a.at(p, c);
                    *a.at_mut(p, c) = tmp;
                }
            }
            let pivot = a.at(k, k);
            for r in k + 1..n {
                let l = a.at(r, k) / pivot;
                *a.at_mut(r, k) = l;
                if l != T::zero() {
                    for c in k + 1..n {
                        let u = a.at(k, c);
                        *a.at_mut(r, c) -= l * u;
                    }
                }
            }
        }
        Ok(Self { lu: a, pivots })
    }

    /// Solves `A x = b`.
    pub fn solve(&self, b: &Blocks<T, N, S>) -> Blocks<T, N, S> {
        let n = N * S;
        let mut x = *b;
        for k in 0..n {
            // `p < n` by construction; `min` says so to the optimiser, which then drops the
            // bounds checks of `flat` (the panic-free firmware image links only without them).
            let p = self.pivots[(k / N) % S][k % N].min(n - 1);
            if p != k {
                let tmp = flat(&x, k);
                *flat_mut(&mut x, k) = flat(&x, p);
                *flat_mut(&mut x, p) = tmp;
            }
        }
        for r in 0..n {
            let mut s = flat(&x, r);
            for c in 0..r {
                s -= self.lu.at(r, c) * flat(&x, c);
            }
            *flat_mut(&mut x, r) = s;
        }
        for r in (0..n).rev() {
            let mut s = flat(&x, r);
            for c in r + 1..n {
                s -= self.lu.at(r, c) * flat(&x, c);
            }
            *flat_mut(&mut x, r) = s / self.lu.at(r, r);
        }
        x
    }
}

/// The equations of one implicit step, `residual(x) = 0`.
pub(crate) trait NewtonProblem<T: Real, const N: usize, const S: usize> {
    /// The residual at `x`. For a problem started by fixed-point iteration it must have the
    /// form `x - phi(x)`, so that `x - residual(x)` is the fixed-point update.
    fn residual(&mut self, x: &Blocks<T, N, S>) -> Result<Blocks<T, N, S>, Error>;

    /// The residual's Jacobian (exact or approximate) at `x`; called only right after
    /// [`NewtonProblem::residual`] at the same `x`, so it may reuse work done there.
    fn newton_matrix(&mut self, x: &Blocks<T, N, S>) -> Result<BlockMatrix<T, N, S>, Error>;

    /// Each unknown's scale at `x`, that the tolerance is relative to.
    fn weights(&self, x: &Blocks<T, N, S>) -> Blocks<T, N, S>;
}

/// Where the iteration starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Start {
    /// Newton from the first iteration.
    Newton,
    /// Fixed-point iteration `x <- x - residual(x)` while it contracts at least by half per
    /// iteration, Newton from the first iteration where it does not.
    FixedPoint,
}

/// Solves `problem` from the guess `x`, in place; returns the iterations used.
///
/// # Errors
/// [`Error::NoConvergence`] after `settings.max_iterations`; [`Error::NonFiniteState`] when a
/// residual, Jacobian or iterate is not finite; [`Error::SingularJacobian`]; whatever the
/// problem's evaluations return.
pub(crate) fn solve<T, P, const N: usize, const S: usize>(
    problem: &mut P,
    x: &mut Blocks<T, N, S>,
    settings: &NewtonSettings<T>,
    start: Start,
) -> Result<u32, Error>
where
    T: Real,
    P: NewtonProblem<T, N, S>,
{
    let slow = T::from_f64(SLOW_RATE);
    let refresh = T::from_f64(REFRESH_RATE);
    let floor = settings.floor;
    let mut fixed_point = start == Start::FixedPoint;
    let mut lu: Option<Lu<T, N, S>> = None;
    // Iterations since the Newton matrix in use was factorised (0: in this one).
    let mut age = 0u32;
    let mut previous: Option<T> = None;
    for iteration in 1..=settings.max_iterations {
        let r = problem.residual(x)?;
        if !all_blocks_finite(&r) {
            return Err(Error::NonFiniteState);
        }
        let dx = if fixed_point {
            r
        } else {
            let factored = match lu {
                Some(f) => {
                    age += 1;
                    f
                }
                None => {
                    age = 0;
                    Lu::factor(problem.newton_matrix(x)?)?
                }
            };
            lu = Some(factored);
            factored.solve(&r)
        };
        for (xi, di) in x.iter_mut().zip(dx.iter()) {
            *xi -= di;
        }
        if !all_blocks_finite(x) {
            return Err(Error::NonFiniteState);
        }
        let size = weighted_size(&dx, &problem.weights(x));
        if size <= settings.tolerance {
            return Ok(iteration);
        }
        if let Some(prev) = previous {
            // A NaN rate counts as slow.
            let rate = size / prev;
            if fixed_point {
                // Too slow, or steady but not fast enough to reach the tolerance within the
                // iterations left less the few Newton would need (a heavily damped kick
                // contracting by 0.25 needs 20 of them): Newton from here.
                let left = settings
                    .max_iterations
                    .saturating_sub(iteration + NEWTON_ITERATIONS);
                let left = i32::try_from(left).unwrap_or(i32::MAX);
                if exceeds(rate, slow) || rate.powi(left) > settings.tolerance / size {
                    fixed_point = false;
                }
            } else if age <= 1 && size <= floor && exceeds(rate, slow) {
                return Ok(iteration);
            } else if age >= 1
                && (exceeds(rate, refresh)
                    || rate.powi(STALE_ITERATIONS) > settings.tolerance / size)
            {
                lu = None;
            }
        }
        previous = Some(size);
    }
    Err(Error::NoConvergence {
        iterations: settings.max_iterations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use lagrange_core::nalgebra::{Matrix2, Vector2};

    /// The LU solve of a block system that needs a row swap across blocks.
    #[test]
    fn lu_solves_with_pivoting_across_blocks() -> Result<(), Error> {
        // Flattened 4x4: [[0,1,2,0],[1,0,0,1],[3,0,1,0],[0,2,0,1]]
        let m = BlockMatrix::<f64, 2, 2>([
            [
                Matrix2::new(0.0, 1.0, 1.0, 0.0),
                Matrix2::new(2.0, 0.0, 0.0, 1.0),
            ],
            [
                Matrix2::new(3.0, 0.0, 0.0, 2.0),
                Matrix2::new(1.0, 0.0, 0.0, 1.0),
            ],
        ]);
        let x = [Vector2::new(1.0, -2.0), Vector2::new(0.5, 3.0)];
        // b = M x, by hand.
        let b = [
            Vector2::new(-2.0 + 1.0, 1.0 + 3.0),
            Vector2::new(3.0 + 0.5, -4.0 + 3.0),
        ];
        let solved = Lu::factor(m)?.solve(&b);
        for (s, e) in solved.iter().zip(x.iter()) {
            assert!(max_abs(&[s - e]) < 1e-14, "{s} vs {e}");
        }
        Ok(())
    }

    #[test]
    fn singular_and_non_finite_matrices_are_reported() {
        let singular = BlockMatrix::<f64, 2, 1>([[Matrix2::new(1.0, 2.0, 2.0, 4.0)]]);
        assert!(matches!(Lu::factor(singular), Err(Error::SingularJacobian)));
        let nan = BlockMatrix::<f64, 2, 1>([[Matrix2::new(1.0, f64::NAN, 0.0, 1.0)]]);
        assert!(matches!(Lu::factor(nan), Err(Error::NonFiniteState)));
    }

    /// `x^2 = 2` from `x = 1` by Newton, and by fixed-point on `x = x - (x^2 - 2) / 3`,
    /// which contracts.
    struct Sqrt2;
    impl NewtonProblem<f64, 1, 1> for Sqrt2 {
        fn residual(&mut self, x: &Blocks<f64, 1, 1>) -> Result<Blocks<f64, 1, 1>, Error> {
            Ok([x[0].map(|v| (v * v - 2.0) / 3.0)])
        }
        fn newton_matrix(
            &mut self,
            x: &Blocks<f64, 1, 1>,
        ) -> Result<BlockMatrix<f64, 1, 1>, Error> {
            Ok(BlockMatrix([[x[0].map(|v| 2.0 * v / 3.0)]]))
        }
        fn weights(&self, x: &Blocks<f64, 1, 1>) -> Blocks<f64, 1, 1> {
            [x[0].map(f64::abs)]
        }
    }

    #[test]
    fn newton_and_fixed_point_reach_rounding() -> Result<(), Error> {
        for start in [Start::Newton, Start::FixedPoint] {
            let mut x = [SVector::<f64, 1>::new(1.0)];
            let iterations = solve(&mut Sqrt2, &mut x, &NewtonSettings::default(), start)?;
            assert!((x[0][0] - core::f64::consts::SQRT_2).abs() <= 4.0 * f64::EPSILON);
            // Measured: 12 (simplified Newton, its matrix refreshed once) and 13 (fixed
            // point, contracting by 0.057 per iteration).
            assert!(iterations <= 14, "{start:?}: {iterations}");
        }
        Ok(())
    }

    /// `c (x - 1) = 0` from `x = 0`: fixed-point iteration contracts by `1 - c` per
    /// iteration (Newton solves it in one); counts the Newton matrices asked for.
    struct Linear {
        c: f64,
        matrices: u32,
    }
    impl NewtonProblem<f64, 1, 1> for Linear {
        fn residual(&mut self, x: &Blocks<f64, 1, 1>) -> Result<Blocks<f64, 1, 1>, Error> {
            Ok([x[0].map(|v| self.c * (v - 1.0))])
        }
        fn newton_matrix(
            &mut self,
            _x: &Blocks<f64, 1, 1>,
        ) -> Result<BlockMatrix<f64, 1, 1>, Error> {
            self.matrices += 1;
            Ok(BlockMatrix([[SMatrix::<f64, 1, 1>::new(self.c)]]))
        }
        fn weights(&self, x: &Blocks<f64, 1, 1>) -> Blocks<f64, 1, 1> {
            [x[0].map(f64::abs)]
        }
    }

    /// A fixed-point iteration that would not reach the tolerance within the limit (20),
    /// contracting by 0.7 or 0.4 (its weighted rate at the second iteration 0.41 and 0.29:
    /// below the half that switches at once, but too slow to finish), gives way to Newton at
    /// its second iteration: one matrix, and the linear problem is solved at the fourth. One
    /// that contracts by 0.1 or 0.05 finishes alone (about 16 and 12 iterations), without a
    /// matrix.
    #[test]
    fn fixed_point_gives_way_to_newton_only_when_too_slow() -> Result<(), Error> {
        for (c, matrices) in [(0.3, 1), (0.6, 1), (0.9, 0), (0.95, 0)] {
            let mut problem = Linear { c, matrices: 0 };
            let mut x = [SVector::<f64, 1>::new(0.0)];
            let settings = NewtonSettings::default();
            let iterations = solve(&mut problem, &mut x, &settings, Start::FixedPoint)?;
            assert!(
                (x[0][0] - 1.0).abs() <= 4.0 * f64::EPSILON,
                "c = {c}: {x:?}"
            );
            assert_eq!(problem.matrices, matrices, "c = {c}");
            if matrices == 1 {
                assert_eq!(iterations, 4, "c = {c}");
            }
        }
        Ok(())
    }

    /// The convergence measure: an unknown whose scale is zero is measured against 2^-20 of
    /// the largest scale, and when every scale is zero against `MIN_POSITIVE / EPSILON`.
    #[test]
    fn weighted_size_floors_the_scales() {
        let dx = [Vector2::new(1e-3, 1e-3)];
        let w = [Vector2::new(1.0, 0.0)];
        assert_eq!(weighted_size(&dx, &w), 1e-3 * 1_048_576.0);
        let w = [Vector2::new(2.0, -4.0)];
        assert_eq!(weighted_size(&dx, &w), 1e-3 / 2.0);
        let zero = [Vector2::new(0.0, 0.0)];
        assert_eq!(
            weighted_size(&dx, &zero),
            1e-3 / (f64::MIN_POSITIVE / f64::EPSILON)
        );
    }

    /// `x = x - (x^2 - 2) / 3` whose residual is NaN past `x = 1.2`: the iteration stops with
    /// `NonFiniteState` at the first NaN, by Newton and by fixed point, not after its limit.
    struct Poisoned(u32);
    impl NewtonProblem<f64, 1, 1> for Poisoned {
        fn residual(&mut self, x: &Blocks<f64, 1, 1>) -> Result<Blocks<f64, 1, 1>, Error> {
            self.0 += 1;
            let [r] = Sqrt2.residual(x)?;
            Ok([r.zip_map(&x[0], |r, v| if v > 1.2 { f64::NAN } else { r })])
        }
        fn newton_matrix(
            &mut self,
            x: &Blocks<f64, 1, 1>,
        ) -> Result<BlockMatrix<f64, 1, 1>, Error> {
            Sqrt2.newton_matrix(x)
        }
        fn weights(&self, x: &Blocks<f64, 1, 1>) -> Blocks<f64, 1, 1> {
            Sqrt2.weights(x)
        }
    }

    #[test]
    fn a_non_finite_residual_stops_the_iteration() {
        for start in [Start::Newton, Start::FixedPoint] {
            let mut problem = Poisoned(0);
            let mut x = [SVector::<f64, 1>::new(1.0)];
            assert_eq!(
                solve(&mut problem, &mut x, &NewtonSettings::default(), start),
                Err(Error::NonFiniteState),
                "{start:?}"
            );
            assert!(problem.0 <= 3, "{start:?}: {} residuals", problem.0);
        }
    }

    #[test]
    fn iteration_cap_gives_no_convergence() -> Result<(), Error> {
        let mut x = [SVector::<f64, 1>::new(1.0)];
        let settings = NewtonSettings::new(f64::EPSILON, 2)?;
        assert_eq!(
            solve(&mut Sqrt2, &mut x, &settings, Start::Newton),
            Err(Error::NoConvergence { iterations: 2 })
        );
        Ok(())
    }

    #[test]
    fn settings_are_validated() {
        for bad in [0.0, 1e-20, 1.0, f64::NAN, -1e-3] {
            assert!(matches!(
                NewtonSettings::new(bad, 10),
                Err(Error::InvalidParameter {
                    name: "tolerance",
                    ..
                })
            ));
        }
        for bad in [0, 1001] {
            assert!(matches!(
                NewtonSettings::new(1e-12, bad),
                Err(Error::InvalidParameter {
                    name: "max_iterations",
                    ..
                })
            ));
        }
    }
}
