//! A stiff spring, `k/m = 1e8`, stepped at `dt = 1e-2` (`h w = 100`): the L-stable methods
//! damp it out, the A-stable symmetric ones keep its energy, and the explicit ones fail with
//! an error, never a panic or a state holding NaN.

use lagrange_core::{Error, Lagrangian, Real, State};
use lagrange_integrators::{
    AdaptiveSettings, BackwardEuler, DormandPrince54, ExplicitEuler, GaussLegendre2,
    ImplicitMidpoint, Integrator, RadauIIA2, Rk4, SemiImplicitEuler, StormerVerlet, VelocityVerlet,
    Yoshida4,
};
use lagrange_systems::SpringMassDamper;
use lagrange_tests::{for_f32_and_f64, pick};

/// `w^2 = k/m` with `m = 1`: a 1.6 kHz oscillation.
const STIFFNESS: f64 = 1e8;
/// The step, 100 times `1 / w`.
const DT: f64 = 1e-2;
/// Steps of each run (10 s).
const STEPS: u64 = 1000;

/// The energies after each step of `I` from `x = 1` at rest.
fn energies<T: Real, I: Integrator<T, 1, SpringMassDamper<T>>>(
    mut i: I,
) -> Result<Vec<f64>, Error> {
    let spring = SpringMassDamper::new(T::one(), T::from_f64(STIFFNESS), T::zero())?;
    let mut s = State::new(T::zero(), [T::one()], [T::zero()]);
    let mut e = vec![spring.energy(&s).to_f64()];
    for _ in 0..STEPS {
        s = i.step(&spring, &s, T::from_f64(DT))?;
        assert!(s.is_finite());
        e.push(spring.energy(&s).to_f64());
    }
    Ok(e)
}

/// Backward Euler and Radau IIA: the energy falls at every step (backward Euler by the
/// factor `1 / (1 + (h w)^2) = 1e-4` per step, Radau IIA by `|R(100 i)|^2 ~ 4e-4`), is gone
/// (below 1e-30 of the start) after 10 steps, and the runs go on through the subnormal range
/// to an exact zero without an error.
fn l_stable_methods_damp_the_stiff_spring<T: Real>() -> Result<(), Error> {
    for (name, e) in [
        (
            "backward Euler",
            energies::<T, _>(BackwardEuler::default())?,
        ),
        ("Radau IIA 2", energies::<T, _>(RadauIIA2::default())?),
    ] {
        println!(
            "{name}: E after 1, 2, 10 steps: {:.2e} {:.2e} {:.2e}",
            e[1] / e[0],
            e[2] / e[0],
            e[10] / e[0]
        );
        for w in e.windows(2) {
            assert!(
                w[1] <= w[0] || w[1] == 0.0,
                "{name}: energy rose {} -> {}",
                w[0],
                w[1]
            );
        }
        assert!(
            e[1] < 1e-3 * e[0],
            "{name}: first step kept {}",
            e[1] / e[0]
        );
        assert!(
            e[10] < 1e-30 * e[0],
            "{name}: ten steps kept {}",
            e[10] / e[0]
        );
    }
    Ok(())
}

/// Implicit midpoint and Gauss-Legendre are A-stable and symmetric: `|R(i y)| = 1`, so the
/// stiff spring keeps its energy (to rounding in the Newton matrix, whose condition number is
/// `(h w)^2 / 4`: measured worst relative change over 1000 steps 4.8e-13 in f64, 9.9e-5 in
/// f32) although its phase is meaningless at this step.
fn a_stable_symmetric_methods_keep_the_energy<T: Real>() -> Result<(), Error> {
    let tolerance = pick::<T>(2e-4, 1e-12);
    for (name, e) in [
        (
            "implicit midpoint",
            energies::<T, _>(ImplicitMidpoint::default())?,
        ),
        (
            "Gauss-Legendre 2",
            energies::<T, _>(GaussLegendre2::default())?,
        ),
    ] {
        let worst = e.iter().map(|x| (x / e[0] - 1.0).abs()).fold(0.0, f64::max);
        println!("{name}: worst relative energy change {worst:.2e}");
        assert!(worst < tolerance, "{name}: {worst}");
    }
    Ok(())
}

