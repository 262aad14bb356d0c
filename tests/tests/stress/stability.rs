//! Step sizes up to and past the stability limit of each explicit method: the library either
//! returns a finite state or a specific error, never a panic or a state holding NaN; on a linear
//! oscillator each method is stable just inside its theoretical limit and blows up (with
//! `Error::NonFiniteState`) just outside it.

use lagrange_core::{Error, Lagrangian, Mechanism, Real, State};
use lagrange_integrators::{ExplicitEuler, Integrator, Rk4, SemiImplicitEuler, VelocityVerlet};
use lagrange_systems::{DoublePendulum, ElasticPendulum, Kepler, SimplePendulum, SpringMassDamper};
use lagrange_tests::{for_f32_and_f64, pick};

/// Frequency of the oscillator (a unit mass on a `SpringMassDamper`), rad/s: stiff, like P5's
/// spring.
const W: f64 = 1000.0;

/// Largest `|E(t) / E(0)|` over `steps` steps of `h = hw / W` from `x = 1` at rest, or the
/// error that stopped the run.
fn energy_growth<T: Real, I: Integrator<T, 1, SpringMassDamper<T>>>(
    mut integrator: I,
    hw: f64,
    steps: u64,
) -> Result<f64, Error> {
    let m = SpringMassDamper::new(T::one(), T::from_f64(W * W), T::zero())?;
    let start = State::new(T::zero(), [T::one()], [T::zero()]);
    let e0 = m.energy(&start).to_f64();
    let mut worst: f64 = 1.0;
    integrator.integrate_with(&m, &start, T::from_f64(hw / W), steps, |s| {
        worst = worst.max(m.energy(s).to_f64() / e0);
    })?;
    Ok(worst)
}

/// Inside the limit the run finishes with bounded energy; outside it the amplitude grows
/// geometrically (by 1.88 per step for Stormer-Verlet and symplectic Euler at `h w = 2.1`, by
/// 1.41 for RK4 at 1.05 of its limit) and the run ends in `NonFiniteState` long before 10^4
/// steps.
///
/// Bounds inside, from rest at `x = 1`: RK4 is dissipative inside its limit
/// (`|R(i h w)| < 1`), so `E <= E(0)` up to rounding (1e-4 in f32, 1e-12 in f64; measured
/// exactly 1 in both). Symplectic Euler and Verlet each conserve a modified energy: from this
/// start Verlet's `E` only swings down (measured max `E / E(0)` = 1 in f64, 1 + 2.7e-5 in f32),
/// and symplectic Euler's swings up to `1 / (1 - h w / 2) = 20` at `h w = 1.9` (measured
/// 19.9999997 in f64, 20.00016 in f32): bound 20.01.
fn linear_limits<T: Real>() -> Result<(), Error> {
    let rk4 = 2.0 * core::f64::consts::SQRT_2;
    let steps = 10_000;
    let inside = energy_growth::<T, _>(Rk4, 0.95 * rk4, steps)?;
    assert!(
        inside <= 1.0 + pick::<T>(1e-4, 1e-12),
        "RK4 inside: {inside}"
    );
    assert_eq!(
        energy_growth::<T, _>(Rk4, 1.05 * rk4, steps),
        Err(Error::NonFiniteState)
    );
    let euler = energy_growth::<T, _>(SemiImplicitEuler, 1.9, steps)?;
    assert!(
        (19.9..=20.01).contains(&euler),
        "symplectic Euler inside: {euler}"
    );
    let verlet = energy_growth::<T, _>(VelocityVerlet, 1.9, steps)?;
    assert!(
        verlet <= 1.0 + pick::<T>(1e-4, 1e-12),
        "Verlet inside: {verlet}"
    );
    assert_eq!(
        energy_growth::<T, _>(SemiImplicitEuler, 2.1, steps),
        Err(Error::NonFiniteState)
    );
    assert_eq!(
        energy_growth::<T, _>(VelocityVerlet, 2.1, steps),
        Err(Error::NonFiniteState)
    );
    Ok(())
}

/// Explicit Euler has no stability limit on an oscillator: each step multiplies the energy by
/// exactly `1 + (h w)^2`. At `h w = 0.1` over 100 steps that is `1.01^100 = 2.7048`; measured
/// to within rounding: relative 1.4e-15 in f64 (bound 1e-12), 3.1e-7 in f32 (bound 1e-4; 100
/// steps rounding at 6e-8 each).
/// At `h w = 10` the energy grows 101-fold per step and the run ends in `NonFiniteState`.
fn explicit_euler_grows_exactly<T: Real>() -> Result<(), Error> {
    let growth = energy_growth::<T, _>(ExplicitEuler, 0.1, 100)?;
    let exact = 1.01f64.powi(100);
    assert!(
        (growth / exact - 1.0).abs() < pick::<T>(1e-4, 1e-12),
        "{growth} vs {exact}"
    );
    assert_eq!(
        energy_growth::<T, _>(ExplicitEuler, 10.0, 10_000),
        Err(Error::NonFiniteState)
    );
    Ok(())
}

