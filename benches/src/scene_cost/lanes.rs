//! Lanes: 1,024 `f32` pendulums and 1,024 `f32` double pendulums stepped by RK4 one by one
//! (the scalar loop), side by side in lanes of 8 (their parameters gathered once), and by a
//! scene's bank (which gathers them every step): ns per instance and step, and the ratios.

use super::frames::ratio;
use super::{Ratio, Row};
use lagrange_benches::timing::Budget;
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, Lanes, Mechanism, State};
use lagrange_integrators::scene::{Bank, NeverSleeps, Scene};
use lagrange_integrators::{Integrator, Rk4};
use lagrange_systems::{DoublePendulum, SimplePendulum};

/// Instances of each mechanism.
const K: usize = 1024;
/// Lanes per group.
const L: usize = 8;
/// The step, s.
const DT: f32 = 1.0 / 120.0;
/// The goal: lanes at least this many times fewer ns per instance-step than the loop.
const LANE_GOAL: f64 = 3.0;

/// `K` instances made by `make(k / K)`, with their starts.
fn instances<M>(
    make: impl Fn(f32) -> Result<(M, State<f32, 2>), Error>,
) -> Result<Vec<(M, State<f32, 2>)>, Error> {
    (0..K).map(|k| make(k as f32 / K as f32)).collect()
}

/// The three ways of stepping one mechanism's instances, timed against each other.
fn measure_one<M, const N: usize>(
    name: &str,
    budget: Budget,
    built: Vec<(M, State<f32, N>)>,
    rows: &mut Vec<Row>,
    ratios: &mut Vec<Ratio>,
) -> Result<(), Error>
where
    M: Mechanism<f32, N> + Clone,
{
    // One by one.
    let mut alone = built.clone();
    // In lanes, gathered once.
    let mut groups = Vec::new();
    for chunk in built.chunks_exact(L) {
        let refs: [&M; L] = core::array::from_fn(|i| &chunk[i].0);
        let lanes = M::gather(refs).ok_or(Error::InvalidParameter {
            name: "mechanism",
            reason: "gathers no lanes",
        })?;
        let starts: [&State<f32, N>; L] = core::array::from_fn(|i| &chunk[i].1);
        let state = State {
            t: Lanes::gather(&starts, |s| s.t),
            q: SVector::from_fn(|j, _| Lanes::gather(&starts, |s| s.q[j])),
            qd: SVector::from_fn(|j, _| Lanes::gather(&starts, |s| s.qd[j])),
        };
        groups.push((lanes, state));
    }
    // A scene's bank.
    let mut bank: Bank<f32, N, K, M, Rk4, NeverSleeps> = Bank::new(Rk4, NeverSleeps)?;
    for (m, s) in &built {
        bank.add(m.clone(), *s)?;
    }
    let mut scene = Scene::new(&mut bank, DT, 1)?;
    let mut failure = None;
    let mut fail = |r: Result<(), Error>| {
        if let Err(e) = r {
            failure = Some(e);
        }
    };
    let (mut r1, mut r2, mut r3) = (Ok(()), Ok(()), Ok(()));
    let (lanes_ratio, ns_alone, ns_lanes) = ratio(
        budget,
        || {
            for (m, s) in &mut alone {
                match Rk4.step(m, s, DT) {
                    Ok(next) => *s = next,
                    Err(e) => r1 = Err(e),
                }
            }
        },
        || {
            for (m, s) in &mut groups {
                match Integrator::<Lanes<f32, L>, N, _>::step(&mut Rk4, m, s, Lanes::splat(DT)) {
                    Ok(next) => *s = next,
                    Err(e) => r2 = Err(e),
                }
            }
        },
    );
    // From the start again, so that one by one and the bank step the same states in lockstep
    // (the cost of a double pendulum's step depends on its angles: past pi/4 its sines take
    // the reduced path).
    alone.clone_from(&built);
    let (bank_ratio, _, ns_bank) = ratio(
        budget,
        || {
            for (m, s) in &mut alone {
                if let Ok(next) = Rk4.step(m, s, DT) {
                    *s = next;
                }
            }
        },
        || {
            if let Err(e) = scene.advance(DT) {
                r3 = Err(e);
            }
        },
    );
    fail(r1);
    fail(r2);
    fail(r3);
    if let Some(e) = failure {
        return Err(e);
    }
    let per = |ns: f64| ns / K as f64;
    println!(
        "{name}: {:.1} ns per instance-step one by one, {:.1} in lanes of {L} ({lanes_ratio:.2}x), \
         {:.1} in a scene's bank ({bank_ratio:.2}x)",
        per(ns_alone),
        per(ns_lanes),
        per(ns_bank)
    );
    for (scene_name, ns) in [
        (format!("{name}, one by one"), ns_alone),
        (format!("{name}, lanes of {L}"), ns_lanes),
        (format!("{name}, a scene's bank in lanes"), ns_bank),
    ] {
        rows.push(Row {
            scene: scene_name,
            instances: K,
            awake_fraction: 1.0,
            integrator: "RK4",
            scalar: "f32",
            ns_per_frame: ns,
        });
    }
    for (what, r) in [
        (
            format!("{name} RK4 f32: one by one / lanes of {L}"),
            lanes_ratio,
        ),
        (
            format!("{name} RK4 f32: one by one / a scene's bank in lanes"),
            bank_ratio,
        ),
    ] {
        ratios.push(Ratio {
            what,
            ratio: r,
            goal: ">= 3",
            met: r >= LANE_GOAL,
        });
    }
    Ok(())
}

/// Both mechanisms.
pub fn measure(budget: Budget, rows: &mut Vec<Row>, ratios: &mut Vec<Ratio>) -> Result<(), Error> {
    let pendulums: Vec<(SimplePendulum<f32>, State<f32, 1>)> = (0..K)
        .map(|k| {
            let x = k as f32 / K as f32;
            Ok((
                SimplePendulum::new(1.0, 0.5 + x, 9.81, 0.0)?,
                State::at_rest([0.2 + 0.5 * x]),
            ))
        })
        .collect::<Result<_, Error>>()?;
    measure_one("1024 pendulums", budget, pendulums, rows, ratios)?;
    let doubles = instances(|x| {
        Ok((
            DoublePendulum::new(1.0, 1.0, 1.0, 0.5 + x, 9.81)?,
            State::at_rest([0.2 + 0.5 * x, -0.4]),
        ))
    })?;
    measure_one("1024 double pendulums", budget, doubles, rows, ratios)?;
    Ok(())
}
