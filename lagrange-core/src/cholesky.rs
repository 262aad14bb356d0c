//! Fixed-size Cholesky solve of `M x = b` for a symmetric positive definite mass matrix.

use crate::{Error, Real};
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
    if x.iter().all(|v| v.is_finite()) {
        Ok(x)
    } else {
        Err(Error::NonFiniteState)
    }
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
            if !d.is_finite() {
                return Err(Error::NonFiniteState);
            }
            if d <= m[(j, j)].abs() * T::EPSILON {
                return Err(Error::SingularMassMatrix { pivot: j });
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
        Ok(Self { l, inv_d })
    }

    /// `x` with `m x = b`: `L y = b` forward, `x = D^-1 y`, then `L^T x = ...` backward, in
    /// place.
    #[must_use]
    pub fn solve(&self, b: &SVector<T, N>) -> SVector<T, N> {
        let l = &self.l;
        let mut x = *b;
        for i in 0..N {
            let mut s = x[i];
            for k in 0..i {
                s -= l[(i, k)] * x[k];
            }
            x[i] = s;
        }
        for i in (0..N).rev() {
            let mut s = x[i] * self.inv_d[i];
            for k in i + 1..N {
                s -= l[(k, i)] * x[k];
            }
            x[i] = s;
        }
        x
    }
}
