//! The second-order jet behind [`EulerLagrange`](crate::EulerLagrange): one evaluation of a
//! kinetic energy over it gives the mass matrix, `dT/dq` and the mixed term of the
//! Euler-Lagrange equations together.
//!
//! A [`Jet`] holds, for a value `x(t, q, q')` computed from the seeded coordinates:
//!
//! ```text
//! v   x
//! gq  dx/dq                      N
//! gp  dx/dq'                     N
//! h   d2x/dq'dq'                 N x N, upper triangle only (i <= j)
//! d   dx/de                      along the direction e: dq = q' (and dt = 1 when seeded)
//! dp  d2x/dq'de                  N
//! ```
//!
//! which is all that `M = d2T/dq'2` and `f = dT/dq - (d2T/dq'dq) q' - d2T/dq'dt` need: the
//! mixed term is one directional derivative of the velocity gradient, `O(N)` per operation
//! instead of the `O(N^2)` of a full mixed Hessian, and only the velocity Hessian is
//! `O(N^2)`, its symmetric half computed. Each part carries a flag that is clear when the
//! part is exactly zero (a parameter, a function of `q` only, a value linear in `q'`), and an
//! operation touches only the parts its operands make non-zero: in the mass matrix's part of
//! the work every sine and cosine of a coordinate is a plain number times the parts it has.
//!
//! The operators work in place on the operand they own and read the other by reference: a
//! jet of a long chain is kilobytes, and a copy of one costs about as much as the arithmetic
//! on it.

use crate::scalar::{powi_by_squaring, Real, Scalar};
use crate::trig_memo::TrigMemo;
use core::marker::PhantomData;
use core::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};
use num_traits::{One, Zero};

/// Flag of `gq`: may be non-zero.
const GQ: u8 = 1;
/// Flag of `gp`.
const GP: u8 = 2;
/// Flag of `h`.
const H: u8 = 4;
/// Flag of `d`.
const D: u8 = 8;
/// Flag of `dp`.
const DP: u8 = 16;

/// A value with its first derivatives in the coordinates and velocities, its second
/// derivatives in the velocities, and the derivative along one direction of it and of its
/// velocity gradient (see the module's docs). A part whose flag is clear is exactly zero, in
/// its storage too.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Jet<'m, S: Scalar, const N: usize, R = <S as Scalar>::Real> {
    /// The value.
    pub(crate) v: S,
    /// `dx/de` along the seeded direction.
    pub(crate) d: S,
    /// Which parts may be non-zero.
    parts: u8,
    /// `dx/dq`.
    pub(crate) gq: [S; N],
    /// `dx/dq'`.
    pub(crate) gp: [S; N],
    /// `d2x/dq'de`.
    pub(crate) dp: [S; N],
    /// `d2x/dq'_i dq'_j` for `i <= j` (the rest stays zero).
    pub(crate) h: [[S; N]; N],
    /// Where its sines and cosines are remembered, if anywhere.
    memo: Memo<'m, S>,
    real: PhantomData<R>,
}

/// The [`TrigMemo`] a jet's sines and cosines go through, if it has one (passed on to every
/// value computed from it). Not part of the value: any two compare equal.
#[derive(Debug, Clone, Copy)]
struct Memo<'m, S: Scalar>(Option<&'m TrigMemo<S>>);

impl<S: Scalar> PartialEq for Memo<'_, S> {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// `x *= c`.
#[inline(always)]
fn scale<S: Scalar, const N: usize>(x: &mut [S; N], c: S) {
    for e in x {
        *e *= c;
    }
}

/// `x += y`.
#[inline(always)]
fn add<S: Scalar, const N: usize>(x: &mut [S; N], y: &[S; N]) {
    for (e, f) in x.iter_mut().zip(y) {
        *e += *f;
    }
}

/// `x -= y`.
#[inline(always)]
fn sub<S: Scalar, const N: usize>(x: &mut [S; N], y: &[S; N]) {
    for (e, f) in x.iter_mut().zip(y) {
        *e -= *f;
    }
}

/// `x += c y`.
#[inline(always)]
fn add_scaled<S: Scalar, const N: usize>(x: &mut [S; N], c: S, y: &[S; N]) {
    for (e, f) in x.iter_mut().zip(y) {
        *e += c * *f;
    }
}

/// `x = c y`.
#[inline(always)]
fn set_scaled<S: Scalar, const N: usize>(x: &mut [S; N], c: S, y: &[S; N]) {
    for (e, f) in x.iter_mut().zip(y) {
        *e = c * *f;
    }
}

