//! Energy over 10^6 steps: a regular double pendulum and a Kepler orbit with e = 0.5. The
//! symplectic, symmetric and variational methods keep the relative energy error bounded with
//! no drift; explicit Euler and RK4 drift. Release-mode runs (`cargo xtask ci` runs them).

use lagrange_core::{Error, EulerLagrange, Lagrangian, Mechanism, State};
use lagrange_integrators::{
    ExplicitEuler, Failure, GaussLegendre2, ImplicitMidpoint, Integrator, Rk4, SemiImplicitEuler,
    StormerVerlet, VariationalMidpoint, VelocityVerlet, Yoshida4,
};
use lagrange_systems::{DoublePendulum, Kepler};
use lagrange_tests::kepler_periapsis;

/// Steps of every run.
const STEPS: u64 = 1_000_000;

/// No drift: the largest energy error over the last tenth of the run may exceed the largest
/// over the first tenth by at most this factor. A bounded, oscillating error has the same
/// maximum over any stretch of many periods (measured ratios 0.997 to 1.001); rounding adds
/// a random walk far below the bounds.
const NO_DRIFT: f64 = 1.1;

/// A drift: the error over the last tenth is at least this many times that over the first
/// (a linear drift gives about 10; measured for RK4: 10.0 on both problems).
const DRIFT: f64 = 3.0;

/// What a run's energy did.
#[derive(Debug)]
struct Record {
    name: &'static str,
    /// Largest relative energy error over the first tenth, the last tenth and the whole run.
    first: f64,
    last: f64,
    max: f64,
    /// The step at which the run failed (a blow-up), if it did.
    failed_at: Option<u64>,
}

impl Record {
    fn report(&self, problem: &str) {
        match self.failed_at {
            Some(k) => println!(
                "{problem}: {:<24} failed at step {k}; max |dE/E| before {:.3e}",
                self.name, self.max
            ),
            None => println!(
                "{problem}: {:<24} max |dE/E| {:.3e}; first tenth {:.3e}, last tenth {:.3e}, ratio {:.3}",
                self.name,
                self.max,
                self.first,
                self.last,
                self.last / self.first
            ),
        }
    }

    /// Bounded by `bound` with no drift.
    fn assert_bounded(&self, problem: &str, bound: f64) {
        self.report(problem);
        assert!(self.failed_at.is_none(), "{problem} {}: failed", self.name);
        assert!(
            self.max < bound,
            "{problem} {}: {} >= {bound}",
            self.name,
            self.max
        );
        assert!(
            self.last <= NO_DRIFT * self.first,
            "{problem} {}: drift, last tenth {} vs first {}",
            self.name,
            self.last,
            self.first
        );
    }

    /// Drifts: the error over the last tenth is `DRIFT` times that over the first.
    fn assert_drifts(&self, problem: &str) {
        self.report(problem);
        assert!(self.failed_at.is_none(), "{problem} {}: failed", self.name);
        assert!(
            self.last >= DRIFT * self.first,
            "{problem} {}: no drift seen",
            self.name
        );
    }

    /// Gains energy without bound: blows up, or its energy error exceeds the energy itself
    /// (explicit Euler's does within the first tenth, then saturates in a chaotic spin).
    fn assert_gains_energy(&self, problem: &str) {
        self.report(problem);
        assert!(
            self.failed_at.is_some() || self.max > 1.0,
            "{problem} {}: energy not gained",
            self.name
        );
    }
}

/// Runs `run`, which calls its observer with every new state, recording the relative energy
/// error `|E - E0| / scale`.
fn record<const N: usize>(
    name: &'static str,
    energy: impl Fn(&State<f64, N>) -> f64,
    start: &State<f64, N>,
    scale: f64,
    run: impl FnOnce(&mut dyn FnMut(&State<f64, N>)) -> Result<State<f64, N>, Failure<f64, N>>,
) -> Record {
    let e0 = energy(start);
    let tenth = STEPS / 10;
    let (mut first, mut last, mut max, mut k) = (0.0f64, 0.0f64, 0.0f64, 0u64);
    let result = run(&mut |s: &State<f64, N>| {
        let e = (energy(s) - e0).abs() / scale;
        if k < tenth {
            first = first.max(e);
        }
        if k >= STEPS - tenth {
            last = last.max(e);
        }
        max = max.max(e);
        k += 1;
    });
    Record {
        name,
        first,
        last,
        max,
        failed_at: result
            .map_err(|f| {
                println!("{name}: {f}");
                f.step
            })
            .err(),
    }
}

/// `I` for `STEPS` steps of `dt`.
fn fixed<I, M, const N: usize>(
    mut integrator: I,
    m: &M,
    start: &State<f64, N>,
    dt: f64,
    scale: f64,
) -> Record
where
    I: Integrator<f64, N, M>,
    M: Mechanism<f64, N>,
{
    record(
        I::NAME,
        |s| m.energy(s),
        start,
        scale,
        |observe| integrator.integrate_with(m, start, dt, STEPS, observe),
    )
}

