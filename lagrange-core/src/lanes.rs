//! [`Lanes`]: `L` values of a [`Real`] side by side, one per lane, so that any mechanism and
//! any integrator written for a [`Real`] steps `L` instances at once, each lane bit for bit
//! what the same code gives for that instance alone.
//!
//! Arithmetic and every function act lane by lane with the scalar's own operation (over a vector
//! unit the lane sine and cosine of `f32` are [`sin_cos_lanes`], bit for bit the scalar ones;
//! elsewhere the scalar `sin` and `cos`, lane by lane): plain arrays, which the compiler
//! vectorizes, no fused multiply-add. What cannot act lane by lane is a branch: code that compares
//! values takes one branch for all lanes. A comparison is therefore true when it holds in every
//! lane, false when in none, and when the lanes disagree it answers false and counts a divergence
//! ([`divergences`]). A caller that steps lanes reads the count before and after: unchanged, every
//! lane took the branch its instance alone would have taken and the result is exact; changed, it
//! discards the result and steps the instances one by one.
//!
//! The tests of a result before it is returned ([`check_finite`](crate::check_finite),
//! [`Real::every_lane_finite`], [`Real::every_lane_positive`]) are data, not branches taken
//! for all lanes: they hold when they hold in every lane and count nothing, because their
//! failure is an error, which ends the computation for every lane, and a caller stepping lanes
//! takes a failed step one instance at a time. Counting is a branch per test, and those
//! branches kept the compiler from joining the tests of a step's stages.
//!
//! [`sin_cos_lanes`]: crate::fast_trig::sin_cos_lanes

use crate::scalar::{cos_each, powi_by_squaring, sin_cos_each, sin_each, Real, Scalar};
use core::cmp::Ordering;
use core::fmt;
use core::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};
use num_traits::{One, Zero};

/// `L` values side by side: a [`Real`] whose every operation acts lane by lane, each lane with
/// the bits the scalar operation gives. A comparison holds when it holds in every lane; where
/// the lanes disagree it is false and counts a divergence ([`divergences`]), so that a caller
/// stepping lanes can tell that one branch was taken for lanes that needed different ones, and
/// step the instances one by one instead.
///
/// ```
/// use lagrange_core::{Lanes, Real, Scalar};
/// let x = Lanes([0.5f32, 1.0, 2.0, 3.0]);
/// let y = x.sin() * 2.0 + Lanes::splat(1.0);
/// for (lane, &xi) in x.0.iter().enumerate() {
///     assert_eq!(y.0[lane], xi.sin() * 2.0 + 1.0); // bit for bit
/// }
/// ```
///
/// Aligned to 32 bytes (a 256-bit vector; a smaller `Lanes` is padded to that size): left at
/// the alignment of `T`, the compiler grouped the 8 lanes of an `f32` pendulum as 2, 4 and 2
/// rather than 4 and 4, and stepping 1,024 of them in lanes of 8 took 1.25 times as long.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(32))]
pub struct Lanes<T, const L: usize>(pub [T; L]);

impl<T: Real, const L: usize> Lanes<T, L> {
    /// `x` in every lane.
    #[must_use]
    pub const fn splat(x: T) -> Self {
        Self([x; L])
    }

    /// `f` of each lane's index.
    #[must_use]
    pub fn from_fn(f: impl FnMut(usize) -> T) -> Self {
        Self(core::array::from_fn(f))
    }

    /// One field of `L` instances, lane `i` from `instances[i]`: how a mechanism gathers its
    /// parameters ([`Gather::gather`](crate::Gather::gather)).
    #[must_use]
    #[inline(always)]
    pub fn gather<M>(instances: &[&M; L], field: impl Fn(&M) -> T) -> Self {
        Self(core::array::from_fn(|i| field(instances[i])))
    }

