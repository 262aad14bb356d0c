//! [`Delassus`]: the mass-weighted geometry `W = J M^-1 J^T` of a set of candidate rows, and
//! the exact solution of their linear complementarity problem: the forces of resting contacts
//! (at the acceleration level), the impulses of an impact or of a time step (at the velocity
//! level), a projection's displacements (at the position level).

use crate::nalgebra::{SMatrix, SVector};
use crate::{all_finite, split_dot, Error, Real};

mod relaxed;

/// How a row of [`Delassus::complementary`] is held: the bounds of its multiplier
/// `lambda`, and what its `a = W lambda + b` must be inside them (zero; at a bound, of the
/// sign that would push the multiplier out).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Row<T> {
    /// `a >= 0`, `lambda >= 0`, `lambda a = 0`: a contact.
    Unilateral,
    /// `a = 0`, `lambda` of either sign; must not depend on the other such rows.
    Bilateral,
    /// `a = 0`, `lambda` of either sign, like a bilateral row, but left out where it depends
    /// on the rows held with it (a resting contact projected back onto zero).
    Held,
    /// `|lambda| <= bound` (finite, `>= 0`): `a = 0` inside, `a <= 0` at `+bound`, `a >= 0`
    /// at `-bound`. Coulomb friction of a contact whose normal impulse is known, its bound
    /// `mu` times it: the tangent sticks (`a = 0`, no sliding) or slides against the bound.
    /// Left out, at zero, where it depends on the rows held with it.
    Bounded(T),
}

impl<T: Real> Row<T> {
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

    /// The multiplier's bounds, lower and upper.
    fn bounds(&self) -> (T, T) {
        match *self {
            Self::Unilateral => (T::zero(), T::INFINITY),
            Self::Bilateral | Self::Held => (-T::INFINITY, T::INFINITY),
            Self::Bounded(b) => (-b, b),
        }
    }
}

/// A solution of [`Delassus::complementary`]: the multipliers and the rows solved for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Complementary<T: Real, const C: usize> {
    /// The multipliers (forces, impulses or displacements): zero on the rows neither in
    /// `active` nor at a bound.
    pub lambda: SVector<T, C>,
    /// The rows solved for, `a = 0`: bilateral rows, unilateral rows that push, bounded rows
    /// inside their bounds.
    pub active: [bool; C],
    /// The passes the method took, each one solve of the rows solved for (an `F D F^T`
    /// factorisation of the rows that changed): what this solve cost, below the cap of
    /// `4 C + 4` ([`Delassus::relaxed`]: its sweeps).
    pub passes: u32,
}

/// The rows of a set marked as candidates, with their mobilities `Y = M^-1 J^T` (one mass
/// solve per candidate) and `W = J Y` over the candidates, built once and solved for as many
/// subsets as the complementarity problem asks. Work: `R` mass solves and `R^2 N` for `W`
/// (`R` candidates), then per pass of [`Delassus::complementary`] an `F D F^T` factorisation
/// of the active rows that changed (at most `R^3 / 6`).
#[derive(Debug, Clone, Copy)]
pub struct Delassus<T: Real, const N: usize, const C: usize> {
    /// The candidates' rows of the Jacobian as columns (`J^T`; zero off the candidates):
    /// each row's entries side by side, for its products with the velocities and the
    /// mobilities.
    rows: SMatrix<T, N, C>,
    mobility: SMatrix<T, N, C>,
    w: SMatrix<T, C, C>,
    /// The factor `F D F^T` of the active rows, transposed: `factor[(q, p)]` for positions
    /// `q <= p` in the active set, `D` on the diagonal (scratch, kept so that a solve does
    /// not clear `C^2` numbers a pass).
    factor: SMatrix<T, C, C>,
    /// The rows the factor holds, in its order: `factored[..factored_n]` (cleared whenever
    /// `W` changes), so that a solve of the same rows again (the next round of a contact
    /// step, its drift correction) factors none of them.
    factored: [usize; C],
    factored_n: usize,
    candidate: [bool; C],
    /// The candidates listed (made again whenever they change), for the loops over them
    /// alone: a step's solve reads them a few dozen times, and they change a few times.
    listed: Listed<C>,
}

impl<T: Real, const N: usize, const C: usize> Delassus<T, N, C> {
    /// The rows of `jacobian` marked `candidate` (the others are zeroed), with `mobility_of`
    /// turning the columns of `J^T` in place into their velocity changes (the generalized
    /// impulses of unit row impulses; the other rows' columns are zero and stay zero):
    /// [`Mechanism::velocity_jumps`], or [`each_column`] of a mass solve.
    ///
    /// [`Mechanism::velocity_jumps`]: crate::Mechanism::velocity_jumps
    ///
    /// # Errors
    /// `mobility_of`'s; [`Error::NonFiniteState`] when `W` is not finite.
    pub fn new<F>(
        jacobian: &SMatrix<T, C, N>,
        mobility_of: F,
        candidate: &[bool; C],
    ) -> Result<Self, Error>
    where
        F: FnOnce(&mut SMatrix<T, N, C>) -> Result<(), Error>,
    {
        let mut d = Self::empty();
        d.rebuild(jacobian, mobility_of, candidate)?;
        Ok(d)
    }

    /// No rows: storage for [`Delassus::rebuild`] to fill, step after step, in place.
    #[must_use]
    pub fn empty() -> Self {
        Self {
            rows: SMatrix::zeros(),
            mobility: SMatrix::zeros(),
            w: SMatrix::zeros(),
            factor: SMatrix::zeros(),
            factored: [0; C],
            factored_n: 0,
            candidate: [false; C],
            listed: Listed::of(&[false; C]),
        }
    }

    /// No rows, in place (after a failed fill: the columns and `W` zero off the candidates,
    /// which [`Delassus::rebuild`] and [`Delassus::insert`] rely on).
    fn none(&mut self) {
        self.rows.fill(T::zero());
        self.mobility.fill(T::zero());
        self.w.fill(T::zero());
        self.candidate = [false; C];
        self.listed = Listed::of(&self.candidate);
        self.factored_n = 0;
    }

    /// As [`Delassus::new`], in place: what a stepper that keeps its rows from step to step
    /// calls, with no storage of `C^2` numbers made and cleared again.
    ///
    /// # Errors
    /// As [`Delassus::new`]; after an error the rows are none.
    pub fn rebuild<F>(
        &mut self,
        jacobian: &SMatrix<T, C, N>,
        mobility_of: F,
        candidate: &[bool; C],
    ) -> Result<(), Error>
    where
        F: FnOnce(&mut SMatrix<T, N, C>) -> Result<(), Error>,
    {
        self.factored_n = 0;
        // The entries of W of rows that stop being candidates are cleared (W is zero off
        // the candidates); the candidates' are all written below.
        let leaving: [bool; C] = core::array::from_fn(|i| self.candidate[i] && !candidate[i]);
        if leaving.contains(&true) {
            clear(&mut self.w, &leaving);
        }
        self.candidate = [false; C];
        // The candidates' rows as columns and their mobilities starting as them, before the
        // mass solve (nalgebra's row and column fills walk a strided iterator an entry at a
        // time). The other columns are zero: only the leaving rows' are cleared (writing all
        // `C` columns of both was 3% of a landing ragdoll's heaviest step, for its 9 rows of
        // 31).
        let columns = self
            .rows
            .as_mut_slice()
            .chunks_exact_mut(N)
            .zip(self.mobility.as_mut_slice().chunks_exact_mut(N));
        for ((i, (row, mobility)), (&on, &left)) in
            columns.enumerate().zip(candidate.iter().zip(&leaving))
        {
            if on {
                for (c, (x, m)) in row.iter_mut().zip(mobility.iter_mut()).enumerate() {
                    *x = jacobian[(within::<C>(i), c.min(N.saturating_sub(1)))];
                    *m = *x;
                }
            } else if left {
                row.fill(T::zero());
                mobility.fill(T::zero());
            }
        }
        if let Err(e) = mobility_of(&mut self.mobility) {
            self.none();
            return Err(e);
        }
        // W's entries as products of columns, in partial sums (each its own short chain).
        let mut finite = true;
        for i in (0..C).filter(|&i| candidate[i]).map(within::<C>) {
            let row = column_of(&self.rows, i);
            for k in (i..C).filter(|&k| candidate[k]).map(within::<C>) {
                let x = split_dot(row, column_of(&self.mobility, k));
                finite &= x.is_finite();
                self.w[(i, k)] = x;
                self.w[(k, i)] = x;
            }
        }
        if !finite {
            self.none();
            return Err(Error::NonFiniteState);
        }
        self.candidate = *candidate;
        self.listed = Listed::of(candidate);
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
        for i in (0..C).filter(|&i| joining[i]).map(within::<C>) {
            let j = jacobian.row(i).transpose();
            let b = solve_mass(&j)?;
            self.insert(i, &j, &b)?;
        }
        Ok(())
    }

