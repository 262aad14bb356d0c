//! Hand-written RK4 loops for the pendulum and the double pendulum: plain, non-generic `f64` and
//! `f32` code with the state in local variables, no trait, no `Result`, no checks. They are the
//! speed limit for RK4 on these two problems: the library's `Rk4` is measured against them.
//!
//! Each loop is written once in a macro and stamped out for `f64` and `f32`, so that both
//! precisions run the same arithmetic. The sines and cosines are the library's own for that
//! precision (`libm` for `f64`; `lagrange_core::fast_trig`, or `libm` with the feature
//! `libm-trig`, for `f32`), called on the concrete type through [`Scalar`], and the double
//! pendulum takes `sin` and `cos` of `th1 - th2` from one `Scalar::sin_cos` as the library's
//! `DoublePendulum` does: the comparison measures the library's overhead, not two trig
//! routines.

use lagrange_core::Scalar;

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
