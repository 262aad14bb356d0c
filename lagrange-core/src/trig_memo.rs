//! Sines and cosines remembered over one evaluation of a mechanism's energies, so that `T` and
//! `V` (and repeated calls within either) pay once for each angle.
//!
//! A kinetic and a potential energy usually take the sine and cosine of the same angles (a
//! pendulum's `cos th` is in both), and over the automatic path's derivative types each costs
//! both functions (the derivative of a sine is a cosine). The automatic path evaluates `T` and
//! `V` over the same [`Jet`](crate::jet::Jet)s, which refer to one memo: the second call for
//! an angle is a look-up. On the double pendulum, the cart-pole and the acrobot that was half
//! of the trigonometry of an automatic acceleration.

use crate::Scalar;
use core::cell::Cell;

/// How many angles one memo holds; a further angle is computed each time it is asked for.
/// Sixteen covers every mechanism small enough for the jet (below 11 coordinates, one or two
/// angles each) at 384 bytes of stack in `f64`.
const ENTRIES: usize = 16;

/// The sines and cosines computed so far: `(x, sin x, cos x)`, in the order first asked for.
///
/// Only for plain numbers (`f32`, `f64`): a hit returns the bits a new computation would,
/// since two non-zero floats that compare equal are the same float (zero, whose sine keeps its
/// sign, is never looked up; NaN equals nothing).
#[derive(Debug)]
pub(crate) struct TrigMemo<S: Scalar> {
    entries: [Cell<(S, S, S)>; ENTRIES],
    len: Cell<usize>,
}

impl<S: Scalar> TrigMemo<S> {
    /// An empty memo.
    pub(crate) fn new() -> Self {
        Self {
            entries: core::array::from_fn(|_| Cell::new((S::zero(), S::zero(), S::zero()))),
            len: Cell::new(0),
        }
    }

    /// `(sin x, cos x)`, from the memo when `x` was asked for before.
    #[inline]
    pub(crate) fn sin_cos(&self, x: S) -> (S, S) {
        if x.is_zero() {
            return x.sin_cos();
        }
        let len = self.len.get();
        let seen = self.entries.get(..len).unwrap_or_default();
        if let Some((_, s, c)) = seen.iter().map(Cell::get).find(|e| e.0 == x) {
            return (s, c);
        }
        let (s, c) = x.sin_cos();
        if let Some(free) = self.entries.get(len) {
            free.set((x, s, c));
            self.len.set(len + 1);
        }
        (s, c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every answer is the function's own, bit for bit, whether remembered, computed again
    /// when the memo is full, or never remembered (zeros of either sign).
    #[test]
    fn answers_are_the_functions_bit_for_bit() {
        let memo = TrigMemo::<f64>::new();
        let xs: [f64; 24] = core::array::from_fn(|k| 0.37 * k as f64 - 3.0);
        for round in 0..3 {
            for &x in xs.iter().chain(&[0.0, -0.0, 1e-300, -1e300, f64::INFINITY]) {
                let (s, c) = memo.sin_cos(x);
                let (s0, c0) = Scalar::sin_cos(x);
                assert_eq!(
                    (s.to_bits(), c.to_bits()),
                    (s0.to_bits(), c0.to_bits()),
                    "{x} in round {round}"
                );
            }
        }
        assert_eq!(memo.len.get(), ENTRIES);
        let (s, c) = memo.sin_cos(f64::NAN);
        assert!(s.is_nan() && c.is_nan());
    }

    /// A remembered angle is not computed again: the memo's stored answer is what comes back
    /// (checked by planting a wrong one).
    #[test]
    fn a_second_call_is_a_look_up() {
        let memo = TrigMemo::<f32>::new();
        let _ = memo.sin_cos(0.5);
        if let Some(e) = memo.entries.first() {
            e.set((0.5, 2.0, 3.0));
        }
        assert_eq!(memo.sin_cos(0.5), (2.0, 3.0));
        assert_eq!(memo.sin_cos(0.25), Scalar::sin_cos(0.25f32));
    }
}
