//! Pure-`f32` sine and cosine: what [`Real`](crate::Real) uses for `f32` by default.
//!
//! `libm::sinf` and `libm::cosf` compute in `f64` internally, which a Cortex-M4F emulates in
//! software; these stay in single precision and integer arithmetic, so an `f32` step costs a
//! fraction as much there, and the code is smaller. They use only IEEE-754 `f32` additions and
//! multiplications (never fused), exact conversions and integer operations, so every target
//! gives the same bits.
//!
//! # Method
//!
//! ```text
//! |x| <= pi/4         r = x, quadrant 0
//! pi/4 < |x| < 512    k = round(x 2/pi) (at most 326), r = x - k pi/2 with pi/2 split in
//!                     four f32s P1..P4, the first three of 15 bits so that k Pi is exact:
//!                     x - k P1 is exact, and error-free sums (TwoSum) carry the rest as
//!                     r_hi + r_lo, to about 2^-62 absolute
//! 512 <= |x| < inf    x 2/pi = k + f, k an integer, |f| <= 1/2, in fixed point:
//!                     x = m 2^e (m a 24-bit integer) times a 96-bit window of the bits of
//!                     2/pi (Payne-Hanek: only the bits that can change k mod 4 and f); then
//!                     r = f pi/2 as r_hi + r_lo, two f32s carrying 64 bits
//! sin r = r + r^3 S(r^2)          S, C: minimax polynomials on |r| <= pi/4 for the relative
//! cos r = 1 - r^2/2 + r^4 C(r^2)  error, fitted by `cargo xtask trig-fit`
//! then the quadrant k mod 4 selects +-sin r or +-cos r.
//! ```
//!
//! The fraction `f` is kept to 2^-71 absolute (the 2/pi bits past the window contribute less)
//! and normalised before the multiplication by pi/2, so `r_hi + r_lo` carries about 64
//! significant bits even where `x` is within a hair of a multiple of pi/2: large arguments lose
//! nothing.
//!
//! # Accuracy
//!
//! At most [`MAX_ULP_ERROR`] units in the last place against the exact value, for every finite
//! input. Infinities and NaN give NaN; `sin(-0.0) = -0.0`.
//!
//! ```
//! use lagrange_core::fast_trig;
//! let (s, c) = fast_trig::sin_cos(0.5);
//! assert_eq!((s, c), (fast_trig::sin(0.5), fast_trig::cos(0.5)));
//! assert!((s - 0.479_425_55).abs() <= 1e-7 && (c - 0.877_582_56).abs() <= 1e-7);
//! ```

/// The error bound, in units in the last place of the result, over every finite `f32` input.
///
/// The polynomials' own relative error (3.8e-9 for the sine, 1.2e-10 for the cosine: 0.06
/// and 0.002 ulp) plus the rounding of a handful of `f32` operations and of `r` stay inside
/// it. Measured (`tests/tests/fast_trig.rs`): 1.323 ulp at most over every finite `f32` (one
/// exhaustive run, 10 minutes on two threads); in every CI run, exhaustively over every `f32`
/// from 2^-12 to 2^20, 1.246 ulp without reduction, 1.287 with the medium and 1.315 with the
/// large reduction, and within the bound over sweeps of 2.8 million inputs in every binade,
/// random arguments, and the `f32`s nearest to multiples of pi/2. `libm::sinf`/`cosf`, for
/// comparison, are within 0.501 ulp.
pub const MAX_ULP_ERROR: f32 = 2.0;

/// Coefficients of `S(u)`, `u = r^2`, lowest degree first: `sin r = r + r^3 S(r^2)` on
/// `|r| <= pi/4`.
///
/// A weighted minimax fit for the relative error of `sin r`, rounded once to `f32`
/// (`cargo xtask trig-fit` derives and checks them).
pub const SIN_POLY: [f32; 3] = [-0.166_666_55, 0.008_332_16, -0.000_195_152_82];

