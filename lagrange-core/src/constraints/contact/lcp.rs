//! [`Delassus`]: the mass-weighted geometry `W = J M^-1 J^T` of a set of candidate rows, and
//! the exact solution of their linear complementarity problem, which both levels of the
//! event-driven contact law solve: the forces of the resting contacts (accelerations) and the
//! impulses of an impact (velocities).

use crate::constraints::schur::{cholesky, cholesky_solve};
use crate::nalgebra::{SMatrix, SVector};
use crate::{Error, Real};

/// The rows marked `candidate`, with `Y = M^-1 J^T` (one mass solve per candidate) and
/// `W = J Y`, built once and solved for as many subsets as the complementarity problem asks.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Delassus<T: Real, const N: usize, const C: usize> {
    jacobian: SMatrix<T, C, N>,
    mobility: SMatrix<T, N, C>,
    w: SMatrix<T, C, C>,
    candidate: [bool; C],
}

/// How a row of [`Delassus::complementary`] is held.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Row {
    /// `a >= 0`, `lambda >= 0`, `lambda a = 0`: a contact.
    Unilateral,
    /// `a = 0`, `lambda` of either sign; must not depend on the other such rows.
    Bilateral,
    /// `a = 0`, `lambda` of either sign, like a bilateral row, but left out where it depends
    /// on the rows held with it (a resting contact projected back onto zero).
    Held,
}

impl Row {
    /// `Bilateral` where `bilateral` is true, else `Unilateral`.
    pub(crate) fn kinds<const C: usize>(bilateral: &[bool; C]) -> [Self; C] {
        core::array::from_fn(|i| {
            if bilateral[i] {
                Self::Bilateral
            } else {
                Self::Unilateral
            }
        })
    }
}

/// A solution of [`Delassus::complementary`]: the multipliers (zero off the active rows) and
/// the rows that carry them.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Complementary<T: Real, const C: usize> {
    /// The multipliers (forces or impulses), zero on the rows not in `active`.
    pub(crate) lambda: SVector<T, C>,
    /// The rows in force: bilateral rows, and unilateral rows that push.
    pub(crate) active: [bool; C],
}

impl<T: Real, const N: usize, const C: usize> Delassus<T, N, C> {
    /// The candidate rows of `jacobian` (the others are zeroed), with `solve_mass` giving
    /// `M^-1 b`.
    ///
    /// # Errors
    /// `solve_mass`'s; [`Error::NonFiniteState`] when `W` is not finite.
    pub(crate) fn new<F>(
        jacobian: SMatrix<T, C, N>,
        mut solve_mass: F,
        candidate: &[bool; C],
    ) -> Result<Self, Error>
    where
        F: FnMut(&SVector<T, N>) -> Result<SVector<T, N>, Error>,
    {
        let mut jacobian = jacobian;
        let mut mobility = SMatrix::<T, N, C>::zeros();
        for (i, &on) in candidate.iter().enumerate() {
            if on {
                mobility.set_column(i, &solve_mass(&jacobian.row(i).transpose())?);
            } else {
                jacobian.row_mut(i).fill(T::zero());
            }
        }
        let w = jacobian * mobility;
        if !w.iter().all(|x| x.is_finite()) {
            return Err(Error::NonFiniteState);
        }
        Ok(Self {
            jacobian,
            mobility,
            w,
            candidate: *candidate,
        })
    }

    /// The Jacobian of the candidate rows (the others are zero).
    pub(crate) fn jacobian(&self) -> &SMatrix<T, C, N> {
        &self.jacobian
    }

    /// `M^-1 J^T lambda`.
    pub(crate) fn response(&self, lambda: &SVector<T, C>) -> SVector<T, N> {
        self.mobility * lambda
    }

