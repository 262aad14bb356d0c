//! Criterion micro-benchmarks: ns per acceleration evaluation and per step of every fixed-step
//! integrator for every standard system, f32 and f64 (the adaptive ones, whose step is not a
//! fixed `dt`, are timed by the work-precision bench instead). `cargo bench -p lagrange-benches`;
//! under `cargo test` each benchmark runs once, as a smoke test.

use criterion::{BenchmarkGroup, Criterion};
use lagrange_benches::{
    acrobot, atwood, bead, cart_pole, chain, double_pendulum, double_pendulum_automatic, elastic,
    falling_particle, kepler, pendulum, precision, spherical, spring, Fixture,
};
use lagrange_core::{Error, Mechanism, Real};
use lagrange_integrators::{
    BackwardEuler, ExplicitEuler, GaussLegendre2, ImplicitMidpoint, Integrator, RadauIIA2, Rk4,
    SemiImplicitEuler, StormerVerlet, VariationalMidpoint, VelocityVerlet, Yoshida4,
};
use std::hint::black_box;

/// Step of every timed step, s.
const DT: f64 = 1e-3;

/// One step of `integrator` from the fixture's state. Each step starts from the fixture's
/// state, not from the last step's result: a method that keeps what it learnt from its last
/// step (the variational integrator's momenta) starts afresh every time.
fn step<T: Real, I: Integrator<T, N, M>, M: Mechanism<T, N>, const N: usize>(
    g: &mut BenchmarkGroup<'_, criterion::measurement::WallTime>,
    mut integrator: I,
    f: &Fixture<M, T, N>,
) {
    let dt = T::from_f64(DT);
    g.bench_function(format!("step/{}", I::NAME), |b| {
        b.iter(|| integrator.step(black_box(&f.mechanism), black_box(&f.state), dt));
    });
}

/// The acceleration and a step of each integrator for one fixture.
fn system<T: Real, M: Mechanism<T, N>, const N: usize>(
    c: &mut Criterion,
    fixture: Result<Fixture<M, T, N>, Error>,
) {
    let Ok(f) = fixture else {
        eprintln!("fixture refused: {fixture:?}", fixture = fixture.err());
        return;
    };
    let mut g = c.benchmark_group(format!("{}/{}", f.name, precision::<T>()));
    g.bench_function("acceleration", |b| {
        b.iter(|| f.mechanism.acceleration(black_box(&f.state)));
    });
    step(&mut g, ExplicitEuler, &f);
    step(&mut g, SemiImplicitEuler, &f);
    step(&mut g, VelocityVerlet, &f);
    step(&mut g, StormerVerlet::<T, N>::default(), &f);
    step(&mut g, Rk4, &f);
    step(&mut g, Yoshida4::new(StormerVerlet::<T, N>::default()), &f);
    step(&mut g, ImplicitMidpoint::<T>::default(), &f);
    step(&mut g, GaussLegendre2::<T>::default(), &f);
    step(&mut g, BackwardEuler::<T>::default(), &f);
    step(&mut g, RadauIIA2::<T>::default(), &f);
    step(&mut g, VariationalMidpoint::<T, N>::default(), &f);
    step(
        &mut g,
        Yoshida4::new(VariationalMidpoint::<T, N>::default()),
        &f,
    );
    g.finish();
}

/// Every fixture in one precision.
fn all<T: Real>(c: &mut Criterion) {
    system(c, falling_particle::<T>());
    system(c, pendulum::<T>());
    system(c, bead::<T>());
    system(c, double_pendulum::<T>());
    system(c, double_pendulum_automatic::<T>());
    system(c, chain::<T, 5>());
    system(c, chain::<T, 20>());
    system(c, spring::<T>());
    system(c, elastic::<T>());
    system(c, spherical::<T>());
    system(c, cart_pole::<T>());
    system(c, acrobot::<T>());
    system(c, atwood::<T>());
    system(c, kepler::<T>());
}

/// What `criterion_main!` would generate, written out so that every item is documented.
fn main() {
    let mut c = Criterion::default().configure_from_args();
    all::<f64>(&mut c);
    all::<f32>(&mut c);
    c.final_summary();
}