/// `x = a x + b y`.
#[inline(always)]
fn combine<S: Scalar, const N: usize>(x: &mut [S; N], a: S, b: S, y: &[S; N]) {
    for (e, f) in x.iter_mut().zip(y) {
        *e = a * *e + b * *f;
    }
}

/// Each row `i` of the upper triangle of `h` (from its diagonal) with `i`.
#[inline(always)]
fn upper<S, const N: usize>(h: &mut [[S; N]; N]) -> impl Iterator<Item = (usize, &mut [S])> {
    h.iter_mut()
        .enumerate()
        .map(|(i, row)| (i, row.get_mut(i..).unwrap_or_default()))
}

/// `h *= c` over the upper triangle.
#[inline(always)]
fn scale_upper<S: Scalar, const N: usize>(h: &mut [[S; N]; N], c: S) {
    for (_, row) in upper(h) {
        for e in row {
            *e *= c;
        }
    }
}

/// `h += k` over the upper triangle.
#[inline(always)]
fn add_upper<S: Scalar, const N: usize>(h: &mut [[S; N]; N], k: &[[S; N]; N]) {
    for ((i, row), other) in upper(h).zip(k) {
        for (e, f) in row.iter_mut().zip(other.iter().skip(i)) {
            *e += *f;
        }
    }
}

/// `h -= k` over the upper triangle.
#[inline(always)]
fn sub_upper<S: Scalar, const N: usize>(h: &mut [[S; N]; N], k: &[[S; N]; N]) {
    for ((i, row), other) in upper(h).zip(k) {
        for (e, f) in row.iter_mut().zip(other.iter().skip(i)) {
            *e -= *f;
        }
    }
}

/// `h += c k` over the upper triangle.
#[inline(always)]
fn add_scaled_upper<S: Scalar, const N: usize>(h: &mut [[S; N]; N], c: S, k: &[[S; N]; N]) {
    for ((i, row), other) in upper(h).zip(k) {
        for (e, f) in row.iter_mut().zip(other.iter().skip(i)) {
            *e += c * *f;
        }
    }
}

/// `h += a b^T + b a^T` over the upper triangle.
#[inline(always)]
fn add_outer<S: Scalar, const N: usize>(h: &mut [[S; N]; N], a: &[S; N], b: &[S; N]) {
    for ((i, row), (ai, bi)) in upper(h).zip(a.iter().zip(b)) {
        for (e, (aj, bj)) in row.iter_mut().zip(a.iter().zip(b).skip(i)) {
            *e += *ai * *bj + *bi * *aj;
        }
    }
}

/// `h += c a a^T` over the upper triangle.
#[inline(always)]
fn add_square<S: Scalar, const N: usize>(h: &mut [[S; N]; N], c: S, a: &[S; N]) {
    for ((i, row), ai) in upper(h).zip(a) {
        let ci = c * *ai;
        for (e, aj) in row.iter_mut().zip(a.iter().skip(i)) {
            *e += ci * *aj;
        }
    }
}

impl<'m, S: Scalar<Real = R>, const N: usize, R: Real> Jet<'m, S, N, R> {
    /// A constant: every derivative zero.
    #[inline(always)]
    pub(crate) fn constant(v: S) -> Self {
        Self {
            v,
            d: S::zero(),
            parts: 0,
            gq: [S::zero(); N],
            gp: [S::zero(); N],
            dp: [S::zero(); N],
            h: [[S::zero(); N]; N],
            memo: Memo(None),
            real: PhantomData,
        }
    }

    /// Coordinate `k` at `q`, moving at `rate` along the direction (`gq` and `d` seeded).
    #[inline(always)]
    pub(crate) fn coordinate(q: S, k: usize, rate: S) -> Self {
        let mut x = Self::constant(q);
        x.seed_coordinate(q, k, rate);
        x
    }

    /// Velocity `k` at `qd` (`gp` seeded).
    #[inline(always)]
    pub(crate) fn velocity(qd: S, k: usize) -> Self {
        let mut x = Self::constant(qd);
        x.seed_velocity(qd, k);
        x
    }

    /// Time at `t`, moving at unit rate along the direction (`d` seeded).
    #[inline(always)]
    pub(crate) fn time(t: S) -> Self {
        let mut x = Self::constant(t);
        x.d = S::one();
        x.parts = D;
        x
    }

