//! The origin's workflow end to end, "derive symbolically, implement numerically": T and V
//! written with SymPy in `derive/specs/spring_cart_pendulum.py`, turned by `cargo xtask derive`
//! into `lagrange_generated::SpringCartPendulum` (a committed file: no Python is needed here),
//! integrated, and compared with the automatic path of the same T and V. Then the cost of one
//! acceleration: hand-derived, generated and automatic, for every generated mechanism.
//!
//! `cargo run --release --example derived`

use lagrange_core::constraints::Holonomic;
use lagrange_examples::TIMING_RUNS;
use lagrange_generated as generated;
use lagrange_integrators::prelude::*;
use lagrange_systems as hand;
use std::hint::black_box;
use std::time::Instant;

/// The spec, as committed.
const SPEC: &str = include_str!("../derive/specs/spring_cart_pendulum.py");
/// Acceleration evaluations per timing run.
const EVALUATIONS: usize = 100_000;
/// Random states the timing cycles through.
const TIMING_STATES: usize = 64;

fn main() -> Result<(), Error> {
    round_trip()?;
    println!("\nns per acceleration (fastest of {TIMING_RUNS} runs of {EVALUATIONS}, random states; automatic = EulerLagrange of the generated T and V):");
    costs::<f64>("f64")?;
    costs::<f32>("f32")?;
    Ok(())
}

/// The spec, the generated type stepped by RK4 beside the automatic path, damping set.
fn round_trip() -> Result<(), Error> {
    println!("derive/specs/spring_cart_pendulum.py (the lines that say what the mechanism is):\n");
    for line in SPEC.lines().filter(|l| {
        ["q =", "bob_x", "T =", "V =", "Q ="]
            .iter()
            .any(|p| l.starts_with(p))
    }) {
        println!("    {line}");
    }
    println!("\n$ cargo xtask derive derive/specs/spring_cart_pendulum.py --tests --out derive/generated/src/spring_cart_pendulum.rs\n");

    let generated = generated::SpringCartPendulum::<f64>::default();
    let automatic = EulerLagrange::new(generated);
    let start = State::new(0.0, [0.1, 1.0], [0.0, 0.0]);
    let (dt, steps) = (1e-3, 10_000);
    let e0 = generated.energy(&start);
    let (mut worst, mut drift) = (0.0f64, 0.0f64);
    let (mut end, mut auto_end) = (start, start);
    for _ in 0..steps {
        end = Rk4.step(&generated, &end, dt)?;
        auto_end = Rk4.step(&automatic, &auto_end, dt)?;
        drift = drift.max((generated.energy(&end) - e0).abs());
        let gap = (end.q - auto_end.q)
            .abs()
            .max()
            .max((end.qd - auto_end.qd).abs().max());
        worst = worst.max(gap);
    }
    println!("SpringCartPendulum (defaults: m_cart 2 kg, m 0.5 kg, k 20 N/m, l 0.8 m), RK4 at dt = 1e-3 for 10 s from x = 0.1 m, th = 1 rad:");
    println!(
        "  generated:  x = {:+.9} m, th = {:+.9} rad, max |E - E0| = {drift:.1e} J",
        end.q[0], end.q[1]
    );
    println!(
        "  automatic:  x = {:+.9} m, th = {:+.9} rad (largest gap from the generated run over the 10 s: {worst:.1e})",
        auto_end.q[0], auto_end.q[1]
    );
    let damped = generated::SpringCartPendulum::new(2.0, 0.5, 20.0, 0.8, 0.8, 9.81)?;
    let end = Rk4.integrate(&damped, &start, dt, 5 * steps)?;
    println!(
        "  with the cart damped (c = 0.8 N s/m): E = {:.6} J after 50 s, from {e0:.6} J",
        damped.energy(&end)
    );
    Ok(())
}

/// A small seeded generator (SplitMix64), so that the timed states are the same on every run.
struct Rng(u64);

impl Rng {
    fn uniform<T: Real>(&mut self, lo: f64, hi: f64) -> T {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        T::from_f64(lo + (hi - lo) * ((z >> 11) as f64 / (1u64 << 53) as f64))
    }
}

/// `TIMING_STATES` states with coordinates in `q` and velocities in `(-2, 2)`.
fn states<T: Real, const N: usize>(seed: u64, q: (f64, f64)) -> Vec<State<T, N>> {
    let mut rng = Rng(seed);
    (0..TIMING_STATES)
        .map(|_| {
            let qs: [T; N] = core::array::from_fn(|_| rng.uniform(q.0, q.1));
            let qds: [T; N] = core::array::from_fn(|_| rng.uniform(-2.0, 2.0));
            State::new(T::zero(), qs, qds)
        })
        .collect()
}