    /// `W` lanes from lane `at` on; lanes past the end repeat the last lane (how a bank takes
    /// a group of its instances from all of them gathered: [`Gather::window`]).
    ///
    /// ```
    /// use lagrange_core::Lanes;
    /// let all = Lanes([1.0f32, 2.0, 3.0, 4.0, 5.0, 6.0]);
    /// assert_eq!(all.window::<4>(2).0, [3.0, 4.0, 5.0, 6.0]);
    /// assert_eq!(all.window::<4>(4).0, [5.0, 6.0, 6.0, 6.0]);
    /// ```
    ///
    /// [`Gather::window`]: crate::Gather::window
    #[must_use]
    #[inline(always)]
    pub fn window<const W: usize>(&self, at: usize) -> Lanes<T, W> {
        let inside = self.0.get(at..).and_then(|rest| rest.get(..W));
        match inside.and_then(|lanes| <[T; W]>::try_from(lanes).ok()) {
            // One load of `W` lanes where they are all there.
            Some(lanes) => Lanes(lanes),
            None => self.window_past_end(at),
        }
    }

    /// [`Lanes::window`] where it runs past the end (out of line: a bank's last group).
    #[cold]
    #[inline(never)]
    fn window_past_end<const W: usize>(&self, at: usize) -> Lanes<T, W> {
        let last = self.0.last().copied().unwrap_or_else(T::zero);
        Lanes(core::array::from_fn(|i| {
            at.checked_add(i)
                .and_then(|j| self.0.get(j))
                .copied()
                .unwrap_or(last)
        }))
    }

    /// Sets lane `lane` to `x`; nothing when `lane` is not below `L` (how a bank writes an
    /// instance into its gathered mechanism: [`Gather::put`]).
    ///
    /// [`Gather::put`]: crate::Gather::put
    #[inline(always)]
    pub fn set(&mut self, lane: usize, x: T) {
        if let Some(slot) = self.0.get_mut(lane) {
            *slot = x;
        }
    }

    /// `f` of each lane.
    #[inline(always)]
    fn map(self, mut f: impl FnMut(T) -> T) -> Self {
        let mut out = self.0;
        for x in &mut out {
            *x = f(*x);
        }
        Self(out)
    }

    /// `f` of each pair of lanes.
    #[inline(always)]
    fn zip(self, other: Self, mut f: impl FnMut(T, T) -> T) -> Self {
        let mut out = self.0;
        for (x, y) in out.iter_mut().zip(other.0) {
            *x = f(*x, y);
        }
        Self(out)
    }

    /// `test` in every lane, in none, or (a divergence, counted) in some.
    #[inline(always)]
    fn all(self, other: Self, test: impl Fn(T, T) -> bool) -> bool {
        let (mut every, mut any) = (true, false);
        for (x, y) in self.0.into_iter().zip(other.0) {
            let yes = test(x, y);
            every &= yes;
            any |= yes;
        }
        if any && !every {
            diverged();
        }
        every
    }
}

#[cfg(target_has_atomic = "32")]
static DIVERGENCES: core::sync::atomic::AtomicU32 = core::sync::atomic::AtomicU32::new(0);

/// Counts a comparison on which the lanes disagreed.
#[cold]
fn diverged() {
    #[cfg(target_has_atomic = "32")]
    DIVERGENCES.fetch_add(1, core::sync::atomic::Ordering::Relaxed);
}

/// Comparisons on which the lanes of some [`Lanes`] disagreed, so far, in this program (any
/// thread; it wraps). `None` on a target without 32-bit atomics, where divergences cannot be
/// counted and lanes must not be used to step instances.
#[must_use]
pub fn divergences() -> Option<u32> {
    #[cfg(target_has_atomic = "32")]
    {
        Some(DIVERGENCES.load(core::sync::atomic::Ordering::Relaxed))
    }
    #[cfg(not(target_has_atomic = "32"))]
    {
        None
    }
}

impl<T: Real, const L: usize> Default for Lanes<T, L> {
    fn default() -> Self {
        Self::splat(T::zero())
    }
}

/// Equal in every lane; lanes that disagree count a divergence.
impl<T: Real, const L: usize> PartialEq for Lanes<T, L> {
    fn eq(&self, other: &Self) -> bool {
        self.all(*other, |x, y| x == y)
    }
}