/// Coefficients of `C(u)`, `u = r^2`, lowest degree first: `cos r = 1 - r^2/2 + r^4 C(r^2)`
/// on `|r| <= pi/4`.
///
/// A weighted minimax fit for the relative error of `cos r`, rounded once to `f32`
/// (`cargo xtask trig-fit` derives and checks them).
pub const COS_POLY: [f32; 3] = [0.041_666_646, -0.001_388_731_6, 2.443_315_7e-5];

/// The first 256 bits of the fraction of `2/pi` (`0.101000101111...` in binary), most
/// significant first: bit `i` (from 1) is bit `31 - (i - 1) % 32` of word `(i - 1) / 32`.
///
/// Enough for every finite `f32`: the reduction of `x = m 2^e` reads a 128-bit window starting
/// at bit `max(1, e - 1)`, and `e <= 104`. Derived by `cargo xtask trig-fit` from Machin's
/// formula.
pub const FRAC_2_PI_BITS: [u32; 8] = [
    0xa2f9_836e,
    0x4e44_1529,
    0xfc27_57d1,
    0xf534_ddc0,
    0xdb62_9599,
    0x3c43_9041,
    0xfe51_63ab,
    0xdebb_c561,
];

/// `pi/2` in unsigned fixed point with 62 fractional bits, rounded to nearest.
pub const FRAC_PI_2_FIXED: u64 = 0x6487_ed51_10b4_611a;

/// `pi/2 = P1 + P2 + P3 + P4` (to 2^-71): `P1`, `P2`, `P3` are consecutive 15-bit slices of
/// its binary expansion (so `k Pi` is exact for `k < 2^9`), `P4` the rest rounded to `f32`.
/// Derived by `cargo xtask trig-fit`.
pub const FRAC_PI_2_PARTS: [f32; 4] = [1.570_739_7, 5.657_971e-5, 9.920_882e-10, 5.390_303e-15];

/// The bits of `512.0`: inputs below it (and above pi/4) are reduced with
/// [`FRAC_PI_2_PARTS`], larger ones with [`FRAC_2_PI_BITS`].
const MEDIUM_BITS: u32 = 0x4400_0000;

/// The bits of the largest `f32` not above `pi/4`: inputs up to it need no reduction.
const FRAC_PI_4_BITS: u32 = 0x3f49_0fda;

/// The bits of `2^-12`: below it `sin x = x` to within 2^-25 relative (`x^2/6 < 2^-26`), and
/// returning `x` keeps the sign of zero, which `x + x^3 S` would lose.
const TINY_BITS: u32 = 0x3980_0000;

/// The sign bit of an `f32`.
const SIGN: u32 = 0x8000_0000;

/// A reduced argument: `x = k pi/2 + r_hi + r_lo` with `quadrant = k mod 4`.
#[derive(Clone, Copy)]
struct Reduced {
    /// `k mod 4`.
    quadrant: u32,
    /// The leading part of `r`, `|r| <= pi/4`.
    hi: f32,
    /// The rest of `r`, below one unit in the last place of `hi`.
    lo: f32,
}

/// `2^e` for `-126 <= e <= 127`, built from its bits (exact).
#[inline]
fn pow2(e: i32) -> f32 {
    let field = (e + 127).clamp(1, 254);
    #[allow(clippy::cast_sign_loss)] // clamped to 1..=254
    f32::from_bits((field as u32) << 23)
}

/// The 96 bits of [`FRAC_2_PI_BITS`] from bit `start + 1` on (`start` counted from 0), as the
/// low 96 bits of a `u128`, the earliest bit most significant.
#[inline]
fn window(start: u32) -> u128 {
    let word = (start / 32) as usize;
    let offset = start % 32;
    let at = |k: usize| u128::from(FRAC_2_PI_BITS[(word + k) & 7]);
    let t = (at(0) << 96) | (at(1) << 64) | (at(2) << 32) | at(3);
    (t << offset) >> 32
}

/// `(s, e)` with `s = fl(a + b)` and `a + b = s + e` exactly (Knuth's TwoSum).
#[inline]
fn two_sum(a: f32, b: f32) -> (f32, f32) {
    let s = a + b;
    let b_virtual = s - a;
    let e = (a - (s - b_virtual)) + (b - b_virtual);
    (s, e)
}

