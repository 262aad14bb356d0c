//! Time-dependent integration: a spring-mass-damper driven by `F0 cos(w t)`, a force that reads
//! `state.t`, against its closed form ([`DrivenOscillator`]). Every fixed-step method's fitted
//! order and its error at a named step, f32 and f64, so that a stage evaluated at the wrong time
//! shows.

use lagrange_core::nalgebra::{SVector, Vector1};
use lagrange_core::{Error, EulerLagrange, Mechanism, Real, State};
use lagrange_integrators::{
    BackwardEuler, ExplicitEuler, GaussLegendre2, ImplicitMidpoint, Integrator, RadauIIA2, Rk4,
    SemiImplicitEuler, StormerVerlet, VariationalMidpoint, VelocityVerlet, Yoshida4,
};
use lagrange_systems::exact::DrivenOscillator;
use lagrange_systems::SpringMassDamper;
use lagrange_tests::{fitted_order, for_f32_and_f64, pick, state_error};

/// `m = 1`, `k = 4` (`w0 = 2`), `c = 0.5`, driven at `w = 3` (off resonance, 1.5 `w0`) with
/// `F0 = 3`, as large as the spring's force `k x0 = 4` at the start `x0 = 1`, `x0' = 0`.
const M: f64 = 1.0;
const K: f64 = 4.0;
const C: f64 = 0.5;
const F0: f64 = 3.0;
const W: f64 = 3.0;
const X0: f64 = 1.0;
const V0: f64 = 0.0;
/// Horizon, s: a little over a period of the drive (2.09 s) and of the spring (3.14 s).
const T_END: f64 = 4.0;
/// Allowed distance of the fitted from the stated order.
const ORDER_TOLERANCE: f64 = 0.2;

/// The drive `F0 cos(w t)`, read from the state's time.
fn drive<T: Real>() -> Drive<T> {
    |s: &State<T, 1>| Vector1::new(T::from_f64(F0) * (T::from_f64(W) * s.t).cos())
}

/// The drive as a force: a plain function of the state.
type Drive<T> = fn(&State<T, 1>) -> SVector<T, 1>;

/// The driven spring.
type Driven<T> = lagrange_core::Forced<SpringMassDamper<T>, Drive<T>>;

/// The spring-mass-damper, which every method but the variational one steps.
fn spring<T: Real>() -> Result<SpringMassDamper<T>, Error> {
    SpringMassDamper::new(T::from_f64(M), T::from_f64(K), T::from_f64(C))
}

/// The start, at `t = 0`.
fn start<T: Real>() -> State<T, 1> {
    State::new(T::zero(), [T::from_f64(X0)], [T::from_f64(V0)])
}

/// The exact `(x, x')` at `t`.
fn exact(t: f64) -> Result<[f64; 2], Error> {
    let (x, v) = DrivenOscillator::new(M, K, C, F0, W)?.state(X0, V0, t)?;
    Ok([x, v])
}

/// What a method is held to: its stated order, fitted over the step sizes `dts` (the f32 and
/// the f64 sets), and a bound on its error at the first (largest) of them, `(f32, f64)`.
struct Expect {
    dts: (&'static [f64], &'static [f64]),
    bound: (f64, f64),
}

/// Step sizes: powers of two, so that every step's time `n dt` is exact in f32 too. (A decimal
/// step rounds `t + dt` at every step; over 4000 steps of 1e-3 in f32 the time drifted by up
/// to 4e-4 s from the motion, an error of 1e-4 to 1e-3 in the state that hid every method's
/// order.) Each set is coarse enough for its errors to stay far above rounding (f32: about
/// 1e-6 here) and fine enough to be in the asymptotic regime (`w dt <= 0.4`; f32's fourth-order
/// set starts at `w dt = 0.75` and has three steps, as the fourth would sit at rounding).
const FIRST_ORDER: &[f64] = &[3.90625e-3, 1.953125e-3, 9.765625e-4, 4.8828125e-4];
const SECOND_ORDER: &[f64] = &[3.125e-2, 1.5625e-2, 7.8125e-3, 3.90625e-3];
const HIGH_ORDER: &[f64] = &[0.125, 0.0625, 0.03125, 0.015625];
const HIGH_ORDER_F32: &[f64] = &[0.25, 0.125, 0.0625];
const THIRD_ORDER_F32: &[f64] = &[0.25, 0.125, 0.0625, 0.03125];