    /// Row `i` joins the candidates (or is replaced) with Jacobian row `j` and mobility `b`
    /// (`M^-1 j^T`, from a velocity jump): its entries of `W`, `R N` products.
    ///
    /// # Errors
    /// [`Error::NonFiniteState`] when an entry is not finite (the row is then no candidate).
    pub fn insert(&mut self, i: usize, j: &SVector<T, N>, b: &SVector<T, N>) -> Result<(), Error> {
        if i >= C {
            return Err(Error::InvalidParameter {
                name: "row",
                reason: "must be below the set's size",
            });
        }
        // The factor holds as far as this row, where it is one of its rows.
        self.factored_n = self
            .factored
            .iter()
            .take(self.factored_n)
            .position(|&r| r == i)
            .unwrap_or(self.factored_n);
        self.rows.set_column(i, j);
        self.mobility.set_column(i, b);
        self.candidate[i] = true;
        for k in (0..C).filter(|&k| self.candidate[k]).map(within::<C>) {
            let x = split_dot(column_of(&self.rows, k), b.as_slice());
            if !x.is_finite() {
                self.candidate[i] = false;
                self.rows.column_mut(i).fill(T::zero());
                self.mobility.column_mut(i).fill(T::zero());
                self.w.row_mut(i).fill(T::zero());
                self.w.column_mut(i).fill(T::zero());
                self.listed = Listed::of(&self.candidate);
                return Err(Error::NonFiniteState);
            }
            self.w[(i, k)] = x;
            self.w[(k, i)] = x;
        }
        self.listed = Listed::of(&self.candidate);
        Ok(())
    }

    /// The candidate rows.
    #[must_use]
    pub fn candidates(&self) -> &[bool; C] {
        &self.candidate
    }

    /// The Jacobian of the candidate rows (the others are zero).
    #[must_use]
    pub fn jacobian(&self) -> SMatrix<T, C, N> {
        self.rows.transpose()
    }

    /// `W = J M^-1 J^T` over the candidate rows (zero elsewhere).
    #[must_use]
    pub fn w(&self) -> &SMatrix<T, C, C> {
        &self.w
    }

    /// `M^-1 J^T lambda`: the change of the motion the multipliers `lambda` cause.
    #[must_use]
    pub fn response(&self, lambda: &SVector<T, C>) -> SVector<T, N> {
        // The candidates' columns alone, in order (the same sum as the whole product: the
        // others are zero), so that a step's few rows of a large set cost a few columns.
        let mut out = SVector::<T, N>::zeros();
        for i in self.listed.rows() {
            let l = lambda[i];
            if l != T::zero() {
                for (o, m) in out.iter_mut().zip(column_of(&self.mobility, i)) {
                    *o += *m * l;
                }
            }
        }
        out
    }

    /// `J v`, the candidate rows' speeds at velocities `v` (zero on the other rows).
    #[must_use]
    pub fn speeds(&self, v: &SVector<T, N>) -> SVector<T, C> {
        let mut out = SVector::<T, C>::zeros();
        for i in self.listed.rows() {
            out[i] = split_dot(column_of(&self.rows, i), v.as_slice());
        }
        out
    }

    /// The multipliers `lambda` of the candidate rows for which `a = W lambda + b` is zero on
    /// the bilateral and held rows (see [`Row`]) and, on the unilateral ones, `lambda >= 0`,
    /// `a >= 0` and `lambda a = 0`: each unilateral row either pushes and holds (`a = 0`) or
    /// is free and opens (`a >= 0`), never pulls and never closes; a bounded row sticks
    /// (`a = 0`) inside its bounds or rests against one. With `b` the free accelerations of
    /// the rows (`J a0 + J'q'`) these are the contact forces; with `b` the velocities of the
    /// rows less their targets, the impulses that reach the targets.
    ///
    /// The primal active-set method of the convex program `min lambda^T W lambda / 2 +
    /// b^T lambda` over the rows' bounds, from `lambda = 0`, every unilateral candidate held
    /// at zero and the others solved for: the solve on the rows solved for, the others at
    /// their bounds; where a multiplier comes out beyond a bound, a step towards the
    /// solution as far as every multiplier stays within its bounds, and the row that reached
    /// a bound is held there; where every multiplier is within its bounds, the held row whose
    /// `a` would lower the program most by moving off its bound (a unilateral row: the one
    /// that would close fastest) is solved for again. Each step lowers the program's value,
    /// so the method ends, in a few passes per row. A row that depends on the rows solved
    /// for (more contacts than the motion has freedoms: `W` only semi-definite) joins along
    /// the ray that leaves `W lambda` unchanged, as far as the first bound: the row that
    /// reaches it is held there (the program falls along the ray at the rate of the row's
    /// pull). Where no bound ends the ray (held rows, with no bounds, that disagree), the
    /// row is left out. A row whose part independent of the rows solved for is too small
    /// for the pivot test to tell (below `EPSILON^(1/4)` of its size) and that pulls by no
    /// more than that share of its terms is left at its bound: the conditions hold to that
    /// share on such near-dependent sets.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `bound` for a bounded row's bound that is negative or not
    /// finite; [`Error::RedundantConstraints`] when bilateral rows depend on each other;
    /// [`Error::NoConvergence`] where no multipliers meet the conditions (a contact whose
    /// ray no bound ends: the program falls without end, as for two opposed rows that both
    /// approach), or after `4 C + 4` passes (a degenerate set that cycles);
    /// [`Error::NonFiniteState`] for non-finite multipliers.
    pub fn complementary(
        &mut self,
        b: &SVector<T, C>,
        kinds: &[Row<T>; C],
    ) -> Result<Complementary<T, C>, Error> {
        let all = self.candidate;
        self.complementary_from(b, kinds, &all)
    }