/// Reduces `pi/4 < ax < 512` modulo `pi/2` with [`FRAC_PI_2_PARTS`].
#[inline]
fn reduce_medium(ax: f32) -> Reduced {
    let [p1, p2, p3, p4] = FRAC_PI_2_PARTS;
    // k = round(ax 2/pi) <= 326; a k off by one near a half-integer only moves r a hair past
    // pi/4, where the polynomials are still accurate.
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // 1..=326
    let k = (ax * core::f32::consts::FRAC_2_PI + 0.5) as u32;
    #[allow(clippy::cast_precision_loss)] // below 2^9: exact
    let kf = k as f32;
    // Exact: k P1 has 24 bits, and ax - k P1 is a multiple of ulp(ax) below 1.
    let t1 = ax - kf * p1;
    let (t2, e2) = two_sum(t1, -(kf * p2));
    let (t3, e3) = two_sum(t2, -(kf * p3));
    let (hi, lo) = two_sum(t3, (e2 + e3) - kf * p4);
    Reduced {
        quadrant: k,
        hi,
        lo,
    }
}

/// Reduces a finite `|x| > pi/4` (given as its bits without the sign) modulo `pi/2`.
#[inline]
fn reduce(abs_bits: u32) -> Reduced {
    if abs_bits < MEDIUM_BITS {
        reduce_medium(f32::from_bits(abs_bits))
    } else {
        reduce_large(abs_bits)
    }
}

/// Reduces a finite `|x| >= 512` (given as its bits without the sign) modulo `pi/2`.
#[inline(never)]
fn reduce_large(abs_bits: u32) -> Reduced {
    // |x| = m 2^e with m a 24-bit integer (finite and at least 512, so normal; e >= -14).
    let m = (abs_bits & 0x007f_ffff) | 0x0080_0000;
    #[allow(clippy::cast_possible_wrap)] // an 8-bit field
    let e = (abs_bits >> 23) as i32 - 150;
    // Bits of 2/pi from position i0 on; earlier bits only add multiples of 4 to x 2/pi.
    let i0 = (e - 1).max(1);
    // x 2/pi mod 4 = (m W) 2^-s, W the 96-bit window from bit i0; s is in 94..=110.
    #[allow(clippy::cast_sign_loss)] // i0 >= 1
    let w = window((i0 - 1) as u32);
    #[allow(clippy::cast_sign_loss)] // 94..=110 for finite inputs from 512
    let s = (i0 + 95 - e) as u32;
    let p = u128::from(m) * w;
    // Quadrant bits at the top: shifting out the higher bits is the reduction mod 4.
    let g = p.wrapping_shl(126_u32.wrapping_sub(s));
    #[allow(clippy::cast_possible_truncation)] // two bits
    let quadrant = (g.wrapping_add(1 << 125) >> 126) as u32;
    // The fraction, rounded to the nearest quadrant: in [-1/2, 1/2) of 2^128.
    #[allow(clippy::cast_possible_wrap)] // two's complement is the point
    let f = (g << 2) as i128;
    let a = f.unsigned_abs();
    if a == 0 {
        return Reduced {
            quadrant,
            hi: 0.0,
            lo: 0.0,
        };
    }
    let lz = a.leading_zeros();
    #[allow(clippy::cast_possible_truncation)] // the top 64 bits
    let n = ((a << lz) >> 64) as u64;
    // r 2^(62 + lz) = n * (pi/2 2^62) / 2^64, with n in [2^63, 2^64).
    #[allow(clippy::cast_possible_truncation)] // the top 64 bits
    let hi64 = ((u128::from(n) * u128::from(FRAC_PI_2_FIXED)) >> 64) as u64;
    let z = hi64.leading_zeros();
    let norm = hi64 << z;
    // r = norm 2^-(62 + lz + z): its top 24 bits exactly, then the next 24 (truncated).
    #[allow(clippy::cast_possible_wrap)] // lz <= 128, z < 64
    let scale = -62 - (lz + z) as i32;
    #[allow(clippy::cast_possible_truncation)] // 24 bits
    let top = (norm >> 40) as u32;
    #[allow(clippy::cast_possible_truncation)] // 24 bits
    let next = ((norm >> 16) & 0x00ff_ffff) as u32;
    #[allow(clippy::cast_precision_loss)] // below 2^24: exact
    let (mut hi, mut lo) = (
        top as f32 * pow2(scale + 40),
        next as f32 * pow2(scale + 16),
    );
    if f < 0 {
        hi = -hi;
        lo = -lo;
    }
    Reduced { quadrant, hi, lo }
}