/// Wall time of one `acceleration` call of `m`, cycling through `states`: the fastest of
/// [`TIMING_RUNS`] runs, the one a shared machine disturbed least.
fn ns<T: Real, M: Mechanism<T, N>, const N: usize>(m: &M, states: &[State<T, N>]) -> f64 {
    (0..TIMING_RUNS)
        .map(|_| {
            let clock = Instant::now();
            for s in states.iter().cycle().take(EVALUATIONS) {
                let _ = black_box(black_box(m).acceleration(black_box(s)));
            }
            clock.elapsed().as_secs_f64() * 1e9 / EVALUATIONS as f64
        })
        .fold(f64::INFINITY, f64::min)
}

/// Largest relative disagreement of two mechanisms' accelerations over `states`.
fn gap<T: Real, const N: usize>(
    a: &impl Mechanism<T, N>,
    b: &impl Mechanism<T, N>,
    states: &[State<T, N>],
) -> Result<f64, Error> {
    let mut worst = 0.0f64;
    for s in states {
        let (x, y) = (a.acceleration(s)?, b.acceleration(s)?);
        let size = x.iter().fold(0.0f64, |m, v| m.max(v.abs().to_f64()));
        let diff = (x - y).iter().fold(0.0f64, |m, v| m.max(v.abs().to_f64()));
        worst = worst.max(diff / (size + 1.0));
    }
    Ok(worst)
}

/// One row: the hand-derived mechanism's time (when there is one), the generated one, and the
/// automatic path of the generated one's `T` and `V`.
fn row<T: Real, const N: usize>(
    name: &str,
    hand: Option<f64>,
    generated: &impl Mechanism<T, N>,
    automatic: &impl Mechanism<T, N>,
    states: &[State<T, N>],
) -> Result<(), Error> {
    let h = hand;
    let g = ns(generated, states);
    let a = ns(automatic, states);
    let hand_text = h.map_or_else(|| "-".to_string(), |h| format!("{h:.1}"));
    let ratio = h.map_or_else(|| "-".to_string(), |h| format!("{:.2}", g / h));
    println!(
        "| {name} | {N} | {hand_text} | {g:.1} | {a:.1} | {ratio} | {:.1} | {:.1e} |",
        a / g,
        gap(generated, automatic, states)?
    );
    Ok(())
}

/// The table in precision `T`.
fn costs<T: Real>(label: &str) -> Result<(), Error> {
    println!("\n{label}:\n");
    println!("| mechanism | N | hand | generated | automatic | generated / hand | automatic / generated | generated vs automatic (relative) |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|");
    let [m, l, g] = [1.0, 1.0, 9.81].map(T::from_f64);

    let s = states::<T, 1>(1, (-3.0, 3.0));
    let p = hand::SimplePendulum::new(m, l, g, T::zero())?;
    let gen = generated::Pendulum::<T>::default();
    row(
        "pendulum",
        Some(ns(&p, &s)),
        &gen,
        &EulerLagrange::new(gen),
        &s,
    )?;

    let s = states::<T, 2>(2, (-3.0, 3.0));
    let p = hand::DoublePendulum::new(m, m, l, l, g)?;
    let gen = generated::DoublePendulum::<T>::default();
    row(
        "double pendulum",
        Some(ns(&p, &s)),
        &gen,
        &EulerLagrange::new(gen),
        &s,
    )?;

    let s = states::<T, 3>(3, (-3.0, 3.0));
    let p = hand::NLinkPendulum::new([m; 3], [l; 3], g)?;
    let gen = generated::TriplePendulum::<T>::default();
    row(
        "three-link chain",
        Some(ns(&p, &s)),
        &gen,
        &EulerLagrange::new(gen),
        &s,
    )?;

    let s = states::<T, 2>(4, (-1.0, 1.0));
    let gen = generated::SpringCartPendulum::<T>::default();
    row(
        "spring-cart pendulum",
        None,
        &gen,
        &EulerLagrange::new(gen),
        &s,
    )?;

    let s = states::<T, 1>(5, (-3.0, 3.0));
    let gen = generated::KapitzaPendulum::<T>::default();
    row("Kapitza pendulum", None, &gen, &EulerLagrange::new(gen), &s)?;

    // On the circle: the rows hold.
    let c = hand::CartesianPendulum::new(m, l, g)?;
    let s: Vec<State<T, 2>> = states::<T, 1>(6, (-3.0, 3.0))
        .iter()
        .map(|x| c.state_from_angle(T::zero(), x.q[0], x.qd[0]))
        .collect();
    let hand_c = Constrained::new(c);
    let gen = generated::CartesianPendulum::<T>::default();
    row(
        "Cartesian pendulum (constrained)",
        Some(ns(&hand_c, &s)),
        &Constrained::new(gen),
        &EulerLagrange::new(gen).held_by(Holonomic::new(gen)),
        &s,
    )?;
    Ok(())
}
