//! Property tests over random valid parameters and states for every standard system, f32 and
//! f64: accelerations are finite; an undamped system's energy (the bead's Jacobi integral) is
//! conserved to a stated bound over a short run; damping never increases energy. Over random
//! invalid inputs (NaN, infinities, zero, negative): a specific error, never a panic. Fixed
//! seed, failures saved to a committed file, more cases in the optimised pass.

use lagrange_core::{Error, Lagrangian, Mechanism, Real, State, ViscousDamping};
use lagrange_integrators::{ExplicitEuler, Integrator, Rk4, SemiImplicitEuler, VelocityVerlet};
use lagrange_systems::{BeadOnRotatingHoop, DoublePendulum, FallingParticle, SimplePendulum};
use lagrange_tests::pick;
use proptest::prelude::*;
use proptest::test_runner::{FileFailurePersistence, RngSeed, TestCaseError};

/// Reproducible runs: a fixed seed, and failures saved to (and replayed first from)
/// `tests/proptest-regressions/properties.txt`, committed. 48 cases per property in the quick
/// unoptimised pass; 16 times as many in the optimised pass. The properties are `#[ignore]`d
/// in optimised builds, since the only optimised pass of `cargo xtask ci` is
/// `cargo test --release -- --ignored`: so they run in both passes (locally in release:
/// `cargo test --release -- --include-ignored`).
fn config() -> ProptestConfig {
    ProptestConfig {
        cases: if cfg!(debug_assertions) { 48 } else { 48 * 16 },
        rng_seed: RngSeed::Fixed(0x1a67_a4e5_0012),
        failure_persistence: Some(Box::new(FileFailurePersistence::Direct(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/proptest-regressions/properties.txt"
        )))),
        ..ProptestConfig::default()
    }
}

/// A library result inside a property.
fn ok<V, E: Into<Error>>(r: Result<V, E>) -> Result<V, TestCaseError> {
    r.map_err(|e| TestCaseError::fail(format!("unexpected error: {}", e.into())))
}

/// Length of the short runs, steps.
const STEPS: u64 = 500;
/// Their step: `h w = 0.01` with `w` an upper estimate of the system's fastest rate (so that
/// random parameters over two decades all get the same relative resolution), at most 1 ms.
fn step(omega: f64) -> f64 {
    (0.01 / omega).min(1e-3)
}

/// Largest `|I(t) - I(0)| / scale` over a short RK4 run of `m` from `start`, where `I` is the
/// conserved quantity `invariant` and `omega` the fastest rate.
fn invariant_drift<T: Real, M: Mechanism<T, N>, const N: usize>(
    m: &M,
    start: &State<T, N>,
    invariant: impl Fn(&State<T, N>) -> T,
    scale: f64,
    omega: f64,
) -> Result<f64, TestCaseError> {
    let i0 = invariant(start).to_f64();
    let mut worst: f64 = 0.0;
    ok(
        Rk4.integrate_with(m, start, T::from_f64(step(omega)), STEPS, |s| {
            worst = worst.max((invariant(s).to_f64() - i0).abs() / scale);
        }),
    )?;
    Ok(worst)
}

/// The largest rise of `E` above its running minimum over a short RK4 run: zero for a
/// mechanism whose damping only removes energy, up to integration error.
fn energy_rise<T: Real, M: Mechanism<T, N>, const N: usize>(
    m: &M,
    start: &State<T, N>,
    scale: f64,
    omega: f64,
) -> Result<f64, TestCaseError> {
    let mut low = m.energy(start).to_f64();
    let mut rise: f64 = 0.0;
    ok(
        Rk4.integrate_with(m, start, T::from_f64(step(omega)), STEPS, |s| {
            let e = m.energy(s).to_f64();
            rise = rise.max((e - low) / scale);
            low = low.min(e);
        }),
    )?;
    Ok(rise)
}

/// `acceleration` is `Ok` and finite.
fn finite_acceleration<T: Real, M: Mechanism<T, N>, const N: usize>(
    m: &M,
    s: &State<T, N>,
) -> Result<(), TestCaseError> {
    let a = ok(m.acceleration(s))?;
    prop_assert!(
        a.iter().all(|x| x.is_finite()),
        "acceleration {a:?} at {s:?}"
    );
    Ok(())
}

/// A bound on a relative drift (or rise) per precision.
#[derive(Clone, Copy)]
pub(crate) struct Bound {
    /// In f32.
    pub(crate) f32: f64,
    /// In f64.
    pub(crate) f64: f64,
}

