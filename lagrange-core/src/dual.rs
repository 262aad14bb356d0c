//! Forward-mode dual numbers with `K` derivative directions, nestable for second derivatives.
//!
//! `Dual<S, K>` carries a value and its derivatives along `K` seeded directions. Because `Dual`
//! is itself a [`Scalar`], `Dual<Dual<f64, N>, N>` gives second derivatives: that is how
//! [`EulerLagrange`](crate::EulerLagrange) gets the mass matrix and the mixed terms of a
//! Lagrangian with no symbolic step and no heap.

use crate::scalar::{powi_by_squaring, Scalar};
use core::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};
use num_traits::{One, Zero};

/// A value `re` with first derivatives `eps` along `K` directions.
///
/// ```
/// use lagrange_core::{Dual, Scalar};
/// // d/dx sin(x) * x at x = 1
/// let x = Dual::<f64, 1>::variable(1.0, 0);
/// let y = x.sin() * x;
/// assert!((y.eps[0] - (1.0f64.cos() + 1.0f64.sin())).abs() < 1e-15);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dual<S, const K: usize> {
    /// The value.
    pub re: S,
    /// The derivative along each seeded direction.
    pub eps: [S; K],
}

impl<S: Scalar, const K: usize> Dual<S, K> {
    /// A constant: all derivatives zero.
    #[must_use]
    pub fn constant(re: S) -> Self {
        Self {
            re,
            eps: [S::zero(); K],
        }
    }

    /// The independent variable of direction `k`: derivative one along `k`, zero elsewhere
    /// (a constant when `k >= K`).
    #[must_use]
    pub fn variable(re: S, k: usize) -> Self {
        let mut d = Self::constant(re);
        if let Some(e) = d.eps.get_mut(k) {
            *e = S::one();
        }
        d
    }

    /// Chain rule: the value `f` of a function at `re` with derivative `df` there.
    #[inline]
    fn chain(self, f: S, df: S) -> Self {
        Self {
            re: f,
            eps: self.eps.map(|e| e * df),
        }
    }
}

impl<S: Scalar, const K: usize> Add for Dual<S, K> {
    type Output = Self;
    #[inline]
    fn add(mut self, o: Self) -> Self {
        self += o;
        self
    }
}

impl<S: Scalar, const K: usize> AddAssign for Dual<S, K> {
    #[inline]
    fn add_assign(&mut self, o: Self) {
        self.re += o.re;
        for (a, b) in self.eps.iter_mut().zip(o.eps) {
            *a += b;
        }
    }
}

impl<S: Scalar, const K: usize> Sub for Dual<S, K> {
    type Output = Self;
    #[inline]
    fn sub(mut self, o: Self) -> Self {
        self -= o;
        self
    }
}

impl<S: Scalar, const K: usize> SubAssign for Dual<S, K> {
    #[inline]
    fn sub_assign(&mut self, o: Self) {
        self.re -= o.re;
        for (a, b) in self.eps.iter_mut().zip(o.eps) {
            *a -= b;
        }
    }
}

impl<S: Scalar, const K: usize> Mul for Dual<S, K> {
    type Output = Self;
    #[inline]
    fn mul(self, o: Self) -> Self {
        let mut eps = self.eps;
        for (a, b) in eps.iter_mut().zip(o.eps) {
            *a = self.re * b + *a * o.re;
        }
        Self {
            re: self.re * o.re,
            eps,
        }
    }
}

impl<S: Scalar, const K: usize> MulAssign for Dual<S, K> {
    #[inline]
    fn mul_assign(&mut self, o: Self) {
        *self = *self * o;
    }
}

impl<S: Scalar, const K: usize> Div for Dual<S, K> {
    type Output = Self;
    #[inline]
    fn div(self, o: Self) -> Self {
        let inv = o.re.recip();
        let re = self.re * inv;
        let mut eps = self.eps;
        for (a, b) in eps.iter_mut().zip(o.eps) {
            *a = (*a - re * b) * inv;
        }
        Self { re, eps }
    }
}

impl<S: Scalar, const K: usize> DivAssign for Dual<S, K> {
    #[inline]
    fn div_assign(&mut self, o: Self) {
        *self = *self / o;
    }
}

impl<S: Scalar, const K: usize> Neg for Dual<S, K> {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Self {
            re: -self.re,
            eps: self.eps.map(|e| -e),
        }
    }
}

impl<S: Scalar, const K: usize> Zero for Dual<S, K> {
    fn zero() -> Self {
        Self::constant(S::zero())
    }
    fn is_zero(&self) -> bool {
        self.re.is_zero() && self.eps.iter().all(Zero::is_zero)
    }
}

impl<S: Scalar, const K: usize> One for Dual<S, K> {
    fn one() -> Self {
        Self::constant(S::one())
    }
}

impl<S: Scalar, const K: usize> Scalar for Dual<S, K> {
    type Real = S::Real;

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
        if self.re.value() < <S::Real as Zero>::zero() {
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
        Self {
            re: self.re.atan2(x.re),
            eps,
        }
    }
    fn recip(self) -> Self {
        let r = self.re.recip();
        self.chain(r, -(r * r))
    }
}