    /// The multipliers `lambda` of the candidate rows for which `a = W lambda + b` is zero on
    /// the bilateral and held rows (see [`Row`]) and, on the unilateral ones, `lambda >= 0`, `a >= 0` and
    /// `lambda a = 0`: each unilateral row either pushes and holds (`a = 0`) or is free and
    /// opens (`a >= 0`), never pulls and never closes. With `b` the free accelerations of
    /// the rows (`J a0 + J'q'`) these are the contact forces; with `b` the velocities of the
    /// rows, the impulses of a plastic impact.
    ///
    /// The primal active-set method of the convex program `min lambda^T W lambda / 2 +
    /// b^T lambda` over `lambda_u >= 0`, from `lambda = 0` and every candidate active: the
    /// solve on the active rows; where a unilateral multiplier comes out negative, a step
    /// towards it as far as the multipliers stay non-negative, and the row that reached zero
    /// leaves; where every multiplier pushes, the row that would close fastest (`a` most
    /// negative) joins. Each step lowers the program's value, so the method ends, for a
    /// positive definite `W` in at most a few passes per row. A row that depends on the
    /// active ones (more contacts than the motion has freedoms: the others already hold it)
    /// cannot join them until one leaves.
    ///
    /// # Errors
    /// [`Error::RedundantConstraints`] when bilateral rows depend on each other (a held or
    /// unilateral row that depends on the others is left out instead);
    /// [`Error::NoConvergence`] after `4 C + 4` passes (a degenerate set that cycles);
    /// [`Error::NonFiniteState`] for non-finite multipliers.
    pub(crate) fn complementary(
        &self,
        b: &SVector<T, C>,
        kinds: &[Row; C],
    ) -> Result<Complementary<T, C>, Error> {
        let unilateral: [bool; C] =
            core::array::from_fn(|i| self.candidate[i] && kinds[i] == Row::Unilateral);
        let mut active = self.candidate;
        // Rows that could not join the active rows (dependent on them) until one leaves.
        let mut blocked = [false; C];
        let mut lambda = SVector::<T, C>::zeros();
        let passes = 4 * C + 4;
        for _ in 0..passes {
            let factor = match cholesky(&self.masked(&active)) {
                Ok(l) => l,
                Err(Error::RedundantConstraints { row })
                    if active[row] && kinds.get(row).is_some_and(|&k| k != Row::Bilateral) =>
                {
                    active[row] = false;
                    blocked[row] = true;
                    lambda[row] = T::zero();
                    continue;
                }
                Err(e) => return Err(e),
            };
            let x = cholesky_solve(&factor, &active, &(-b));
            // The step from lambda towards x, as far as no unilateral multiplier goes
            // negative; the row that stops it leaves.
            let mut stop: Option<(usize, T)> = None;
            for i in 0..C {
                if active[i] && unilateral[i] && x[i] < T::zero() {
                    let reach = lambda[i] / (lambda[i] - x[i]);
                    if stop.is_none_or(|(_, r)| reach < r) {
                        stop = Some((i, reach));
                    }
                }
            }
            if let Some((row, reach)) = stop {
                lambda += (x - lambda) * reach;
                lambda[row] = T::zero();
                active[row] = false;
                blocked = [false; C];
                continue;
            }
            lambda = x;
            // Every active row pushes: the free row that would close fastest joins.
            let a = self.w * lambda + b;
            let mut join: Option<(usize, T)> = None;
            for i in 0..C {
                let closing = a[i] < -self.slack(i, &lambda, b);
                let free = unilateral[i] && !active[i] && !blocked[i];
                if free && closing && join.is_none_or(|(_, worst)| a[i] < worst) {
                    join = Some((i, a[i]));
                }
            }
            match join {
                Some((row, _)) => active[row] = true,
                None if lambda.iter().all(|x| x.is_finite()) => {
                    return Ok(Complementary { lambda, active });
                }
                None => return Err(Error::NonFiniteState),
            }
        }
        Err(Error::NoConvergence {
            iterations: u32::try_from(passes).unwrap_or(u32::MAX),
        })
    }

