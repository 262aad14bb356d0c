//! The standard mechanisms of `lagrange-systems`. For each, RK4 at dt = 1e-3 over 10 s
//! (relative energy error, ns per step) and the cost of one acceleration evaluation, in f64 and
//! f32; the n-link chain's cost against N; and each integrator's position error on the Kepler
//! orbit of problem P4 after 10 periods.
//!
//! `cargo run --release --example mechanisms`

use lagrange_core::solve_spd;
use lagrange_examples::{ns_per_step, TIMING_RUNS};
use lagrange_integrators::prelude::*;
use lagrange_integrators::{ExplicitEuler, SemiImplicitEuler, VelocityVerlet};
use lagrange_systems::exact::kepler_orbit;
use lagrange_systems::{
    Acrobot, BeadOnRotatingHoop, CartPole, DoublePendulum, ElasticPendulum, FallingParticle,
    Kepler, NLinkPendulum, SimplePendulum, SphericalPendulum, SpringMassDamper, SwingingAtwood,
};
use std::hint::black_box;
use std::time::Instant;

const G: f64 = 9.81;
const DT: f64 = 1e-3;
const STEPS: u64 = 10_000;
/// Acceleration evaluations per timing run.
const EVALUATIONS: usize = 200_000;
/// States, sampled along the run, that the acceleration timing cycles through.
const TIMING_STATES: u64 = 64;

/// One mechanism's figures in one precision.
struct Row {
    name: &'static str,
    /// Largest `|E(t) - E(0)| / |E(0) - E_ref|` over the run (`E_ref` the lowest energy, or 0);
    /// `None` for the driven bead, whose `T + V` is not conserved.
    energy_error: Option<f64>,
    ns_per_step: f64,
    ns_per_acceleration: f64,
}

