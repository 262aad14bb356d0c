//! [`Schur`]: the factored Schur complement `J M^-1 J^T` that every constrained solve,
//! projection and impulse shares.

use super::Constraints;
use crate::{Error, Mechanism, Real, State};
use nalgebra::{SMatrix, SVector};

/// The mass-weighted constraint geometry at one configuration, for the rows marked active:
///
/// ```text
/// J           the Jacobian of the active rows (inactive rows zero)
/// Y = M^-1 J^T                 N x C, by C calls of Mechanism::solve_mass
/// S = J M^-1 J^T               C x C, symmetric positive definite when the active rows are
///                              independent; factored by Cholesky (identity on inactive rows)
/// ```
///
/// It is the Schur complement of the KKT system `[M J^T; J 0] [q''; -lambda] = [f; -J'q']`
/// (whose `N + C` size needs no unstable const arithmetic this way). With it:
/// `lambda = S^-1 r` ([`Schur::multipliers`]) and the mass-weighted correction
/// `dq = M^-1 J^T S^-1 r` ([`Schur::correction`]) that changes `J q` by exactly `r`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Schur<T: Real, const N: usize, const C: usize> {
    jacobian: SMatrix<T, C, N>,
    mobility: SMatrix<T, N, C>,
    factor: SMatrix<T, C, C>,
    active: [bool; C],
}

impl<T: Real, const N: usize, const C: usize> Schur<T, N, C> {
    /// The Schur complement of `constraints`' rows marked in `active` for `mechanism` at
    /// `state` (only `state.q` matters to the constraints; the mass solve sees the whole
    /// state).
    ///
    /// Rows are accepted while their Cholesky pivot keeps at least `sqrt(EPSILON)` of the
    /// row's own diagonal `S_ii`: a scale-free test (invariant under scaling a row) that a row
    /// is not a combination of the rows before it.
    ///
    /// # Errors
    /// [`Error::RedundantConstraints`] naming the first dependent active row;
    /// [`Error::NonFiniteState`] when `S` is not finite; whatever
    /// [`Mechanism::solve_mass`] returns.
    pub(crate) fn new<M, K>(
        mechanism: &M,
        constraints: &K,
        state: &State<T, N>,
        active: &[bool; C],
    ) -> Result<Self, Error>
    where
        M: Mechanism<T, N>,
        K: Constraints<T, N, C>,
    {
        Self::from_parts(
            constraints.jacobian(&state.q),
            |b| mechanism.solve_mass(state, b),
            active,
        )
    }

    /// The same from a Jacobian and a mass solve `b -> M^-1 b` already at hand: the fast path
    /// of a hand-derived mechanism that computes its trigonometry once per evaluation.
    ///
    /// # Errors
    /// As [`Schur::new`], with `solve_mass`'s errors.
    pub(crate) fn from_parts<F>(
        jacobian: SMatrix<T, C, N>,
        mut solve_mass: F,
        active: &[bool; C],
    ) -> Result<Self, Error>
    where
        F: FnMut(&SVector<T, N>) -> Result<SVector<T, N>, Error>,
    {
        let mut jacobian = jacobian;
        let mut mobility = SMatrix::<T, N, C>::zeros();
        for (i, &on) in active.iter().enumerate() {
            if on {
                let column = solve_mass(&jacobian.row(i).transpose())?;
                mobility.set_column(i, &column);
            } else {
                jacobian.row_mut(i).fill(T::zero());
            }
        }
        let mut s = jacobian * mobility;
        for (i, &on) in active.iter().enumerate() {
            if !on {
                s[(i, i)] = T::one();
            }
        }
        Ok(Self {
            jacobian,
            mobility,
            factor: cholesky(&s)?,
            active: *active,
        })
    }

    /// The Jacobian of the active rows (inactive rows are zero).
    #[must_use]
    pub(crate) fn jacobian(&self) -> &SMatrix<T, C, N> {
        &self.jacobian
    }

    /// `S^-1 r` on the active rows, zero on the inactive ones (whose entries of `r` are
    /// ignored): the multipliers or impulses that change `J q` (or `J q'`) by `r`.
    #[must_use]
    pub(crate) fn multipliers(&self, r: &SVector<T, C>) -> SVector<T, C> {
        cholesky_solve(&self.factor, &self.active, r)
    }

    /// `M^-1 J^T lambda`: the change of `q''` (or `q'`, or `q`) that the generalized force
    /// (impulse, displacement) `J^T lambda` causes.
    #[must_use]
    pub(crate) fn response(&self, lambda: &SVector<T, C>) -> SVector<T, N> {
        self.mobility * lambda
    }

    /// `M^-1 J^T S^-1 r`: the smallest change in the mass-weighted norm that changes `J x` by
    /// `r` on the active rows.
    #[must_use]
    pub(crate) fn correction(&self, r: &SVector<T, C>) -> SVector<T, N> {
        self.response(&self.multipliers(r))
    }
}

/// `S^-1 r` on the `active` rows of a factor `l` from [`cholesky`] (identity on the inactive
/// rows, whose entries of `r` are ignored), zero on the inactive ones.
pub(crate) fn cholesky_solve<T: Real, const C: usize>(
    l: &SMatrix<T, C, C>,
    active: &[bool; C],
    r: &SVector<T, C>,
) -> SVector<T, C> {
    let mut x = SVector::<T, C>::from_fn(|i, _| if active[i] { r[i] } else { T::zero() });
    for i in 0..C {
        let mut s = x[i];
        for k in 0..i {
            s -= l[(i, k)] * x[k];
        }
        x[i] = s / l[(i, i)];
    }
    for i in (0..C).rev() {
        let mut s = x[i];
        for k in i + 1..C {
            s -= l[(k, i)] * x[k];
        }
        x[i] = s / l[(i, i)];
    }
    x
}

/// The lower Cholesky factor of the symmetric `s`, refusing a pivot below `sqrt(EPSILON)` of
/// its diagonal entry.
pub(crate) fn cholesky<T: Real, const C: usize>(
    s: &SMatrix<T, C, C>,
) -> Result<SMatrix<T, C, C>, Error> {
    let threshold = T::SQRT_EPSILON;
    let mut l = SMatrix::<T, C, C>::zeros();
    for j in 0..C {
        let mut d = s[(j, j)];
        for k in 0..j {
            d -= l[(j, k)] * l[(j, k)];
        }
        if !d.is_finite() {
            return Err(Error::NonFiniteState);
        }
        if d <= s[(j, j)].abs() * threshold {
            return Err(Error::RedundantConstraints { row: j });
        }
        let ljj = d.sqrt();
        l[(j, j)] = ljj;
        for i in j + 1..C {
            let mut x = s[(i, j)];
            for k in 0..j {
                x -= l[(i, k)] * l[(j, k)];
            }
            l[(i, j)] = x / ljj;
        }
    }
    Ok(l)
}

#[cfg(feature = "defmt")]
impl<T: Real, const N: usize, const C: usize> defmt::Format for Schur<T, N, C> {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "Schur {{ active: {} }}", self.active);
    }
}