    /// `self`, its sines and cosines (and those of every value computed from it) remembered
    /// in `memo` where given: only for plain numbers (see [`TrigMemo`]).
    #[inline(always)]
    pub(crate) fn remembering(mut self, memo: Option<&'m TrigMemo<S>>) -> Self {
        self.memo = Memo(memo);
        self
    }

    /// `(sin v, cos v)` of the value, through the memo where there is one.
    #[inline(always)]
    fn sin_cos_value(&self) -> (S, S) {
        match self.memo.0 {
            Some(memo) => memo.sin_cos(self.v),
            None => self.v.sin_cos(),
        }
    }

    /// Takes `o`'s memo where `self` has none (a constant combined with a variable).
    #[inline(always)]
    fn share_memo(&mut self, o: &Self) {
        if self.memo.0.is_none() {
            self.memo = o.memo;
        }
    }

    /// Makes `self`, a constant, coordinate `k` at `q` moving at `rate`.
    #[inline(always)]
    fn seed_coordinate(&mut self, q: S, k: usize, rate: S) {
        self.v = q;
        if let Some(e) = self.gq.get_mut(k) {
            *e = S::one();
            self.parts |= GQ;
        }
        self.d = rate;
        self.parts |= D;
    }

    /// Makes `self`, a constant, velocity `k` at `qd`.
    #[inline(always)]
    fn seed_velocity(&mut self, qd: S, k: usize) {
        self.v = qd;
        if let Some(e) = self.gp.get_mut(k) {
            *e = S::one();
            self.parts |= GP;
        }
    }

    /// `d2x/dq'_i dq'_j`, read from the stored upper triangle.
    pub(crate) fn hessian(&self, i: usize, j: usize) -> S {
        let (i, j) = if i <= j { (i, j) } else { (j, i) };
        self.h
            .get(i)
            .and_then(|row| row.get(j))
            .copied()
            .unwrap_or_else(S::zero)
    }

    /// Every part times `c` (the first-order parts whatever their flags: zeros stay zero).
    #[inline(always)]
    fn scale_by(&mut self, c: S) {
        self.v *= c;
        self.d *= c;
        scale(&mut self.gq, c);
        scale(&mut self.gp, c);
        let p = self.parts;
        if p & H != 0 {
            scale_upper(&mut self.h, c);
        }
        if p & DP != 0 {
            scale(&mut self.dp, c);
        }
    }

    /// `self = c o` for `self` a constant: the second-order parts only where `o` has them
    /// (they are zero in `self` already).
    #[inline(always)]
    fn set_scaled(&mut self, c: S, o: &Self) {
        let p = o.parts;
        self.share_memo(o);
        self.v = c * o.v;
        self.d = c * o.d;
        set_scaled(&mut self.gq, c, &o.gq);
        set_scaled(&mut self.gp, c, &o.gp);
        if p & H != 0 {
            add_scaled_upper(&mut self.h, c, &o.h);
        }
        if p & DP != 0 {
            set_scaled(&mut self.dp, c, &o.dp);
        }
        self.parts = p;
    }

    /// `self = g(self)` for a function `g` with value `f0`, first derivative `f1` and second
    /// derivative `f2` at `self.v`.
    #[inline(always)]
    fn chain(&mut self, f0: S, f1: S, f2: S) {
        let p = self.parts;
        if p & GP != 0 {
            if p & H != 0 {
                scale_upper(&mut self.h, f1);
            }
            add_square(&mut self.h, f2, &self.gp);
            if p & DP != 0 {
                scale(&mut self.dp, f1);
            }
            add_scaled(&mut self.dp, f2 * self.d, &self.gp);
            self.parts |= H | DP;
        }
        scale(&mut self.gp, f1);
        scale(&mut self.gq, f1);
        self.d *= f1;
        self.v = f0;
    }

