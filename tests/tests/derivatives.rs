//! The derivative tools on their own: every rule of the dual numbers against the derivative
//! written out by hand (first and, nested, second), and the `Jacobian` record with the central
//! differences that fill it, whose step follows the size of the coordinate.

use lagrange_core::nalgebra::{SMatrix, SVector, Vector1};
use lagrange_core::{central_difference_jacobian, Dual, Error, Jacobian, Real, Scalar, State};
use lagrange_tests::{for_f32_and_f64, pick};

/// Zero and one, and whether a number is zero, through the bound (`Scalar` asks for
/// `num_traits`' `Zero` and `One`).
fn zero<S: Scalar>() -> S {
    S::zero()
}
fn one<S: Scalar>() -> S {
    S::one()
}
fn is_zero<S: Scalar>(x: &S) -> bool {
    x.is_zero()
}

/// `x` seeded along the first of two directions.
fn var<T: Real>(x: f64) -> Dual<T, 2> {
    Dual::variable(T::from_f64(x), 0)
}

/// `|got - want| <= tol (1 + |want|)` for a value and both its derivatives.
fn near<T: Real>(got: Dual<T, 2>, want: [f64; 3], tol: f64, what: &str) {
    let got = [got.re, got.eps[0], got.eps[1]].map(Real::to_f64);
    for (g, w) in got.iter().zip(want) {
        assert!(
            (g - w).abs() <= tol * (1.0 + w.abs()),
            "{what}: {got:?}, want {want:?}"
        );
    }
}

/// Every arithmetic rule, between dual numbers and with a plain number, in the operator and
/// the assigning form, at `x = 0.7`, `y = -1.3` (`x` seeded along 0, `y` along 1).
fn arithmetic_rules<T: Real>() -> Result<(), Error> {
    // A few roundings of the operands: 8 ulps, relative.
    let tol = 8.0 * T::EPSILON.to_f64();
    let (x0, y0) = (0.7, -1.3);
    let x = var::<T>(x0);
    let y = Dual::<T, 2>::variable(T::from_f64(y0), 1);
    near(x + y, [x0 + y0, 1.0, 1.0], tol, "x + y");
    near(x - y, [x0 - y0, 1.0, -1.0], tol, "x - y");
    near(x * y, [x0 * y0, y0, x0], tol, "x y");
    near(x / y, [x0 / y0, 1.0 / y0, -x0 / (y0 * y0)], tol, "x / y");
    near(-x, [-x0, -1.0, 0.0], tol, "-x");
    let mut z = x;
    z += y;
    near(z, [x0 + y0, 1.0, 1.0], tol, "x += y");
    z = x;
    z -= y;
    near(z, [x0 - y0, 1.0, -1.0], tol, "x -= y");
    z = x;
    z *= y;
    near(z, [x0 * y0, y0, x0], tol, "x *= y");
    z = x;
    z /= y;
    near(z, [x0 / y0, 1.0 / y0, -x0 / (y0 * y0)], tol, "x /= y");
    let c = T::from_f64(2.5);
    near(x + c, [x0 + 2.5, 1.0, 0.0], tol, "x + 2.5");
    near(x - c, [x0 - 2.5, 1.0, 0.0], tol, "x - 2.5");
    near(x * c, [x0 * 2.5, 2.5, 0.0], tol, "x 2.5");
    near(x / c, [x0 / 2.5, 1.0 / 2.5, 0.0], tol, "x / 2.5");
    z = x;
    z += c;
    near(z, [x0 + 2.5, 1.0, 0.0], tol, "x += 2.5");
    z = x;
    z -= c;
    near(z, [x0 - 2.5, 1.0, 0.0], tol, "x -= 2.5");
    z = x;
    z *= c;
    near(z, [x0 * 2.5, 2.5, 0.0], tol, "x *= 2.5");
    z = x;
    z /= c;
    near(z, [x0 / 2.5, 1.0 / 2.5, 0.0], tol, "x /= 2.5");
    // Constants, and which numbers are zero: a zero value with a derivative is not.
    near(
        Dual::<T, 2>::from_f64(3.0),
        [3.0, 0.0, 0.0],
        0.0,
        "from_f64",
    );
    near(
        Dual::<T, 2>::from_real(c),
        [2.5, 0.0, 0.0],
        0.0,
        "from_real",
    );
    near(one::<Dual<T, 2>>(), [1.0, 0.0, 0.0], 0.0, "one");
    assert_eq!(x.value(), T::from_f64(x0));
    assert!(is_zero(&zero::<Dual<T, 2>>()));
    assert!(!is_zero(&var::<T>(0.0)));
    assert!(!is_zero(&Dual::<T, 2>::constant(T::one())));
    // A direction past the last is no direction: a constant.
    near(
        Dual::<T, 2>::variable(c, 2),
        [2.5, 0.0, 0.0],
        0.0,
        "variable(_, 2)",
    );
    Ok(())
}

