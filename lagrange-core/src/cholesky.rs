//! Fixed-size Cholesky solve of `M x = b` for a symmetric positive definite mass matrix.

use crate::{check_finite, Error, Real};
use nalgebra::{SMatrix, SVector};

/// Solves `m x = b` for symmetric positive definite `m` by Cholesky factorisation, on the
/// stack, reading only the lower triangle.
///
/// A pivot that is not positive, or that lost every significant digit to cancellation
/// (below `EPSILON` times its diagonal entry), means `m` is singular or indefinite.
///
/// # Errors
/// [`Error::SingularMassMatrix`] with the index of the failing pivot;
/// [`Error::NonFiniteState`] when `m` holds NaN or infinity (a non-finite state), or the
/// solution is not finite (`b` not finite, or so large that `x` overflows).
///
/// ```
/// use lagrange_core::{solve_spd, Error};
/// use nalgebra::{Matrix2, Vector2};
/// let x = solve_spd(&Matrix2::<f64>::new(4.0, 2.0, 2.0, 3.0), &Vector2::new(2.0, 1.0))?;
/// assert!((x[0] - 0.5).abs() < 1e-15 && x[1].abs() < 1e-15);
/// assert_eq!(
///     solve_spd(&Matrix2::new(1.0, 1.0, 1.0, 1.0), &Vector2::new(1.0, 1.0)),
///     Err(Error::SingularMassMatrix { pivot: 1 })
/// );
/// # Ok::<(), Error>(())
/// ```
pub fn solve_spd<T: Real, const N: usize>(
    m: &SMatrix<T, N, N>,
    b: &SVector<T, N>,
) -> Result<SVector<T, N>, Error> {
    let x = Cholesky::factor(m)?.solve(b);
    check_finite(x.as_slice(), Error::NonFiniteState).map(|()| x)
}

/// Up to how many coordinates [`Cholesky::factor`] checks its pivots after the loop rather
/// than in it. A pivot depends only on the columns before it, so the first bad one, and the
/// error, are the same either way. Measured (f64, x86-64): a solve at five coordinates took 40
/// rather than 72 ns with the exits out of the loop, but one at twenty took a few percent
/// longer.
const CHECKED_AFTER: usize = 8;

/// `Ok` where `d`, the pivot of column `j` (`m_jj` on `M`'s diagonal), is finite and well above
/// rounding.
pub(crate) fn pivot<T: Real>(d: T, m_jj: T, j: usize) -> Result<(), Error> {
    if !d.is_finite() {
        return Err(Error::NonFiniteState);
    }
    if d <= m_jj.abs() * T::EPSILON {
        return Err(Error::SingularMassMatrix { pivot: j });
    }
    Ok(())
}

/// The Cholesky factorisation of a symmetric positive definite matrix, factored once to solve
/// `m x = b` for any number of right-hand sides (a constant mass matrix).
///
/// Kept square-root free, `m = L D L^T` with `L` unit lower triangular and `D` diagonal (the
/// squares of the usual Cholesky factor's diagonal), with the reciprocals of `D`: factoring
/// costs `N` divisions and no square root, solving only multiplications and additions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cholesky<T: Real, const N: usize> {
    /// `L` below the diagonal, `D` on it.
    l: SMatrix<T, N, N>,
    /// `1 / D`.
    inv_d: SVector<T, N>,
}

impl<T: Real, const N: usize> Cholesky<T, N> {
    /// Factors `m`, reading only its lower triangle.
    ///
    /// # Errors
    /// As [`solve_spd`].
    pub fn factor(m: &SMatrix<T, N, N>) -> Result<Self, Error> {
        let mut l = SMatrix::<T, N, N>::zeros();
        let mut inv_d = SVector::<T, N>::zeros();
        // Column j: w_k = L_jk D_k, D_j = m_jj - sum_k L_jk w_k, then
        // L_ij = (m_ij - sum_k L_ik w_k) / D_j below it.
        let mut w = [T::zero(); N];
        for j in 0..N {
            let mut d = m[(j, j)];
            for k in 0..j {
                w[k] = l[(j, k)] * l[(k, k)];
                d -= l[(j, k)] * w[k];
            }
            if N > CHECKED_AFTER {
                pivot(d, m[(j, j)], j)?;
            }
            let inv = d.recip();
            l[(j, j)] = d;
            inv_d[j] = inv;
            for i in j + 1..N {
                let mut s = m[(i, j)];
                for k in 0..j {
                    s -= l[(i, k)] * w[k];
                }
                l[(i, j)] = s * inv;
            }
        }
        if N <= CHECKED_AFTER {
            for j in 0..N {
                pivot(l[(j, j)], m[(j, j)], j)?;
            }
        }
        Ok(Self { l, inv_d })
    }