    /// `W` on the `active` rows, the identity on the others (so that its factor solves the
    /// active rows alone).
    fn masked(&self, active: &[bool; C]) -> SMatrix<T, C, C> {
        SMatrix::from_fn(|i, j| match (active[i] && active[j], i == j) {
            (true, _) => self.w[(i, j)],
            (false, true) => T::one(),
            (false, false) => T::zero(),
        })
    }

    /// How far below zero row `i`'s `a = W lambda + b` may be and still count as zero: the
    /// rounding of its sum (64 ulps of the sizes of its terms), so that a row held at zero
    /// does not rejoin on the sign of rounding noise.
    fn slack(&self, i: usize, lambda: &SVector<T, C>, b: &SVector<T, C>) -> T {
        let size = (0..C).fold(b[i].abs(), |s, k| s + (self.w[(i, k)] * lambda[k]).abs());
        T::from_f64(64.0) * T::EPSILON * size
    }
}

#[cfg(test)]
mod tests {
    use super::{Delassus, Row};
    use crate::nalgebra::{SMatrix, SVector};
    use crate::Error;

    /// Two rows on one unit mass in the plane (so `W = J J^T`): a floor `y >= 0` and a wall
    /// `x >= 0` that meet at a corner, and a third row `x + y >= 0` that depends on both.
    fn corner() -> Result<Delassus<f64, 2, 3>, Error> {
        let j = SMatrix::<f64, 3, 2>::new(0.0, 1.0, 1.0, 0.0, 1.0, 1.0);
        Delassus::new(j, |b| Ok(*b), &[true; 3])
    }

    /// Pushed into the corner, both walls push and the dependent row is not needed; pulled
    /// away from the wall, only the floor pushes and the wall opens.
    #[test]
    fn complementarity_holds() -> Result<(), Error> {
        let d = corner()?;
        for b in [
            SVector::<f64, 3>::new(-1.0, -2.0, -3.0),
            SVector::<f64, 3>::new(-1.0, 2.0, 1.0),
            SVector::<f64, 3>::new(1.0, 2.0, 3.0),
            SVector::<f64, 3>::new(-3.0, -0.5, -1.0),
        ] {
            let s = d.complementary(&b, &[Row::Unilateral; 3])?;
            let a = d.w * s.lambda + b;
            for i in 0..3 {
                assert!(s.lambda[i] >= 0.0, "{b:?}: {s:?}");
                assert!(a[i] >= -1e-12, "{b:?}: a = {a:?}");
                assert!(
                    (s.lambda[i] * a[i]).abs() < 1e-12,
                    "{b:?}: {s:?}, a = {a:?}"
                );
            }
        }
        Ok(())
    }

    /// The greedy rule this replaced (drop the row that pulls hardest and solve again) let a
    /// dropped row close: here the floor alone, solved with the third row, pulls; dropped, the
    /// floor must come back. The exact solution has the floor push and the others free.
    #[test]
    fn a_dropped_row_rejoins_when_it_would_close() -> Result<(), Error> {
        let d = corner()?;
        let b = SVector::<f64, 3>::new(-1.0, 3.0, 1.0);
        let s = d.complementary(&b, &[Row::Unilateral; 3])?;
        let a = d.w * s.lambda + b;
        assert!(
            (s.lambda[0] - 1.0).abs() < 1e-15 && a[0].abs() < 1e-15,
            "{s:?}"
        );
        assert_eq!(s.active, [true, false, false]);
        Ok(())
    }

    /// A bilateral row holds whatever its multiplier's sign.
    #[test]
    fn bilateral_rows_hold_both_ways() -> Result<(), Error> {
        let d = corner()?;
        let b = SVector::<f64, 3>::new(1.0, -1.0, 0.0);
        let s = d.complementary(&b, &Row::kinds(&[true, false, false]))?;
        let a = d.w * s.lambda + b;
        assert!(s.lambda[0] < 0.0 && a[0].abs() < 1e-15, "{s:?}");
        assert!(a[1].abs() < 1e-15 && s.lambda[1] > 0.0, "{s:?}");
        Ok(())
    }
}