/// An order that holds in every lane; lanes that disagree count a divergence and compare as
/// unordered.
impl<T: Real, const L: usize> PartialOrd for Lanes<T, L> {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        let mut orders = self.0.iter().zip(&other.0).map(|(x, y)| x.partial_cmp(y));
        let first = orders.next().flatten();
        if orders.all(|o| o == first) {
            first
        } else {
            diverged();
            None
        }
    }
    fn lt(&self, other: &Self) -> bool {
        self.all(*other, |x, y| x < y)
    }
    fn le(&self, other: &Self) -> bool {
        self.all(*other, |x, y| x <= y)
    }
    fn gt(&self, other: &Self) -> bool {
        self.all(*other, |x, y| x > y)
    }
    fn ge(&self, other: &Self) -> bool {
        self.all(*other, |x, y| x >= y)
    }
}

impl<T: Real, const L: usize> fmt::Display for Lanes<T, L> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("[")?;
        for (i, x) in self.0.iter().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            fmt::Display::fmt(x, f)?;
        }
        f.write_str("]")
    }
}

impl<T: Real, const L: usize> fmt::LowerExp for Lanes<T, L> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("[")?;
        for (i, x) in self.0.iter().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            fmt::LowerExp::fmt(x, f)?;
        }
        f.write_str("]")
    }
}

/// The arithmetic operators, lane by lane, with lanes and with a plain value on the right.
macro_rules! lane_ops {
    ($($op:ident $method:ident $assign:ident $assign_method:ident),*) => {$(
        impl<T: Real, const L: usize> $op for Lanes<T, L> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, other: Self) -> Self {
                self.zip(other, |x, y| $op::$method(x, y))
            }
        }
        impl<T: Real, const L: usize> $op<T> for Lanes<T, L> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, other: T) -> Self {
                self.map(|x| $op::$method(x, other))
            }
        }
        impl<T: Real, const L: usize> $assign for Lanes<T, L> {
            #[inline(always)]
            fn $assign_method(&mut self, other: Self) {
                *self = $op::$method(*self, other);
            }
        }
        impl<T: Real, const L: usize> $assign<T> for Lanes<T, L> {
            #[inline(always)]
            fn $assign_method(&mut self, other: T) {
                *self = $op::$method(*self, other);
            }
        }
    )*};
}

lane_ops!(
    Add add AddAssign add_assign,
    Sub sub SubAssign sub_assign,
    Mul mul MulAssign mul_assign,
    Div div DivAssign div_assign
);

impl<T: Real, const L: usize> Neg for Lanes<T, L> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        self.map(|x| -x)
    }
}

impl<T: Real, const L: usize> Zero for Lanes<T, L> {
    fn zero() -> Self {
        Self::splat(T::zero())
    }
    fn is_zero(&self) -> bool {
        self.all(*self, |x, _| x.is_zero())
    }
}

impl<T: Real, const L: usize> One for Lanes<T, L> {
    fn one() -> Self {
        Self::splat(T::one())
    }
}

/// A function of one argument, lane by lane.
macro_rules! lane_fns {
    ($($name:ident),*) => {$(
        #[inline(always)]
        fn $name(self) -> Self {
            self.map(|x| x.$name())
        }
    )*};
}

impl<T: Real, const L: usize> Scalar for Lanes<T, L> {
    type Real = Self;
    fn from_real(x: Self) -> Self {
        x
    }
    fn from_f64(x: f64) -> Self {
        Self::splat(T::from_f64(x))
    }
    fn value(self) -> Self {
        self
    }
    /// The scalar sine of each lane: over a vector unit, through [`Real::sin_lanes`]
    /// (branch-free, the lanes together); elsewhere lane by lane with the scalar's branches,
    /// which cost less than computing both of its paths for every lane.
    #[inline(always)]
    fn sin(self) -> Self {
        if VECTOR_UNIT {
            Self(T::sin_lanes(self.0))
        } else {
            self.map(Scalar::sin)
        }
    }
    /// The scalar cosine of each lane (as [`Lanes::sin`]).
    #[inline(always)]
    fn cos(self) -> Self {
        if VECTOR_UNIT {
            Self(T::cos_lanes(self.0))
        } else {
            self.map(Scalar::cos)
        }
    }
    /// The scalar sine and cosine of each lane (as [`Lanes::sin`]).
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = if VECTOR_UNIT {
            T::sin_cos_lanes(self.0)
        } else {
            sin_cos_each(self.0)
        };
        (Self(s), Self(c))
    }
    lane_fns!(tan, sqrt, exp, ln, abs, recip);
    fn powi(self, n: i32) -> Self {
        powi_by_squaring(self, n)
    }
    fn atan2(self, x: Self) -> Self {
        self.zip(x, |y, x| y.atan2(x))
    }
}

