//! Lanes: 1,024 `f32` pendulums and 1,024 `f32` double pendulums, all awake, stepped by RK4 in a
//! scene's bank in lanes ([`InLanes`]) against the same bank one by one ([`OneByOne`]), timed
//! interleaved (rows `bank_pendulums`, `bank_double_pendulums`); and by hand, without a bank,
//! one by one and in lanes gathered once (rows `pendulums_by_hand`, `double_pendulums_by_hand`):
//! what the bank's lanes can reach at most. After the timing, the two banks' states are
//! compared bit for bit (they took the same frames).

use super::frames::ratio;
use super::{Ratio, Row};
use lagrange_benches::timing::Budget;
use lagrange_core::nalgebra::SVector;
use lagrange_core::{divergences, Error, Gather, Lanes, State};
use lagrange_integrators::scene::{Bank, Id, InLanes, Layout, NeverSleeps, OneByOne, Scene, LANES};
use lagrange_integrators::{Integrator, Rk4};
use lagrange_systems::{DoublePendulum, SimplePendulum};

/// Instances of each mechanism.
const K: usize = 1024;
/// The step, s.
const DT: f32 = 1.0 / 120.0;
/// The goal: a bank in lanes at least this many times fewer ns per instance-step than the
/// same bank one by one.
const LANE_GOAL: f64 = 3.0;

/// A scene of one bank of `built`, laid out by `Y`, and the instances' ids in order.
type Built<const N: usize, M, Y> = (Scene<f32, Bank<f32, N, K, M, Rk4, NeverSleeps, Y>>, Vec<Id>);

/// The bank of `built`, laid out by `Y`, in a scene of one step per frame.
fn scene<M, const N: usize, Y>(built: &[(M, State<f32, N>)]) -> Result<Built<N, M, Y>, Error>
where
    M: Gather<f32, N> + Clone,
    Y: Layout<f32, N, K, M>,
{
    let mut bank = Bank::new(Rk4, NeverSleeps)?;
    let ids = built
        .iter()
        .map(|(m, s)| bank.add(m.clone(), *s))
        .collect::<Result<_, _>>()?;
    Ok((Scene::new(bank, DT, 1)?, ids))
}