    /// `x` with `m x = b`: `L y = b` forward, `x = D^-1 y`, then `L^T x = ...` backward, in
    /// place.
    #[must_use]
    pub fn solve(&self, b: &SVector<T, N>) -> SVector<T, N> {
        let mut x: [[T; 1]; N] = core::array::from_fn(|i| [b[i]]);
        self.substitute(&mut x);
        SVector::from_fn(|i, _| x[i][0])
    }

    /// Each column of `b` that is not zero replaced by its [`Cholesky::solve`] (bit for bit;
    /// zero columns left as they are), sixteen at a time side by side where the target has
    /// SIMD lanes: each step of the substitutions is one operation on sixteen columns rather
    /// than a chain of its own per column (a contact step's fifteen mobilities `M^-1 J^T` of
    /// a ragdoll cost about what four single solves do).
    pub fn solve_columns<const K: usize>(&self, b: &mut SMatrix<T, N, K>) {
        in_lanes(b, |x| self.substitute(x));
    }

    /// `L y = b` forward, `x = D^-1 y`, then `L^T x = ...` backward, in place, on each of
    /// the `L` columns of `x` (by coordinate: `x[i][c]` is coordinate `i` of column `c`), the
    /// same operations in the same order on each: one column for [`Cholesky::solve`],
    /// `LANES` for [`Cholesky::solve_columns`].
    fn substitute<const L: usize>(&self, x: &mut [[T; L]; N]) {
        // By index: the bounds then provably hold (no panic path in optimised code).
        let l = &self.l;
        for i in 0..N {
            let mut s = x[i];
            for k in 0..i {
                let (lik, xk) = (l[(i, k)], x[k]);
                for (a, b) in s.iter_mut().zip(xk) {
                    *a -= lik * b;
                }
            }
            x[i] = s;
        }
        for i in (0..N).rev() {
            let inv = self.inv_d[i];
            let mut s = x[i].map(|v| v * inv);
            for k in i + 1..N {
                let (lki, xk) = (l[(k, i)], x[k]);
                for (a, b) in s.iter_mut().zip(xk) {
                    *a -= lki * b;
                }
            }
            x[i] = s;
        }
    }
}

/// The columns [`Cholesky::solve_columns`] solves side by side: sixteen where the target has
/// SIMD lanes (x86_64's SSE2, aarch64's NEON, wasm32's `simd128`: measured on a resting
/// ragdoll's fifteen columns, 900 ns with eight, 750 with sixteen, f32), one where it has none
/// (a Cortex-M: the lanes would be done one by one, padding and all). The bits are the same
/// either way: each lane does the operations of a single solve, in their order.
pub(crate) const LANES: usize = if cfg!(any(
    target_arch = "x86_64",
    target_arch = "aarch64",
    target_feature = "simd128"
)) {
    16
} else {
    1
};

