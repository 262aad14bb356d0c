//! [`Tangents`]: the friction directions of one step's contacts, each with its mobility
//! through the mechanism's own mass solve; and the rows' checks.

use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{Error, Real};

/// One tangent direction: its Jacobian row `j`, its mobility `b = M^-1 j^T` (the velocity
/// change of a unit impulse, from the mechanism's velocity jump, which keeps a constrained
/// mechanism's own constraints), and `1 / (j b)`, the impulse that changes its speed by one.
#[derive(Debug, Clone, Copy)]
pub(super) struct Direction<T: Real, const N: usize> {
    pub(super) j: SVector<T, N>,
    pub(super) b: SVector<T, N>,
    pub(super) inverse: T,
}

impl<T: Real, const N: usize> Direction<T, N> {
    /// The direction `j` with its mobility `b`; `None` where `j` moves nothing (a zero row:
    /// a joint limit has no tangent; or one the mechanism's own constraints hold).
    pub(super) fn new(j: SVector<T, N>, b: SVector<T, N>) -> Option<Self> {
        let d = j.dot(&b);
        // A direction whose own inverse mass is below the rounding of its terms moves nothing.
        let size = j
            .iter()
            .zip(b.iter())
            .fold(T::zero(), |s, (x, y)| s + (*x * *y).abs());
        (d > T::from_f64(64.0) * T::EPSILON * size).then(|| Self {
            j,
            b,
            inverse: d.recip(),
        })
    }
}

/// `rows` when every entry of the rows marked `used` is finite, else
/// [`Error::NonFiniteRow`] naming the first that is not.
pub(super) fn finite_rows<T: Real, const N: usize, const C: usize>(
    rows: SMatrix<T, C, N>,
    used: &[bool; C],
) -> Result<SMatrix<T, C, N>, Error> {
    match (0..C).find(|&i| used[i] && !rows.row(i).iter().all(|x| x.is_finite())) {
        Some(row) => Err(Error::NonFiniteRow { row }),
        None => Ok(rows),
    }
}

/// `gaps` when every gap is finite, else [`Error::NonFiniteRow`] naming the first that is not.
pub(super) fn finite_gaps<T: Real, const C: usize>(
    gaps: SVector<T, C>,
) -> Result<SVector<T, C>, Error> {
    match (0..C).find(|&i| !gaps[i].is_finite()) {
        Some(row) => Err(Error::NonFiniteRow { row }),
        None => Ok(gaps),
    }
}