impl Bound {
    /// The bound for `T`.
    pub(crate) fn get<T: Real>(self) -> f64 {
        pick::<T>(self.f32, self.f64)
    }
}

/// Conservation bounds over 500 RK4 steps at `h w = 0.01`, relative to the energy scale
/// (kinetic energy plus the range of the potential), at about 5 times the worst drift
/// measured over the first 4800 cases of the fixed seed (the passes run the first 48 and 768).
/// RK4's error per step is about `(h w)^5 / 120` of the scale, 1e-12, so 500 steps give about
/// 5e-10 in f64 where the rate estimate `w` holds; in f32 rounding dominates, 500 steps of
/// 6e-8 walking to about 1.3e-6.
///
/// ```text
/// system                              f64 measured   bound      f32 measured   bound
/// pendulum                            5.2e-11        2.6e-10    1.1e-5         6e-5
/// double pendulum (looser rate)       9.5e-8         5e-7       5.6e-6         2.8e-5
/// bead (Jacobi integral)              4.5e-11        2.2e-10    7.3e-6         3.6e-5
/// falling particle (exact for RK4)    2.2e-14        1.1e-13    1.2e-5         6e-5
/// damped (largest rise of E above     0              1e-14      2.4e-7         1.2e-6
///   its running minimum)
/// ```
///
/// The f64 bound on a rise is a few ulps of the scale, as the measured rise is exactly zero;
/// damping of the wrong sign (b up to 5) exceeds it by orders of magnitude.
const PENDULUM: Bound = Bound {
    f32: 6e-5,
    f64: 2.6e-10,
};
const DOUBLE: Bound = Bound {
    f32: 2.8e-5,
    f64: 5e-7,
};
const BEAD: Bound = Bound {
    f32: 3.6e-5,
    f64: 2.2e-10,
};
const PARTICLE: Bound = Bound {
    f32: 6e-5,
    f64: 1.1e-13,
};
const DAMPED: Bound = Bound {
    f32: 1.2e-6,
    f64: 1e-14,
};

/// `drift` of `what` within `bound`.
fn conserved<T: Real>(what: &str, bound: Bound, drift: f64) -> Result<(), TestCaseError> {
    prop_assert!(
        drift <= bound.get::<T>(),
        "{what}: relative drift {drift:e} > {:e}",
        bound.get::<T>()
    );
    Ok(())
}

/// Random parameters and state of each system, one property per system, in f32 and f64.
fn pendulum<T: Real>(m: f64, l: f64, g: f64, th: f64, w: f64) -> Result<f64, TestCaseError> {
    let p = ok(SimplePendulum::new(
        T::from_f64(m),
        T::from_f64(l),
        T::from_f64(g),
        T::zero(),
    ))?;
    let s = State::new(T::zero(), [T::from_f64(th)], [T::from_f64(w)]);
    finite_acceleration(&p, &s)?;
    let scale = 0.5 * m * l * l * w * w + 2.0 * m * g * l + f64::MIN_POSITIVE;
    invariant_drift(&p, &s, |x| p.energy(x), scale, (g / l).sqrt() + w.abs())
}

/// An upper estimate of the double pendulum's fastest rate: a bound on the faster normal
/// mode's frequency at the hanging state, plus the rates themselves, each scaled by how much a
/// light upper bob amplifies them (`th1''` carries `m2 / m1` times the lower bob's centripetal
/// term when `sin(th1 - th2)` is small).
fn double_rate(p: [f64; 5], q: [f64; 4]) -> f64 {
    let [m1, m2, l1, l2, g] = p;
    let whip = (1.0 + m2 / m1).sqrt();
    (g * (1.0 + m2 / m1) * (1.0 / l1 + 1.0 / l2)).sqrt() * (1.0 + l1 / l2).sqrt()
        + whip * (q[2].abs() + q[3].abs() * (1.0 + l2 / l1))
}

fn double<T: Real>(p: [f64; 5], q: [f64; 4]) -> Result<f64, TestCaseError> {
    let [m1, m2, l1, l2, g] = p;
    let dp = ok(DoublePendulum::new(
        T::from_f64(m1),
        T::from_f64(m2),
        T::from_f64(l1),
        T::from_f64(l2),
        T::from_f64(g),
    ))?;
    let s = State::new(
        T::zero(),
        [T::from_f64(q[0]), T::from_f64(q[1])],
        [T::from_f64(q[2]), T::from_f64(q[3])],
    );
    finite_acceleration(&dp, &s)?;
    let kinetic = dp.kinetic_energy(&s).to_f64();
    let scale = kinetic + 2.0 * g * ((m1 + m2) * l1 + m2 * l2) + f64::MIN_POSITIVE;
    invariant_drift(&dp, &s, |x| dp.energy(x), scale, double_rate(p, q))
}