/// Median wall time of one `acceleration` call, cycling through `states`.
fn ns_per_acceleration<T: Real, M: Mechanism<T, N>, const N: usize>(
    m: &M,
    states: &[State<T, N>],
) -> f64 {
    let mut times: Vec<f64> = (0..TIMING_RUNS)
        .map(|_| {
            let clock = Instant::now();
            for s in states.iter().cycle().take(EVALUATIONS) {
                let _ = black_box(black_box(m).acceleration(black_box(s)));
            }
            clock.elapsed().as_secs_f64() * 1e9 / EVALUATIONS as f64
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[TIMING_RUNS / 2]
}

/// RK4 from `start` for `STEPS` steps: energy error, then the timings (the acceleration on
/// states sampled along the run).
fn measure<T: Real, M: Mechanism<T, N>, const N: usize>(
    name: &'static str,
    m: &M,
    start: State<T, N>,
    reference: Option<T>,
) -> Result<Row, Error> {
    let e0 = m.energy(&start);
    let scale = reference.map(|r| (e0 - r).abs().to_f64());
    let stride = STEPS / TIMING_STATES;
    let (mut energy_error, mut n, mut states) = (0.0f64, 0u64, Vec::new());
    Rk4.integrate_with(m, &start, T::from_f64(DT), STEPS, |s| {
        if let Some(scale) = scale {
            energy_error = energy_error.max((m.energy(s) - e0).abs().to_f64() / scale);
        }
        n += 1;
        if n % stride == 0 {
            states.push(*s);
        }
    })?;
    Ok(Row {
        name,
        energy_error: scale.map(|_| energy_error),
        ns_per_step: ns_per_step(Rk4, m, &start, T::from_f64(DT), STEPS),
        ns_per_acceleration: ns_per_acceleration(m, &states),
    })
}

/// Every standard mechanism in `T`, in the start states of the energy tests
/// (tests/tests/mechanisms_energy.rs), undamped and without input.
fn rows<T: Real>() -> Result<Vec<Row>, Error> {
    let c = T::from_f64;
    let (one, zero, g) = (T::one(), T::zero(), c(G));
    let particle = FallingParticle::new(one, g)?;
    let pendulum = SimplePendulum::new(one, one, g, zero)?;
    let bead = BeadOnRotatingHoop::new(one, T::HALF, c(6.0), g)?;
    let double = DoublePendulum::new(one, one, one, one, g)?;
    let chain = NLinkPendulum::new([one; 5], [one; 5], g)?;
    let smd = SpringMassDamper::new(one, c(4.0), zero)?;
    let elastic = ElasticPendulum::new(one, c(100.0), one, g)?;
    let spherical = SphericalPendulum::new(one, one, g)?;
    let cart_pole = CartPole::new(one, c(0.1), c(0.5), c(9.8))?;
    let acrobot = Acrobot::<T>::spong();
    let atwood = SwingingAtwood::new(c(1.5), one, g)?;
    let kepler = Kepler::new(one)?;
    let half_pi = c(core::f64::consts::FRAC_PI_2);
    Ok(vec![
        measure(
            "FallingParticle",
            &particle,
            State::at_rest([c(10.0)]),
            // Relative to the energy converted in the fall: m g (g t^2 / 2) over 10 s.
            Some(c(G * (10.0 - 0.5 * G * 100.0))),
        )?,
        measure(
            "SimplePendulum",
            &pendulum,
            State::at_rest([c(core::f64::consts::FRAC_PI_6)]),
            Some(-g),
        )?,
        measure(
            "BeadOnRotatingHoop",
            &bead,
            State::new(zero, [c(0.3)], [one]),
            None,
        )?,
        measure(
            "DoublePendulum",
            &double,
            State::at_rest([half_pi; 2]),
            Some(c(-3.0 * G)),
        )?,
        measure(
            "NLinkPendulum<5>",
            &chain,
            State::at_rest([c(core::f64::consts::FRAC_PI_4); 5]),
            Some(chain.energy(&State::at_rest([zero; 5]))),
        )?,
        measure(
            "SpringMassDamper",
            &smd,
            State::new(zero, [one], [c(0.5)]),
            Some(zero),
        )?,
        measure(
            "ElasticPendulum",
            &elastic,
            State::at_rest([c(1.2), c(0.5)]),
            Some(elastic.energy(&State::at_rest([c(1.0 + G / 100.0), zero]))),
        )?,
        measure(
            "SphericalPendulum",
            &spherical,
            State::new(zero, [one, zero], [zero, c(2.0)]),
            Some(-g),
        )?,
        measure(
            "CartPole",
            &cart_pole,
            State::at_rest([zero, c(0.3)]),
            Some(cart_pole.energy(&State::at_rest([zero, T::PI]))),
        )?,
        measure(
            "Acrobot",
            &acrobot,
            State::at_rest([one, c(0.5)]),
            Some(acrobot.energy(&State::at_rest([zero; 2]))),
        )?,
        measure(
            "SwingingAtwood",
            &atwood,
            State::at_rest([one, half_pi]),
            Some(zero),
        )?,
        measure(
            "Kepler",
            &kepler,
            State::new(zero, [T::HALF, zero], [zero, c(12f64.sqrt())]),
            Some(zero),
        )?,
    ])
}

/// The chain's cost per acceleration with `N` unit links in `T`: the O(N) tension recursion it
/// uses, and for comparison forming `M` and `f` and solving by Cholesky.
fn chain_cost<T: Real, const N: usize>() -> Result<(f64, f64), Error> {
    let chain = NLinkPendulum::new([T::one(); N], [T::one(); N], T::from_f64(G))?;
    let start = State::at_rest([T::from_f64(core::f64::consts::FRAC_PI_4); N]);
    let mut states = Vec::new();
    let mut n = 0u64;
    Rk4.integrate_with(&chain, &start, T::from_f64(DT), 2_000, |s| {
        n += 1;
        if n % 30 == 0 {
            states.push(*s);
        }
    })?;
    let through_cholesky = CholeskyPath(chain);
    Ok((
        ns_per_acceleration(&chain, &states),
        ns_per_acceleration(&through_cholesky, &states),
    ))
}

/// A mechanism whose acceleration is the default: `M` and `f` formed, then Cholesky.
struct CholeskyPath<M>(M);

impl<T: Real, const N: usize, M: Lagrangian<T, N>> Lagrangian<T, N> for CholeskyPath<M> {
    fn kinetic<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>, qd: &SVector<S, N>) -> S {
        self.0.kinetic(t, q, qd)
    }
    fn potential<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>) -> S {
        self.0.potential(t, q)
    }
}