/// The bank in lanes against one by one, and by hand, of one mechanism's instances.
fn measure_one<M, const N: usize>(
    name: &str,
    budget: Budget,
    built: &[(M, State<f32, N>)],
    rows: &mut Vec<Row>,
    ratios: &mut Vec<Ratio>,
) -> Result<(), Error>
where
    M: Gather<f32, N> + Clone,
{
    let (mut lanes, lane_ids) = scene::<M, N, InLanes>(built)?;
    let (mut each, each_ids) = scene::<M, N, OneByOne>(built)?;
    let (mut r1, mut r2) = (Ok(()), Ok(()));
    let diverged = divergences();
    let (bank_ratio, ns_each, ns_lanes) = ratio(
        budget,
        || {
            if let Err(e) = each.advance(DT) {
                r1 = Err(e);
            }
        },
        || {
            if let Err(e) = lanes.advance(DT) {
                r2 = Err(e);
            }
        },
    );
    r1?;
    r2?;
    // Comparisons on which lanes disagreed while timed: each sent a group one by one.
    let diverged = divergences()
        .zip(diverged)
        .map_or(0, |(after, before)| after.wrapping_sub(before));
    // The same frames were taken by both: the same bits.
    for (&a, &b) in lane_ids.iter().zip(&each_ids) {
        let (x, y) = (lanes.banks().state(a)?, each.banks().state(b)?);
        if x.q != y.q || x.qd != y.qd || x.t.to_bits() != y.t.to_bits() {
            return Err(Error::InvalidParameter {
                name: "lanes",
                reason: "a bank in lanes left the bits of the same bank one by one",
            });
        }
    }

    let (hand_ratio, ns_alone, ns_hand) = by_hand(budget, built)?;
    let per = |ns: f64| ns / K as f64;
    println!(
        "{name}: a bank {:.1} ns per instance-step one by one, {:.1} in lanes of {LANES} \
         ({bank_ratio:.2}x; {diverged} divergences while timed); by hand {:.1} one by one, {:.1} \
         in lanes ({hand_ratio:.2}x)",
        per(ns_each),
        per(ns_lanes),
        per(ns_alone),
        per(ns_hand)
    );
    for (scene, layout, ns) in [
        (format!("bank_{name}"), "one_by_one", ns_each),
        (format!("bank_{name}"), "lanes", ns_lanes),
        (format!("{name}_by_hand"), "one_by_one", ns_alone),
        (format!("{name}_by_hand"), "lanes", ns_hand),
    ] {
        rows.push(Row {
            scene,
            layout,
            instances: K,
            awake_fraction: 1.0,
            integrator: "RK4",
            scalar: "f32",
            ns_per_frame: ns,
        });
    }
    for (what, r) in [
        (
            format!("bank_{name} RK4 f32: one_by_one / lanes (of {LANES})"),
            bank_ratio,
        ),
        (
            format!("{name}_by_hand RK4 f32: one_by_one / lanes (of {LANES}, gathered once)"),
            hand_ratio,
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

/// The instances stepped by hand without a bank, one by one and in lanes of [`LANES`] (their
/// mechanisms gathered once), timed interleaved: the ratio and each side's ns per frame.
fn by_hand<M, const N: usize>(
    budget: Budget,
    built: &[(M, State<f32, N>)],
) -> Result<(f64, f64, f64), Error>
where
    M: Gather<f32, N> + Clone,
{
    let mut alone = built.to_vec();
    let mut groups = Vec::new();
    for chunk in built.chunks_exact(LANES) {
        let refs: [&M; LANES] = core::array::from_fn(|i| &chunk[i].0);
        let starts: [&State<f32, N>; LANES] = core::array::from_fn(|i| &chunk[i].1);
        let state = State {
            t: Lanes::gather(&starts, |s| s.t),
            q: SVector::from_fn(|j, _| Lanes::gather(&starts, |s| s.q[j])),
            qd: SVector::from_fn(|j, _| Lanes::gather(&starts, |s| s.qd[j])),
        };
        groups.push((M::gather(refs), state));
    }
    let (mut r1, mut r2) = (Ok(()), Ok(()));
    let out = ratio(
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
                match Integrator::<Lanes<f32, LANES>, N, _>::step(&mut Rk4, m, s, Lanes::splat(DT))
                {
                    Ok(next) => *s = next,
                    Err(e) => r2 = Err(e),
                }
            }
        },
    );
    r1?;
    r2?;
    Ok(out)
}

/// Both mechanisms: pendulums of lengths 0.5 to 1.5 m from 0.2 to 0.7 rad; double pendulums
/// with lower rods of 0.5 to 1.5 m from (0.2 to 0.7, -0.4) rad.
pub fn measure(budget: Budget, rows: &mut Vec<Row>, ratios: &mut Vec<Ratio>) -> Result<(), Error> {
    let x = |k: usize| k as f32 / K as f32;
    let pendulums = (0..K)
        .map(|k| {
            let p = SimplePendulum::new(1.0, 0.5 + x(k), 9.81, 0.0)?;
            Ok((p, State::at_rest([0.2 + 0.5 * x(k)])))
        })
        .collect::<Result<Vec<_>, Error>>()?;
    measure_one("pendulums", budget, &pendulums, rows, ratios)?;
    let doubles = (0..K)
        .map(|k| {
            let p = DoublePendulum::new(1.0, 1.0, 1.0, 0.5 + x(k), 9.81)?;
            Ok((p, State::at_rest([0.2 + 0.5 * x(k), -0.4])))
        })
        .collect::<Result<Vec<_>, Error>>()?;
    measure_one("double_pendulums", budget, &doubles, rows, ratios)?;
    Ok(())
}