fn bead<T: Real>(p: [f64; 4], th: f64, w: f64) -> Result<f64, TestCaseError> {
    let [m, r, omega, g] = p;
    let b = ok(BeadOnRotatingHoop::new(
        T::from_f64(m),
        T::from_f64(r),
        T::from_f64(omega),
        T::from_f64(g),
    ))?;
    let s = State::new(T::zero(), [T::from_f64(th)], [T::from_f64(w)]);
    finite_acceleration(&b, &s)?;
    let scale = 0.5 * m * r * r * (w * w + omega * omega) + 2.0 * m * g * r + f64::MIN_POSITIVE;
    let rate = (g / r).sqrt() + omega.abs() + w.abs();
    invariant_drift(&b, &s, |x| b.jacobi_integral(x), scale, rate)
}

fn particle<T: Real>(m: f64, g: f64, y: f64, v: f64) -> Result<f64, TestCaseError> {
    let p = ok(FallingParticle::new(T::from_f64(m), T::from_f64(g)))?;
    let s = State::new(T::zero(), [T::from_f64(y)], [T::from_f64(v)]);
    finite_acceleration(&p, &s)?;
    // Over 0.5 s (1 ms steps) the particle falls at most 5 * 0.5 + 20 * 0.125 = 5 m.
    let scale = 0.5 * m * (v.abs() + 10.0).powi(2) + m * g * (y.abs() + 5.0) + f64::MIN_POSITIVE;
    invariant_drift(&p, &s, |x| p.energy(x), scale, 1.0)
}

/// Damping: the pendulum's own, and viscous damping wrapped around the double pendulum.
fn damped<T: Real>(b: f64, c: [f64; 2], th: [f64; 2], w: [f64; 2]) -> Result<(), TestCaseError> {
    let (one, g) = (T::one(), T::from_f64(9.81));
    let p = ok(SimplePendulum::new(one, one, g, T::from_f64(b)))?;
    let s1 = State::new(T::zero(), [T::from_f64(th[0])], [T::from_f64(w[0])]);
    let rate = 9.81f64.sqrt() + w[0].abs();
    let rise = energy_rise(&p, &s1, 0.5 * w[0] * w[0] + 2.0 * 9.81, rate)?;
    conserved::<T>("damped pendulum, rise", DAMPED, rise)?;
    let dp =
        ok(DoublePendulum::new(one, one, one, one, g))?.with_force(ok(ViscousDamping::new([
            T::from_f64(c[0]),
            T::from_f64(c[1]),
        ]))?);
    let s2 = State::new(
        T::zero(),
        [T::from_f64(th[0]), T::from_f64(th[1])],
        [T::from_f64(w[0]), T::from_f64(w[1])],
    );
    let scale = dp.kinetic_energy(&s2).to_f64() + 6.0 * 9.81;
    let rate = double_rate([1.0, 1.0, 1.0, 1.0, 9.81], [th[0], th[1], w[0], w[1]]);
    let rise = energy_rise(&dp, &s2, scale, rate)?;
    conserved::<T>("damped double pendulum, rise", DAMPED, rise)?;
    Ok(())
}

/// Angles anywhere on the circle, rates up to 5 rad/s.
fn angle() -> impl Strategy<Value = f64> {
    -core::f64::consts::PI..core::f64::consts::PI
}
fn rate() -> impl Strategy<Value = f64> {
    -5.0..5.0f64
}
/// Masses and lengths over two decades.
fn size() -> impl Strategy<Value = f64> {
    0.1..10.0f64
}
fn gravity() -> impl Strategy<Value = f64> {
    0.0..20.0f64
}