impl<T: Real, const L: usize> crate::scalar::sealed::Sealed for Lanes<T, L> {}

impl<T: Real, const L: usize> Real for Lanes<T, L> {
    const HALF: Self = Self::splat(T::HALF);
    const TWO: Self = Self::splat(T::TWO);
    const PI: Self = Self::splat(T::PI);
    const EPSILON: Self = Self::splat(T::EPSILON);
    const INFINITY: Self = Self::splat(T::INFINITY);
    const MAX: Self = Self::splat(T::MAX);
    const MIN_POSITIVE: Self = Self::splat(T::MIN_POSITIVE);
    const CBRT_EPSILON: Self = Self::splat(T::CBRT_EPSILON);
    const SQRT_EPSILON: Self = Self::splat(T::SQRT_EPSILON);
    const FOURTH_ROOT_EPSILON: Self = Self::splat(T::FOURTH_ROOT_EPSILON);

    /// Finite in every lane (lanes that disagree count a divergence).
    fn is_finite(self) -> bool {
        self.all(self, |x, _| x.is_finite())
    }
    /// The first lane (lanes that differ count a divergence: a report of one lane only).
    fn to_f64(self) -> f64 {
        self.first_if_uniform().to_f64()
    }
    /// The first lane (lanes that differ count a divergence).
    fn to_f32(self) -> f32 {
        self.first_if_uniform().to_f32()
    }
    fn from_f32(x: f32) -> Self {
        Self::splat(T::from_f32(x))
    }
    fn max(self, other: Self) -> Self {
        self.zip(other, Real::max)
    }
    fn min(self, other: Self) -> Self {
        self.zip(other, Real::min)
    }
    lane_fns!(floor, round, asin, acos, atan);
    fn powf(self, e: Self) -> Self {
        self.zip(e, Real::powf)
    }
    fn sin_cos_lanes<const K: usize>(x: [Self; K]) -> ([Self; K], [Self; K]) {
        sin_cos_each(x)
    }
    fn sin_lanes<const K: usize>(x: [Self; K]) -> [Self; K] {
        sin_each(x)
    }
    fn cos_lanes<const K: usize>(x: [Self; K]) -> [Self; K] {
        cos_each(x)
    }
    /// Every lane of every value finite, with no branch per lane and no divergence counted:
    /// over a vector unit one AND a lane (`x * 0 == 0`), elsewhere one sum of `x * 0` over
    /// them all, compared with zero once.
    #[inline(always)]
    fn every_lane_finite(values: &[Self]) -> bool {
        if VECTOR_UNIT {
            every_lane_finite_and(values)
        } else {
            every_lane_finite_sum(values)
        }
    }
    /// Every lane of every value positive, one AND with no branch (see
    /// [`Lanes::every_lane_finite`]).
    #[inline(always)]
    fn every_lane_positive(values: &[Self]) -> bool {
        let mut positive = true;
        for value in values {
            for x in value.0 {
                positive &= x > T::zero();
            }
        }
        positive
    }
}

/// Whether [`Lanes`] map onto a vector unit on the target built for: x86_64 (SSE2), aarch64
/// (NEON) and wasm32 built with `simd128` (`-C target-feature=+simd128`). Where they do not
/// (the Cortex-M4F, wasm32 without `simd128`), lanes give the same bits at no gain, and a
/// scene's bank steps its instances one by one.
///
/// Inside, it chooses the lanes' sine and test of finiteness: where there is no vector unit a
/// lane's sine goes lane by lane through the scalar's branches, and the test is a sum, because
/// the branch-free forms a vector unit needs cost more there (the lanes of 4 pendulums took
/// 1.14 times the instructions of one by one with them on the Cortex-M4F).
pub const VECTOR_UNIT: bool = cfg!(any(
    target_arch = "x86_64",
    target_arch = "aarch64",
    all(target_arch = "wasm32", target_feature = "simd128")
));

