//! Hand-written RK4 loops: for the pendulum and the double pendulum, plain, non-generic `f64`
//! and `f32` code with the state in local variables, no trait, no `Result`, no checks; for every
//! other problem, one loop over arrays ([`rk4`]) on the problem's equations written by hand
//! ([`HandRhs`]). They are the speed limit for RK4: the library's `Rk4` is measured against
//! them.
//!
//! Each loop is written once in a macro and stamped out for `f64` and `f32`, so that both
//! precisions run the same arithmetic. The sines and cosines are the library's own for that
//! precision (`libm` for `f64`; `lagrange_core::fast_trig`, or `libm` with the feature
//! `libm-trig`, for `f32`), called on the concrete type through [`Scalar`], and the double
//! pendulum takes `sin` and `cos` of `th1 - th2` from one `Scalar::sin_cos` as the library's
//! `DoublePendulum` does: the comparison measures the library's overhead, not two trig
//! routines.

use super::hand_rhs::HandRhs;
use lagrange_core::{Real, Scalar, State};

/// Stamps out `pendulum_$t`: RK4 on `th'' = -w2 sin th`.
macro_rules! pendulum_loop {
    ($name:ident, $t:ty) => {
        /// RK4 on the pendulum `th'' = -w2 sin th` (`w2 = g / l`): `steps` steps of `dt` from
        /// `[th, th']`, returning `[th, th']`.
        pub fn $name(w2: $t, y: [$t; 2], dt: $t, steps: u64) -> [$t; 2] {
            let [mut th, mut om] = y;
            let half = 0.5 * dt;
            let sixth = dt / 6.0;
            for _ in 0..steps {
                let a1 = -w2 * <$t as Scalar>::sin(th);
                let (th2, om2) = (th + half * om, om + half * a1);
                let a2 = -w2 * <$t as Scalar>::sin(th2);
                let (th3, om3) = (th + half * om2, om + half * a2);
                let a3 = -w2 * <$t as Scalar>::sin(th3);
                let (th4, om4) = (th + dt * om3, om + dt * a3);
                let a4 = -w2 * <$t as Scalar>::sin(th4);
                th += sixth * (om + 2.0 * (om2 + om3) + om4);
                om += sixth * (a1 + 2.0 * (a2 + a3) + a4);
            }
            [th, om]
        }
    };
}

/// Stamps out `double_$t`: RK4 on the double pendulum with unit masses and unit lengths.
macro_rules! double_loop {
    ($name:ident, $t:ty) => {
        /// RK4 on the double pendulum with `m1 = m2 = l1 = l2 = 1` in gravity `g`: `steps`
        /// steps of `dt` from `[th1, th2, th1', th2']`, returning the same.
        pub fn $name(g: $t, y: [$t; 4], dt: $t, steps: u64) -> [$t; 4] {
            // M = [[2, c], [c, 1]], f = [-s w2^2 - 2 g sin th1, s w1^2 - g sin th2],
            // c = cos(th1 - th2), s = sin(th1 - th2); q'' = M^-1 f.
            let acc = |a: $t, b: $t, wa: $t, wb: $t| -> ($t, $t) {
                let d = a - b;
                let (s, c) = <$t as Scalar>::sin_cos(d);
                let f1 = -s * wb * wb - 2.0 * g * <$t as Scalar>::sin(a);
                let f2 = s * wa * wa - g * <$t as Scalar>::sin(b);
                let det = 2.0 - c * c;
                ((f1 - c * f2) / det, (2.0 * f2 - c * f1) / det)
            };
            let [mut a, mut b, mut wa, mut wb] = y;
            let half = 0.5 * dt;
            let sixth = dt / 6.0;
            for _ in 0..steps {
                let (aa1, ab1) = acc(a, b, wa, wb);
                let (a2, b2, wa2, wb2) = (
                    a + half * wa,
                    b + half * wb,
                    wa + half * aa1,
                    wb + half * ab1,
                );
                let (aa2, ab2) = acc(a2, b2, wa2, wb2);
                let (a3, b3, wa3, wb3) = (
                    a + half * wa2,
                    b + half * wb2,
                    wa + half * aa2,
                    wb + half * ab2,
                );
                let (aa3, ab3) = acc(a3, b3, wa3, wb3);
                let (a4, b4, wa4, wb4) = (a + dt * wa3, b + dt * wb3, wa + dt * aa3, wb + dt * ab3);
                let (aa4, ab4) = acc(a4, b4, wa4, wb4);
                a += sixth * (wa + 2.0 * (wa2 + wa3) + wa4);
                b += sixth * (wb + 2.0 * (wb2 + wb3) + wb4);
                wa += sixth * (aa1 + 2.0 * (aa2 + aa3) + aa4);
                wb += sixth * (ab1 + 2.0 * (ab2 + ab3) + ab4);
            }
            [a, b, wa, wb]
        }
    };
}

pendulum_loop!(pendulum_f64, f64);
pendulum_loop!(pendulum_f32, f32);
double_loop!(double_f64, f64);
double_loop!(double_f32, f32);

/// RK4 over arrays on `rhs`: `steps` steps of `dt` from `start`, with the library's `Rk4`'s
/// arithmetic in the same order (`q + q' h/2`, ..., `q + (k1 + 2 (k2 + k3) + k4) h/6`), the
/// state in stack arrays and nothing checked. The time of the end is `t + steps dt`.
#[allow(clippy::needless_range_loop)] // indices read like the formulas, over four arrays at once
pub fn rk4<T: Real, R: HandRhs<T, N>, const N: usize>(
    rhs: &R,
    start: &State<T, N>,
    dt: T,
    steps: u64,
) -> State<T, N> {
    let (mut q, mut v): ([T; N], [T; N]) = (start.q.into(), start.qd.into());
    let half = dt * T::HALF;
    let sixth = dt / T::from_f64(6.0);
    let t0 = start.t;
    let mut t = t0;
    let zero = [T::zero(); N];
    let (mut a1, mut a2, mut a3, mut a4) = (zero, zero, zero, zero);
    let (mut q2, mut v2, mut q3, mut v3, mut q4, mut v4) = (zero, zero, zero, zero, zero, zero);
    for _ in 0..steps {
        rhs.accelerations(t, &q, &v, &mut a1);
        for i in 0..N {
            q2[i] = q[i] + v[i] * half;
            v2[i] = v[i] + a1[i] * half;
        }
        rhs.accelerations(t + half, &q2, &v2, &mut a2);
        for i in 0..N {
            q3[i] = q[i] + v2[i] * half;
            v3[i] = v[i] + a2[i] * half;
        }
        rhs.accelerations(t + half, &q3, &v3, &mut a3);
        for i in 0..N {
            q4[i] = q[i] + v3[i] * dt;
            v4[i] = v[i] + a3[i] * dt;
        }
        rhs.accelerations(t + dt, &q4, &v4, &mut a4);
        for i in 0..N {
            q[i] += (v[i] + (v2[i] + v3[i]) * T::TWO + v4[i]) * sixth;
            v[i] += (a1[i] + (a2[i] + a3[i]) * T::TWO + a4[i]) * sixth;
        }
        t += dt;
    }
    State {
        t: t0 + dt * T::from_f64(steps as f64),
        q: q.into(),
        qd: v.into(),
    }
}