    /// `self = g(self, o)` for a function `g` with value `f0`, first derivatives `fa`, `fb`
    /// and second derivatives `faa`, `fab`, `fbb` at `(self.v, o.v)` (every part computed:
    /// for the rare functions of two variables).
    fn chain2(&mut self, o: &Self, f0: S, (fa, fb): (S, S), (faa, fab, fbb): (S, S, S)) {
        let (a, b) = (*self, o);
        let mix = |x: &[S; N], y: &[S; N]| core::array::from_fn(|i| fa * x[i] + fb * y[i]);
        self.gq = mix(&a.gq, &b.gq);
        self.gp = mix(&a.gp, &b.gp);
        self.d = fa * a.d + fb * b.d;
        self.dp = core::array::from_fn(|i| {
            fa * a.dp[i]
                + fb * b.dp[i]
                + (faa * a.d + fab * b.d) * a.gp[i]
                + (fbb * b.d + fab * a.d) * b.gp[i]
        });
        scale_upper(&mut self.h, fa);
        add_scaled_upper(&mut self.h, fb, &b.h);
        add_square(&mut self.h, faa, &a.gp);
        add_square(&mut self.h, fbb, &b.gp);
        add_outer(&mut self.h, &a.gp, &b.gp.map(|x| x * fab));
        self.v = f0;
        self.share_memo(b);
        self.parts = a.parts | b.parts;
        if self.parts & GP != 0 {
            self.parts |= H | DP;
        }
    }

    /// `self += o`, or `self -= o` with `PLUS` false (the first-order parts whatever their
    /// flags).
    #[inline(always)]
    fn add_jet<const PLUS: bool>(&mut self, o: &Self) {
        let p = o.parts;
        self.share_memo(o);
        if PLUS {
            self.v += o.v;
            self.d += o.d;
            add(&mut self.gq, &o.gq);
            add(&mut self.gp, &o.gp);
        } else {
            self.v -= o.v;
            self.d -= o.d;
            sub(&mut self.gq, &o.gq);
            sub(&mut self.gp, &o.gp);
        }
        if p & H != 0 {
            if PLUS {
                add_upper(&mut self.h, &o.h);
            } else {
                sub_upper(&mut self.h, &o.h);
            }
        }
        if p & DP != 0 {
            if PLUS {
                add(&mut self.dp, &o.dp);
            } else {
                sub(&mut self.dp, &o.dp);
            }
        }
        self.parts |= p;
    }

    /// `self *= o`.
    #[inline(always)]
    fn mul_jet(&mut self, o: &Self) {
        if o.parts == 0 {
            self.scale_by(o.v);
        } else if self.parts == 0 {
            self.set_scaled(self.v, o);
        } else {
            self.mul_general(o);
        }
    }

    /// `self *= o` when both have derivatives.
    #[inline(always)]
    fn mul_general(&mut self, o: &Self) {
        let (a, b) = (self.parts, o.parts);
        self.share_memo(o);
        let (av, bv) = (self.v, o.v);
        // Second-order parts first: they read the first-order parts before those change.
        if a & H != 0 {
            scale_upper(&mut self.h, bv);
        }
        if b & H != 0 {
            add_scaled_upper(&mut self.h, av, &o.h);
        }
        if a & b & GP != 0 {
            add_outer(&mut self.h, &self.gp, &o.gp);
            self.parts |= H;
        }
        // dp' = b.v a.dp + a.v b.dp + b.d a.gp + a.d b.gp.
        if (a | b) & DP != 0 {
            combine(&mut self.dp, bv, av, &o.dp);
        }
        if a & GP != 0 && b & D != 0 {
            add_scaled(&mut self.dp, o.d, &self.gp);
            self.parts |= DP;
        }
        if a & D != 0 && b & GP != 0 {
            add_scaled(&mut self.dp, self.d, &o.gp);
            self.parts |= DP;
        }
        // First-order parts: x' = b.v a' + a.v b'.
        combine(&mut self.gq, bv, av, &o.gq);
        combine(&mut self.gp, bv, av, &o.gp);
        self.d = bv * self.d + av * o.d;
        self.v = av * bv;
        self.parts |= b;
    }
}

impl<'m, S: Scalar<Real = R>, const N: usize, R: Real> AddAssign for Jet<'m, S, N, R> {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        self.add_jet::<true>(&o);
    }
}

impl<'m, S: Scalar<Real = R>, const N: usize, R: Real> SubAssign for Jet<'m, S, N, R> {
    #[inline(always)]
    fn sub_assign(&mut self, o: Self) {
        self.add_jet::<false>(&o);
    }
}

impl<'m, S: Scalar<Real = R>, const N: usize, R: Real> MulAssign for Jet<'m, S, N, R> {
    #[inline(always)]
    fn mul_assign(&mut self, o: Self) {
        self.mul_jet(&o);
    }
}

impl<'m, S: Scalar<Real = R>, const N: usize, R: Real> DivAssign for Jet<'m, S, N, R> {
    #[inline(always)]
    fn div_assign(&mut self, o: Self) {
        if o.parts == 0 {
            let v = self.v / o.v;
            self.scale_by(o.v.recip());
            self.v = v;
        } else {
            self.mul_jet(&o.recip());
        }
    }
}

