//! The PI step-size controller of the adaptive integrators.
//!
//! It works in `f32` whatever the scalar, with its own base-2 logarithm and exponential: a
//! step-size factor needs a few digits, not an ulp, and `libm`'s `ln` and `exp` in `f64` were
//! a tenth of a Dormand-Prince 8(5,3) step on a small mechanism. Pure `f32` arithmetic on the
//! bits, so the same on every target (native on a Cortex-M4F).

/// Safety factor of the step-size proposal.
const SAFETY: f32 = 0.9;
/// Smallest factor by which a step may shrink.
const FAC_MIN: f32 = 0.2;
/// Largest factor by which a step may grow.
const FAC_MAX: f32 = 10.0;
/// The PI controller's weight on the previous error (Hairer's `beta`).
const BETA: f32 = 0.04;
/// `log2` of the floor of the previous error kept by the controller (`1e-4`).
const LOG2_ERROR_FLOOR: f32 = -13.287_712;
/// Squared errors at or below this (errors of `1e-15`) grow the step by [`FAC_MAX`] (for any
/// order here, up to 8, `0.9 err^-alpha` is above 10 long before; it also keeps subnormals out
/// of [`log2`]).
const ERROR_SQ_NEGLIGIBLE: f32 = 1e-30;

/// The PI controller, given the square of the error estimate (see [`PiController::accept`]):
///
/// ```text
/// accepted (err <= 1):  factor = clamp(0.9 err^-(1/k - 0.75 beta) err_prev^beta, 0.2, 10),
///                       at most 1 right after a rejection; err_prev = max(err, 1e-4)
/// rejected:             factor = max(0.2, 0.9 err^(-1/k))   (0.2 for a NaN error)
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) struct PiController {
    /// `1/k`, the error estimate scaling like `h^k`.
    inv_k: f32,
    /// `1/k - 0.75 beta`.
    alpha: f32,
    /// `log2` of the previous accepted step's error, floored.
    log2_previous: f32,
    /// The last attempt was rejected.
    rejected_last: bool,
}

impl PiController {
    /// A controller for an error estimate of order `h^k`, with no history.
    pub(super) fn new(k: u32) -> Self {
        #[allow(clippy::cast_precision_loss)] // an order, below 20
        let inv_k = 1.0 / k as f32;
        Self {
            inv_k,
            alpha: inv_k - 0.75 * BETA,
            log2_previous: LOG2_ERROR_FLOOR,
            rejected_last: false,
        }
    }

    /// Forgets the history (a restart).
    pub(super) fn reset(&mut self) {
        self.log2_previous = LOG2_ERROR_FLOOR;
        self.rejected_last = false;
    }

    /// True when the last attempt was rejected.
    pub(super) fn rejected_last(&self) -> bool {
        self.rejected_last
    }

    /// The factor for the next step after one accepted with error `err` (`<= 1`), given
    /// `err_sq = err^2`: the adaptive pairs form the square (a sum of squares), and its
    /// logarithm halved is the error's, with no square root between.
    pub(super) fn accept(&mut self, err_sq: f32) -> f32 {
        let (factor, log2_err) = if err_sq > ERROR_SQ_NEGLIGIBLE {
            let l = 0.5 * log2(err_sq);
            let growth = SAFETY * exp2(BETA * self.log2_previous - self.alpha * l);
            (growth.clamp(FAC_MIN, FAC_MAX), l)
        } else {
            (FAC_MAX, LOG2_ERROR_FLOOR)
        };
        let factor = if self.rejected_last {
            factor.min(1.0)
        } else {
            factor
        };
        self.log2_previous = log2_err.max(LOG2_ERROR_FLOOR);
        self.rejected_last = false;
        factor
    }

    /// The factor by which to shrink a step rejected with error `err` (`> 1`, or NaN), given
    /// `err_sq = err^2` (an infinity where the square overflows: the factor is then the least
    /// anyway).
    pub(super) fn reject(&mut self, err_sq: f32) -> f32 {
        self.rejected_last = true;
        if err_sq.is_finite() {
            (SAFETY * exp2(-0.5 * self.inv_k * log2(err_sq))).max(FAC_MIN)
        } else {
            FAC_MIN
        }
    }
}

/// `log2 x` for a positive normal `x`, to about 1e-7 plus the rounding of the result to
/// `f32`: `x = 2^e m` with `m` in `[sqrt(1/2), sqrt 2)`, then
/// `ln m = 2 atanh((m - 1)/(m + 1))` by its series to `t^7` (`|t| <= 0.172`, so the first
/// omitted term is below 3e-8).
fn log2(x: f32) -> f32 {
    let bits = x.to_bits();
    #[allow(clippy::cast_possible_wrap)] // an 8-bit field
    let mut e = ((bits >> 23) & 0xff) as i32 - 127;
    let mut m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    if m > core::f32::consts::SQRT_2 {
        m *= 0.5;
        e += 1;
    }
    let t = (m - 1.0) / (m + 1.0);
    let t2 = t * t;
    let series = t * (1.0 + t2 * (1.0 / 3.0 + t2 * (1.0 / 5.0 + t2 * (1.0 / 7.0))));
    #[allow(clippy::cast_precision_loss)] // |e| <= 127
    let e = e as f32;
    e + 2.0 * core::f32::consts::LOG2_E * series
}

