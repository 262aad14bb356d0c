//! Scalars: [`Scalar`], what a Lagrangian is written over, and [`Real`], `f32` or `f64`.
//!
//! All math goes through these traits to `libm` (or, for `f32` sine and cosine, to the pure-`f32`
//! [`fast_trig`](crate::fast_trig)), never to `std`'s inherent float methods, so the same code
//! gives the same bits on a desktop and on a Cortex-M.

use core::fmt::{Debug, Display, LowerExp};
use core::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};
use num_traits::{One, Zero};

use crate::scalar_trig;
use crate::Error;

/// A number a Lagrangian can be evaluated in: `f32`, `f64`, or a [`Dual`](crate::Dual) number
/// built on one of them (which is how the equations of motion are derived automatically).
///
/// Write kinetic and potential energies generic over `S: Scalar<Real = T>`, and they can be
/// both evaluated and differentiated. A scalar mixes with plain numbers of its [`Real`] type
/// (parameters, literals) on its right: `qd[0] * qd[0] * (0.5 * self.m)`, `q[1] * self.g`,
/// `x + 1.0`, `r / 2.0`. (Put the plain number on the right: Rust cannot make `0.5 * x` mean a
/// dual number `x` in code generic over `S`; there, [`Scalar::from_real`] lifts a value.)
///
/// A scalar need not be `'static`: for mechanisms of many coordinates the automatic path
/// records `T` and `V` on a tape on the stack, in numbers that borrow it. So nalgebra's
/// methods that ask for a `'static` scalar (`dot`, `norm_squared`, matrix products,
/// `SVector::new`) are not available on `S` inside a kinetic or potential energy: index the
/// vectors and sum with iterators (`qd.iter().fold(S::zero(), |s, &x| s + x * x)`). The
/// constraint traits, whose rows are only ever differentiated by dual numbers, ask for
/// `S: Scalar + 'static` and may use them.
pub trait Scalar:
    Copy
    + Debug
    + PartialEq
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + DivAssign
    + Add<<Self as Scalar>::Real, Output = Self>
    + Sub<<Self as Scalar>::Real, Output = Self>
    + Mul<<Self as Scalar>::Real, Output = Self>
    + Div<<Self as Scalar>::Real, Output = Self>
    + AddAssign<<Self as Scalar>::Real>
    + SubAssign<<Self as Scalar>::Real>
    + MulAssign<<Self as Scalar>::Real>
    + DivAssign<<Self as Scalar>::Real>
    + Zero
    + One
{
    /// The floating-point type underneath (`f32` or `f64`).
    type Real: Real;
    /// A constant: a parameter of the mechanism, with zero derivative.
    fn from_real(x: Self::Real) -> Self;
    /// A literal, rounded to the underlying precision (`0.5`, `2.0`, ...).
    fn from_f64(x: f64) -> Self;
    /// The plain value, with every derivative part dropped.
    fn value(self) -> Self::Real;
    /// Sine.
    fn sin(self) -> Self;
    /// Cosine.
    fn cos(self) -> Self;
    /// Sine and cosine together (cheaper than both apart for dual numbers).
    fn sin_cos(self) -> (Self, Self);
    /// Tangent.
    fn tan(self) -> Self;
    /// Square root.
    fn sqrt(self) -> Self;
    /// Natural exponential.
    fn exp(self) -> Self;
    /// Natural logarithm.
    fn ln(self) -> Self;
    /// Integer power, by repeated squaring (exact sequence of products on every target).
    fn powi(self, n: i32) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
    /// Four-quadrant arctangent of `self / x`.
    fn atan2(self, x: Self) -> Self;
    /// `1 / self`.
    fn recip(self) -> Self;
}

pub(crate) mod sealed {
    pub trait Sealed {}
    impl Sealed for f32 {}
    impl Sealed for f64 {}
}

