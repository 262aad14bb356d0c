//! Forward-mode dual numbers with `K` derivative directions, nestable for second derivatives.
//!
//! `Dual<S, K>` carries a value and its derivatives along `K` seeded directions. Because `Dual`
//! is itself a [`Scalar`], `Dual<Dual<f64, N>, N>` gives second derivatives: that is how
//! [`EulerLagrange`](crate::EulerLagrange) gets the mass matrix and the mixed terms of a
//! Lagrangian with no symbolic step and no heap.

use crate::scalar::{powi_by_squaring, Real, Scalar};
use core::marker::PhantomData;
use core::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};
use num_traits::{One, Zero};

/// A value `re` with first derivatives `eps` along `K` directions.
///
/// `R` is the floating-point type underneath (`f32` or `f64`, the default from `S`): carried
/// in the type so that a dual number can be multiplied, divided, added to and subtracted from
/// by a plain `R` (a parameter, a literal) as any [`Scalar`] can.
///
/// ```
/// use lagrange_core::{Dual, Scalar};
/// // d/dx sin(x) * x at x = 1, then scaled by a plain number
/// let x = Dual::<f64, 1>::variable(1.0, 0);
/// let y = x.sin() * x * 2.0;
/// assert!((y.eps[0] - 2.0 * (1.0f64.cos() + 1.0f64.sin())).abs() < 1e-15);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dual<S: Scalar, const K: usize, R = <S as Scalar>::Real> {
    /// The value.
    pub re: S,
    /// The derivative along each seeded direction.
    pub eps: [S; K],
    real: PhantomData<R>,
}

impl<S: Scalar<Real = R>, const K: usize, R: Real> Dual<S, K, R> {
    /// The value `re` with the derivatives `eps`.
    #[must_use]
    pub fn new(re: S, eps: [S; K]) -> Self {
        Self {
            re,
            eps,
            real: PhantomData,
        }
    }

    /// A constant: all derivatives zero.
    #[must_use]
    pub fn constant(re: S) -> Self {
        Self::new(re, [S::zero(); K])
    }

    /// The independent variable of direction `k`: derivative one along `k`, zero elsewhere
    /// (a constant when `k >= K`).
    #[must_use]
    pub fn variable(re: S, k: usize) -> Self {
        let mut d = Self::constant(re);
        d.seed(re, k);
        d
    }

    /// Makes `self`, a constant, [`Dual::variable`]`(re, k)` in place (an array of seeds
    /// filled where it stands: built and moved one by one, each was a call to `memcpy`).
    #[inline]
    pub(crate) fn seed(&mut self, re: S, k: usize) {
        self.re = re;
        if let Some(e) = self.eps.get_mut(k) {
            *e = S::one();
        }
    }

    /// Chain rule: the value `f` of a function at `re` with derivative `df` there.
    #[inline]
    fn chain(self, f: S, df: S) -> Self {
        Self::new(f, self.eps.map(|e| e * df))
    }
}

impl<S: Scalar<Real = R>, const K: usize, R: Real> Add for Dual<S, K, R> {
    type Output = Self;
    #[inline]
    fn add(mut self, o: Self) -> Self {
        self += o;
        self
    }
}

impl<S: Scalar<Real = R>, const K: usize, R: Real> AddAssign for Dual<S, K, R> {
    #[inline]
    fn add_assign(&mut self, o: Self) {
        self.re += o.re;
        for (a, b) in self.eps.iter_mut().zip(o.eps) {
            *a += b;
        }
    }
}

impl<S: Scalar<Real = R>, const K: usize, R: Real> Sub for Dual<S, K, R> {
    type Output = Self;
    #[inline]
    fn sub(mut self, o: Self) -> Self {
        self -= o;
        self
    }
}

impl<S: Scalar<Real = R>, const K: usize, R: Real> SubAssign for Dual<S, K, R> {
    #[inline]
    fn sub_assign(&mut self, o: Self) {
        self.re -= o.re;
        for (a, b) in self.eps.iter_mut().zip(o.eps) {
            *a -= b;
        }
    }
}

impl<S: Scalar<Real = R>, const K: usize, R: Real> Mul for Dual<S, K, R> {
    type Output = Self;
    #[inline]
    fn mul(self, o: Self) -> Self {
        let mut eps = self.eps;
        for (a, b) in eps.iter_mut().zip(o.eps) {
            *a = self.re * b + *a * o.re;
        }
        Self::new(self.re * o.re, eps)
    }
}

impl<S: Scalar<Real = R>, const K: usize, R: Real> MulAssign for Dual<S, K, R> {
    #[inline]
    fn mul_assign(&mut self, o: Self) {
        *self = *self * o;
    }
}