    /// As [`Delassus::complementary`], with the unilateral rows of `guess` (among the
    /// candidates; the other kinds always) as the first rows solved for: a good guess (the
    /// rows that pushed a moment ago) ends the method in one pass.
    ///
    /// # Errors
    /// As [`Delassus::complementary`].
    pub fn complementary_from(
        &mut self,
        b: &SVector<T, C>,
        kinds: &[Row<T>; C],
        guess: &[bool; C],
    ) -> Result<Complementary<T, C>, Error> {
        // The candidates, listed: the method runs on their positions in the list (in the
        // rows' order, so the same sums in the same order as over the rows), and every loop
        // and array below holds the candidates alone, not the set's `C` rows (read through
        // an index list and the set's flags, they cost a landing ragdoll's heaviest step 4%
        // of its instructions more, 6 of its 31 rows candidates).
        let listed = self.listed;
        let m = listed.len();
        // The positions, clamped (no-ops: the optimiser does not carry `m <= C` into a loop's
        // index, and a bounds check is a panic path).
        let positions = || (0..m).map(within::<C>);
        if positions().any(|p| {
            matches!(kinds[listed.row(p)], Row::Bounded(x) if !(x >= T::zero() && x.is_finite()))
        }) {
            return Err(Error::InvalidParameter {
                name: "bound",
                reason: "a bounded row's bound must be finite and not negative",
            });
        }
        // Each position's bounds and `b`, and whether it is solved for (a = 0 between its
        // bounds), in the order they joined (so that a row that depends on the others is
        // always the one joining, at its bound: leaving it out changes no multiplier); the
        // other candidates are held at a bound, or left out at zero while they depend on the
        // rows solved for (`blocked`).
        let mut bounds = [(T::zero(), T::zero()); C];
        let mut b_at = [T::zero(); C];
        let mut free = [false; C];
        for p in positions() {
            let i = listed.row(p);
            bounds[p] = kinds[i].bounds();
            b_at[p] = b[i];
            free[p] = match kinds[i] {
                Row::Unilateral => guess[i],
                Row::Bounded(x) => x > T::zero(),
                Row::Bilateral | Row::Held => true,
            };
        }
        // First the rows of the last factor that are solved for again, in its order: the
        // factor of those still holds (a round of a contact step whose rows pushing did not
        // change factors none; in the candidates' order, a row that had joined late moved up
        // and every row after it was factored again). Then the others, by index.
        let (mut order, mut n) = ([0usize; C], 0usize);
        let mut placed = [false; C];
        for &r in self.factored.iter().take(self.factored_n) {
            let Some(p) = listed.position(r).filter(|&p| free[p]) else {
                break;
            };
            order[within::<C>(n)] = p;
            placed[p] = true;
            n += 1;
        }
        let mut kept = n;
        for p in positions().filter(|&p| free[p] && !placed[p]) {
            order[within::<C>(n)] = p;
            n += 1;
        }
        let mut blocked = [false; C];
        let mut lambda = [T::zero(); C];
        // The row that joined last, the way it moves off its bound, and whether its pull was
        // beyond what a dependence the pivot test cannot tell from near-dependence explains.
        let mut joined: Option<(usize, T, bool)> = None;
        let passes = 4 * C + 4;
        // The solution of each pass's rows, written in place: returned by value, its copy
        // waited on the stores of the substitution (a tenth of a one-row solve).
        let mut x = [T::zero(); C];
        // The rows whose multipliers push, listed anew where a sum runs over them.
        let mut pushing = [0usize; C];
        for pass in 1..=passes {
            // The rows held at a bound push on the rows solved for (listed first, in order:
            // the same sums, without a test per pair of rows).
            let held = nonzero(positions().filter(|&k| !free[k]), &lambda, &mut pushing);
            let mut rhs = [T::zero(); C];
            for i in positions().filter(|&i| free[i]) {
                rhs[i] = pushing
                    .iter()
                    .take(held)
                    .map(|&k| within::<C>(k))
                    .fold(-b_at[i], |r, k| r - self.w_at(&listed, i, k) * lambda[k]);
            }
            let dependent = match self.solve(&listed, &order, n, kept, &rhs, &mut x) {
                Ok(()) => None,
                Err(Error::RedundantConstraints { row }) => match listed.position(row) {
                    Some(p) => Some((row, p)),
                    None => return Err(Error::RedundantConstraints { row }),
                },
                Err(e) => return Err(e),
            };
            // (Clamped, no-ops: the optimiser does not follow a row number through the
            // `Option`, and a bounds check is a panic path.)
            match dependent.map(|(row, p)| (within::<C>(row), within::<C>(p))) {
                None => {}
                // A joining row that depends on the rows solved for: along the ray that moves
                // it off its bound and them so that W lambda is unchanged, the program falls
                // at the rate of its pull; as far as the first bound, where that row is held.
                Some((row, p)) if joined.is_some_and(|(j, _, _)| j == p) => {
                    let (way, pulls) =
                        joined.map_or((T::zero(), false), |(_, w, pulls)| (w, pulls));
                    joined = None;
                    let ray = if pulls {
                        self.ray(
                            &listed,
                            &mut order,
                            &mut n,
                            &mut free,
                            &mut lambda,
                            &bounds,
                            p,
                            way,
                        )?
                    } else {
                        None
                    };
                    match ray {
                        Some(from) => {
                            kept = from;
                            blocked = [false; C];
                        }
                        // No bound ends the ray of a contact that pulls beyond rounding: the
                        // program falls along it without end, and no multipliers meet the
                        // conditions (two opposed rows that both approach). The caller's
                        // fallback, at once rather than after the passes' cap.
                        None if pulls && kinds[row] == Row::Unilateral => {
                            return Err(Error::NoConvergence {
                                iterations: u32::try_from(pass).unwrap_or(u32::MAX),
                            });
                        }
                        // Else the row is left out at its bound.
                        None => {
                            kept = remove(&mut order, &mut n, p);
                            free[p] = false;
                            blocked[p] = true;
                        }
                    }
                    continue;
                }
                // A row of the first set that depends on the ones before it, at zero: left
                // out, free to join later (along a ray).
                Some((row, p)) if kinds[row] != Row::Bilateral => {
                    kept = remove(&mut order, &mut n, p);
                    free[p] = false;
                    lambda[p] = T::zero();
                    continue;
                }
                Some((row, _)) => return Err(Error::RedundantConstraints { row }),
            }
            kept = n;
            joined = None;
            // The step from lambda towards x, as far as every multiplier stays within its
            // bounds; the row that stops it is held at the bound it reached.
            let mut stop: Option<(usize, T, T)> = None;
            for i in positions().filter(|&i| free[i]) {
                let (lo, hi) = bounds[i];
                let (reach, at) = if x[i] < lo {
                    ((lambda[i] - lo) / (lambda[i] - x[i]), lo)
                } else if x[i] > hi {
                    ((hi - lambda[i]) / (x[i] - lambda[i]), hi)
                } else {
                    continue;
                };
                if stop.is_none_or(|(_, r, _)| reach < r) {
                    stop = Some((i, reach, at));
                }
            }
            if let Some((row, reach, at)) = stop {
                let row = within::<C>(row);
                for i in positions().filter(|&i| free[i]) {
                    let l = lambda[i];
                    lambda[i] = l + (x[i] - l) * reach;
                }
                lambda[row] = at;
                free[row] = false;
                kept = remove(&mut order, &mut n, row);
                blocked = [false; C];
                continue;
            }
            for i in positions().filter(|&i| free[i]) {
                lambda[i] = x[i];
            }
            // Every multiplier within its bounds: the held row whose a would lower the
            // program most by moving off its bound is solved for.
            let mut join: Option<(usize, T, T)> = None;
            let all = nonzero(0..m, &lambda, &mut pushing);
            for i in positions().filter(|&i| !free[i] && !blocked[i]) {
                let (lo, hi) = bounds[i];
                if lo == hi {
                    continue;
                }
                let (a, size) = pushing.iter().take(all).map(|&k| within::<C>(k)).fold(
                    (b_at[i], b_at[i].abs()),
                    |(a, s), k| {
                        let term = self.w_at(&listed, i, k) * lambda[k];
                        (a + term, s + term.abs())
                    },
                );
                // Off the lower bound where a < 0, off the upper where a > 0 (a row left
                // out at zero inside its bounds: either way). Rounding (64 ulps of the sum's
                // terms) is no pull: a row held at a bound does not leave it on the sign of
                // noise.
                let pull = if lambda[i] <= lo {
                    -a
                } else if lambda[i] >= hi {
                    a
                } else {
                    a.abs()
                };
                if pull > T::from_f64(64.0) * T::EPSILON * size
                    && join.is_none_or(|(_, most, _)| pull > most)
                {
                    join = Some((i, pull, size));
                }
            }
            match join {
                Some((row, pull, size)) if n < C => {
                    let row = within::<C>(row);
                    free[row] = true;
                    order[within::<C>(n)] = row;
                    n += 1;
                    // The way it moves off its bound: up from the lower, down from the upper,
                    // against a from inside.
                    let (lo, hi) = bounds[row];
                    let a = positions()
                        .fold(T::zero(), |a, k| a + self.w_at(&listed, row, k) * lambda[k])
                        + b_at[row];
                    let way = if lambda[row] <= lo {
                        T::one()
                    } else if lambda[row] >= hi || a > T::zero() {
                        -T::one()
                    } else {
                        T::one()
                    };
                    // The pivot test takes a row whose part independent of the rows solved
                    // for is below EPSILON^(1/4) of its size for dependent; a pull within that
                    // share of its terms is what such a part can leave, not a pull to follow
                    // along a ray (which assumes W lambda unchanged, and moved by 1 / that
                    // part, cycled: the next solve left the row out again at zero).
                    let beyond = pull > T::FOURTH_ROOT_EPSILON * size;
                    joined = Some((row, way, beyond));
                }
                None if all_finite(&lambda) => {
                    return Ok(listed.scatter(&lambda, &free, pass));
                }
                _ => return Err(Error::NonFiniteState),
            }
        }
        Err(Error::NoConvergence {
            iterations: u32::try_from(passes).unwrap_or(u32::MAX),
        })
    }