/// A floating-point type the library computes in: `f32` or `f64` (sealed).
pub trait Real:
    Scalar<Real = Self> + 'static + PartialOrd + Default + Display + LowerExp + sealed::Sealed
{
    /// 1/2.
    const HALF: Self;
    /// 2.
    const TWO: Self;
    /// pi.
    const PI: Self;
    /// Machine epsilon.
    const EPSILON: Self;
    /// Positive infinity.
    const INFINITY: Self;
    /// The largest finite value.
    const MAX: Self;
    /// The smallest positive normal number (below it, precision is lost to subnormals).
    const MIN_POSITIVE: Self;
    /// `EPSILON^(1/3)`: the relative step of central differences that balances truncation
    /// against rounding (a constant, so that a Jacobian costs no `powf`).
    const CBRT_EPSILON: Self;
    /// `EPSILON^(1/2)`, as `EPSILON.sqrt()` rounds it: the pivot tests' share (a constant, so
    /// that a factorisation waits on no square root).
    const SQRT_EPSILON: Self;
    /// `EPSILON^(1/4)`, as `EPSILON.sqrt().sqrt()` rounds it.
    const FOURTH_ROOT_EPSILON: Self;
    /// Neither NaN nor infinite.
    fn is_finite(self) -> bool;
    /// Widen to `f64` (for reports and logs).
    fn to_f64(self) -> f64;
    /// Round to `f32` (for heuristics that need no more, such as a step-size controller:
    /// native single precision on a Cortex-M4F whatever the scalar).
    fn to_f32(self) -> f32;
    /// From an `f32`, exactly.
    fn from_f32(x: f32) -> Self;
    /// The larger of two values (the other one where one is NaN).
    fn max(self, other: Self) -> Self;
    /// The smaller of two values (the other one where one is NaN).
    fn min(self, other: Self) -> Self;
    /// Largest integer not above `self`.
    fn floor(self) -> Self;
    /// Nearest integer, halves away from zero.
    fn round(self) -> Self;
    /// Arcsine.
    fn asin(self) -> Self;
    /// Arccosine.
    fn acos(self) -> Self;
    /// Arctangent.
    fn atan(self) -> Self;
    /// `self` to a real power.
    fn powf(self, e: Self) -> Self;
    /// Sine and cosine of each of `L` values, bit for bit [`Scalar::sin_cos`] of each: what
    /// [`Lanes`](crate::Lanes) computes with (`f32`'s a vectorizable form of
    /// [`fast_trig`](crate::fast_trig)).
    fn sin_cos_lanes<const L: usize>(x: [Self; L]) -> ([Self; L], [Self; L]);
    /// The sine of each of `L` values: [`Real::sin_cos_lanes`]'s first half, bit for bit,
    /// without the cosine's work.
    fn sin_lanes<const L: usize>(x: [Self; L]) -> [Self; L];
    /// The cosine of each of `L` values: [`Real::sin_cos_lanes`]'s second half, bit for bit,
    /// without the sine's work.
    fn cos_lanes<const L: usize>(x: [Self; L]) -> [Self; L];
    /// True when every lane of every value is finite: [`all_finite`] for a plain scalar.
    /// Over [`Lanes`](crate::Lanes) it is data, not a branch taken for all lanes, so lanes
    /// that disagree count no divergence: for a test whose `false` fails the computation
    /// ([`check_finite`]), which a caller stepping lanes then takes one instance at a time.
    fn every_lane_finite(values: &[Self]) -> bool;
    /// True when every lane of every value is greater than zero (NaN is not): `x > 0` for
    /// each value of a plain scalar. Over [`Lanes`](crate::Lanes), as
    /// [`Real::every_lane_finite`], data that counts no divergence: for a test whose `false`
    /// fails the computation.
    fn every_lane_positive(values: &[Self]) -> bool;
}

/// True when every value is finite (neither NaN nor infinite).
///
/// Every value is tested, without stopping at the first that fails, over a slice: the tests
/// then vectorise, with one branch for all. (Over nalgebra's own iterators, `v.iter()`, they
/// do not: the test of a 40-coordinate chain's accelerations in `f32` took 70 ns that way, a
/// sixth of an RK4 step.) Give it a vector's `as_slice()`. Over [`Lanes`](crate::Lanes), where
/// each test of a value whose lanes disagree counts a divergence, not stopping at the first
/// failure may count more of them: the answer is the same.
///
/// ```
/// use lagrange_core::all_finite;
/// assert!(all_finite(&[1.0f32, -2.0, 0.0]));
/// assert!(!all_finite(&[1.0f64, f64::NAN]));
/// assert!(!all_finite(&[f32::INFINITY]));
/// ```
#[inline(always)]
#[must_use]
pub fn all_finite<T: Real>(values: &[T]) -> bool {
    values.iter().fold(true, |all, x| all & x.is_finite())
}