proptest! {
    #![proptest_config(config())]

    #[test]
    #[cfg_attr(not(debug_assertions), ignore = "optimised: run with --ignored, 16x the cases")]
    fn pendulum_finite_and_conservative(m in size(), l in size(), g in gravity(), th in angle(), w in rate()) {
        conserved::<f32>("pendulum", PENDULUM, pendulum::<f32>(m, l, g, th, w)?)?;
        conserved::<f64>("pendulum", PENDULUM, pendulum::<f64>(m, l, g, th, w)?)?;
    }

    #[test]
    #[cfg_attr(not(debug_assertions), ignore = "optimised: run with --ignored, 16x the cases")]
    fn double_pendulum_finite_and_conservative(
        m1 in size(), m2 in size(), l1 in size(), l2 in size(), g in gravity(),
        th1 in angle(), th2 in angle(), w1 in rate(), w2 in rate(),
    ) {
        let (p, q) = ([m1, m2, l1, l2, g], [th1, th2, w1, w2]);
        conserved::<f32>("double pendulum", DOUBLE, double::<f32>(p, q)?)?;
        conserved::<f64>("double pendulum", DOUBLE, double::<f64>(p, q)?)?;
    }

    #[test]
    #[cfg_attr(not(debug_assertions), ignore = "optimised: run with --ignored, 16x the cases")]
    fn bead_finite_and_jacobi_conserved(
        m in size(), r in size(), omega in -10.0..10.0f64, g in gravity(), th in angle(), w in rate(),
    ) {
        conserved::<f32>("bead", BEAD, bead::<f32>([m, r, omega, g], th, w)?)?;
        conserved::<f64>("bead", BEAD, bead::<f64>([m, r, omega, g], th, w)?)?;
    }

    #[test]
    #[cfg_attr(not(debug_assertions), ignore = "optimised: run with --ignored, 16x the cases")]
    fn particle_finite_and_conservative(m in size(), g in gravity(), y in -100.0..100.0f64, v in rate()) {
        conserved::<f32>("particle", PARTICLE, particle::<f32>(m, g, y, v)?)?;
        conserved::<f64>("particle", PARTICLE, particle::<f64>(m, g, y, v)?)?;
    }

    #[test]
    #[cfg_attr(not(debug_assertions), ignore = "optimised: run with --ignored, 16x the cases")]
    fn damping_never_adds_energy(
        b in 0.0..5.0f64, c1 in 0.0..5.0f64, c2 in 0.0..5.0f64,
        th1 in angle(), th2 in angle(), w1 in rate(), w2 in rate(),
    ) {
        damped::<f32>(b, [c1, c2], [th1, th2], [w1, w2])?;
        damped::<f64>(b, [c1, c2], [th1, th2], [w1, w2])?;
    }
}

/// What a parameter may be.
#[derive(Clone, Copy)]
enum Valid {
    /// Finite and above zero.
    Positive,
    /// Finite and not below zero.
    NonNegative,
    /// Finite.
    Finite,
}

/// An invalid value for a parameter of kind `kind`, the `pick`-th of its kind, `x > 0` giving
/// the magnitude of a negative one.
fn invalid(kind: Valid, pick: usize, x: f64) -> f64 {
    match kind {
        Valid::Positive => [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 0.0, -x][pick % 5],
        Valid::NonNegative => [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -x][pick % 4],
        Valid::Finite => [f64::NAN, f64::INFINITY, f64::NEG_INFINITY][pick % 3],
    }
}

/// Builds with `valid` parameters except number `broken`, made invalid, in precision `T`, and
/// requires `InvalidParameter` naming exactly that parameter.
fn refuses<T: Real, V: core::fmt::Debug, const K: usize>(
    names: [&str; K],
    kinds: [Valid; K],
    mut params: [f64; K],
    broken: usize,
    pick: usize,
    build: impl Fn([T; K]) -> Result<V, Error>,
) -> Result<(), TestCaseError> {
    let i = broken % K;
    params[i] = invalid(kinds[i], pick, params[i]);
    let result = build(params.map(T::from_f64));
    prop_assert!(
        matches!(result, Err(Error::InvalidParameter { name, .. }) if name == names[i]),
        "{} = {}: expected InvalidParameter {{ name: {} }}, got {result:?}",
        names[i],
        params[i],
        names[i]
    );
    Ok(())
}