/// `a op b` from `a op= b`, for jets and for plain numbers on the right.
macro_rules! by_value {
    ($op:ident, $f:ident, $assign:ident, $fa:ident) => {
        impl<'m, S: Scalar<Real = R>, const N: usize, R: Real> $op<R> for Jet<'m, S, N, R> {
            type Output = Self;
            #[inline(always)]
            fn $f(mut self, o: R) -> Self {
                $assign::$fa(&mut self, o);
                self
            }
        }
    };
    ($op:ident, $f:ident, $assign:ident, $fa:ident, jets) => {
        by_value!($op, $f, $assign, $fa);
        impl<'m, S: Scalar<Real = R>, const N: usize, R: Real> $op for Jet<'m, S, N, R> {
            type Output = Self;
            #[inline(always)]
            fn $f(mut self, o: Self) -> Self {
                $assign::$fa(&mut self, o);
                self
            }
        }
    };
}

by_value!(Sub, sub, SubAssign, sub_assign, jets);
by_value!(Div, div, DivAssign, div_assign, jets);
by_value!(Add, add, AddAssign, add_assign);
by_value!(Mul, mul, MulAssign, mul_assign);

/// `c + x` with `c` a constant (a parameter, a literal) returns `x`'s own storage with `c`
/// added to its value: a jet of a long chain is kilobytes, not worth writing again.
impl<'m, S: Scalar<Real = R>, const N: usize, R: Real> Add for Jet<'m, S, N, R> {
    type Output = Self;
    #[inline(always)]
    fn add(mut self, mut o: Self) -> Self {
        if self.parts == 0 {
            o.v = self.v + o.v;
            o
        } else {
            self.add_jet::<true>(&o);
            self
        }
    }
}

/// `c * x` with `c` a constant (the usual order in a kinetic energy: `S::from_real(m) * ...`)
/// scales `x`'s own storage in place, as `x * c` does.
impl<'m, S: Scalar<Real = R>, const N: usize, R: Real> Mul for Jet<'m, S, N, R> {
    type Output = Self;
    #[inline(always)]
    fn mul(mut self, mut o: Self) -> Self {
        if self.parts == 0 {
            o.scale_by(self.v);
            o
        } else {
            self.mul_jet(&o);
            self
        }
    }
}

impl<'m, S: Scalar<Real = R>, const N: usize, R: Real> Neg for Jet<'m, S, N, R> {
    type Output = Self;
    #[inline(always)]
    fn neg(mut self) -> Self {
        self.scale_by(-S::one());
        self
    }
}

impl<'m, S: Scalar<Real = R>, const N: usize, R: Real> AddAssign<R> for Jet<'m, S, N, R> {
    #[inline(always)]
    fn add_assign(&mut self, x: R) {
        self.v += x;
    }
}

impl<'m, S: Scalar<Real = R>, const N: usize, R: Real> SubAssign<R> for Jet<'m, S, N, R> {
    #[inline(always)]
    fn sub_assign(&mut self, x: R) {
        self.v -= x;
    }
}

impl<'m, S: Scalar<Real = R>, const N: usize, R: Real> MulAssign<R> for Jet<'m, S, N, R> {
    #[inline(always)]
    fn mul_assign(&mut self, x: R) {
        self.scale_by(S::from_real(x));
    }
}

impl<'m, S: Scalar<Real = R>, const N: usize, R: Real> DivAssign<R> for Jet<'m, S, N, R> {
    #[inline(always)]
    fn div_assign(&mut self, x: R) {
        *self /= Self::constant(S::from_real(x));
    }
}

impl<'m, S: Scalar<Real = R>, const N: usize, R: Real> Zero for Jet<'m, S, N, R> {
    fn zero() -> Self {
        Self::constant(S::zero())
    }
    fn is_zero(&self) -> bool {
        let flat = |x: &[S; N]| x.iter().all(Zero::is_zero);
        self.v.is_zero()
            && self.d.is_zero()
            && flat(&self.gq)
            && flat(&self.gp)
            && flat(&self.dp)
            && self.h.iter().all(flat)
    }
}

impl<'m, S: Scalar<Real = R>, const N: usize, R: Real> One for Jet<'m, S, N, R> {
    fn one() -> Self {
        Self::constant(S::one())
    }
}

impl<'m, S: Scalar<Real = R>, const N: usize, R: Real> Scalar for Jet<'m, S, N, R> {
    type Real = R;