/// `a . b` over the shorter of the two, summed in four partial sums (terms `0, 4, 8, ...`
/// in the first, `1, 5, ...` in the second; then the first two and the last two added, and
/// the two sums): a chain of additions a quarter as long as one running sum's. What a sweep
/// of Gauss-Seidel wants, where each row's speed waits on the last row's impulse (the
/// impulse stepper's friction sweeps: a landing ragdoll's slowest step 6.5 -> 4.6 us). Not
/// the bits of a running sum (nalgebra's `dot`), but for four terms or fewer, which are one
/// running sum (no shorter chain exists; the empty partial sums would only add zeros to a
/// double pendulum's two terms).
///
/// ```
/// use lagrange_core::split_dot;
/// assert_eq!(split_dot(&[1.0f64, 2.0, 3.0], &[4.0, 5.0, 6.0]), 32.0);
/// assert_eq!(split_dot::<f32>(&[], &[]), 0.0);
/// ```
#[inline]
#[must_use]
pub fn split_dot<T: Real>(a: &[T], b: &[T]) -> T {
    if a.len().min(b.len()) <= 4 {
        let mut terms = a.iter().zip(b).map(|(x, y)| *x * *y);
        let first = terms.next().unwrap_or_else(T::zero);
        return terms.fold(first, |s, t| s + t);
    }
    let mut sums = [T::zero(); 4];
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        sums[k % 4] += *x * *y;
    }
    (sums[0] + sums[1]) + (sums[2] + sums[3])
}

/// `Ok(())` when every value is finite, else `Err(error)`: the test of a result before it is
/// returned.
///
/// As [`all_finite`], except over [`Lanes`](crate::Lanes): there the values must be finite in
/// every lane, and lanes that disagree count no divergence
/// ([`divergences`](crate::divergences)), since the error ends the computation for all of
/// them and a caller stepping lanes takes a failed step one instance at a time. A test
/// whose `false` does not end in an error (a branch between two formulas) must use
/// [`Real::is_finite`] or [`all_finite`], which count. Counting costs a branch per test, and
/// over lanes those branches kept the compiler from joining the tests of a step's stages:
/// stepping 1,024 `f32` pendulums in lanes of 8 took twice as long.
///
/// ```
/// use lagrange_core::{check_finite, Error};
/// assert_eq!(check_finite(&[1.0f64, 2.0], Error::NonFiniteState), Ok(()));
/// assert_eq!(check_finite(&[f32::NAN], Error::NonFiniteState), Err(Error::NonFiniteState));
/// ```
///
/// # Errors
/// `error` when a value (or a lane of one) is NaN or infinite.
#[inline(always)]
pub fn check_finite<T: Real>(values: &[T], error: Error) -> Result<(), Error> {
    if T::every_lane_finite(values) {
        Ok(())
    } else {
        Err(error)
    }
}

/// `sin_cos` of each value, one at a time.
#[inline]
pub(crate) fn sin_cos_each<S: Scalar, const L: usize>(x: [S; L]) -> ([S; L], [S; L]) {
    let (mut s, mut c) = (x, x);
    for ((si, ci), xi) in s.iter_mut().zip(&mut c).zip(x) {
        (*si, *ci) = xi.sin_cos();
    }
    (s, c)
}

/// The sine of each value, one at a time.
#[inline]
pub(crate) fn sin_each<S: Scalar, const L: usize>(x: [S; L]) -> [S; L] {
    x.map(Scalar::sin)
}

/// The cosine of each value, one at a time.
#[inline]
pub(crate) fn cos_each<S: Scalar, const L: usize>(x: [S; L]) -> [S; L] {
    x.map(Scalar::cos)
}