impl<T: Real, const N: usize, M: Mechanism<T, N>> Mechanism<T, N> for CholeskyPath<M> {
    fn mass_matrix(&self, s: &State<T, N>) -> lagrange_core::nalgebra::SMatrix<T, N, N> {
        self.0.mass_matrix(s)
    }
    fn rhs(&self, s: &State<T, N>) -> SVector<T, N> {
        self.0.rhs(s)
    }
    fn law<F: GeneralizedForce<T, N>>(
        &self,
        s: &State<T, N>,
        extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        solve_spd(&self.0.mass_matrix(s), &extra.added_to(s, self.0.rhs(s)))
    }
}

/// Problem P4 (mu = 1, a = 1, e = 0.5 from periapsis) for 10 periods at dt = 1e-3 with `I`:
/// the position error against Kepler's equation.
fn kepler_error<I: Integrator<f64, 2, Kepler<f64>>>(mut integrator: I) -> Result<f64, Error> {
    let kepler = Kepler::new(1.0)?;
    let start = kepler_orbit(1.0, 1.0, 0.5, 0.0)?;
    let steps = (20.0 * core::f64::consts::PI / DT).round() as u64;
    let end = integrator.integrate(&kepler, &start, DT, steps)?;
    // Time from the step count, not the sum of the steps.
    let exact = kepler_orbit(1.0, 1.0, 0.5, steps as f64 * DT)?;
    let (r, phi, re, phie) = (end.q[0], end.q[1], exact.q[0], exact.q[1]);
    Ok((r * phi.cos() - re * phie.cos()).hypot(r * phi.sin() - re * phie.sin()))
}

fn main() -> Result<(), String> {
    let text = |e: Error| e.to_string();
    let (wide, narrow) = (rows::<f64>().map_err(text)?, rows::<f32>().map_err(text)?);
    println!("\nStandard mechanisms: RK4 dt=1e-3, 10 s: relative energy error and ns/step");
    println!("(ns/accel: one acceleration evaluation; medians of {TIMING_RUNS} runs)");
    println!(
        "{:<20} {:>11} {:>11} {:>9} {:>9} {:>9} {:>9}",
        "mechanism", "dE/E f64", "dE/E f32", "step f64", "step f32", "acc f64", "acc f32"
    );
    let error = |e: Option<f64>| e.map_or_else(|| "(driven)".into(), |e| format!("{e:.2e}"));
    for (a, b) in wide.iter().zip(&narrow) {
        println!(
            "{:<20} {:>11} {:>11} {:>9.1} {:>9.1} {:>9.1} {:>9.1}",
            a.name,
            error(a.energy_error),
            error(b.energy_error),
            a.ns_per_step,
            b.ns_per_step,
            a.ns_per_acceleration,
            b.ns_per_acceleration
        );
    }

    println!("\nNLinkPendulum<N>, ns per acceleration: O(N) tension recursion (used) against");
    println!("forming M and f and solving by Cholesky (O(N^3))");
    println!(
        "{:>4} {:>12} {:>12} {:>12} {:>12}",
        "N", "tension f64", "tension f32", "Cholesky f64", "Cholesky f32"
    );
    let costs = [
        (2, chain_cost::<f64, 2>(), chain_cost::<f32, 2>()),
        (5, chain_cost::<f64, 5>(), chain_cost::<f32, 5>()),
        (10, chain_cost::<f64, 10>(), chain_cost::<f32, 10>()),
        (20, chain_cost::<f64, 20>(), chain_cost::<f32, 20>()),
    ];
    for (n, wide, narrow) in costs {
        let ((t64, c64), (t32, c32)) = (wide.map_err(text)?, narrow.map_err(text)?);
        println!("{n:>4} {t64:>12.1} {t32:>12.1} {c64:>12.1} {c32:>12.1}");
    }

    println!("\nKepler orbit P4 (e = 0.5), 10 periods, dt = 1e-3, f64: position error");
    for (name, err) in [
        ("ExplicitEuler", kepler_error(ExplicitEuler)),
        ("SemiImplicitEuler", kepler_error(SemiImplicitEuler)),
        ("VelocityVerlet", kepler_error(VelocityVerlet)),
        ("RK4", kepler_error(Rk4)),
    ] {
        match err {
            Ok(e) => println!("{name:<20} {e:>11.2e}"),
            Err(e) => println!("{name:<20} failed: {e}"),
        }
    }
    Ok(())
}