    /// `W` between the candidates at positions `p` and `q` of `listed`.
    #[inline(always)]
    fn w_at(&self, listed: &Listed<C>, p: usize, q: usize) -> T {
        self.w[(listed.row(p), listed.row(q))]
    }

    /// The ray step of [`Delassus::complementary_from`] for the candidate at position `row`
    /// of `listed`, last of `order[..n]` and dependent on the rows before it, moving `way` (+1
    /// up, -1 down) off its bound: `c = W_FF^-1 W_F,row` on those rows, then `lambda_row +=
    /// way t` and `lambda_F -= way c t` (which leaves `W lambda` unchanged) as far as the
    /// first bound; the row that reaches it is held there (`row` itself, or one of the
    /// others, which `row` then replaces). The position in the order from which it changed;
    /// `None`, with nothing changed, where no bound ends the ray (rows with no bounds that
    /// depend on each other and do not agree). Positions throughout, as the method's.
    ///
    /// # Errors
    /// As the solve of the rows before `row`.
    #[allow(clippy::too_many_arguments)]
    fn ray(
        &mut self,
        listed: &Listed<C>,
        order: &mut [usize; C],
        n: &mut usize,
        free: &mut [bool; C],
        lambda: &mut [T; C],
        bounds: &[(T, T); C],
        row: usize,
        way: T,
    ) -> Result<Option<usize>, Error> {
        let row = within::<C>(row);
        let before = (*n).min(C).saturating_sub(1);
        let partners = order.iter().take(before).map(|&k| within::<C>(k));
        let mut column = [T::zero(); C];
        for k in partners.clone() {
            column[k] = self.w_at(listed, k, row);
        }
        let mut c = [T::zero(); C];
        self.solve(listed, order, before, before, &column, &mut c)?;
        let (lo, hi) = bounds[row];
        let own = if way > T::zero() {
            hi - lambda[row]
        } else {
            lambda[row] - lo
        };
        let mut limit: (usize, T, T) = (row, own, if way > T::zero() { hi } else { lo });
        for k in partners.clone() {
            let rate = -way * c[k];
            let (lo, hi) = bounds[k];
            let (t, at) = if rate < T::zero() {
                ((lambda[k] - lo) / -rate, lo)
            } else if rate > T::zero() {
                ((hi - lambda[k]) / rate, hi)
            } else {
                continue;
            };
            if t < limit.1 {
                limit = (k, t, at);
            }
        }
        let (held, t, at) = limit;
        let held = within::<C>(held);
        if !t.is_finite() {
            return Ok(None);
        }
        for k in partners {
            lambda[k] -= way * c[k] * t;
        }
        lambda[row] += way * t;
        lambda[held] = at;
        free[held] = false;
        Ok(Some(remove(order, n, held)))
    }

    /// `x = W_AA^-1 r_A` on the candidates at the positions `order[..n]` of `listed` (`x` and
    /// `r` by position, `x` zero elsewhere), by a factorisation `W_AA = F D F^T` of those
    /// rows alone in that order (`F` unit lower triangular, `D` diagonal), refusing a pivot
    /// `D` below `sqrt(EPSILON)` of its diagonal entry of `W` (a row dependent on the ones
    /// before it: [`Error::RedundantConstraints`] names its row). The factor's first `kept`
    /// rows are those of the last call's (the same rows in the same order): only the rows
    /// after them are factored.
    fn solve(
        &mut self,
        listed: &Listed<C>,
        order: &[usize; C],
        n: usize,
        kept: usize,
        r: &[T; C],
        x: &mut [T; C],
    ) -> Result<(), Error> {
        let n = n.min(C);
        let kept = kept.min(n);
        let threshold = T::SQRT_EPSILON;
        for (f, &o) in self.factored.iter_mut().zip(order).take(kept) {
            *f = listed.row(o);
        }
        self.factored_n = kept;
        // Stored transposed, `lt[(q, p)] = F[p][q]` for `q < p` (row `p` of `F`, which the
        // factor's inner products and the forward substitution walk, is a column in storage
        // order), and `lt[(p, p)] = D[p]`. The substitutions divide by `D` once a row's sum
        // is done, off the chain of sums the next rows wait on: Cholesky's `L L^T`, whose
        // substitutions divide each row's sum before the next can use it, spent a third of
        // a solve waiting on those divisions.
        let lt = &mut self.factor;
        let place = |p: usize| within::<C>(order[p]);
        let row = |p: usize| listed.row(place(p));
        // `c[q] = F[p][q] D[q]` of the row being factored.
        let mut c = [T::zero(); C];
        for p in kept..n {
            let row_p = row(p);
            for q in 0..p {
                c[q] = (0..q).fold(self.w[(row(q), row_p)], |x, k| x - c[k] * lt[(k, q)]);
                lt[(q, p)] = c[q] / lt[(q, q)];
            }
            let wpp = self.w[(row_p, row_p)];
            let d = (0..p).fold(wpp, |d, k| d - c[k] * lt[(k, p)]);
            if !d.is_finite() {
                return Err(Error::NonFiniteState);
            }
            if d <= wpp.abs() * threshold {
                return Err(Error::RedundantConstraints { row: row_p });
            }
            lt[(p, p)] = d;
            self.factored[p] = row_p;
            self.factored_n = p + 1;
        }
        let mut y = [T::zero(); C];
        for p in 0..n {
            y[p] = (0..p).fold(r[place(p)], |s, k| s - lt[(k, p)] * y[k]);
        }
        for (p, y) in y.iter_mut().enumerate().take(n) {
            *y /= lt[(p, p)];
        }
        x.fill(T::zero());
        for p in (0..n).rev() {
            x[place(p)] = (p + 1..n).fold(y[p], |s, k| s - lt[(p, k)] * x[place(k)]);
        }
        Ok(())
    }
}

/// Candidate rows, listed: `rows[p]` the row at position `p` (in the rows' order),
/// `position[i]` the position of row `i` (`C` where it is no candidate).
#[derive(Debug, Clone, Copy)]
struct Listed<const C: usize> {
    rows: [usize; C],
    position: [usize; C],
    m: usize,
}

impl<const C: usize> Listed<C> {
    /// The rows marked in `candidate`.
    fn of(candidate: &[bool; C]) -> Self {
        let mut rows = [0; C];
        let m = list((0..C).filter(|&i| candidate[i]), &mut rows);
        let mut position = [C; C];
        for (p, &i) in rows.iter().enumerate().take(m) {
            if let Some(slot) = position.get_mut(i) {
                *slot = p;
            }
        }
        Self { rows, position, m }
    }

    /// How many (at most `C`: what the optimiser reads to drop the bounds checks of the
    /// arrays indexed by position).
    fn len(&self) -> usize {
        self.m.min(C)
    }

