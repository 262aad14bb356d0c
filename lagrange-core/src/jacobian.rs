//! [`Jacobian`]: derivatives with respect to `q` and `q'`, and the central-difference default
//! ([`central_difference_jacobian`]) that exact dual-number Jacobians override.

use crate::{all_finite, Real, State};
use nalgebra::{SMatrix, SVector};

/// The derivatives of a vector function `g(t, q, q')` of a state: `dg/dq` and `dg/dq'`, column
/// `j` holding the derivative along `q_j` (resp. `q'_j`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jacobian<T: Real, const N: usize> {
    /// `dg/dq`.
    pub wrt_q: SMatrix<T, N, N>,
    /// `dg/dq'`.
    pub wrt_qd: SMatrix<T, N, N>,
}

impl<T: Real, const N: usize> Jacobian<T, N> {
    /// Both blocks zero: the Jacobian of a constant.
    #[must_use]
    pub fn zeros() -> Self {
        Self {
            wrt_q: SMatrix::zeros(),
            wrt_qd: SMatrix::zeros(),
        }
    }

    /// True when every entry of both blocks is finite.
    #[must_use]
    pub fn is_finite(&self) -> bool {
        all_finite(self.wrt_q.as_slice()) & all_finite(self.wrt_qd.as_slice())
    }
}

impl<T: Real, const N: usize> core::ops::Sub for Jacobian<T, N> {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Self {
            wrt_q: self.wrt_q - o.wrt_q,
            wrt_qd: self.wrt_qd - o.wrt_qd,
        }
    }
}

impl<T: Real, const N: usize> core::ops::Add for Jacobian<T, N> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self {
            wrt_q: self.wrt_q + o.wrt_q,
            wrt_qd: self.wrt_qd + o.wrt_qd,
        }
    }
}

/// `(dg/dq, dg/dq')` at `state` by central differences, `4 N` evaluations of `g`.
///
/// ```text
/// dg/dx_j ~ (g(x + h_j e_j) - g(x - h_j e_j)) / (2 h_j),     h_j = EPSILON^(1/3) (1 + |x_j|)
/// ```
///
/// No error channel: where `g` or the state is not finite, entries are NaN or infinite
/// ([`Jacobian::is_finite`] tells; the implicit integrators refuse such a Jacobian).
///
/// The truncation error `O(h^2)` and the rounding error `O(EPSILON / h)` balance at a relative
/// accuracy of about `EPSILON^(2/3)`: ~4e-11 in `f64`, ~2e-5 in `f32`. Exact (to rounding) for
/// `g` linear in the state. That is accurate enough for a Newton matrix: Newton still converges
/// to the exact root, because the residual it drives to zero is evaluated exactly.
///
/// ```
/// use lagrange_core::{central_difference_jacobian, State};
/// use nalgebra::Vector1;
/// let s = State::new(0.0, [0.5], [2.0]);
/// let j = central_difference_jacobian(&s, |s: &State<f64, 1>| Vector1::new(s.q[0].sin() * s.qd[0]));
/// assert!((j.wrt_q[(0, 0)] - 0.5f64.cos() * 2.0).abs() < 1e-9);
/// assert!((j.wrt_qd[(0, 0)] - 0.5f64.sin()).abs() < 1e-9);
/// ```
pub fn central_difference_jacobian<T: Real, const N: usize>(
    state: &State<T, N>,
    mut g: impl FnMut(&State<T, N>) -> SVector<T, N>,
) -> Jacobian<T, N> {
    let rel = T::CBRT_EPSILON;
    let mut j = Jacobian::<T, N>::zeros();
    for k in 0..N {
        for velocity in [false, true] {
            let mut plus = *state;
            let mut minus = *state;
            let x = if velocity { state.qd[k] } else { state.q[k] };
            let h = rel * (T::one() + x.abs());
            let (xp, xm) = (x + h, x - h);
            if velocity {
                plus.qd[k] = xp;
                minus.qd[k] = xm;
            } else {
                plus.q[k] = xp;
                minus.q[k] = xm;
            }
            // Divide by the step actually represented, not the one intended.
            let column = (g(&plus) - g(&minus)) / (xp - xm);
            if velocity {
                j.wrt_qd.set_column(k, &column);
            } else {
                j.wrt_q.set_column(k, &column);
            }
        }
    }
    j
}

#[cfg(test)]
mod tests {
    use crate::Real;

    /// The constant step is the cube root of epsilon to the precision of its type (its own
    /// rounding, tripled, and the rounding of the product: measured 8 ulp in f64).
    #[test]
    fn cbrt_epsilon_is_the_cube_root() {
        let r64 = f64::CBRT_EPSILON * f64::CBRT_EPSILON * f64::CBRT_EPSILON / f64::EPSILON;
        let r32 = f32::CBRT_EPSILON * f32::CBRT_EPSILON * f32::CBRT_EPSILON / f32::EPSILON;
        assert!((r64 - 1.0).abs() < 16.0 * f64::EPSILON, "{r64}");
        assert!((r32 - 1.0).abs() < 16.0 * f32::EPSILON, "{r32}");
    }
}