/// Every function's value and derivative at a point where it is smooth.
fn function_rules<T: Real>() -> Result<(), Error> {
    // The functions' own rounding (libm, fast_trig in f32: a few ulps) times the argument.
    let tol = 16.0 * T::EPSILON.to_f64();
    let x0 = 0.7f64;
    let x = var::<T>(x0);
    near(x.sin(), [x0.sin(), x0.cos(), 0.0], tol, "sin");
    near(x.cos(), [x0.cos(), -x0.sin(), 0.0], tol, "cos");
    let (s, c) = x.sin_cos();
    near(s, [x0.sin(), x0.cos(), 0.0], tol, "sin_cos.0");
    near(c, [x0.cos(), -x0.sin(), 0.0], tol, "sin_cos.1");
    let sec2 = 1.0 / (x0.cos() * x0.cos());
    near(x.tan(), [x0.tan(), sec2, 0.0], tol, "tan");
    near(x.sqrt(), [x0.sqrt(), 0.5 / x0.sqrt(), 0.0], tol, "sqrt");
    near(x.exp(), [x0.exp(), x0.exp(), 0.0], tol, "exp");
    near(x.ln(), [x0.ln(), 1.0 / x0, 0.0], tol, "ln");
    near(x.recip(), [1.0 / x0, -1.0 / (x0 * x0), 0.0], tol, "recip");
    near(x.powi(3), [x0.powi(3), 3.0 * x0 * x0, 0.0], tol, "powi(3)");
    near(
        x.powi(-2),
        [x0.powi(-2), -2.0 / x0.powi(3), 0.0],
        tol,
        "powi(-2)",
    );
    near(x.abs(), [x0, 1.0, 0.0], tol, "abs(0.7)");
    near(var::<T>(-x0).abs(), [x0, -1.0, 0.0], tol, "abs(-0.7)");
    // atan2(y, x) with y = x0 along 0 and x = -1.3 along 1.
    let w = Dual::<T, 2>::variable(T::from_f64(-1.3), 1);
    let r2 = x0 * x0 + 1.3 * 1.3;
    near(
        x.atan2(w),
        [x0.atan2(-1.3), -1.3 / r2, -x0 / r2],
        tol,
        "atan2",
    );
    Ok(())
}

/// Nested, `Dual<Dual<T, 1>, 1>` gives the second derivative: `d2/dx2 (sin(x) x^2 / (1 + x))`
/// at 0.7 against the formula written out by hand.
fn second_derivatives<T: Real>() -> Result<(), Error> {
    type D2<T> = Dual<Dual<T, 1>, 1>;
    let x0 = 0.7f64;
    let inner = Dual::<T, 1>::variable(T::from_f64(x0), 0);
    let x = D2::<T>::new(inner, [Dual::constant(T::one())]);
    let mut f = x.sin() * x * x;
    f /= x + T::one();
    // f = u / v, u = sin x x^2, v = 1 + x.
    let (s, c) = (x0.sin(), x0.cos());
    let u = s * x0 * x0;
    let du = c * x0 * x0 + 2.0 * s * x0;
    let ddu = -s * x0 * x0 + 4.0 * c * x0 + 2.0 * s;
    let v = 1.0 + x0;
    let want = u / v;
    let d1 = du / v - u / (v * v);
    let d2 = ddu / v - 2.0 * du / (v * v) + 2.0 * u / (v * v * v);
    let got = [f.re.re, f.re.eps[0], f.eps[0].eps[0]].map(Real::to_f64);
    // A few dozen roundings through the nested rules.
    let tol = 64.0 * T::EPSILON.to_f64();
    for (g, w) in got.iter().zip([want, d1, d2]) {
        assert!((g - w).abs() <= tol * (1.0 + w.abs()), "{got:?}");
    }
    Ok(())
}

