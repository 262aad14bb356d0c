//! [`TreeFactor`]: the mass matrix of a branched mechanism factored along its tree.

use crate::cholesky::{in_lanes, pivot};
use crate::{Error, Real};
use nalgebra::SMatrix;

/// No parent: a root of the tree.
const ROOT: usize = usize::MAX;

/// The factorisation `M = L^T D L` (`L` unit lower triangular, `D` diagonal) of a symmetric
/// positive definite matrix whose coordinates form a tree, each after its parent, and whose
/// entries are zero but between a coordinate and its ancestors: the mass matrix of a branched
/// mechanism in joint coordinates (a ragdoll's limbs each depend on the torso, not on each
/// other). Worked from the leaves to the roots (Featherstone's LTDL), it fills no entry that
/// the tree leaves zero: factoring costs about the sum over the coordinates of their depth
/// squared, and a solve twice the sum of their depths, where a dense factorisation costs
/// `N^3 / 6` and its solve `N^2` (a ragdoll's 12 coordinates, at most 5 deep: 40 multiply-adds
/// a solve rather than 144).
///
/// ```
/// use lagrange_core::nalgebra::{Matrix3, SMatrix};
/// use lagrange_core::TreeFactor;
/// // Coordinate 0 the root, 1 and 2 its two branches: they do not couple.
/// let m = Matrix3::new(4.0, 1.0, 1.0, 1.0, 2.0, 0.0, 1.0, 0.0, 3.0);
/// let f = TreeFactor::factor(&m, &[None, Some(0), Some(0)])?;
/// let mut b = SMatrix::<f64, 3, 1>::new(1.0, 2.0, 3.0);
/// f.solve_columns(&mut b);
/// assert!((m * b - SMatrix::<f64, 3, 1>::new(1.0, 2.0, 3.0)).amax() < 1e-15);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TreeFactor<T: Real, const N: usize> {
    /// `L` below the diagonal, along each coordinate's ancestors; `D` on it.
    h: SMatrix<T, N, N>,
    /// `1 / D`.
    inv_d: [T; N],
    /// Each coordinate's parent (`ROOT` for none).
    parent: [usize; N],
}

impl<T: Real, const N: usize> TreeFactor<T, N> {
    /// Factors `m` (reading its lower triangle along the tree alone) for the tree `parent`:
    /// each coordinate's parent, before it, or `None` for a root.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `parent` for a parent that does not come before its child;
    /// [`Error::SingularMassMatrix`] with the index of a pivot that is not positive (or lost
    /// every digit to cancellation); [`Error::NonFiniteState`] when `m` is not finite where
    /// it is read.
    pub fn factor(m: &SMatrix<T, N, N>, parent: &[Option<usize>; N]) -> Result<Self, Error> {
        let mut tree = [ROOT; N];
        for (i, (to, from)) in tree.iter_mut().zip(parent).enumerate() {
            match *from {
                Some(p) if p < i => *to = p,
                None => {}
                Some(_) => {
                    return Err(Error::InvalidParameter {
                        name: "parent",
                        reason: "each coordinate's parent must come before it",
                    })
                }
            }
        }
        let mut h = *m;
        let mut inv_d = [T::zero(); N];
        for k in (0..N).rev() {
            // Every descendant of k is done: its pivot is final.
            let d = h[(k, k)];
            pivot(d, m[(k, k)], k)?;
            let inv = d.recip();
            inv_d[k] = inv;
            let mut i = tree[k];
            while i < N {
                let a = h[(k, i)] * inv;
                let mut j = i;
                while j < N {
                    let kj = h[(k, j)];
                    h[(i, j)] -= a * kj;
                    j = tree[j];
                }
                h[(k, i)] = a;
                i = tree[i];
            }
        }
        Ok(Self {
            h,
            inv_d,
            parent: tree,
        })
    }

    /// Each column of `b` that is not zero replaced by `x` with `m x = b` (zero columns left
    /// as they are), sixteen side by side where the target has SIMD lanes (as
    /// [`Cholesky::solve_columns`](crate::Cholesky::solve_columns)).
    pub fn solve_columns<const K: usize>(&self, b: &mut SMatrix<T, N, K>) {
        in_lanes(b, |x| self.substitute(x));
    }

    /// `L^T z = b` from the leaves up (each coordinate, once final, taken from its
    /// ancestors), `y = D^-1 z`, then `L x = y` from the roots down, on each lane of `x`.
    fn substitute<const L: usize>(&self, x: &mut [[T; L]; N]) {
        let h = &self.h;
        for k in (0..N).rev() {
            let xk = x[k];
            let mut i = self.parent[k];
            while i < N {
                let l = h[(k, i)];
                for (a, b) in x[i].iter_mut().zip(xk) {
                    *a -= l * b;
                }
                i = self.parent[i];
            }
        }
        for (xk, inv) in x.iter_mut().zip(self.inv_d) {
            for a in xk.iter_mut() {
                *a *= inv;
            }
        }
        for k in 0..N {
            let mut s = x[k];
            let mut i = self.parent[k];
            while i < N {
                let l = h[(k, i)];
                for (a, b) in s.iter_mut().zip(x[i]) {
                    *a -= l * b;
                }
                i = self.parent[i];
            }
            x[k] = s;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::TreeFactor;
    use crate::{Cholesky, Error};
    use nalgebra::SMatrix;

    /// A tree of 7 coordinates (a root chain of two, then three branches, one of them two
    /// deep) and a matrix with its sparsity: the solves agree with the dense factor's to
    /// rounding, zero columns stay zero, and a child before its parent is refused.
    #[test]
    fn solves_as_the_dense_factor_does() -> Result<(), Error> {
        let parent = [None, Some(0), Some(1), Some(1), Some(3), Some(1), None];
        let ancestor = |mut i: usize, j: usize| loop {
            if i == j {
                return true;
            }
            match parent[i] {
                Some(p) => i = p,
                None => return false,
            }
        };
        let m = SMatrix::<f64, 7, 7>::from_fn(|i, j| {
            if i == j {
                5.0 + i as f64
            } else if ancestor(i, j) || ancestor(j, i) {
                0.7 / (1.0 + (i + j) as f64)
            } else {
                0.0
            }
        });
        let mut b = SMatrix::<f64, 7, 3>::from_fn(|i, j| {
            if j == 1 {
                0.0
            } else {
                1.0 + (i * (j + 2)) as f64
            }
        });
        let mut dense = b;
        TreeFactor::factor(&m, &parent)?.solve_columns(&mut b);
        Cholesky::factor(&m)?.solve_columns(&mut dense);
        assert!((b - dense).amax() < 1e-14, "{b} {dense}");
        assert!(b.column(1).iter().all(|x| *x == 0.0));
        let backwards = [None, Some(2), None, Some(1), Some(3), Some(1), None];
        assert_eq!(
            TreeFactor::factor(&m, &backwards).map(|_| ()),
            Err(Error::InvalidParameter {
                name: "parent",
                reason: "each coordinate's parent must come before it"
            })
        );
        Ok(())
    }
}