/// Each column of `b` that is not zero replaced by what `substitute` makes of it, [`LANES`]
/// columns side by side (by coordinate: `x[i][c]` is coordinate `i` of the `c`-th), zero
/// columns left as they are: each step of a substitution is then one operation on the lanes
/// rather than a chain of its own per column. The columns are read as slices in storage
/// order (nalgebra's column iterator walks an entry at a time through a strided iterator).
pub(crate) fn in_lanes<T: Real, const N: usize, const K: usize>(
    b: &mut SMatrix<T, N, K>,
    mut substitute: impl FnMut(&mut [[T; LANES]; N]),
) {
    if N == 0 {
        return;
    }
    let mut nonzero = [false; K];
    for (flag, column) in nonzero.iter_mut().zip(b.as_slice().chunks_exact(N)) {
        *flag = column.iter().any(|v| *v != T::zero());
    }
    let mut columns = (0..K).filter(|&k| nonzero[k]);
    loop {
        let mut which = [None::<usize>; LANES];
        let mut x = [[T::zero(); LANES]; N];
        for (slot, k) in which.iter_mut().zip(columns.by_ref()) {
            *slot = Some(k);
        }
        if which[0].is_none() {
            return;
        }
        for (c, &k) in which.iter().enumerate() {
            if let Some(column) = k.and_then(|k| b.as_slice().chunks_exact(N).nth(k)) {
                for (xi, v) in x.iter_mut().zip(column) {
                    xi[c] = *v;
                }
            }
        }
        substitute(&mut x);
        for (c, &k) in which.iter().enumerate() {
            if let Some(column) = k.and_then(|k| b.as_mut_slice().chunks_exact_mut(N).nth(k)) {
                for (v, xi) in column.iter_mut().zip(x.iter()) {
                    *v = xi[c];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `M` = a well-conditioned symmetric positive definite matrix of size `N`, with the
    /// diagonal entries `bad` set (`(index, value)`).
    fn with<const N: usize>(bad: &[(usize, f64)]) -> SMatrix<f64, N, N> {
        let mut m = SMatrix::<f64, N, N>::from_fn(|i, j| {
            if i == j {
                4.0
            } else {
                0.5 / (1.0 + (i + j) as f64)
            }
        });
        for &(k, v) in bad {
            m[(k, k)] = v;
            for j in 0..N {
                if j != k {
                    m[(k, j)] = 0.0;
                    m[(j, k)] = 0.0;
                }
            }
        }
        m
    }

    /// The first bad pivot decides the error, whether the pivots are checked in the loop
    /// (more than [`CHECKED_AFTER`] coordinates) or after it.
    fn first_bad_pivot_decides<const N: usize>() {
        let nan = f64::NAN;
        assert_eq!(
            Cholesky::factor(&with::<N>(&[(3, 0.0)])).err(),
            Some(Error::SingularMassMatrix { pivot: 3 })
        );
        assert_eq!(
            Cholesky::factor(&with::<N>(&[(2, nan), (4, 0.0)])).err(),
            Some(Error::NonFiniteState)
        );
        assert_eq!(
            Cholesky::factor(&with::<N>(&[(2, -1.0), (4, nan)])).err(),
            Some(Error::SingularMassMatrix { pivot: 2 })
        );
        assert_eq!(
            Cholesky::factor(&with::<N>(&[(N - 1, f64::INFINITY)])).err(),
            Some(Error::NonFiniteState)
        );
        let x = solve_spd(&with::<N>(&[]), &SVector::from_element(1.0));
        assert!(x.is_ok_and(|x| x.iter().all(|v| v.is_finite() && *v > 0.0)));
    }

    /// Twenty columns (three chunks of lanes), three of them zero (one of them `-0`
    /// somewhere): each column that is not zero the bits of its own solve, the zero ones
    /// untouched.
    #[test]
    fn columns_are_solved_bit_for_bit_as_one_by_one() -> Result<(), Error> {
        let f = Cholesky::factor(&with::<12>(&[]))?;
        let mut b = SMatrix::<f64, 12, 20>::from_fn(|i, k| ((i * 7 + k * 3) as f64).sin());
        for k in [1, 9, 19] {
            b.column_mut(k).fill(0.0);
        }
        b[(4, 9)] = -0.0;
        let before = b;
        f.solve_columns(&mut b);
        for k in 0..20 {
            let expected = if [1, 9, 19].contains(&k) {
                before.column(k).into_owned()
            } else {
                f.solve(&before.column(k).into_owned())
            };
            let same = b
                .column(k)
                .iter()
                .zip(expected.iter())
                .all(|(x, y)| x.to_bits() == y.to_bits());
            assert!(same, "column {k}");
        }
        Ok(())
    }

    #[test]
    fn the_first_bad_pivot_decides_the_error() {
        const { assert!(5 <= CHECKED_AFTER && CHECKED_AFTER < 12) };
        first_bad_pivot_decides::<5>();
        first_bad_pivot_decides::<12>();
    }
}
