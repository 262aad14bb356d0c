//! [`Delassus`]: the mass-weighted geometry `W = J M^-1 J^T` of a set of candidate rows, and
//! the exact solution of their linear complementarity problem: the forces of resting contacts
//! (at the acceleration level), the impulses of an impact or of a time step (at the velocity
//! level), a projection's displacements (at the position level).

use crate::nalgebra::{SMatrix, SVector};
use crate::{Error, Real};

/// How a row of [`Delassus::complementary`] is held.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Row {
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
    #[must_use]
    pub fn kinds<const C: usize>(bilateral: &[bool; C]) -> [Self; C] {
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
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Complementary<T: Real, const C: usize> {
    /// The multipliers (forces, impulses or displacements), zero on the rows not in `active`.
    pub lambda: SVector<T, C>,
    /// The rows in force: bilateral rows, and unilateral rows that push.
    pub active: [bool; C],
}

/// The rows of a set marked as candidates, with their mobilities `Y = M^-1 J^T` (one mass
/// solve per candidate) and `W = J Y` over the candidates, built once and solved for as many
/// subsets as the complementarity problem asks. Work: `R` mass solves and `R^2 N` for `W`
/// (`R` candidates), then per pass of [`Delassus::complementary`] a Cholesky factorisation
/// of the active rows (at most `R^3 / 6`).
#[derive(Debug, Clone, Copy)]
pub struct Delassus<T: Real, const N: usize, const C: usize> {
    jacobian: SMatrix<T, C, N>,
    mobility: SMatrix<T, N, C>,
    w: SMatrix<T, C, C>,
    /// The Cholesky factor of the active rows, `factor[(p, q)]` for positions `q <= p` in
    /// the active set (scratch, kept so that a solve does not clear `C^2` numbers a pass).
    factor: SMatrix<T, C, C>,
    candidate: [bool; C],
}

impl<T: Real, const N: usize, const C: usize> Delassus<T, N, C> {
    /// The rows of `jacobian` marked `candidate` (the others are zeroed), with `mobility_of`
    /// giving the velocity changes of the columns of `J^T` (the generalized impulses of unit
    /// row impulses; zero columns for the other rows): [`Mechanism::velocity_jumps`], or
    /// [`each_column`] of a mass solve.
    ///
    /// [`Mechanism::velocity_jumps`]: crate::Mechanism::velocity_jumps
    ///
    /// # Errors
    /// `mobility_of`'s; [`Error::NonFiniteState`] when `W` is not finite.
    pub fn new<F>(
        jacobian: SMatrix<T, C, N>,
        mobility_of: F,
        candidate: &[bool; C],
    ) -> Result<Self, Error>
    where
        F: FnOnce(&SMatrix<T, N, C>) -> Result<SMatrix<T, N, C>, Error>,
    {
        let mut d = Self::empty();
        d.rebuild(jacobian, mobility_of, candidate)?;
        Ok(d)
    }

    /// No rows: storage for [`Delassus::rebuild`] to fill, step after step, in place.
    #[must_use]
    pub fn empty() -> Self {
        Self {
            jacobian: SMatrix::zeros(),
            mobility: SMatrix::zeros(),
            w: SMatrix::zeros(),
            factor: SMatrix::zeros(),
            candidate: [false; C],
        }
    }

    /// As [`Delassus::new`], in place.
    ///
    /// # Errors
    /// As [`Delassus::new`].
    pub fn rebuild<F>(
        &mut self,
        jacobian: SMatrix<T, C, N>,
        mobility_of: F,
        candidate: &[bool; C],
    ) -> Result<(), Error>
    where
        F: FnOnce(&SMatrix<T, N, C>) -> Result<SMatrix<T, N, C>, Error>,
    {
        self.jacobian = jacobian;
        for (i, &on) in candidate.iter().enumerate() {
            if !on {
                self.jacobian.row_mut(i).fill(T::zero());
            }
        }
        self.mobility = mobility_of(&self.jacobian.transpose())?;
        self.candidate = *candidate;
        for i in (0..C).filter(|&i| candidate[i]) {
            let row = self.jacobian.row(i).transpose();
            for k in (i..C).filter(|&k| candidate[k]) {
                // `k < C`, clamped (a no-op) so that the optimiser drops the bounds check it
                // otherwise keeps (a panic path).
                let x = row.dot(&self.mobility.column(k.min(C - 1)));
                if !x.is_finite() {
                    return Err(Error::NonFiniteState);
                }
                self.w[(i, k)] = x;
                self.w[(k, i)] = x;
            }
        }
        Ok(())
    }

    /// The same rows with the rows marked in `rows` of `jacobian` (the Jacobian of the whole
    /// set at the same configuration) joining the candidates: `solve_mass` (a velocity jump)
    /// for each that joins, and their entries of `W`.
    ///
    /// # Errors
    /// As [`Delassus::new`].
    pub fn extend<F>(
        &mut self,
        jacobian: &SMatrix<T, C, N>,
        mut solve_mass: F,
        rows: &[bool; C],
    ) -> Result<(), Error>
    where
        F: FnMut(&SVector<T, N>) -> Result<SVector<T, N>, Error>,
    {
        let joining: [bool; C] = core::array::from_fn(|i| rows[i] && !self.candidate[i]);
        for i in (0..C).filter(|&i| joining[i]) {
            let j = jacobian.row(i).transpose();
            let b = solve_mass(&j)?;
            self.jacobian.set_row(i, &j.transpose());
            self.mobility.set_column(i, &b);
            self.candidate[i] = true;
            for k in (0..C).filter(|&k| self.candidate[k]) {
                let x = self.jacobian.row(k).transpose().dot(&b);
                if !x.is_finite() {
                    return Err(Error::NonFiniteState);
                }
                self.w[(i, k)] = x;
                self.w[(k, i)] = x;
            }
        }
        Ok(())
    }

    /// The candidate rows.
    #[must_use]
    pub fn candidates(&self) -> &[bool; C] {
        &self.candidate
    }

    /// The Jacobian of the candidate rows (the others are zero).
    #[must_use]
    pub fn jacobian(&self) -> &SMatrix<T, C, N> {
        &self.jacobian
    }

    /// `W = J M^-1 J^T` over the candidate rows (zero elsewhere).
    #[must_use]
    pub fn w(&self) -> &SMatrix<T, C, C> {
        &self.w
    }

    /// `M^-1 J^T lambda`: the change of the motion the multipliers `lambda` cause.
    #[must_use]
    pub fn response(&self, lambda: &SVector<T, C>) -> SVector<T, N> {
        self.mobility * lambda
    }

    /// The multipliers `lambda` of the candidate rows for which `a = W lambda + b` is zero on
    /// the bilateral and held rows (see [`Row`]) and, on the unilateral ones, `lambda >= 0`,
    /// `a >= 0` and `lambda a = 0`: each unilateral row either pushes and holds (`a = 0`) or
    /// is free and opens (`a >= 0`), never pulls and never closes. With `b` the free
    /// accelerations of the rows (`J a0 + J'q'`) these are the contact forces; with `b` the
    /// velocities of the rows less their targets, the impulses that reach the targets.
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
    pub fn complementary(
        &mut self,
        b: &SVector<T, C>,
        kinds: &[Row; C],
    ) -> Result<Complementary<T, C>, Error> {
        let all = self.candidate;
        self.complementary_from(b, kinds, &all)
    }

    /// As [`Delassus::complementary`], with the unilateral rows of `guess` (among the
    /// candidates; bilateral and held rows always) as the first active set: a good guess (the
    /// rows that pushed a moment ago) ends the method in one pass.
    ///
    /// # Errors
    /// As [`Delassus::complementary`].
    pub fn complementary_from(
        &mut self,
        b: &SVector<T, C>,
        kinds: &[Row; C],
        guess: &[bool; C],
    ) -> Result<Complementary<T, C>, Error> {
        let unilateral: [bool; C] =
            core::array::from_fn(|i| self.candidate[i] && kinds[i] == Row::Unilateral);
        let mut active: [bool; C] =
            core::array::from_fn(|i| self.candidate[i] && (guess[i] || !unilateral[i]));
        // Rows that could not join the active rows (dependent on them) until one leaves.
        let mut blocked = [false; C];
        let mut lambda = SVector::<T, C>::zeros();
        let passes = 4 * C + 4;
        for _ in 0..passes {
            let x = match self.solve(&active, &(-b)) {
                Ok(x) => x,
                Err(Error::RedundantConstraints { row })
                    if kinds.get(row).is_some_and(|&k| k != Row::Bilateral) =>
                {
                    active[row] = false;
                    blocked[row] = true;
                    lambda[row] = T::zero();
                    continue;
                }
                Err(e) => return Err(e),
            };
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
                // `row < C`: reached through `get_mut`, so that no bounds check (no panic
                // path) is left where the optimiser cannot see it.
                if let (Some(l), Some(a)) = (lambda.get_mut(row), active.get_mut(row)) {
                    (*l, *a) = (T::zero(), false);
                }
                blocked = [false; C];
                continue;
            }
            lambda = x;
            // Every active row pushes: the free row that would close fastest joins.
            let mut join: Option<(usize, T)> = None;
            for i in (0..C).filter(|&i| unilateral[i] && !active[i] && !blocked[i]) {
                let (a, size) =
                    (0..C)
                        .filter(|&k| active[k])
                        .fold((b[i], b[i].abs()), |(a, s), k| {
                            let term = self.w[(i, k)] * lambda[k];
                            (a + term, s + term.abs())
                        });
                // Rounding (64 ulps of the sum's terms) is no closing: a row held at zero
                // does not rejoin on the sign of noise.
                let closing = a < -(T::from_f64(64.0) * T::EPSILON * size);
                if closing && join.is_none_or(|(_, worst)| a < worst) {
                    join = Some((i, a));
                }
            }
            match join {
                Some((row, _)) => {
                    if let Some(a) = active.get_mut(row) {
                        *a = true;
                    }
                }
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

    /// `x = W_AA^-1 r_A` on the `active` rows (zero elsewhere), by a Cholesky factorisation
    /// of the active rows alone, refusing a pivot below `sqrt(EPSILON)` of its diagonal
    /// entry (a row dependent on the ones before it).
    fn solve(&mut self, active: &[bool; C], r: &SVector<T, C>) -> Result<SVector<T, C>, Error> {
        // The active rows in order, `n` of them. Every index below is in range by
        // construction; where the optimiser cannot see it (a count, a row number read back
        // from `set`) it is clamped, a no-op, so that no bounds check (no panic path) is left.
        let mut set = [0usize; C];
        let mut n = 0;
        for (slot, i) in set.iter_mut().zip((0..C).filter(|&i| active[i])) {
            *slot = i;
            n += 1;
        }
        let n = n.min(C);
        let row = |p: usize| set[p].min(C - 1);
        let threshold = T::EPSILON.sqrt();
        let l = &mut self.factor;
        for p in 0..n {
            let wpp = self.w[(row(p), row(p))];
            let d = (0..p).fold(wpp, |d, k| d - l[(p, k)] * l[(p, k)]);
            if !d.is_finite() {
                return Err(Error::NonFiniteState);
            }
            if d <= wpp.abs() * threshold {
                return Err(Error::RedundantConstraints { row: row(p) });
            }
            let lpp = d.sqrt();
            l[(p, p)] = lpp;
            for q in p + 1..n {
                let x = (0..p).fold(self.w[(row(q), row(p))], |x, k| x - l[(q, k)] * l[(p, k)]);
                l[(q, p)] = x / lpp;
            }
        }
        let mut y = [T::zero(); C];
        for p in 0..n {
            y[p] = (0..p).fold(r[row(p)], |s, k| s - l[(p, k)] * y[k]) / l[(p, p)];
        }
        // Solved in the active rows' order, then put in place.
        let mut solved = [T::zero(); C];
        for p in (0..n).rev() {
            let s = (p + 1..n).fold(y[p], |s, k| s - l[(k, p)] * solved[k]);
            solved[p] = s / l[(p, p)];
        }
        let mut x = SVector::<T, C>::zeros();
        for (p, value) in solved.iter().enumerate().take(n) {
            x[row(p)] = *value;
        }
        Ok(x)
    }
}

/// `solve` applied to each column of `columns` that is not zero (a zero column stays zero):
/// the mobilities of rows from a mass solve of one right-hand side at a time.
///
/// # Errors
/// The first error of `solve`.
pub fn each_column<T: Real, const N: usize, const C: usize, F>(
    columns: &SMatrix<T, N, C>,
    mut solve: F,
) -> Result<SMatrix<T, N, C>, Error>
where
    F: FnMut(&SVector<T, N>) -> Result<SVector<T, N>, Error>,
{
    let mut out = SMatrix::<T, N, C>::zeros();
    for k in 0..C {
        if (0..N).any(|i| columns[(i, k)] != T::zero()) {
            let column = SVector::<T, N>::from_fn(|i, _| columns[(i, k)]);
            out.set_column(k, &solve(&column)?);
        }
    }
    Ok(out)
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
        Delassus::new(j, |jt| Ok(*jt), &[true; 3])
    }

    /// Pushed into the corner, both walls push and the dependent row is not needed; pulled
    /// away from the wall, only the floor pushes and the wall opens.
    #[test]
    fn complementarity_holds() -> Result<(), Error> {
        let mut d = corner()?;
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
        let mut d = corner()?;
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
        let mut d = corner()?;
        let b = SVector::<f64, 3>::new(1.0, -1.0, 0.0);
        let s = d.complementary(&b, &Row::kinds(&[true, false, false]))?;
        let a = d.w * s.lambda + b;
        assert!(s.lambda[0] < 0.0 && a[0].abs() < 1e-15, "{s:?}");
        assert!(a[1].abs() < 1e-15 && s.lambda[1] > 0.0, "{s:?}");
        Ok(())
    }

    /// Only candidates take part: the dependent third row left out, the corner's two rows
    /// solve as before; a bilateral row that depends on another bilateral row is an error
    /// naming it.
    #[test]
    fn candidates_and_dependent_bilateral_rows() -> Result<(), Error> {
        let j = SMatrix::<f64, 3, 2>::new(0.0, 1.0, 1.0, 0.0, 1.0, 1.0);
        let mut d = Delassus::new(j, |jt| Ok(*jt), &[true, true, false])?;
        let s = d.complementary(
            &SVector::<f64, 3>::new(-1.0, -2.0, -100.0),
            &[Row::Unilateral; 3],
        )?;
        assert_eq!(s.lambda, SVector::<f64, 3>::new(1.0, 2.0, 0.0));
        let mut all = Delassus::new(j, |jt| Ok(*jt), &[true; 3])?;
        let bilateral = Row::kinds(&[true; 3]);
        assert_eq!(
            all.complementary(&SVector::<f64, 3>::zeros(), &bilateral),
            Err(Error::RedundantConstraints { row: 2 })
        );
        Ok(())
    }
}