    fn from_real(x: R) -> Self {
        Self::constant(S::from_real(x))
    }
    fn from_f64(x: f64) -> Self {
        Self::constant(S::from_f64(x))
    }
    fn value(self) -> R {
        self.v.value()
    }
    #[inline(always)]
    fn sin(mut self) -> Self {
        let (s, c) = self.sin_cos_value();
        self.chain(s, c, -s);
        self
    }
    #[inline(always)]
    fn cos(mut self) -> Self {
        let (s, c) = self.sin_cos_value();
        self.chain(c, -s, -c);
        self
    }
    #[inline(always)]
    fn sin_cos(mut self) -> (Self, Self) {
        // One copy: the cosine takes `self`'s own storage.
        let (s, c) = self.sin_cos_value();
        let mut sin = self;
        sin.chain(s, c, -s);
        self.chain(c, -s, -c);
        (sin, self)
    }
    fn tan(mut self) -> Self {
        let t = self.v.tan();
        let f1 = S::one() + t * t;
        self.chain(t, f1, (t + t) * f1);
        self
    }
    fn sqrt(mut self) -> Self {
        let r = self.v.sqrt();
        let f1 = (r + r).recip();
        self.chain(r, f1, -(f1 * f1) / r);
        self
    }
    fn exp(mut self) -> Self {
        let e = self.v.exp();
        self.chain(e, e, e);
        self
    }
    fn ln(mut self) -> Self {
        let r = self.v.recip();
        self.chain(self.v.ln(), r, -(r * r));
        self
    }
    fn powi(self, n: i32) -> Self {
        powi_by_squaring(self, n)
    }
    fn abs(self) -> Self {
        if self.v.value() < R::zero() {
            -self
        } else {
            self
        }
    }
    fn atan2(mut self, x: Self) -> Self {
        // g(y, x) = atan2(y, x): g_y = x / r2, g_x = -y / r2, g_yy = -2 x y / r2^2 = -g_xx,
        // g_yx = (y^2 - x^2) / r2^2.
        let (y0, x0) = (self.v, x.v);
        let inv = (x0 * x0 + y0 * y0).recip();
        let xy = (x0 * y0 + x0 * y0) * inv * inv;
        self.chain2(
            &x,
            y0.atan2(x0),
            (x0 * inv, -(y0 * inv)),
            (-xy, (y0 * y0 - x0 * x0) * inv * inv, xy),
        );
        self
    }
    #[inline(always)]
    fn recip(mut self) -> Self {
        let r = self.v.recip();
        let f1 = -(r * r);
        self.chain(r, f1, -(f1 + f1) * r);
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Dual;

    type J = Jet<'static, f64, 2>;
    type D2 = Dual<Dual<f64, 4>, 4>;

    /// Variables of the jet: `q0, q1` moving at `r0, r1`, then `p0, p1`, time moving at 1.
    fn jets(x: [f64; 5]) -> [J; 5] {
        [
            J::coordinate(x[0], 0, 0.3),
            J::coordinate(x[1], 1, -0.7),
            J::velocity(x[2], 0),
            J::velocity(x[3], 1),
            J::time(x[4]),
        ]
    }

    /// The same with nested duals over `(q0, q1, p0, p1)`, and time as a constant.
    fn duals(x: [f64; 5]) -> [D2; 5] {
        let v = |k: usize| D2::variable(Dual::variable(x[k], k), k);
        [v(0), v(1), v(2), v(3), D2::constant(Dual::constant(x[4]))]
    }

    /// A function of everything, through every operation a jet has.
    fn f<S: Scalar<Real = f64>>([q0, q1, p0, p1, _]: [S; 5]) -> S {
        let (s, c) = (q0 - q1).sin_cos();
        let a = p0 * p0 * c + p0 * p1 * s * 1.5 - (p1 * q0).sin() / (q1.exp() + 2.0);
        let b = (p0 + q1).cos() * (p1 * p1 + 1.0).sqrt() + (p0 * p0 + 3.0).ln() * q0.tan();
        let e = (p1 - q0).atan2(p0 + 2.0) * (q1 + p0).recip() + (p1 - 2.0).abs().powi(3) / 4.0;
        a + b * 0.5 + e - p0 / (q0 * q0 + 1.0)
    }

    /// Every part of the jet equals the nested duals' derivatives to rounding.
    #[test]
    fn parts_agree_with_nested_duals() {
        let x = [0.4, -1.1, 0.8, -0.3, 2.0];
        let j = f(jets(x));
        let r = f(duals(x));
        let rate = [0.3, -0.7];
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-13 * (1.0 + b.abs());
        assert!(close(j.v, r.re.re));
        for i in 0..2 {
            assert!(close(j.gq[i], r.re.eps[i]), "gq {i}");
            assert!(close(j.gp[i], r.re.eps[2 + i]), "gp {i}");
            for k in 0..2 {
                assert!(close(j.hessian(i, k), r.eps[2 + i].eps[2 + k]), "h {i} {k}");
            }
            let dp = r.eps[2 + i].eps[0] * rate[0] + r.eps[2 + i].eps[1] * rate[1];
            assert!(close(j.dp[i], dp), "dp {i}: {} {dp}", j.dp[i]);
        }
        assert!(close(j.d, r.re.eps[0] * rate[0] + r.re.eps[1] * rate[1]));
    }

    /// The forms `f` leaves out: a constant on the left of a product, a quotient or an
    /// assignment whose right side has every part (the mixed `dp` and the Hessian), and
    /// functions of two variables whose second argument has them too.
    fn g<S: Scalar<Real = f64>>([q0, q1, p0, p1, t]: [S; 5]) -> S {
        let mixed = (q0 - q1).cos() * p0 * p1 + p0 * p0 * q1;
        let mut a = S::from_f64(1.5);
        a *= mixed;
        let mut b = S::from_f64(0.5);
        b /= mixed + 3.0;
        let mut c = S::from_f64(2.0);
        c -= mixed * t;
        c += p1 * p1 * q0.sin();
        let e = (p1 * q0).atan2(mixed + 4.0) + (q1 * p0).atan2(p1 * p1 * q0 + 2.0);
        let h =
            S::from_f64(0.25) * (mixed * p1 * q0.cos()) - S::from_f64(3.0) / (mixed * mixed + 1.0);
        a + b + c * 0.5 + e + h
    }

    /// Every part of the jet of `g` equals the nested duals' derivatives to rounding, with
    /// time seeded in the direction (the duals' fifth variable at unit rate).
    #[test]
    fn every_form_agrees_with_nested_duals() {
        type D5 = Dual<Dual<f64, 5>, 5>;
        let x = [0.4, -1.1, 0.8, -0.3, 2.0];
        let rate = [0.3, -0.7, 0.0, 0.0, 1.0];
        let j = g(jets(x));
        let v = |k: usize| D5::variable(Dual::variable(x[k], k), k);
        let r = g([v(0), v(1), v(2), v(3), v(4)]);
        let direction = |d: &[f64; 5]| (0..5).map(|k| d[k] * rate[k]).sum::<f64>();
        // The two evaluations round differently: a few ulps of the largest term.
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-13 * (1.0 + b.abs());
        assert!(close(j.v, r.re.re));
        assert!(
            close(j.d, direction(&r.re.eps)),
            "d {} {}",
            j.d,
            direction(&r.re.eps)
        );
        for i in 0..2 {
            assert!(close(j.gq[i], r.re.eps[i]), "gq {i}");
            assert!(close(j.gp[i], r.re.eps[2 + i]), "gp {i}");
            for k in 0..2 {
                assert!(close(j.hessian(i, k), r.eps[2 + i].eps[2 + k]), "h {i} {k}");
            }
            let dp = direction(&r.eps[2 + i].eps);
            assert!(close(j.dp[i], dp), "dp {i}: {} {dp}", j.dp[i]);
        }
    }

    /// A chain-like function of six coordinates: every part agrees with nested duals over all
    /// twelve variables.
    #[test]
    fn chain_agrees_with_nested_duals() {
        const M: usize = 6;
        type Big = Dual<Dual<f64, 12>, 12>;
        fn chain<S: Scalar<Real = f64>>(q: &[S; M], p: &[S; M]) -> S {
            let (mut vx, mut vy, mut t) = (S::zero(), S::zero(), S::zero());
            for j in 0..M {
                let (s, c) = q[j].sin_cos();
                let u = p[j] * (1.0 + 0.1 * j as f64);
                vx += u * c;
                vy += u * s;
                t += (vx * vx + vy * vy) * (0.5 + 0.2 * j as f64);
            }
            // Terms that reach back to the first links, and one of two variables.
            t + p[0] * p[M - 1] * q[2].cos() - (p[3] * q[4]).sin() / (q[0] * q[0] + 2.0)
                + p[1].atan2(q[1] + 3.0)
        }
        let x: [f64; 2 * M] = core::array::from_fn(|i| 0.3 * (i as f64 + 1.0).sin());
        let rate: [f64; M] = core::array::from_fn(|i| x[M + i]);
        let jq: [Jet<'static, f64, M>; M] =
            core::array::from_fn(|k| Jet::coordinate(x[k], k, rate[k]));
        let jp: [Jet<'static, f64, M>; M] = core::array::from_fn(|k| Jet::velocity(x[M + k], k));
        let j = chain(&jq, &jp);
        let v = |k: usize| Big::variable(Dual::variable(x[k], k), k);
        let r = chain(
            &core::array::from_fn(v),
            &core::array::from_fn(|k| v(M + k)),
        );
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-13 * (1.0 + b.abs());
        assert!(close(j.v, r.re.re));
        let mut d = 0.0;
        for i in 0..M {
            d += r.re.eps[i] * rate[i];
            assert!(close(j.gq[i], r.re.eps[i]), "gq {i}");
            assert!(close(j.gp[i], r.re.eps[M + i]), "gp {i}");
            let mut dp = 0.0;
            for (k, rk) in rate.iter().enumerate() {
                assert!(close(j.hessian(i, k), r.eps[M + i].eps[M + k]), "h {i} {k}");
                dp += r.eps[M + i].eps[k] * rk;
            }
            assert!(close(j.dp[i], dp), "dp {i}: {} {dp}", j.dp[i]);
        }
        assert!(close(j.d, d));
    }

    /// Time seeded along the direction: `d` and `dp` pick up `d/dt`.
    #[test]
    fn time_enters_the_direction() {
        let [_, _, p0, _, t] = jets([0.0, 0.0, 0.5, 0.0, 2.0]);
        let x = p0 * p0 * t;
        // d/dt = p0^2 = 0.25; d/dt d/dp0 = 2 p0 = 1.
        assert_eq!((x.d, x.dp[0]), (0.25, 1.0));
    }

    /// A function of the coordinates alone leaves the velocity parts alone: near zero the
    /// square root's second derivative overflows (here -inf), and a value without a velocity
    /// gradient does not take it in, so `p0^2 (1 + sqrt(q0^2 + 1e-250))` keeps its finite
    /// Hessian `2 (1 + 1e-125)`.
    #[test]
    fn coordinates_alone_touch_no_velocity_part() {
        let [q0, _, p0, _, _] = jets([0.0, 0.0, 1.0, 0.0, 0.0]);
        let root = (q0 * q0 + 1e-250).sqrt();
        let x = p0 * p0 * (root + 1.0);
        assert_eq!(x.hessian(0, 0), 2.0);
        assert_eq!(x.dp, [0.0, 0.0]);
    }

    /// A Lagrangian may ask a value for its plain number or whether it is zero: a jet is
    /// zero only when its value and every part are (each part alone makes it non-zero).
    #[test]
    fn zero_means_every_part_zero() {
        let [q0, _, p0, _, t] = jets([0.0, 0.0, 0.0, 0.0, 0.0]);
        assert_eq!((q0 + 0.25).value(), 0.25);
        assert!(J::zero().is_zero() && (q0 * 0.0).is_zero());
        assert!(!J::constant(1e-300).is_zero());
        // q0 moves at 0.3: gq and d non-zero; t alone: d; p0: gp; p0 p0: h; p0 t: dp.
        let mut only_gq = q0;
        only_gq.d = 0.0;
        let parts = [only_gq, t, p0, p0 * p0, p0 * t];
        let flat = |x: &[f64; 2]| x.iter().all(|&e| e == 0.0);
        for (k, x) in parts.into_iter().enumerate() {
            let mut x = x;
            x.v = 0.0;
            let nonzero = [
                x.d != 0.0,
                !flat(&x.gq),
                !flat(&x.gp),
                !flat(&x.dp),
                !x.h.iter().all(flat),
            ];
            assert_eq!(nonzero.iter().filter(|&&n| n).count(), 1, "part {k}: {x:?}");
            assert!(!x.is_zero(), "part {k}: {x:?}");
        }
    }

    /// A constant touches no derivative, and division by one is exact.
    #[test]
    fn constants_stay_constant() {
        let c = J::from_f64(2.0) * J::from_f64(3.0) / J::one() + 1.0;
        assert_eq!(c, J::constant(7.0));
        assert!((c - 7.0).is_zero());
    }
}