/// `sin r` for `|r| <= pi/4`.
#[inline]
fn sin_kernel(r: f32) -> f32 {
    let u = r * r;
    let p = SIN_POLY[0] + u * (SIN_POLY[1] + u * SIN_POLY[2]);
    r + r * u * p
}

/// `cos r` for `|r| <= pi/4`.
#[inline]
fn cos_kernel(r: f32) -> f32 {
    let u = r * r;
    let p = COS_POLY[0] + u * (COS_POLY[1] + u * COS_POLY[2]);
    (1.0 - 0.5 * u) + u * u * p
}

/// `sin(hi + lo)` for `|hi| <= pi/4`, `lo` below an ulp of `hi`:
/// `sin hi + lo cos hi`, with `cos hi ~ 1` to the precision `lo` needs.
#[inline]
fn sin_kernel_lo(hi: f32, lo: f32) -> f32 {
    let u = hi * hi;
    let p = SIN_POLY[0] + u * (SIN_POLY[1] + u * SIN_POLY[2]);
    hi + (hi * u * p + lo * (1.0 - 0.5 * u))
}

/// `cos(hi + lo)` for `|hi| <= pi/4`, `lo` below an ulp of `hi`: `cos hi - lo sin hi`.
#[inline]
fn cos_kernel_lo(hi: f32, lo: f32) -> f32 {
    let u = hi * hi;
    let p = COS_POLY[0] + u * (COS_POLY[1] + u * COS_POLY[2]);
    (1.0 - 0.5 * u) + (u * u * p - hi * lo)
}

