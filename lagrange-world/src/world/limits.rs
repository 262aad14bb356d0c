//! A body's own rows ([`Limits`]): joint limits and the like, rows of its coordinates alone
//! that a [`World`](super::World) solves with its contacts.

use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, Real};

/// A body's own unilateral rows `g_i(q) >= 0` (joint limits), at most [`MAX_OWN_ROWS`]: a
/// [`World`](super::World) solves them with its contacts in the same impulse solve, every
/// step (a limb struck hard turns further in one step than any margin could foresee), so
/// that a ragdoll's limits hold while it is struck.
pub trait Limits<T: Real, const N: usize>: Clone {
    /// Calls `visit(index, gap, jacobian)` for each row at `q`: its index (stable from step
    /// to step: its warm start is matched by it), its gap and its Jacobian `dg/dq`.
    fn rows<F: FnMut(u32, T, SVector<T, N>)>(&self, q: &SVector<T, N>, visit: F);
}

/// The most rows a body's [`Limits`] may have.
pub const MAX_OWN_ROWS: usize = 32;

/// No rows of its own: a rigid body, a pendulum.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct NoLimits;

impl<T: Real, const N: usize> Limits<T, N> for NoLimits {
    fn rows<F: FnMut(u32, T, SVector<T, N>)>(&self, _: &SVector<T, N>, _: F) {}
}

/// Limits on `L` coordinates: `lower <= q[c] <= upper` for each (a ragdoll's joints), two
/// rows each (`2 k` the lower, `2 k + 1` the upper).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CoordinateLimits<const L: usize> {
    coordinates: [usize; L],
    bounds: [[f64; 2]; L],
}

impl<const L: usize> CoordinateLimits<L> {
    /// Coordinate `coordinates[k]` kept within `bounds[k] = [lower, upper]`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `bounds` when one is not finite or its lower is above its
    /// upper.
    pub fn new(coordinates: [usize; L], bounds: [[f64; 2]; L]) -> Result<Self, Error> {
        if bounds
            .iter()
            .any(|&[lo, hi]| !(lo.is_finite() && hi.is_finite() && lo <= hi))
        {
            return Err(Error::InvalidParameter {
                name: "bounds",
                reason: "each must be finite, its lower at most its upper",
            });
        }
        Ok(Self {
            coordinates,
            bounds,
        })
    }
}

impl<T: Real, const N: usize, const L: usize> Limits<T, N> for CoordinateLimits<L> {
    fn rows<F: FnMut(u32, T, SVector<T, N>)>(&self, q: &SVector<T, N>, mut visit: F) {
        for (k, (&c, &[lo, hi])) in self.coordinates.iter().zip(&self.bounds).enumerate() {
            let Some(&x) = q.get(c) else {
                continue;
            };
            let index = u32::try_from(2 * k).unwrap_or(u32::MAX - 1);
            let unit =
                |sign: T| SVector::<T, N>::from_fn(|i, _| if i == c { sign } else { T::zero() });
            visit(index, x - T::from_f64(lo), unit(T::one()));
            visit(index + 1, T::from_f64(hi) - x, unit(-T::one()));
        }
    }
}