/// The outcome of a run at one step size: a finite state, or one of the errors a blow-up may
/// give (the state overflowed, or left the coordinates' domain: `r <= 0` for the elastic
/// pendulum and Kepler). Anything else fails the test.
fn finite_or_specific<T: Real, const N: usize, E: Into<Error>>(
    result: Result<State<T, N>, E>,
    what: &str,
) -> bool {
    let result = result.map_err(Into::into);
    if let Ok(s) = &result {
        assert!(s.is_finite(), "{what}: Ok with a non-finite state {s:?}");
    }
    assert!(
        matches!(
            result,
            Ok(_)
                | Err(Error::NonFiniteState
                    | Error::SingularMassMatrix { .. }
                    | Error::Singularity { .. })
        ),
        "{what}: unexpected outcome {result:?}"
    );
    result.is_ok()
}

/// Runs every explicit method over a sweep of steps from well inside to far past its limit.
/// Returns, per method, how many step sizes ended in an error.
fn sweep<T: Real, M: Mechanism<T, N>, const N: usize>(
    m: &M,
    start: &State<T, N>,
    dts: &[f64],
    steps: u64,
    what: &str,
) -> [usize; 4] {
    let mut failures = [0; 4];
    for &dt in dts {
        let dt_t = T::from_f64(dt);
        let outcomes = [
            ExplicitEuler.integrate(m, start, dt_t, steps),
            SemiImplicitEuler.integrate(m, start, dt_t, steps),
            VelocityVerlet.integrate(m, start, dt_t, steps),
            Rk4.integrate(m, start, dt_t, steps),
        ];
        for (count, outcome) in failures.iter_mut().zip(outcomes) {
            if !finite_or_specific(outcome, &format!("{what}, dt = {dt:e}")) {
                *count += 1;
            }
        }
    }
    failures
}

/// `n` step sizes from `lo` to `hi`, geometrically.
fn geometric(lo: f64, hi: f64, n: u32) -> Vec<f64> {
    (0..n)
        .map(|i| lo * (hi / lo).powf(f64::from(i) / f64::from(n - 1)))
        .collect()
}

/// The stiff elastic pendulum of the bench's P5 (radial frequency 1000 rad/s) from `h w = 0.1`
/// to `h w = 100`: every outcome finite or a specific error, and every method fails somewhere
/// past its limit.
fn stiff_elastic_sweep<T: Real>() -> Result<(), Error> {
    let one = T::one();
    let m = ElasticPendulum::new(one, T::from_f64(1e6), one, T::from_f64(9.81))?;
    let start = State::new(
        T::zero(),
        [T::from_f64(1.0 + 9.81e-6 + 1e-3), T::from_f64(0.3)],
        [T::zero(); 2],
    );
    let failures = sweep(&m, &start, &geometric(1e-4, 0.1, 10), 1_000, "elastic");
    assert!(failures.iter().all(|&f| f > 0), "{failures:?}");
    // At h w = 0.1 the three methods with a stability region finish. Explicit Euler has none:
    // its energy grows by (1 + 0.01)^n and it may or may not have left the finite range.
    let inside = sweep(&m, &start, &[1e-4], 1_000, "elastic, inside");
    assert_eq!(inside[1..], [0, 0, 0]);
    Ok(())
}

/// The pendulum and the double pendulum (bounded forces) from `dt = 1e-3` to `dt = 10`: the
/// state may stay finite at any step (the sine bounds the force), but never holds NaN. The
/// Kepler orbit of P4 from `dt = 1e-3` to `dt = 10`: a large step throws the body through the
/// centre, which is `Singularity`, never a NaN.
fn pendulum_sweeps<T: Real>() -> Result<(), Error> {
    let g = T::from_f64(9.81);
    let one = T::one();
    let p = SimplePendulum::new(one, one, g, T::zero())?;
    let dts = geometric(1e-3, 10.0, 13);
    sweep(
        &p,
        &State::at_rest([T::from_f64(0.5)]),
        &dts,
        1_000,
        "pendulum",
    );
    let dp = DoublePendulum::new(one, one, one, one, g)?;
    let half_pi = T::from_f64(core::f64::consts::FRAC_PI_2);
    sweep(
        &dp,
        &State::at_rest([half_pi; 2]),
        &dts,
        1_000,
        "double pendulum",
    );
    let kepler = Kepler::new(one)?;
    let periapsis = State::new(
        T::zero(),
        [T::from_f64(0.5), T::zero()],
        [T::zero(), T::from_f64(12f64.sqrt())],
    );
    let failures = sweep(&kepler, &periapsis, &dts, 1_000, "Kepler");
    assert!(failures.iter().all(|&f| f > 0), "{failures:?}");
    Ok(())
}

for_f32_and_f64!(
    linear_limits,
    explicit_euler_grows_exactly,
    stiff_elastic_sweep,
    pendulum_sweeps
);