/// Sine and cosine of a reduced argument, by quadrant.
#[inline]
fn by_quadrant(r: Reduced) -> (f32, f32) {
    let s = sin_kernel_lo(r.hi, r.lo);
    let c = cos_kernel_lo(r.hi, r.lo);
    match r.quadrant & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// Sine of `x` (radians), within [`MAX_ULP_ERROR`] ulp.
#[must_use]
pub fn sin(x: f32) -> f32 {
    let bits = x.to_bits();
    let abs = bits & !SIGN;
    if abs <= FRAC_PI_4_BITS {
        return if abs < TINY_BITS { x } else { sin_kernel(x) };
    }
    if abs >= 0x7f80_0000 {
        return f32::NAN; // for infinities and NaN
    }
    let r = reduce(abs);
    let s = match r.quadrant & 3 {
        0 => sin_kernel_lo(r.hi, r.lo),
        1 => cos_kernel_lo(r.hi, r.lo),
        2 => -sin_kernel_lo(r.hi, r.lo),
        _ => -cos_kernel_lo(r.hi, r.lo),
    };
    if bits & SIGN == 0 {
        s
    } else {
        -s
    }
}

/// Cosine of `x` (radians), within [`MAX_ULP_ERROR`] ulp.
#[must_use]
pub fn cos(x: f32) -> f32 {
    let abs = x.to_bits() & !SIGN;
    if abs <= FRAC_PI_4_BITS {
        return cos_kernel(x);
    }
    if abs >= 0x7f80_0000 {
        return f32::NAN;
    }
    let r = reduce(abs);
    match r.quadrant & 3 {
        0 => cos_kernel_lo(r.hi, r.lo),
        1 => -sin_kernel_lo(r.hi, r.lo),
        2 => -cos_kernel_lo(r.hi, r.lo),
        _ => sin_kernel_lo(r.hi, r.lo),
    }
}

/// Sine and cosine of `x` together, bit for bit `(sin(x), cos(x))`, reducing once.
#[must_use]
pub fn sin_cos(x: f32) -> (f32, f32) {
    let bits = x.to_bits();
    let abs = bits & !SIGN;
    if abs <= FRAC_PI_4_BITS {
        let s = if abs < TINY_BITS { x } else { sin_kernel(x) };
        return (s, cos_kernel(x));
    }
    if abs >= 0x7f80_0000 {
        return (f32::NAN, f32::NAN);
    }
    let (s, c) = by_quadrant(reduce(abs));
    if bits & SIGN == 0 {
        (s, c)
    } else {
        (-s, c)
    }
}

/// The bits of `|x|` as a signed integer (below 2^31: compared as such, the comparison
/// vectorizes where unsigned ones do not).
#[inline(always)]
#[allow(clippy::cast_possible_wrap)] // the sign bit is cleared
fn magnitude(x: f32) -> i32 {
    (x.to_bits() & !SIGN) as i32
}

/// `if take { a } else { b }` by the bits, with no branch (both computed: the lanes of a
/// vector take different sides).
#[inline(always)]
fn pick(take: bool, a: f32, b: f32) -> f32 {
    let mask = u32::from(take).wrapping_neg();
    f32::from_bits((a.to_bits() & mask) | (b.to_bits() & !mask))
}

/// `sin_cos` of each of `L` arguments, bit for bit [`sin_cos`] of each: when every lane is
/// within pi/4, the small path alone; else every lane up to 512 in magnitude takes the medium
/// path (a small one with no reduction, which gives the small path's bits), with no branch,
/// so that the loop vectorizes; the rare one beyond 512, infinite or NaN, is then done alone.
/// The same operations as [`sin_cos`], in the same order.
#[must_use]
#[inline(always)]
pub fn sin_cos_lanes<const L: usize>(x: [f32; L]) -> ([f32; L], [f32; L]) {
    if all_small(&x) {
        return (small_sin_lanes(&x), small_cos_lanes(&x));
    }
    sin_cos_lanes_reduced(x)
}

/// The sine of each of `L` arguments: [`sin_cos_lanes`]'s first half, bit for bit, without
/// the cosine's work where every lane is small (the compiler did not always drop it).
#[must_use]
#[inline(always)]
pub fn sin_lanes<const L: usize>(x: [f32; L]) -> [f32; L] {
    if all_small(&x) {
        return small_sin_lanes(&x);
    }
    sin_cos_lanes_reduced(x).0
}

/// The cosine of each of `L` arguments: [`sin_cos_lanes`]'s second half, bit for bit, as
/// [`sin_lanes`].
#[must_use]
#[inline(always)]
pub fn cos_lanes<const L: usize>(x: [f32; L]) -> [f32; L] {
    if all_small(&x) {
        return small_cos_lanes(&x);
    }
    sin_cos_lanes_reduced(x).1
}

/// True when every lane is within pi/4 (the small path), with one branch for all.
#[inline(always)]
fn all_small<const L: usize>(x: &[f32; L]) -> bool {
    let mut reduced = 0u32;
    for &xi in x {
        reduced |= u32::from(magnitude(xi) > FRAC_PI_4_BITS as i32);
    }
    reduced == 0
}

/// The small path's sine over the lanes, stage by stage (each stage a loop the compiler
/// vectorizes), the operations of `sin_kernel`; a tiny argument is itself, with no branch.
#[inline(always)]
#[allow(clippy::needless_range_loop)] // the formulas over two arrays at once
fn small_sin_lanes<const L: usize>(x: &[f32; L]) -> [f32; L] {
    let u = x.map(|r| r * r);
    let mut sin = [0.0; L];
    for i in 0..L {
        let (r, u) = (x[i], u[i]);
        let p = SIN_POLY[0] + u * (SIN_POLY[1] + u * SIN_POLY[2]);
        let kernel = r + r * u * p;
        sin[i] = pick(magnitude(r) < TINY_BITS as i32, r, kernel);
    }
    sin
}

/// The small path's cosine over the lanes, stage by stage, the operations of `cos_kernel`.
#[inline(always)]
fn small_cos_lanes<const L: usize>(x: &[f32; L]) -> [f32; L] {
    let u = x.map(|r| r * r);
    u.map(|u| {
        let p = COS_POLY[0] + u * (COS_POLY[1] + u * COS_POLY[2]);
        (1.0 - 0.5 * u) + u * u * p
    })
}

/// `v` truncated, as an integer and as an `f32`: `v as i32` and that as `f32` for
/// `0 <= v < 2^23` (the medium reduction's `k`), meaningless otherwise. In float and integer
/// operations that vectorize: `v as i32` saturates, which the compiler does lane by lane,
/// and the lanes' reduction took 5 times as long as the small path for it. `v + 2^23` rounds
/// `v` to the nearest integer in its low bits, exactly; one less where that rounded up.
#[inline(always)]
fn truncate(v: f32) -> (i32, f32) {
    const TWO_23: f32 = 8_388_608.0;
    let y = v + TWO_23;
    let nearest = y - TWO_23;
    let up = nearest > v;
    #[allow(clippy::cast_possible_wrap)] // the bits of y, an f32 of 2^23 or more
    let k = (y.to_bits() as i32)
        .wrapping_sub(TWO_23.to_bits() as i32)
        .wrapping_sub(i32::from(up));
    (k, nearest - pick(up, 1.0, 0.0))
}

/// [`sin_cos_lanes`] where some lane needs reducing: every lane through the medium path, the
/// small ones with `k = 0` (out of line, so that the small path inlines).
#[inline(never)]
fn sin_cos_lanes_reduced<const L: usize>(x: [f32; L]) -> ([f32; L], [f32; L]) {
    let [p1, p2, p3, p4] = FRAC_PI_2_PARTS;
    let (mut sin, mut cos) = ([0.0; L], [0.0; L]);
    let mut rare = 0u32;
    for ((s, c), &xi) in sin.iter_mut().zip(&mut cos).zip(&x) {
        let abs = magnitude(xi);
        let small = abs <= FRAC_PI_4_BITS as i32;
        // Medium, as `reduce_medium` (k below 2^9 where it matters, so a signed conversion
        // gives the same k); meaningless in the lanes that are rare, whose results come from
        // elsewhere. A small lane (|x| <= pi/4) takes k = 0: then `hi = |x|` and `lo = 0`
        // exactly, the `_lo` kernels add a zero to the plain kernels' last sums, and the
        // signs below restore `x`'s, so the small path's bits come out of the same formulas
        // (the kernels are odd and even to the bit), at the cost of one path, not two.
        let ax = xi.abs();
        let (k, kf) = truncate(ax * core::f32::consts::FRAC_2_PI + 0.5);
        let (k, kf) = (k & -i32::from(!small), pick(small, 0.0, kf));
        let t1 = ax - kf * p1;
        let (t2, e2) = two_sum(t1, -(kf * p2));
        let (t3, e3) = two_sum(t2, -(kf * p3));
        let (hi, lo) = two_sum(t3, (e2 + e3) - kf * p4);
        let ms = sin_kernel_lo(hi, lo);
        let mc = cos_kernel_lo(hi, lo);
        // by_quadrant, as selects: odd quadrants swap, then the signs of quadrants 2 and 3
        // (first) and 1 and 2 (second).
        let odd = k & 1 != 0;
        let (first, second) = (pick(odd, mc, ms), pick(odd, ms, mc));
        let first = pick(k & 2 != 0, -first, first);
        let second = pick(k.wrapping_add(1) & 2 != 0, -second, second);
        let sin = pick(xi.to_bits() & SIGN == 0, first, -first);
        // The small path returns a tiny `x` itself.
        *s = pick(abs < TINY_BITS as i32, xi, sin);
        *c = second;
        rare |= u32::from(abs >= MEDIUM_BITS as i32);
    }
    if rare != 0 {
        for ((s, c), &xi) in sin.iter_mut().zip(&mut cos).zip(&x) {
            if xi.to_bits() & !SIGN >= MEDIUM_BITS {
                (*s, *c) = sin_cos(xi);
            }
        }
    }
    (sin, cos)
}