/// Every constructor, one random parameter broken.
fn constructors_refuse<T: Real>(
    p: [f64; 5],
    broken: usize,
    pick: usize,
) -> Result<(), TestCaseError> {
    use Valid::{Finite, NonNegative, Positive};
    let [a, b, c, d, e] = p;
    refuses::<T, _, 2>(
        ["mass", "gravity"],
        [Positive, NonNegative],
        [a, b],
        broken,
        pick,
        |[m, g]| FallingParticle::new(m, g),
    )?;
    refuses::<T, _, 4>(
        ["mass", "length", "gravity", "damping"],
        [Positive, Positive, NonNegative, NonNegative],
        [a, b, c, d],
        broken,
        pick,
        |[m, l, g, damping]| SimplePendulum::new(m, l, g, damping),
    )?;
    refuses::<T, _, 4>(
        ["mass", "radius", "omega", "gravity"],
        [Positive, Positive, Finite, NonNegative],
        [a, b, c, d],
        broken,
        pick,
        |[m, r, w, g]| BeadOnRotatingHoop::new(m, r, w, g),
    )?;
    refuses::<T, _, 5>(
        ["m1", "m2", "l1", "l2", "gravity"],
        [Positive, Positive, Positive, Positive, NonNegative],
        [a, b, c, d, e],
        broken,
        pick,
        |[m1, m2, l1, l2, g]| DoublePendulum::new(m1, m2, l1, l2, g),
    )?;
    refuses::<T, _, 2>(
        ["coefficients[0]", "coefficients[1]"],
        [NonNegative, NonNegative],
        [a, b],
        broken,
        pick,
        ViscousDamping::<T, 2>::new,
    )?;
    Ok(())
}

/// One step of `integrator` from a state with a non-finite component is `NonFiniteState`; a
/// step of zero or non-finite size is `InvalidParameter { name: "dt" }`.
fn refuses_state<T: Real, I: Integrator<T, N, M>, M: Mechanism<T, N>, const N: usize>(
    mut integrator: I,
    m: &M,
    bad: &State<T, N>,
    good: &State<T, N>,
    bad_dt: T,
) -> Result<(), TestCaseError> {
    let r = integrator.step(m, bad, T::from_f64(1e-3));
    prop_assert_eq!(r, Err(Error::NonFiniteState), "{} from {:?}", I::NAME, bad);
    let r = integrator.step(m, good, bad_dt);
    prop_assert!(
        matches!(r, Err(Error::InvalidParameter { name: "dt", .. })),
        "{} with dt = {:?}: {:?}",
        I::NAME,
        bad_dt,
        r
    );
    Ok(())
}

/// A double pendulum state with component `which` replaced by a NaN or an infinity, through
/// every integrator.
fn integrators_refuse<T: Real>(
    q: [f64; 4],
    which: usize,
    pick: usize,
) -> Result<(), TestCaseError> {
    let one = T::one();
    let dp = ok(DoublePendulum::new(one, one, one, one, T::from_f64(9.81)))?;
    let good = State::new(
        T::zero(),
        [T::from_f64(q[0]), T::from_f64(q[1])],
        [T::from_f64(q[2]), T::from_f64(q[3])],
    );
    let mut bad = good;
    let poison = T::from_f64(invalid(Valid::Finite, pick, 1.0));
    match which % 5 {
        0 => bad.q[0] = poison,
        1 => bad.q[1] = poison,
        2 => bad.qd[0] = poison,
        3 => bad.qd[1] = poison,
        _ => bad.t = poison,
    }
    let bad_dt = T::from_f64([0.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY][pick % 4]);
    refuses_state(ExplicitEuler, &dp, &bad, &good, bad_dt)?;
    refuses_state(SemiImplicitEuler, &dp, &bad, &good, bad_dt)?;
    refuses_state(VelocityVerlet, &dp, &bad, &good, bad_dt)?;
    refuses_state(Rk4, &dp, &bad, &good, bad_dt)
}

proptest! {
    #![proptest_config(config())]

    #[test]
    #[cfg_attr(not(debug_assertions), ignore = "optimised: run with --ignored, 16x the cases")]
    fn invalid_parameters_are_named(
        a in size(), b in size(), c in size(), d in size(), e in size(),
        broken in 0..5usize, pick in 0..5usize,
    ) {
        constructors_refuse::<f32>([a, b, c, d, e], broken, pick)?;
        constructors_refuse::<f64>([a, b, c, d, e], broken, pick)?;
    }

    #[test]
    #[cfg_attr(not(debug_assertions), ignore = "optimised: run with --ignored, 16x the cases")]
    fn non_finite_states_and_steps_are_refused(
        th1 in angle(), th2 in angle(), w1 in rate(), w2 in rate(),
        which in 0..5usize, pick in 0..4usize,
    ) {
        integrators_refuse::<f32>([th1, th2, w1, w2], which, pick)?;
        integrators_refuse::<f64>([th1, th2, w1, w2], which, pick)?;
    }
}