/// The final errors of `run(dt, steps)` over `expect`'s step sizes for `T`; asserts the fitted
/// order within [`ORDER_TOLERANCE`] of `stated` and the error at the first step within the
/// bound.
fn assert_order_and_error<T: Real>(
    name: &str,
    stated: u32,
    expect: &Expect,
    mut run: impl FnMut(T, u64) -> Result<State<T, 1>, Error>,
) -> Result<(), Error> {
    let dts = if pick::<T>(1.0, 0.0) > 0.5 {
        expect.dts.0
    } else {
        expect.dts.1
    };
    let bound = pick::<T>(expect.bound.0, expect.bound.1);
    let mut errs = Vec::new();
    for &dt in dts {
        let end = run(T::from_f64(dt), (T_END / dt).round() as u64)?;
        assert_eq!(end.t.to_f64(), T_END, "{name}: time rounded");
        errs.push(state_error(&end, &exact(T_END)?));
    }
    let order = fitted_order(dts, &errs);
    println!(
        "{name:<22} {:<4} dt {:.2e}: errors {:?} -> order {order:.3} (stated {stated}); bound \
         {bound:.1e}",
        core::any::type_name::<T>(),
        dts[0],
        errs.iter().map(|e| format!("{e:.3e}")).collect::<Vec<_>>()
    );
    assert!(
        (order - f64::from(stated)).abs() < ORDER_TOLERANCE,
        "{name}: fitted order {order:.3}, stated {stated}; errors {errs:?}"
    );
    assert!(
        errs[0] < bound,
        "{name}: error {:.3e} at dt = {} above {bound:.1e}",
        errs[0],
        dts[0]
    );
    Ok(())
}

/// [`assert_order_and_error`] for a fixed-step integrator `I` on the driven spring.
fn fixed_step<T: Real, I>(expect: &Expect) -> Result<(), Error>
where
    I: Integrator<T, 1, Driven<T>> + Default,
{
    let m: Driven<T> = spring::<T>()?.with_force(drive::<T>());
    assert_order_and_error::<T>(I::NAME, I::ORDER, expect, |dt, steps| {
        Ok(I::default().integrate(&m, &start(), dt, steps)?)
    })
}

/// The explicit methods. Error at the first step size, measured (f32 / f64) and bound (about
/// 5x, the same in both precisions where the truncation error dominates):
///
/// ```text
/// method               dt       measured            bound
/// explicit Euler       2^-8     6.3e-2 / 6.3e-2     0.3
/// semi-implicit Euler  2^-8     1.0e-2 / 1.0e-2     5e-2
/// velocity Verlet      2^-5     2.7e-3 / 2.7e-3     1.3e-2
/// RK4                  2^-2     4.3e-3              2e-2      (f32)
/// RK4                  2^-3               2.6e-4    1.3e-3    (f64)
/// ```
fn explicit_methods<T: Real>() -> Result<(), Error> {
    fixed_step::<T, ExplicitEuler>(&Expect {
        dts: (FIRST_ORDER, FIRST_ORDER),
        bound: (0.3, 0.3),
    })?;
    fixed_step::<T, SemiImplicitEuler>(&Expect {
        dts: (FIRST_ORDER, FIRST_ORDER),
        bound: (5e-2, 5e-2),
    })?;
    fixed_step::<T, VelocityVerlet>(&Expect {
        dts: (SECOND_ORDER, SECOND_ORDER),
        bound: (1.3e-2, 1.3e-2),
    })?;
    fixed_step::<T, Rk4>(&Expect {
        dts: (HIGH_ORDER_F32, HIGH_ORDER),
        bound: (2e-2, 1.3e-3),
    })
}

