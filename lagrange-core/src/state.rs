//! [`State`]: time, generalized coordinates and generalized velocities.

use crate::{all_finite, Error, Real};
use nalgebra::SVector;

/// The state of a mechanism with `N` degrees of freedom at time `t`.
///
/// Two halves rather than one `2N` vector, so that `N` stays a plain const generic.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State<T: Real, const N: usize> {
    /// Time, s.
    pub t: T,
    /// Generalized coordinates `q`.
    pub q: SVector<T, N>,
    /// Generalized velocities `q'`.
    pub qd: SVector<T, N>,
}

impl<T: Real, const N: usize> State<T, N> {
    /// A state at time `t` from coordinate and velocity arrays.
    #[must_use]
    pub fn new(t: T, q: [T; N], qd: [T; N]) -> Self {
        Self {
            t,
            q: SVector::from(q),
            qd: SVector::from(qd),
        }
    }

    /// At rest at time zero with coordinates `q`.
    #[must_use]
    pub fn at_rest(q: [T; N]) -> Self {
        Self::new(T::zero(), q, [T::zero(); N])
    }

    /// True when `t`, every coordinate and every velocity are finite.
    #[must_use]
    ///
    /// Every component is tested ([`all_finite`](crate::all_finite)), with one branch for all,
    /// in every step's check.
    #[inline]
    pub fn is_finite(&self) -> bool {
        self.t.is_finite() & all_finite(self.q.as_slice()) & all_finite(self.qd.as_slice())
    }

    /// `Ok(())` when finite, else [`Error::NonFiniteState`].
    ///
    /// Over [`Lanes`](crate::Lanes), every lane must be finite, and lanes that disagree count
    /// no divergence ([`check_finite`](crate::check_finite)). Inlined: called, it spilled
    /// every live float of a step in lanes around it.
    ///
    /// # Errors
    /// [`Error::NonFiniteState`] when any component is NaN or infinite.
    #[inline(always)]
    pub fn check_finite(&self) -> Result<(), Error> {
        if T::every_lane_finite(&[self.t])
            & T::every_lane_finite(self.q.as_slice())
            & T::every_lane_finite(self.qd.as_slice())
        {
            Ok(())
        } else {
            Err(Error::NonFiniteState)
        }
    }
}

#[cfg(feature = "defmt")]
impl<T: Real, const N: usize> defmt::Format for State<T, N> {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "State {{ t: {}, q: ", self.t.to_f64());
        format_vector(f, &self.q);
        defmt::write!(f, ", qd: ");
        format_vector(f, &self.qd);
        defmt::write!(f, " }}");
    }
}

/// Writes `[a, b, ...]` as `f64`s (nalgebra's vectors have no `defmt::Format`).
#[cfg(feature = "defmt")]
pub(crate) fn format_vector<T: Real, const N: usize>(f: defmt::Formatter<'_>, v: &SVector<T, N>) {
    defmt::write!(f, "[");
    for (i, x) in v.iter().enumerate() {
        if i > 0 {
            defmt::write!(f, ", ");
        }
        defmt::write!(f, "{}", x.to_f64());
    }
    defmt::write!(f, "]");
}