/// Every lane of every value finite (`x * 0` is zero exactly where `x` is finite), one AND a
/// lane, which vectorises: the lanes stay apart until the end. (A count of the finite lanes,
/// compared with their number, took longer: lanes of 8 pendulums at 3.1 rather than 3.8 times
/// the scalar loop.)
#[inline(always)]
fn every_lane_finite_and<T: Real, const L: usize>(values: &[Lanes<T, L>]) -> bool {
    let mut finite = true;
    for value in values {
        for x in value.0 {
            finite &= x * T::zero() == T::zero();
        }
    }
    finite
}

/// Every lane of every value finite, as one sum of `x * 0` over them all (zero, or NaN once
/// any `x` is infinite or NaN) and one comparison: a multiply-add a lane, where the AND of
/// [`every_lane_finite_and`] is three instructions a lane without a vector unit.
#[inline(always)]
fn every_lane_finite_sum<T: Real, const L: usize>(values: &[Lanes<T, L>]) -> bool {
    let mut sum = T::zero();
    for value in values {
        for x in value.0 {
            sum += x * T::zero();
        }
    }
    sum == T::zero()
}

impl<T: Real, const L: usize> Lanes<T, L> {
    /// The first lane, counting a divergence when another lane differs.
    fn first_if_uniform(self) -> T {
        let first = self.0.first().copied().unwrap_or_else(T::zero);
        let same = self.0.iter().filter(|&&x| x == first).count();
        if same != L {
            diverged();
        }
        first
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both forms of the finiteness test, whichever the target uses, answer as lane-by-lane
    /// `is_finite` over every lane of every value, over values with each special in each
    /// place (the host runs only the vector unit's form otherwise).
    fn finiteness_forms_agree<T: Real>() {
        let specials = [
            T::zero(),
            -T::zero(),
            T::from_f64(1.5),
            -(T::MIN_POSITIVE * T::HALF),
            -T::MAX,
            T::MAX,
            T::from_f64(f64::NAN),
            T::INFINITY,
            -T::INFINITY,
        ];
        let (mut finite, mut not) = (0, 0);
        for (a, b) in specials
            .iter()
            .flat_map(|&a| specials.iter().map(move |&b| (a, b)))
        {
            for place in 0..8 {
                let mut values = [Lanes::<T, 4>::splat(T::from_f64(0.75)); 2];
                let (first, second) = (place % 4, (place + 1) % 4);
                values[place / 4].0[first] = a;
                values[1 - place / 4].0[second] = b;
                let truth = values.iter().all(|v| v.0.iter().all(|x| x.is_finite()));
                assert_eq!(every_lane_finite_and(&values), truth, "{values:?}");
                assert_eq!(every_lane_finite_sum(&values), truth, "{values:?}");
                if truth {
                    finite += 1;
                } else {
                    not += 1;
                }
            }
        }
        assert!(finite > 100 && not > 100, "{finite} finite, {not} not");
    }

    #[test]
    fn finiteness_forms_agree_f32() {
        finiteness_forms_agree::<f32>();
    }

    #[test]
    fn finiteness_forms_agree_f64() {
        finiteness_forms_agree::<f64>();
    }

    /// A window inside the lanes reads them; one that runs past the end repeats the last lane;
    /// `set` past the end changes nothing.
    #[test]
    fn windows_and_set() {
        let wide = Lanes::<f32, 6>::from_fn(|i| i as f32);
        assert_eq!(wide.window::<4>(1).0, [1.0, 2.0, 3.0, 4.0]);
        assert_eq!(wide.window::<4>(4).0, [4.0, 5.0, 5.0, 5.0]);
        assert_eq!(wide.window::<2>(9).0, [5.0, 5.0]);
        let mut lanes = wide;
        lanes.set(2, -1.0);
        lanes.set(6, -2.0);
        assert_eq!(lanes.0, [0.0, 1.0, -1.0, 3.0, 4.0, 5.0]);
    }
}