/// The symmetric methods, the composition among them. Measured at the first step size (f32 /
/// f64) and bound:
///
/// ```text
/// method               dt       measured            bound
/// Stormer-Verlet       2^-5     1.6e-3 / 1.6e-3     8e-3
/// Yoshida 4            2^-2     4.0e-2              0.2       (f32)
/// Yoshida 4            2^-3               2.4e-3    1.2e-2    (f64)
/// ```
fn symmetric_methods<T: Real>() -> Result<(), Error> {
    fixed_step::<T, StormerVerlet<T, 1>>(&Expect {
        dts: (SECOND_ORDER, SECOND_ORDER),
        bound: (8e-3, 8e-3),
    })?;
    fixed_step::<T, Yoshida4<StormerVerlet<T, 1>>>(&Expect {
        dts: (HIGH_ORDER_F32, HIGH_ORDER),
        bound: (0.2, 1.2e-2),
    })
}

/// The implicit Runge-Kutta methods, whose stages sit at `t + c_i dt` inside the Newton
/// iteration. Measured at the first step size (f32 / f64) and bound:
///
/// ```text
/// method               dt       measured            bound
/// implicit midpoint    2^-5     2.4e-3 / 2.4e-3     1.2e-2
/// Gauss-Legendre 2     2^-2     6.6e-4              3e-3      (f32)
/// Gauss-Legendre 2     2^-3               4.2e-5    2e-4      (f64)
/// backward Euler       2^-8     6.2e-2 / 6.2e-2     0.3
/// Radau IIA 2          2^-2     2.5e-2              0.12      (f32)
/// Radau IIA 2          2^-3               3.3e-3    1.6e-2    (f64)
/// ```
fn implicit_methods<T: Real>() -> Result<(), Error> {
    fixed_step::<T, ImplicitMidpoint<T>>(&Expect {
        dts: (SECOND_ORDER, SECOND_ORDER),
        bound: (1.2e-2, 1.2e-2),
    })?;
    fixed_step::<T, GaussLegendre2<T>>(&Expect {
        dts: (HIGH_ORDER_F32, HIGH_ORDER),
        bound: (3e-3, 2e-4),
    })?;
    fixed_step::<T, BackwardEuler<T>>(&Expect {
        dts: (FIRST_ORDER, FIRST_ORDER),
        bound: (0.3, 0.3),
    })?;
    fixed_step::<T, RadauIIA2<T>>(&Expect {
        dts: (THIRD_ORDER_F32, HIGH_ORDER),
        bound: (0.12, 1.6e-2),
    })
}

/// The variational integrator, on the automatic path of the same spring with the drive added
/// (its discrete forces are evaluated at the midpoint time of each step). Measured at dt = 2^-5:
/// 2.4e-3 in f32 and f64; bound 1.2e-2.
fn variational_method<T: Real>() -> Result<(), Error> {
    let m = EulerLagrange::new(spring::<T>()?).with_force(drive::<T>());
    let expect = Expect {
        dts: (SECOND_ORDER, SECOND_ORDER),
        bound: (1.2e-2, 1.2e-2),
    };
    assert_order_and_error::<T>("variational midpoint", 2, &expect, |dt, steps| {
        Ok(VariationalMidpoint::default().integrate(&m, &start(), dt, steps)?)
    })
}

/// The drive matters: at `T_END` the driven motion differs from the free one by far more than
/// any error bound above (measured 0.8 in x and x').
fn the_drive_matters<T: Real>() -> Result<(), Error> {
    let m = spring::<T>()?.with_force(drive::<T>());
    let a = m.acceleration(&State::new(T::from_f64(1.0), [T::zero()], [T::zero()]))?;
    assert!((a[0].to_f64() - F0 * W.cos()).abs() < pick::<T>(1e-6, 1e-15));
    let free = lagrange_systems::exact::damped_oscillator(M, K, C, X0, V0, T_END)?;
    let driven = exact(T_END)?;
    let gap = (free.0 - driven[0]).abs().max((free.1 - driven[1]).abs());
    println!("driven vs free at {T_END} s: {gap:.3}");
    assert!(gap > 0.5, "{gap}");
    Ok(())
}

for_f32_and_f64!(
    explicit_methods,
    symmetric_methods,
    implicit_methods,
    variational_method,
    the_drive_matters
);