/// `2^y`, to about 2e-7 relative, for `y` in `[-126, 127]` (clamped there): `y = n + f` with
/// `|f| <= 1/2`, `2^f = e^(f ln 2)` by its Taylor series to the sixth power.
///
/// `n` is found by adding and taking away `1.5 2^23`, which rounds `y` to an integer in the
/// float unit, and read from the sum's low bits: no conversion to and from an integer register
/// on the chain from one step to the next.
fn exp2(y: f32) -> f32 {
    /// `1.5 2^23`: added to `|y| < 2^22`, the sum's ulp is 1, so the sum is `y` rounded.
    const ROUND: f32 = 12_582_912.0;
    let y = y.clamp(-126.0, 127.0);
    let shifted = y + ROUND;
    let x = (y - (shifted - ROUND)) * core::f32::consts::LN_2;
    // By Estrin's scheme, pairs of terms in x^2 and x^4 (three multiplications deep, where
    // Horner's rule is six).
    let x2 = x * x;
    let p = (1.0 + x)
        + x2 * (1.0 / 2.0 + x * (1.0 / 6.0))
        + x2 * x2 * ((1.0 / 24.0 + x * (1.0 / 120.0)) + x2 * (1.0 / 720.0));
    // The sum's bits less ROUND's are n (in -126..=127, two's complement); 2^n has the
    // exponent field n + 127.
    let n = shifted.to_bits().wrapping_sub(ROUND.to_bits());
    let scale = f32::from_bits(n.wrapping_add(127) << 23);
    p * scale
}

#[cfg(test)]
mod tests {
    use super::*;
    use lagrange_core::Real;

    /// Logarithms over the whole normal range and exponentials over the clamped one, against
    /// `f64`: within twice the errors the docs state.
    #[test]
    fn log2_and_exp2_match_f64() {
        let mut worst = (0.0f64, 0.0f64);
        let mut x = 1.5e-38f32;
        while x < 3e38 {
            let exact = f64::from(x).ln() / core::f64::consts::LN_2;
            // In units of 1e-7 plus the result's own rounding (half an f32 ulp, 6e-8 relative).
            let allowed = 1e-7 + 6e-8 * exact.abs();
            worst.0 = worst.0.max((f64::from(log2(x)) - exact).abs() / allowed);
            x *= 1.37;
        }
        let mut y = -125.9f32;
        let mut check = |y: f32| {
            let exact = (f64::from(y) * core::f64::consts::LN_2).exp();
            worst.1 = worst.1.max(((f64::from(exp2(y)) - exact) / exact).abs());
        };
        while y < 126.9 {
            check(y);
            y += 0.0173;
        }
        // The ends of the range, and halves, where the rounding of `y` to `n` ties.
        for y in [
            -126.0, 127.0, -125.5, 126.5, -2.5, -1.5, -0.5, 0.0, 0.5, 1.5, 2.5, 3.5,
        ] {
            check(y);
        }
        assert!(
            worst.0 < 2.0,
            "log2: worst error {} x the stated bound",
            worst.0
        );
        assert!(worst.1 < 4e-7, "exp2: worst relative error {:e}", worst.1);
    }

    /// The controller's factors against the formulas in `f64`.
    #[test]
    fn factors_follow_the_pi_formula() {
        let mut c = PiController::new(8);
        let (k, beta) = (8.0f64, 0.04f64);
        let alpha = 1.0 / k - 0.75 * beta;
        let mut previous = 1e-4f64;
        for err in [0.5f64, 1e-3, 0.9, 1e-6, 0.2] {
            let f = c.accept((err * err) as f32);
            let exact =
                (0.9 * Real::powf(err, -alpha) * Real::powf(previous, beta)).clamp(0.2, 10.0);
            assert!(
                (f64::from(f) - exact).abs() < 1e-5 * exact,
                "{err}: {f} vs {exact}"
            );
            previous = err.max(1e-4);
        }
        let shrink = c.reject(9.0);
        let exact = (0.9 * Real::powf(3.0f64, -1.0 / k)).max(0.2);
        assert!((f64::from(shrink) - exact).abs() < 1e-5);
        assert!(c.rejected_last());
        assert!(c.accept(1e-4) <= 1.0, "no growth right after a rejection");
        assert_eq!(c.reject(f32::NAN), FAC_MIN);
        assert_eq!(c.reject(f32::INFINITY), FAC_MIN, "a square that overflowed");
        assert_eq!(c.accept(0.0), 1.0, "capped at 1 after the rejection");
        assert_eq!(c.accept(0.0), FAC_MAX);
        c.reset();
        assert_eq!(c, PiController::new(8));
    }
}