    /// The rows, in order (clamped: see [`within`]).
    fn rows(&self) -> impl Iterator<Item = usize> + '_ {
        self.rows.iter().take(self.len()).map(|&i| within::<C>(i))
    }

    /// The row at position `p` (clamped: see [`within`]).
    #[inline(always)]
    fn row(&self, p: usize) -> usize {
        within::<C>(self.rows[within::<C>(p)])
    }

    /// The position of row `row`, if it is a candidate.
    fn position(&self, row: usize) -> Option<usize> {
        self.position.get(row).copied().filter(|&p| p < C)
    }

    /// The solution of positions `lambda` and `free`, by row, after `passes` passes.
    fn scatter<T: Real>(
        &self,
        lambda: &[T; C],
        free: &[bool; C],
        passes: usize,
    ) -> Complementary<T, C> {
        let mut out = Complementary {
            lambda: SVector::zeros(),
            active: [false; C],
            passes: u32::try_from(passes).unwrap_or(u32::MAX),
        };
        for p in (0..self.len()).map(within::<C>) {
            let i = self.row(p);
            out.lambda[i] = lambda[p];
            out.active[i] = free[p];
        }
        out
    }
}

/// The positions of `rows` whose multiplier is not zero, in order, written to the front of
/// `out`: how many.
fn nonzero<T: Real, const C: usize>(
    rows: impl Iterator<Item = usize>,
    lambda: &[T; C],
    out: &mut [usize; C],
) -> usize {
    list(
        rows.map(within::<C>).filter(|&k| lambda[k] != T::zero()),
        out,
    )
}

/// The rows of `rows` (at most `C`), in order, written to the front of `out`: how many.
/// (Read back through [`within`]: the optimiser does not follow a row number through an
/// array, and an index it cannot bound is a panic path.)
fn list<const C: usize>(rows: impl Iterator<Item = usize>, out: &mut [usize; C]) -> usize {
    let mut n = 0;
    for (slot, k) in out.iter_mut().zip(rows) {
        *slot = k;
        n += 1;
    }
    n
}

/// The rows and columns of `w` marked in `rows` set to zero.
fn clear<T: Real, const C: usize>(w: &mut SMatrix<T, C, C>, rows: &[bool; C]) {
    for (k, column) in w.as_mut_slice().chunks_exact_mut(C).enumerate() {
        let whole = rows.get(k).copied().unwrap_or(false);
        for (x, &on) in column.iter_mut().zip(rows) {
            if whole || on {
                *x = T::zero();
            }
        }
    }
}

/// `row` taken out of `order[..n]` (the rows after it move up one): the position it had,
/// before which the order is unchanged.
fn remove<const C: usize>(order: &mut [usize; C], n: &mut usize, row: usize) -> usize {
    let count = (*n).min(C);
    let Some(at) = order.iter().take(count).position(|&r| r == row) else {
        return count;
    };
    for p in at..count.saturating_sub(1) {
        order[p] = order[p + 1];
    }
    *n = count.saturating_sub(1);
    at
}

/// Column `k` of `m` as a slice (empty past the last).
fn column_of<T: Real, const N: usize, const C: usize>(m: &SMatrix<T, N, C>, k: usize) -> &[T] {
    m.as_slice().chunks_exact(N).nth(k).unwrap_or(&[])
}

/// `i`, a row of a set of `C` that this module counted or listed (so below `C`), clamped
/// below `C`: a no-op that tells the optimiser, which cannot follow a row number through an
/// array, that no bounds check is needed (a bounds check is a panic path, which the
/// firmware's panic-free image refuses).
fn within<const C: usize>(i: usize) -> usize {
    i.min(C.saturating_sub(1))
}