/// `x^n` by binary powering, shared by every scalar so all give the same sequence of products.
pub(crate) fn powi_by_squaring<S: Scalar>(x: S, n: i32) -> S {
    let mut base = if n < 0 { x.recip() } else { x };
    let mut e = n.unsigned_abs();
    let mut acc = S::one();
    while e > 0 {
        if e & 1 == 1 {
            acc *= base;
        }
        e >>= 1;
        if e > 0 {
            base = base * base;
        }
    }
    acc
}

macro_rules! impl_real {
    ($t:ident, $sin:ident, $cos:ident, $sin_cos:ident, $tan:ident, $sqrt:ident, $exp:ident,
     $ln:ident, $fabs:ident, $atan2:ident, $floor:ident, $round:ident, $asin:ident,
     $acos:ident, $atan:ident, $pow:ident, $lanes:path, $sin_lanes:path, $cos_lanes:path,
     $cbrt_eps:expr, $sqrt_eps:expr, $fourth_root_eps:expr) => {
        impl Scalar for $t {
            type Real = $t;
            #[inline]
            fn from_real(x: $t) -> $t {
                x
            }
            #[inline]
            #[allow(clippy::cast_possible_truncation)]
            fn from_f64(x: f64) -> $t {
                x as $t
            }
            #[inline]
            fn value(self) -> $t {
                self
            }
            #[inline]
            fn sin(self) -> $t {
                scalar_trig::$sin(self)
            }
            #[inline]
            fn cos(self) -> $t {
                scalar_trig::$cos(self)
            }
            #[inline]
            fn sin_cos(self) -> ($t, $t) {
                scalar_trig::$sin_cos(self)
            }
            #[inline]
            fn tan(self) -> $t {
                libm::$tan(self)
            }
            #[inline]
            fn sqrt(self) -> $t {
                libm::$sqrt(self)
            }
            #[inline]
            fn exp(self) -> $t {
                libm::$exp(self)
            }
            #[inline]
            fn ln(self) -> $t {
                libm::$ln(self)
            }
            #[inline]
            fn powi(self, n: i32) -> $t {
                powi_by_squaring(self, n)
            }
            #[inline]
            fn abs(self) -> $t {
                libm::$fabs(self)
            }
            #[inline]
            fn atan2(self, x: $t) -> $t {
                libm::$atan2(self, x)
            }
            #[inline]
            fn recip(self) -> $t {
                1.0 / self
            }
        }

        impl Real for $t {
            const HALF: $t = 0.5;
            const TWO: $t = 2.0;
            const PI: $t = core::$t::consts::PI;
            const EPSILON: $t = $t::EPSILON;
            const INFINITY: $t = $t::INFINITY;
            const MAX: $t = $t::MAX;
            const MIN_POSITIVE: $t = $t::MIN_POSITIVE;
            #[allow(clippy::excessive_precision)]
            const CBRT_EPSILON: $t = $cbrt_eps;
            #[allow(clippy::excessive_precision)]
            const SQRT_EPSILON: $t = $sqrt_eps;
            #[allow(clippy::excessive_precision)]
            const FOURTH_ROOT_EPSILON: $t = $fourth_root_eps;
            #[inline]
            fn is_finite(self) -> bool {
                $t::is_finite(self)
            }
            #[inline]
            fn to_f64(self) -> f64 {
                f64::from(self)
            }
            #[inline]
            #[allow(clippy::cast_possible_truncation)] // rounding to f32 is the point
            fn to_f32(self) -> f32 {
                self as f32
            }
            #[inline]
            fn from_f32(x: f32) -> $t {
                <$t>::from(x)
            }
            #[inline]
            fn max(self, other: $t) -> $t {
                $t::max(self, other)
            }
            #[inline]
            fn min(self, other: $t) -> $t {
                $t::min(self, other)
            }
            #[inline]
            fn floor(self) -> $t {
                libm::$floor(self)
            }
            #[inline]
            fn round(self) -> $t {
                libm::$round(self)
            }
            #[inline]
            fn asin(self) -> $t {
                libm::$asin(self)
            }
            #[inline]
            fn acos(self) -> $t {
                libm::$acos(self)
            }
            #[inline]
            fn atan(self) -> $t {
                libm::$atan(self)
            }
            #[inline]
            fn powf(self, e: $t) -> $t {
                libm::$pow(self, e)
            }
            #[inline(always)]
            fn sin_cos_lanes<const L: usize>(x: [$t; L]) -> ([$t; L], [$t; L]) {
                $lanes(x)
            }
            #[inline(always)]
            fn sin_lanes<const L: usize>(x: [$t; L]) -> [$t; L] {
                $sin_lanes(x)
            }
            #[inline(always)]
            fn cos_lanes<const L: usize>(x: [$t; L]) -> [$t; L] {
                $cos_lanes(x)
            }
            #[inline(always)]
            fn every_lane_finite(values: &[$t]) -> bool {
                all_finite(values)
            }
            #[inline(always)]
            fn every_lane_positive(values: &[$t]) -> bool {
                values.iter().fold(true, |all, &x| all & (x > 0.0))
            }
        }
    };
}