impl<S: Scalar<Real = R>, const K: usize, R: Real> Div for Dual<S, K, R> {
    type Output = Self;
    #[inline]
    fn div(self, o: Self) -> Self {
        let inv = o.re.recip();
        let re = self.re * inv;
        let mut eps = self.eps;
        for (a, b) in eps.iter_mut().zip(o.eps) {
            *a = (*a - re * b) * inv;
        }
        Self::new(re, eps)
    }
}

impl<S: Scalar<Real = R>, const K: usize, R: Real> DivAssign for Dual<S, K, R> {
    #[inline]
    fn div_assign(&mut self, o: Self) {
        *self = *self / o;
    }
}

impl<S: Scalar<Real = R>, const K: usize, R: Real> Neg for Dual<S, K, R> {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Self::new(-self.re, self.eps.map(|e| -e))
    }
}

impl<S: Scalar<Real = R>, const K: usize, R: Real> Zero for Dual<S, K, R> {
    fn zero() -> Self {
        Self::constant(S::zero())
    }
    fn is_zero(&self) -> bool {
        self.re.is_zero() && self.eps.iter().all(Zero::is_zero)
    }
}

impl<S: Scalar<Real = R>, const K: usize, R: Real> One for Dual<S, K, R> {
    fn one() -> Self {
        Self::constant(S::one())
    }
}

impl<S: Scalar<Real = R>, const K: usize, R: Real> Scalar for Dual<S, K, R> {
    type Real = R;

    fn from_real(x: Self::Real) -> Self {
        Self::constant(S::from_real(x))
    }
    fn from_f64(x: f64) -> Self {
        Self::constant(S::from_f64(x))
    }
    fn value(self) -> Self::Real {
        self.re.value()
    }
    fn sin(self) -> Self {
        let (s, c) = self.re.sin_cos();
        self.chain(s, c)
    }
    fn cos(self) -> Self {
        let (s, c) = self.re.sin_cos();
        self.chain(c, -s)
    }
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.re.sin_cos();
        (self.chain(s, c), self.chain(c, -s))
    }
    fn tan(self) -> Self {
        let t = self.re.tan();
        self.chain(t, S::one() + t * t)
    }
    fn sqrt(self) -> Self {
        let r = self.re.sqrt();
        self.chain(r, (r + r).recip())
    }
    fn exp(self) -> Self {
        let e = self.re.exp();
        self.chain(e, e)
    }
    fn ln(self) -> Self {
        self.chain(self.re.ln(), self.re.recip())
    }
    fn powi(self, n: i32) -> Self {
        powi_by_squaring(self, n)
    }
    fn abs(self) -> Self {
        if self.re.value() < R::zero() {
            -self
        } else {
            self
        }
    }
    fn atan2(self, x: Self) -> Self {
        let r2 = (x.re * x.re + self.re * self.re).recip();
        let mut eps = self.eps;
        for (a, b) in eps.iter_mut().zip(x.eps) {
            *a = (x.re * *a - self.re * b) * r2;
        }
        Self::new(self.re.atan2(x.re), eps)
    }
    fn recip(self) -> Self {
        let r = self.re.recip();
        self.chain(r, -(r * r))
    }
}

/// Arithmetic with a plain number of the underlying type: the number is a constant, with zero
/// derivatives.
macro_rules! with_real {
    ($op:ident, $f:ident, $assign:ident, $fa:ident, |$d:ident, $x:ident| $body:expr) => {
        impl<S: Scalar<Real = R>, const K: usize, R: Real> $op<R> for Dual<S, K, R> {
            type Output = Self;
            #[inline]
            fn $f(self, $x: R) -> Self {
                let $d = self;
                $body
            }
        }
        impl<S: Scalar<Real = R>, const K: usize, R: Real> $assign<R> for Dual<S, K, R> {
            #[inline]
            fn $fa(&mut self, x: R) {
                *self = $op::$f(*self, x);
            }
        }
    };
}

with_real!(Add, add, AddAssign, add_assign, |d, x| Self::new(
    d.re + x,
    d.eps
));
with_real!(Sub, sub, SubAssign, sub_assign, |d, x| Self::new(
    d.re - x,
    d.eps
));
with_real!(Mul, mul, MulAssign, mul_assign, |d, x| Self::new(
    d.re * x,
    d.eps.map(|e| e * x)
));
with_real!(Div, div, DivAssign, div_assign, |d, x| Self::new(
    d.re / x,
    d.eps.map(|e| e / x)
));