/// Each column of `columns` that is not zero replaced by `solve` of it (a zero column stays
/// zero): the mobilities of rows from a mass solve of one right-hand side at a time, in place.
///
/// # Errors
/// The first error of `solve` (the columns before it are solved, the rest as they were).
pub fn each_column<T: Real, const N: usize, const C: usize, F>(
    columns: &mut SMatrix<T, N, C>,
    mut solve: F,
) -> Result<(), Error>
where
    F: FnMut(&SVector<T, N>) -> Result<SVector<T, N>, Error>,
{
    for k in 0..C {
        if columns.column(k).iter().any(|x| *x != T::zero()) {
            let solved = solve(&columns.column(k).into_owned())?;
            columns.set_column(k, &solved);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::{Delassus, Listed, Row};
    use crate::nalgebra::{SMatrix, SVector};
    use crate::Error;

    /// Whether a row of `kind` with multiplier `l` and `a = l` meets its conditions to `tol`:
    /// a unilateral row pushes and holds or is free and opens, a bounded row sticks inside
    /// its bounds or rests against one, a bilateral or held row holds.
    fn holds(kind: Row<f64>, l: f64, a: f64, tol: f64) -> bool {
        match kind {
            Row::Unilateral => l >= 0.0 && a >= -tol && (l * a).abs() < tol,
            Row::Bounded(x) => {
                l.abs() <= x
                    && (l.abs() < x - tol && a.abs() < tol
                        || l >= x - tol && a <= tol
                        || l <= -x + tol && a >= -tol)
            }
            Row::Held | Row::Bilateral => a.abs() < tol,
        }
    }

    /// Two rows on one unit mass in the plane (so `W = J J^T`): a floor `y >= 0` and a wall
    /// `x >= 0` that meet at a corner, and a third row `x + y >= 0` that depends on both.
    fn corner() -> Result<Delassus<f64, 2, 3>, Error> {
        let j = SMatrix::<f64, 3, 2>::new(0.0, 1.0, 1.0, 0.0, 1.0, 1.0);
        Delassus::new(&j, |_| Ok(()), &[true; 3])
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

    /// A listing of candidates: rows by position in the rows' order, positions by row (none
    /// for a row that is no candidate), and a solution by position scattered back by row.
    #[test]
    fn listed_candidates_map_rows_and_positions() {
        let listed = Listed::of(&[false, true, false, true, true]);
        assert_eq!(listed.len(), 3);
        let mut rows = listed.rows();
        let listed_rows: [Option<usize>; 4] = core::array::from_fn(|_| rows.next());
        assert_eq!(listed_rows, [Some(1), Some(3), Some(4), None]);
        let by_position: [usize; 3] = core::array::from_fn(|p| listed.row(p));
        assert_eq!(by_position, [1, 3, 4]);
        let positions: [Option<usize>; 6] = core::array::from_fn(|r| listed.position(r));
        assert_eq!(positions, [None, Some(0), None, Some(1), Some(2), None]);
        let out = listed.scatter(
            &[0.5, 0.0, 2.0, 0.0, 0.0],
            &[true, false, true, false, false],
            7,
        );
        assert_eq!(out.lambda.as_slice(), &[0.0, 0.5, 0.0, 0.0, 2.0]);
        assert_eq!(out.active, [false, true, false, false, true]);
        assert_eq!(out.passes, 7);
        assert_eq!(Listed::of(&[false; 4]).rows().count(), 0);
    }

    /// The candidates' speeds and the response of their multipliers, the other rows left
    /// out: a mass of 2 (mobility `J^T / 2`), the third row no candidate.
    #[test]
    fn speeds_and_response_read_the_candidates() -> Result<(), Error> {
        let j = SMatrix::<f64, 3, 2>::new(0.0, 1.0, 1.0, 0.0, 1.0, 1.0);
        let half = |m: &mut SMatrix<f64, 2, 3>| {
            *m *= 0.5;
            Ok(())
        };
        let d = Delassus::new(&j, half, &[true, true, false])?;
        let v = SVector::<f64, 2>::new(3.0, -5.0);
        assert_eq!(d.speeds(&v), SVector::<f64, 3>::new(-5.0, 3.0, 0.0));
        let lambda = SVector::<f64, 3>::new(2.0, 4.0, 100.0);
        assert_eq!(d.response(&lambda), SVector::<f64, 2>::new(2.0, 1.0));
        Ok(())
    }

    /// Only candidates take part: the dependent third row left out, the corner's two rows
    /// solve as before; a bilateral row that depends on another bilateral row is an error
    /// naming it.
    #[test]
    fn candidates_and_dependent_bilateral_rows() -> Result<(), Error> {
        let j = SMatrix::<f64, 3, 2>::new(0.0, 1.0, 1.0, 0.0, 1.0, 1.0);
        let mut d = Delassus::new(&j, |_| Ok(()), &[true, true, false])?;
        let s = d.complementary(
            &SVector::<f64, 3>::new(-1.0, -2.0, -100.0),
            &[Row::Unilateral; 3],
        )?;
        assert_eq!(s.lambda, SVector::<f64, 3>::new(1.0, 2.0, 0.0));
        let mut all = Delassus::new(&j, |_| Ok(()), &[true; 3])?;
        let bilateral = Row::kinds(&[true; 3]);
        assert_eq!(
            all.complementary(&SVector::<f64, 3>::zeros(), &bilateral),
            Err(Error::RedundantConstraints { row: 2 })
        );
        Ok(())
    }

    /// A bounded row (a tangent `x` beside a floor `y >= 0`, and the dependent third row)
    /// sticks inside its bound or rests against the bound it is pushed towards: the
    /// complementarity conditions of each kind hold to rounding, whatever `b`.
    #[test]
    fn bounded_rows_stick_or_rest_against_a_bound() -> Result<(), Error> {
        let mut d = corner()?;
        let kinds = [Row::Unilateral, Row::Bounded(0.5), Row::Unilateral];
        for b in [
            SVector::<f64, 3>::new(-1.0, 0.2, 1.0),
            SVector::<f64, 3>::new(-1.0, 3.0, 1.0),
            SVector::<f64, 3>::new(-1.0, -3.0, -5.0),
            SVector::<f64, 3>::new(2.0, -0.1, -0.5),
            SVector::<f64, 3>::new(-2.0, -0.3, -2.5),
        ] {
            let s = d.complementary(&b, &kinds)?;
            let a = d.w * s.lambda + b;
            let tol = 1e-12;
            for i in [0, 2] {
                assert!(s.lambda[i] >= 0.0 && a[i] >= -tol, "{b:?}: {s:?} {a:?}");
                assert!((s.lambda[i] * a[i]).abs() < tol, "{b:?}: {s:?} {a:?}");
            }
            let t = s.lambda[1];
            assert!(t.abs() <= 0.5, "{b:?}: {s:?}");
            if t.abs() < 0.5 {
                assert!(a[1].abs() < tol, "sticks: {b:?}: {s:?} {a:?}");
            } else {
                assert!(a[1] * t <= tol, "against its bound: {b:?}: {s:?} {a:?}");
            }
        }
        // The floor pushes 1 and the tangent, asked to stop a speed of 3, rests at -0.5.
        let s = d.complementary(&SVector::<f64, 3>::new(-1.0, 3.0, 10.0), &kinds)?;
        assert!(
            (s.lambda[0] - 1.0).abs() < 1e-15 && s.lambda[1] == -0.5,
            "{s:?}"
        );
        // A bound that is negative or not finite is refused by name.
        for bad in [-1.0, f64::NAN, f64::INFINITY] {
            let kinds = [Row::Unilateral, Row::Bounded(bad), Row::Unilateral];
            assert!(matches!(
                d.complementary(&SVector::zeros(), &kinds),
                Err(Error::InvalidParameter { name: "bound", .. })
            ));
        }
        Ok(())
    }

    /// Rows that stop being candidates leave no entries of `W` behind, and a row inserted
    /// with its mobility gives the entries a rebuild would.
    #[test]
    fn rebuilds_and_inserted_rows() -> Result<(), Error> {
        let j = SMatrix::<f64, 3, 2>::new(0.0, 1.0, 1.0, 0.0, 1.0, 1.0);
        let mut d = corner()?;
        d.rebuild(&j, |_| Ok(()), &[true, false, false])?;
        let mut only_floor = SMatrix::<f64, 3, 3>::zeros();
        only_floor[(0, 0)] = 1.0;
        assert_eq!(d.w(), &only_floor);
        d.insert(
            2,
            &SVector::<f64, 2>::new(1.0, 1.0),
            &SVector::<f64, 2>::new(1.0, 1.0),
        )?;
        let rebuilt = Delassus::new(&j, |_| Ok(()), &[true, false, true])?;
        assert_eq!(d.w(), rebuilt.w());
        assert_eq!(d.candidates(), &[true, false, true]);
        assert!(d.insert(3, &SVector::zeros(), &SVector::zeros()).is_err());
        // Extended by the wall alone: it joins, the third row (no candidate, not asked) does
        // not, and the floor and the third stay as they were.
        let mut e = Delassus::new(&j, |_| Ok(()), &[true, false, false])?;
        e.extend(&j, |b| Ok(*b), &[false, true, false])?;
        assert_eq!(e.candidates(), &[true, true, false]);
        let two = Delassus::new(&j, |_| Ok(()), &[true, true, false])?;
        assert_eq!(e.w(), two.w());
        Ok(())
    }

    /// A rebuild writes only the candidates' columns and clears the leaving rows': what the
    /// rows hold is a fresh set's, bit for bit, after fewer rows, other rows, a failed
    /// insert and a failed mass solve alike (a column left behind would be a row's Jacobian
    /// and mobility where it is no candidate).
    #[test]
    fn rebuilt_rows_are_a_fresh_sets() -> Result<(), Error> {
        let j = SMatrix::<f64, 3, 2>::new(0.0, 1.0, 1.0, 0.0, 1.0, 1.0);
        let twice = |m: &mut SMatrix<f64, 2, 3>| {
            *m *= 2.0;
            Ok(())
        };
        let v = SVector::<f64, 2>::new(0.5, -3.0);
        let mut d = Delassus::new(&j, twice, &[true; 3])?;
        for now in [
            [true, false, true],
            [false, true, false],
            [true, true, false],
        ] {
            d.rebuild(&j, twice, &now)?;
            let fresh = Delassus::new(&j, twice, &now)?;
            assert_eq!(d.jacobian(), fresh.jacobian());
            assert_eq!(d.w(), fresh.w());
            assert_eq!(
                d.response(&SVector::repeat(1.0)),
                fresh.response(&SVector::repeat(1.0))
            );
            assert_eq!(d.speeds(&v), fresh.speeds(&v));
        }
        // A row whose entries of W overflow is no candidate, and its column is cleared.
        let huge = SVector::<f64, 2>::repeat(f64::MAX);
        assert!(d.insert(2, &huge, &huge).is_err());
        assert_eq!(
            d.jacobian(),
            Delassus::new(&j, twice, &[true, true, false])?.jacobian()
        );
        // A failed mass solve leaves no rows; the next rebuild is a fresh set's.
        let fails = |_: &mut SMatrix<f64, 2, 3>| Err(Error::NonFiniteState);
        assert!(d.rebuild(&j, fails, &[true; 3]).is_err());
        assert_eq!(d.jacobian(), SMatrix::<f64, 3, 2>::zeros());
        assert_eq!(d.w(), &SMatrix::<f64, 3, 3>::zeros());
        d.rebuild(&j, twice, &[false, false, true])?;
        let fresh = Delassus::new(&j, twice, &[false, false, true])?;
        assert_eq!(d.jacobian(), fresh.jacobian());
        assert_eq!(
            d.response(&SVector::repeat(1.0)),
            fresh.response(&SVector::repeat(1.0))
        );
        Ok(())
    }

    /// A row inserted after a solve keeps the factor of the rows before it, and a row
    /// replaced in the factor is factored again: the multipliers are those of a set built
    /// afresh with the same rows, bit for bit (the same operations in the same order).
    #[test]
    fn inserted_rows_keep_only_the_factor_that_holds() -> Result<(), Error> {
        let j = SMatrix::<f64, 3, 3>::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 1.0);
        let kinds = [Row::Unilateral; 3];
        let b = SVector::<f64, 3>::new(-1.0, -2.0, -3.0);
        let mut d = Delassus::new(&j, |_| Ok(()), &[true, true, false])?;
        d.complementary(&b, &kinds)?;
        d.insert(2, &j.row(2).transpose(), &j.row(2).transpose())?;
        let all = Delassus::new(&j, |_| Ok(()), &[true; 3])?.complementary(&b, &kinds)?;
        assert_eq!(d.complementary(&b, &kinds)?, all);
        // The first row replaced: the factor of the old one must not serve the new.
        let moved = SVector::<f64, 3>::new(2.0, 0.5, 1.0);
        d.insert(0, &moved, &moved)?;
        let mut k = j;
        k.set_row(0, &moved.transpose());
        let fresh = Delassus::new(&k, |_| Ok(()), &[true; 3])?.complementary(&b, &kinds)?;
        assert_eq!(d.complementary(&b, &kinds)?, fresh);
        Ok(())
    }

    /// Random sets of six rows on three freedoms (so that rows depend on each other):
    /// unilateral and bounded rows, and at most one held row (two or more held rows that
    /// span the freedoms leave a pushing row no minimum), right sides `b = J v` of a random
    /// velocity `v` (rows whose targets disagree can squeeze each other for ever: no
    /// minimum): the conditions of each kind hold to rounding (the ray steps make the rows
    /// that depend on the others join).
    #[test]
    fn dependent_rows_of_every_kind_meet_their_conditions() -> Result<(), Error> {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for _ in 0..2000 {
            let j = SMatrix::<f64, 6, 3>::from_fn(|_, _| next());
            let b = j * SVector::<f64, 3>::from_fn(|_, _| next());
            let kinds: [Row<f64>; 6] = core::array::from_fn(|i| {
                let x = next();
                if i == 0 && x > 0.5 {
                    Row::Held
                } else if x < 0.0 {
                    Row::Unilateral
                } else {
                    Row::Bounded(next().abs())
                }
            });
            let mut d = Delassus::new(&j, |_| Ok(()), &[true; 6])?;
            let s = d.complementary(&b, &kinds)?;
            let a = d.w * s.lambda + b;
            let tol = 1e-9;
            for i in 0..6 {
                let (l, ai) = (s.lambda[i], a[i]);
                let ok = holds(kinds[i], l, ai, tol);
                assert!(ok, "row {i} of {kinds:?}: lambda {l}, a {ai}\n{j}{b}");
            }
        }
        Ok(())
    }

    /// A right side that is not a number gives multipliers that are not numbers either: the
    /// solve refuses them rather than return them, whatever the rows' kinds.
    #[test]
    fn a_right_side_not_a_number_is_refused() -> Result<(), Error> {
        let mut d = corner()?;
        for kinds in [
            [Row::Unilateral; 3],
            [Row::Unilateral, Row::Bounded(0.5), Row::Unilateral],
            Row::kinds(&[true, false, false]),
        ] {
            let b = SVector::<f64, 3>::new(f64::NAN, -1.0, -1.0);
            assert_eq!(
                d.complementary(&b, &kinds),
                Err(Error::NonFiniteState),
                "{kinds:?}"
            );
        }
        Ok(())
    }

    /// As above, solved the way a stepper asks: the candidates of the step before rebuilt
    /// into this step's (rows leave and join), and a guess of the rows that pushed. Rows of
    /// every kind, right sides `b = J v`, eight rows on four freedoms and six on three. The
    /// step towards each solve is cut where a row reaches a bound (at the fraction of the way
    /// that reaches it, from below or above) and the ray steps make dependent rows join: the
    /// method ends, within its passes, at a point where every kind's conditions hold. A row
    /// whose part independent of the rows solved for is below the fourth root of `EPSILON`
    /// (1.2e-4) of its size counts as dependent and is left out (the pivot test takes
    /// `sqrt(EPSILON)` of the squared size), so the conditions hold to that share of the
    /// terms of `a_i = b_i + sum_k W_ik lambda_k`, not to rounding: of 180,000 such problems
    /// (three seeds; eight rows on four freedoms, six on three, four on two) two left a
    /// row's `a` beyond 1e-9 of those terms, at 5.1e-7 and 1.5e-5. The rows that are no
    /// candidates take no multiplier.
    #[test]
    fn guessed_and_rebuilt_rows_meet_their_conditions() -> Result<(), Error> {
        fn check<const C: usize, const N: usize>(count: usize) -> Result<(), Error> {
            let mut seed = 0x0bad_cafe_f00d_1234_u64;
            let mut next = || {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
            };
            for _ in 0..count {
                let j = SMatrix::<f64, C, N>::from_fn(|_, _| next());
                let b = j * SVector::<f64, N>::from_fn(|_, _| next());
                let kinds: [Row<f64>; C] = core::array::from_fn(|i| {
                    let x = next();
                    if i == 0 && x > 0.7 {
                        Row::Held
                    } else if x < 0.0 {
                        Row::Unilateral
                    } else if x < 0.1 {
                        Row::Bounded(0.0)
                    } else {
                        Row::Bounded(next().abs())
                    }
                });
                let guess: [bool; C] = core::array::from_fn(|_| next() > 0.0);
                let before: [bool; C] = core::array::from_fn(|_| next() > -0.5);
                let now: [bool; C] = core::array::from_fn(|_| next() > -0.5);
                let mut d = Delassus::new(&j, |_| Ok(()), &before)?;
                d.rebuild(&j, |_| Ok(()), &now)?;
                let s = d.complementary_from(&b, &kinds, &guess)?;
                let a = d.w * s.lambda + b;
                for i in 0..C {
                    let (l, ai) = (s.lambda[i], a[i]);
                    let terms =
                        (0..C).fold(b[i].abs(), |t, k| t + (d.w[(i, k)] * s.lambda[k]).abs());
                    let tol = 2e-4 * (1.0 + terms);
                    let ok = if now[i] {
                        holds(kinds[i], l, ai, tol)
                    } else {
                        l == 0.0
                    };
                    assert!(
                        ok,
                        "row {i} of {kinds:?} ({now:?}): lambda {l}, a {ai}\n{j}{b}"
                    );
                }
            }
            Ok(())
        }
        check::<8, 4>(3200)?;
        check::<6, 3>(2700)
    }

    /// The ray step, traced by hand: the floor, the wall and the row `x + y >= 0` on one
    /// unit mass (`W = [[1, 0, 1], [0, 1, 1], [1, 1, 2]]`), `b = (-2, -1, -2.9)`, no row
    /// guessed. Pass 1 solves nothing and the third row, which pulls hardest, joins; pass 2
    /// gives it 1.45 and the floor, now pulling 0.55, joins; pass 3 gives `(1.1, 0, 0.9)` and
    /// the wall pulls 0.1; pass 4 finds it dependent on the two (`c = (-1, 1)` over floor and
    /// third row) and moves along the ray until the third row reaches zero at `t = 0.9`:
    /// `(2, 0.9, 0)`, the third row held; pass 5 solves floor and wall, `(2, 1)`, and the
    /// third row opens (`a = 0.1`). Guessing every row instead, pass 1 finds the third
    /// dependent and leaves it out, and pass 2 ends there. (The answer is unique: along the
    /// one direction `(1, 1, -1)` that keeps `W lambda` the program changes by `b` on it,
    /// -0.1, so the third row must be at its bound.)
    #[test]
    fn a_dependent_row_joins_along_the_ray() -> Result<(), Error> {
        let mut d = corner()?;
        let b = SVector::<f64, 3>::new(-2.0, -1.0, -2.9);
        let kinds = [Row::Unilateral; 3];
        for (guess, passes) in [([false; 3], 5), ([true; 3], 2)] {
            let s = d.complementary_from(&b, &kinds, &guess)?;
            let exact = SVector::<f64, 3>::new(2.0, 1.0, 0.0);
            assert!((s.lambda - exact).amax() < 1e-15, "{guess:?}: {s:?}");
            assert_eq!(
                (s.active, s.passes),
                ([true, true, false], passes),
                "{guess:?}"
            );
        }
        Ok(())
    }

    /// The method's path where rows depend on each other and bounded rows meet their
    /// bounds along a ray: five small sets of integer rows (one unit mass) on which each
    /// step of the ray (the row's own reach, each partner's, the first bound, the moves)
    /// decides which of the many multipliers of equal `W lambda` the method ends at, and in
    /// how many passes. The figures are those of a reference of the documented method in
    /// plain Python (`tests/reference/lcp_reference.py`, IEEE doubles), to 1e-12 (it sums
    /// in another order), the passes exactly; and every kind's conditions hold.
    #[test]
    fn a_dependent_row_joins_along_the_ray_as_documented() -> Result<(), Error> {
        fn check<const C: usize>(
            j: &[f64],
            b: [f64; C],
            kinds: [Row<f64>; C],
            guess: [bool; C],
            expected: [f64; C],
            passes: u32,
        ) -> Result<(), Error> {
            let j = SMatrix::<f64, C, 2>::from_row_slice(j);
            let mut d = Delassus::new(&j, |_| Ok(()), &[true; C])?;
            let b = SVector::<f64, C>::from(b);
            let s = d.complementary_from(&b, &kinds, &guess)?;
            let a = d.w * s.lambda + b;
            for i in 0..C {
                assert!(holds(kinds[i], s.lambda[i], a[i], 1e-12), "row {i}: {s:?}");
                assert!(
                    (s.lambda[i] - expected[i]).abs() < 1e-12,
                    "{s:?} against {expected:?}"
                );
            }
            assert_eq!(s.passes, passes, "{s:?}");
            Ok(())
        }
        let (u, bounded) = (Row::Unilateral, Row::Bounded);
        check(
            &[-1.0, 0.0, 1.0, 1.0, 2.0, 0.0, 1.0, 0.0],
            [-0.3, -2.0, 0.9, 0.6],
            [u, u, bounded(1.5), bounded(0.6)],
            [true, false, false, true],
            [0.0, 2.45, -1.15, -0.6],
            8,
        )?;
        check(
            &[1.0, 1.0, 2.0, 1.0, 0.0, 1.0],
            [-2.0, -3.0, -1.5],
            [bounded(0.5), bounded(0.3), bounded(0.9)],
            [true, false, false],
            [0.1, 0.3, 0.9],
            7,
        )?;
        check(
            &[1.0, 1.0, 1.0, 0.0, 1.0, 0.0, 1.0, 1.0],
            [-3.8, -2.2, -2.7, -3.9],
            [bounded(2.0), bounded(1.5), u, bounded(0.5)],
            [true, false, false, false],
            [0.6, -1.5, 3.1, 0.5],
            6,
        )?;
        check(
            &[1.0, 0.0, 0.0, 1.0, -1.0, 0.0, 1.0, 0.0],
            [-1.1, -2.1, 1.2, -1.2],
            [bounded(1.5), u, bounded(1.8), u],
            [false, false, false, true],
            [-1.5, 2.1, -1.8, 0.9],
            8,
        )?;
        check(
            &[1.0, 1.0, 2.0, 2.0, 2.0, 1.0],
            [-1.2, -2.6, -0.5],
            [u, bounded(0.3), u],
            [true, false, false],
            [0.0, 0.3, 0.0],
            4,
        )
    }

    /// Near-dependent rows: three contacts nearly parallel, one unit mass pressed onto them
    /// (a body resting on three points of one line: `J` rows `(1, 0)` each turned by a few
    /// micro-radians, `b = -0.4` each), and two nearly opposed rows beside a third. The pivot
    /// test takes such a row for dependent, but its part independent of the others is not
    /// zero, so a ray along which `W lambda` is unchanged is not one: followed, it moved the
    /// multipliers by the inverse of that part, the next solve left the row out again at
    /// zero, and the method cycled to its cap (`NoConvergence` after 16 passes). Now a pull
    /// within `EPSILON^(1/4)` of the row's terms leaves it at its bound: the method ends,
    /// and the conditions hold to that share of the terms.
    #[test]
    fn near_dependent_rows_do_not_cycle() -> Result<(), Error> {
        let sets = [
            (
                SMatrix::<f64, 3, 2>::new(1.000003, 8e-6, 0.999994, -2e-6, 0.999994, 3e-6),
                SVector::<f64, 3>::new(-0.4, -0.4, -0.4),
            ),
            (
                SMatrix::<f64, 3, 2>::new(-1.000009, 4e-6, 0.999994, -2e-6, -0.999993, 0.999994),
                SVector::<f64, 3>::new(0.8, -0.8, -2.0),
            ),
        ];
        // The same sets with right sides a thousand times larger: the pull is judged against
        // the row's terms, whatever their size.
        let scaled = sets.map(|(j, b)| (j, b * 1000.0));
        for (j, b) in sets.into_iter().chain(scaled) {
            let mut d = Delassus::new(&j, |_| Ok(()), &[true; 3])?;
            let kinds = [Row::Unilateral; 3];
            let s = d.complementary_from(&b, &kinds, &[false; 3])?;
            let a = d.w * s.lambda + b;
            for i in 0..3 {
                let terms = (0..3).fold(b[i].abs(), |t, k| t + (d.w[(i, k)] * s.lambda[k]).abs());
                let tol = f64::EPSILON.sqrt().sqrt() * terms;
                assert!(
                    holds(kinds[i], s.lambda[i], a[i], tol),
                    "row {i}: {s:?}, a {a}"
                );
            }
        }
        Ok(())
    }

    /// Rows of small integer Jacobians (entries -1, 0, 1 and 2) on two and three freedoms
    /// depend on each other exactly (repeated, opposed, sums of others): the sets where the
    /// ray steps do the work (a random real set reaches them twice in 65,000; these, 597 of
    /// these 4,000 problems, 656 ray steps). Right sides `b = J v + s`, a velocity and a separation
    /// `s >= 0` of each row, so that no direction of `W`'s null space lowers the program
    /// without end and a solution exists. Unilateral and bounded rows, guessed rows: the
    /// method returns, and each kind's conditions hold to 1e-9 (the sums of a few products
    /// of tenths; the pivot test sees exact dependence, 0, or a pivot of order 1).
    #[test]
    fn exactly_dependent_rows_meet_their_conditions() -> Result<(), Error> {
        fn check<const C: usize, const N: usize>(count: usize, mut seed: u64) -> Result<(), Error> {
            let mut next = move |n: u64| {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                seed % n
            };
            for _ in 0..count {
                let mut j = SMatrix::<f64, C, N>::from_fn(|_, _| {
                    [-1.0, 0.0, 0.0, 1.0, 1.0, 2.0][next(6) as usize]
                });
                for i in 0..C {
                    if j.row(i).iter().all(|&x| x == 0.0) {
                        j[(i, 0)] = 1.0;
                    }
                }
                let v = SVector::<f64, N>::from_fn(|_, _| next(41) as f64 / 10.0 - 3.0);
                let separation =
                    SVector::<f64, C>::from_fn(|_, _| (next(16) as f64 - 10.0).max(0.0) / 10.0);
                let b = j * v + separation;
                let kinds: [Row<f64>; C] = core::array::from_fn(|_| {
                    if next(4) < 3 {
                        Row::Unilateral
                    } else {
                        Row::Bounded((next(20) + 1) as f64 / 10.0)
                    }
                });
                let guess: [bool; C] = core::array::from_fn(|_| next(10) < 3);
                let mut d = Delassus::new(&j, |_| Ok(()), &[true; C])?;
                let s = d.complementary_from(&b, &kinds, &guess)?;
                let a = d.w * s.lambda + b;
                for i in 0..C {
                    let (l, ai) = (s.lambda[i], a[i]);
                    assert!(
                        holds(kinds[i], l, ai, 1e-9),
                        "row {i} of {kinds:?} (guess {guess:?}): lambda {l}, a {ai}\n{j}{b}"
                    );
                }
            }
            Ok(())
        }
        check::<3, 2>(1000, 0x9e37_79b9_7f4a_7c15)?;
        check::<4, 2>(1000, 0xd1b5_4a32_d192_ed03)?;
        check::<5, 3>(1000, 0x8cb9_2ba7_2f3d_8dd7)?;
        check::<4, 3>(1000, 0x2545_f491_4f6c_dd1d)
    }
}