/// `I` from `x = 1` at rest: `NonFiniteState` once the amplitude overflows.
fn blows_up<T: Real, I: Integrator<T, 1, SpringMassDamper<T>>>(mut i: I) -> Result<u64, Error> {
    let spring = SpringMassDamper::new(T::one(), T::from_f64(STIFFNESS), T::zero())?;
    let mut s = State::new(T::zero(), [T::one()], [T::zero()]);
    for k in 0..STEPS {
        match i.step(&spring, &s, T::from_f64(DT)) {
            Ok(next) => s = next,
            Err(Error::NonFiniteState) => return Ok(k),
            Err(e) => return Err(e),
        }
    }
    Err(Error::NoConvergence {
        iterations: u32::try_from(STEPS).unwrap_or(u32::MAX),
    })
}

/// Far past their stability limits (`h w` = 100 against 2 to 2.8), the explicit methods'
/// amplitudes grow every step until the state overflows, which they report as
/// `NonFiniteState`: documented divergence, no panic, no NaN handed back.
fn explicit_methods_report_the_blow_up<T: Real>() -> Result<(), Error> {
    let steps = [
        ("explicit Euler", blows_up::<T, _>(ExplicitEuler)?),
        ("semi-implicit Euler", blows_up::<T, _>(SemiImplicitEuler)?),
        ("velocity Verlet", blows_up::<T, _>(VelocityVerlet)?),
        (
            "Stormer-Verlet",
            blows_up::<T, _>(StormerVerlet::default())?,
        ),
        (
            "Yoshida 4",
            blows_up::<T, _>(Yoshida4::<StormerVerlet<T, 1>>::default())?,
        ),
        ("RK4", blows_up::<T, _>(Rk4)?),
    ];
    for (name, k) in steps {
        println!("{name}: NonFiniteState after {k} steps");
    }
    Ok(())
}

/// The adaptive explicit method does not diverge: its controller keeps the step below the
/// stability limit (`h w < 3.3`; at rtol 1e-3 accuracy holds it near `h w = 0.9`), so 10 s
/// would take some 1e5 steps; with the step limit at 1000 it returns `TooManySteps`, having
/// integrated a finite, bounded state.
fn adaptive_explicit_is_limited_by_stability<T: Real>() -> Result<(), Error> {
    let spring = SpringMassDamper::new(T::one(), T::from_f64(STIFFNESS), T::zero())?;
    let start = State::new(T::zero(), [T::one()], [T::zero()]);
    let settings =
        AdaptiveSettings::new(T::from_f64(1e-3), T::from_f64(1e-6))?.with_max_steps(1000)?;
    let mut dp = DormandPrince54::new(settings);
    let failed = dp.integrate_to(&spring, &start, T::from_f64(STEPS as f64 * DT));
    let Err(failure) = failed else {
        return Err(Error::NoConvergence { iterations: 0 });
    };
    assert_eq!(failure.error, Error::TooManySteps { steps: 1000 });
    let s = failure.last;
    println!(
        "DP5 after 1000 steps: t = {:.3e} s, mean step {:.2e} s, x = {:.3}",
        s.t.to_f64(),
        s.t.to_f64() / 1000.0,
        s.q[0].to_f64()
    );
    assert!(s.is_finite() && s.q[0].abs() < T::from_f64(1.01));
    assert!(s.t.to_f64() / 1000.0 < 4.0 / STIFFNESS.sqrt());
    Ok(())
}

for_f32_and_f64!(
    l_stable_methods_damp_the_stiff_spring,
    a_stable_symmetric_methods_keep_the_energy,
    explicit_methods_report_the_blow_up,
    adaptive_explicit_is_limited_by_stability
);