impl_real!(
    f64,
    sin,
    cos,
    sin_cos,
    tan,
    sqrt,
    exp,
    log,
    fabs,
    atan2,
    floor,
    round,
    asin,
    acos,
    atan,
    pow,
    sin_cos_each,
    sin_each,
    cos_each,
    6.055_454_452_393_343e-6,   // 2^(-52/3)
    1.490_116_119_384_765_6e-8, // 2^-26
    1.220_703_125e-4            // 2^-13
);
impl_real!(
    f32,
    sinf,
    cosf,
    sin_cosf,
    tanf,
    sqrtf,
    expf,
    logf,
    fabsf,
    atan2f,
    floorf,
    roundf,
    asinf,
    acosf,
    atanf,
    powf,
    scalar_trig::sin_cos_lanesf,
    scalar_trig::sin_lanesf,
    scalar_trig::cos_lanesf,
    4.921_566_4e-3, // 2^(-23/3)
    3.452_669_8e-4, // 2^-11.5, rounded
    1.858_136e-2    // its square root, rounded
);

#[cfg(test)]
mod tests {
    use super::{split_dot, Real};

    /// The roots of `EPSILON` are the ones the square root gives, bit for bit: a pivot test
    /// with the constant refuses the rows the computed root did.
    #[test]
    fn roots_of_epsilon_are_the_computed_ones() {
        fn check<T: Real>() {
            let root = T::EPSILON.sqrt();
            assert_eq!(T::SQRT_EPSILON.to_f64().to_bits(), root.to_f64().to_bits());
            let fourth = root.sqrt();
            assert_eq!(
                T::FOURTH_ROOT_EPSILON.to_f64().to_bits(),
                fourth.to_f64().to_bits()
            );
        }
        check::<f32>();
        check::<f64>();
    }

    /// The partial sums are the documented ones: terms `0, 4, ...` in the first, and so on,
    /// then `(first + second) + (third + fourth)`. With `1e16` against `-1e16` four terms
    /// apart, the ones beside them survive (a running sum, or sums of neighbours, lose them
    /// to rounding); twenty terms and none give their exact sums.
    #[test]
    fn partial_sums_as_documented() {
        let a = [1e16, 1.0, 1.0, 1.0, -1e16, 1.0, 1.0, 1.0];
        assert_eq!(split_dot(&a, &[1.0; 8]), 6.0);
        let twenty: [f64; 20] = core::array::from_fn(|k| k as f64);
        assert_eq!(split_dot(&twenty, &[2.0; 20]), 380.0);
        assert_eq!(split_dot::<f32>(&[], &[]), 0.0);
        // Over the shorter; four terms or fewer one running sum (1e16 + 1 is 1e16).
        assert_eq!(split_dot(&[1.0, 2.0, 3.0], &[1.0, 1.0]), 3.0);
        assert_eq!(split_dot(&[1e16, 1.0, -1e16, 1.0], &[1.0; 4]), 1.0);
        assert_eq!(split_dot(&[-0.0f64], &[1.0]).to_bits(), (-0.0f64).to_bits());
    }
}
