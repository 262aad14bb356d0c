//! The sine and cosine behind [`Scalar`](crate::Scalar) for `f64` and `f32`.
//!
//! `f64` uses `libm`. `f32` uses the pure-`f32` [`fast_trig`](crate::fast_trig) by default, or
//! `libm::sinf`/`cosf` (which compute in `f64`) with the feature `libm-trig`. Either way the
//! same code runs on every target, so results are bit-identical between host and firmware built
//! with the same features.

pub(crate) use libm::{cos, sin};

/// `(sin x, cos x)` by `libm`.
#[inline]
pub(crate) fn sin_cos(x: f64) -> (f64, f64) {
    (libm::sin(x), libm::cos(x))
}

#[cfg(not(feature = "libm-trig"))]
pub(crate) use crate::fast_trig::{
    cos as cosf, sin as sinf, sin_cos as sin_cosf, sin_cos_lanes as sin_cos_lanesf,
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