/// The `Jacobian` record: its blocks add and subtract entry by entry, and it is finite only
/// when both blocks are.
fn the_jacobian_record<T: Real>() -> Result<(), Error> {
    let m = |a: f64| SMatrix::<T, 2, 2>::from_fn(|i, j| T::from_f64(a + (2 * i + j) as f64));
    let a = Jacobian {
        wrt_q: m(1.0),
        wrt_qd: m(10.0),
    };
    let b = Jacobian {
        wrt_q: m(-3.0),
        wrt_qd: m(0.5),
    };
    let sum = a + b;
    let difference = a - b;
    for i in 0..2 {
        for j in 0..2 {
            let k = (2 * i + j) as f64;
            assert_eq!(sum.wrt_q[(i, j)].to_f64(), -2.0 + 2.0 * k);
            assert_eq!(sum.wrt_qd[(i, j)].to_f64(), 10.5 + 2.0 * k);
            assert_eq!(difference.wrt_q[(i, j)].to_f64(), 4.0);
            assert_eq!(difference.wrt_qd[(i, j)].to_f64(), 9.5);
        }
    }
    assert!(a.is_finite() && Jacobian::<T, 2>::zeros().is_finite());
    let mut bad = a;
    bad.wrt_q[(1, 0)] = T::from_f64(f64::NAN);
    assert!(!bad.is_finite());
    let mut bad = a;
    bad.wrt_qd[(0, 1)] = T::INFINITY;
    assert!(!bad.is_finite());
    Ok(())
}

/// Central differences of `g = (q^3, q'^3)` at coordinates of 0, 1 and 1000: the step grows
/// with the coordinate (`h = EPSILON^(1/3) (1 + |x|)`), so the derivative stays accurate to
/// about `EPSILON^(2/3)` at every size. A fixed or shrinking step loses it at 1000 to the
/// rounding of `g`; a step that vanishes at 0 or 1 gives NaN.
#[test]
fn central_differences_scale_the_step() {
    let g = |s: &State<f64, 1>| SVector::<f64, 2>::new(s.q[0].powi(3), s.qd[0].powi(3));
    for x in [0.0, 1.0, -1.0, 1000.0] {
        let s = State::new(0.0, [x], [x]);
        // g is 2 x 1 here: two functions of one coordinate, through a 1 x 1 view per block.
        let j = central_difference_jacobian(&s, |s: &State<f64, 1>| Vector1::new(g(s)[0]));
        let jd = central_difference_jacobian(&s, |s: &State<f64, 1>| Vector1::new(g(s)[1]));
        let exact = 3.0 * x * x;
        // Truncation h^2 and rounding EPSILON |g| / h balance at EPSILON^(2/3) ~ 4e-11 of
        // the scale (1 + |x|)^2 of the derivative; measured at most 1.2e-11 here.
        let bound = 1e-10 * (1.0 + x.abs()).powi(2);
        assert!((j.wrt_q[(0, 0)] - exact).abs() <= bound, "{x}: {j:?}");
        assert!((jd.wrt_qd[(0, 0)] - exact).abs() <= bound, "{x}: {jd:?}");
        assert_eq!(j.wrt_qd[(0, 0)], 0.0);
        assert_eq!(jd.wrt_q[(0, 0)], 0.0);
    }
}

/// In `f32` too: the derivative of `sin q` at 0.5 and 300, to `EPSILON^(2/3)` of its scale.
#[test]
fn central_differences_in_f32() {
    for x in [0.5f32, 300.0] {
        let s = State::new(0.0f32, [x], [0.0]);
        let j = central_difference_jacobian(&s, |s: &State<f32, 1>| Vector1::new(s.q[0].sin()));
        // EPSILON^(2/3) ~ 2.5e-5 of the scale (1 + |x|) of the step's rounding.
        let bound = pick::<f32>(1e-4, 0.0) * f64::from(1.0 + x.abs());
        let exact = f64::from(x).cos();
        assert!(
            (f64::from(j.wrt_q[(0, 0)]) - exact).abs() <= bound,
            "{x}: {j:?}"
        );
    }
}

for_f32_and_f64!(
    arithmetic_rules,
    function_rules,
    second_derivatives,
    the_jacobian_record
);
