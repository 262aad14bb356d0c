//! The sine and cosine behind [`Scalar`](crate::Scalar) for `f64` and `f32`.
//!
//! `f64` uses `libm`. `f32` uses the pure-`f32` [`fast_trig`](crate::fast_trig) by default, or
//! `libm::sinf`/`cosf` (which compute in `f64`) with the feature `libm-trig`. Either way the
//! same code runs on every target, so results are bit-identical between host and firmware built
//! with the same features.

pub(crate) use libm::{cos, sin};

/// `(sin x, cos x)` by `libm::sincos`: one argument reduction for both, bit for bit `libm`'s
/// `sin` and `cos` (a test sweeps every binade), a third faster than the two calls (9.4 against
/// 14.1 ns over angles within a few radians, x86_64).
#[inline]
pub(crate) fn sin_cos(x: f64) -> (f64, f64) {
    libm::sincos(x)
}

#[cfg(not(feature = "libm-trig"))]
pub(crate) use crate::fast_trig::{
    cos as cosf, cos_lanes as cos_lanesf, sin as sinf, sin_cos as sin_cosf,
    sin_cos_lanes as sin_cos_lanesf, sin_lanes as sin_lanesf,
};

#[cfg(feature = "libm-trig")]
pub(crate) use libm::{cosf, sinf};

/// `(sin x, cos x)` by `libm`.
#[cfg(feature = "libm-trig")]
#[inline]
pub(crate) fn sin_cosf(x: f32) -> (f32, f32) {
    (libm::sinf(x), libm::cosf(x))
}

/// `(sin x, cos x)` of each lane by `libm`.
#[cfg(feature = "libm-trig")]
#[inline]
pub(crate) fn sin_cos_lanesf<const L: usize>(x: [f32; L]) -> ([f32; L], [f32; L]) {
    (x.map(libm::sinf), x.map(libm::cosf))
}

/// `sin x` of each lane by `libm`.
#[cfg(feature = "libm-trig")]
#[inline]
pub(crate) fn sin_lanesf<const L: usize>(x: [f32; L]) -> [f32; L] {
    x.map(libm::sinf)
}

/// `cos x` of each lane by `libm`.
#[cfg(feature = "libm-trig")]
#[inline]
pub(crate) fn cos_lanesf<const L: usize>(x: [f32; L]) -> [f32; L] {
    x.map(libm::cosf)
}

#[cfg(test)]
mod tests {
    /// With `libm-trig`, the `f32` sines and cosines, alone and by lanes (both together and
    /// each alone), are libm's bit for bit, and so within an ulp of the `f64` ones rounded (libm's `sinf` computes in `f64`).
    #[cfg(feature = "libm-trig")]
    #[test]
    fn libm_trig_f32_is_libm_bit_for_bit() {
        let xs = [0.0f32, -0.0, 0.5, -1.25, 3.0, 100.0, -1e4, 1e-3];
        let near = |got: f32, exact: f64| {
            // One ulp of the f32 result: libm's f32 functions are within it.
            let ulp = f64::from(f32::EPSILON) * exact.abs().max(f64::from(f32::MIN_POSITIVE));
            (f64::from(got) - exact).abs() <= ulp
        };
        for x in xs {
            let (s, c) = super::sin_cosf(x);
            assert_eq!(s.to_bits(), libm::sinf(x).to_bits(), "sin({x:e})");
            assert_eq!(c.to_bits(), libm::cosf(x).to_bits(), "cos({x:e})");
            assert!(near(s, libm::sin(f64::from(x))), "sin({x:e}) = {s:e}");
            assert!(near(c, libm::cos(f64::from(x))), "cos({x:e}) = {c:e}");
        }
        let (s, c) = super::sin_cos_lanesf(xs);
        let (sin, cos) = (super::sin_lanesf(xs), super::cos_lanesf(xs));
        for (i, x) in xs.into_iter().enumerate() {
            assert_eq!(s[i].to_bits(), libm::sinf(x).to_bits(), "lane sin({x:e})");
            assert_eq!(c[i].to_bits(), libm::cosf(x).to_bits(), "lane cos({x:e})");
            assert_eq!(sin[i].to_bits(), s[i].to_bits(), "sin_lanes({x:e})");
            assert_eq!(cos[i].to_bits(), c[i].to_bits(), "cos_lanes({x:e})");
        }
    }

    /// `sin_cos` must be bit for bit `libm`'s `sin` and `cos`: the hand-derived laws, the
    /// automatic path and users' own code mix the two forms, and results are compared bit for
    /// bit across them. Swept: a few hundred arguments in every binade from the subnormals to
    /// `f64::MAX`, both signs, and the doubles nearest to multiples of pi/2 (where the
    /// reduction cancels most).
    #[test]
    fn sin_cos_is_sin_and_cos_bit_for_bit() {
        let mut checked = 0u32;
        let mut check = |x: f64| {
            let (s, c) = super::sin_cos(x);
            assert_eq!(s.to_bits(), libm::sin(x).to_bits(), "sin({x:e})");
            assert_eq!(c.to_bits(), libm::cos(x).to_bits(), "cos({x:e})");
            checked += 1;
        };
        for exponent in 0..2047u64 {
            for k in 0..256u64 {
                let mantissa = k.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 12;
                let x = f64::from_bits((exponent << 52) | mantissa);
                check(x);
                check(-x);
            }
        }
        for k in 1..20_000 {
            let x = f64::from(k) * core::f64::consts::FRAC_PI_2;
            check(x);
            check(f64::from_bits(x.to_bits() + 1));
            check(f64::from_bits(x.to_bits() - 1));
        }
        for x in [0.0, -0.0, f64::INFINITY, f64::NEG_INFINITY] {
            check(x);
        }
        assert_eq!(checked, 2 * 2047 * 256 + 3 * 19_999 + 4);
        let (s, c) = super::sin_cos(f64::NAN);
        assert!(s.is_nan() && c.is_nan());
    }
}