/// The variational integrator for `STEPS` steps of `dt`.
fn variational<M, const N: usize>(m: &M, start: &State<f64, N>, dt: f64, scale: f64) -> Record
where
    M: Mechanism<f64, N>,
{
    record(
        "variational midpoint",
        |s| m.energy(s),
        start,
        scale,
        |observe| VariationalMidpoint::default().integrate_with(m, start, dt, STEPS, observe),
    )
}

/// A regular double pendulum (m = l = 1, g = 9.81; 0.5 and 0.3 rad at rest: quasi-periodic
/// motion on a torus), 10^6 steps of 1e-2 s. The energy is measured from the hanging rest
/// state.
#[test]
#[ignore = "long run: cargo xtask ci runs it in release"]
fn double_pendulum_energy_over_a_million_steps() -> Result<(), Error> {
    let dp = DoublePendulum::new(1.0, 1.0, 1.0, 1.0, 9.81)?;
    let auto = EulerLagrange::new(dp);
    let start = State::at_rest([0.5, 0.3]);
    let scale = dp.energy(&start) - dp.energy(&State::at_rest([0.0, 0.0]));
    let dt = 1e-2;
    let p = "double pendulum";
    // Bounds: the measured maxima (2.61e-4, 3.17e-7, 7.16e-6, 1.89e-9, 1.69e-5) and half
    // again, for other platforms' libm.
    fixed(StormerVerlet::default(), &dp, &start, dt, scale).assert_bounded(p, 4e-4);
    fixed(
        Yoshida4::<StormerVerlet<f64, 2>>::default(),
        &dp,
        &start,
        dt,
        scale,
    )
    .assert_bounded(p, 5e-7);
    fixed(ImplicitMidpoint::default(), &dp, &start, dt, scale).assert_bounded(p, 1.1e-5);
    fixed(GaussLegendre2::default(), &dp, &start, dt, scale).assert_bounded(p, 3e-9);
    variational(&auto, &start, dt, scale).assert_bounded(p, 2.5e-5);
    // Yoshida's composition of the variational integrator: order 4 and symplectic for this
    // configuration-dependent mass matrix (measured 7.05e-8, ratio last/first tenth 1.000).
    fixed(
        Yoshida4::<VariationalMidpoint<f64, 2>>::default(),
        &dp,
        &start,
        dt,
        scale,
    )
    .assert_bounded(p, 1.1e-7);
    fixed(Rk4, &dp, &start, dt, scale).assert_drifts(p);
    fixed(ExplicitEuler, &dp, &start, dt, scale).assert_gains_energy(p);
    // Reported for comparison: semi-implicit Euler (symplectic only for separable systems)
    // and velocity Verlet, which with velocity-dependent accelerations is neither symmetric
    // nor symplectic (its energy drifts on Kepler).
    fixed(SemiImplicitEuler, &dp, &start, dt, scale).report(p);
    fixed(VelocityVerlet, &dp, &start, dt, scale).report(p);
    Ok(())
}

/// Problem P4's orbit (mu = 1, e = 0.5, period 2 pi), 10^6 steps of 2 pi / 1000: a thousand
/// orbits. The variational integrator runs on the automatic path of the same Lagrangian.
#[test]
#[ignore = "long run: cargo xtask ci runs it in release"]
fn kepler_energy_over_a_million_steps() -> Result<(), Error> {
    let kepler = Kepler::new(1.0)?;
    let auto = EulerLagrange::new(kepler);
    let start = kepler_periapsis::<f64>();
    let scale = kepler.energy(&start).abs();
    let dt = 2.0 * core::f64::consts::PI / 1000.0;
    let p = "Kepler e = 0.5";
    // Bounds: the measured maxima (5.12e-5, 8.30e-8, 3.48e-5, 3.91e-10, 1.30e-5) and half
    // again.
    fixed(StormerVerlet::default(), &kepler, &start, dt, scale).assert_bounded(p, 8e-5);
    fixed(
        Yoshida4::<StormerVerlet<f64, 2>>::default(),
        &kepler,
        &start,
        dt,
        scale,
    )
    .assert_bounded(p, 1.3e-7);
    fixed(ImplicitMidpoint::default(), &kepler, &start, dt, scale).assert_bounded(p, 5.5e-5);
    fixed(GaussLegendre2::default(), &kepler, &start, dt, scale).assert_bounded(p, 6e-10);
    variational(&auto, &start, dt, scale).assert_bounded(p, 2e-5);
    // Measured 8.26e-9 (ratio last/first tenth 0.96).
    fixed(
        Yoshida4::<VariationalMidpoint<f64, 2>>::default(),
        &kepler,
        &start,
        dt,
        scale,
    )
    .assert_bounded(p, 1.3e-8);
    fixed(Rk4, &kepler, &start, dt, scale).assert_drifts(p);
    fixed(ExplicitEuler, &kepler, &start, dt, scale).assert_gains_energy(p);
    fixed(SemiImplicitEuler, &kepler, &start, dt, scale).report(p);
    fixed(VelocityVerlet, &kepler, &start, dt, scale).report(p);
    Ok(())
}
