//! `ragdoll_throws`: the thrown ragdoll's cost over sixteen other throws
//! ([`scenes::other_throws`](crate::scenes::other_throws)), one row per stepper and scalar.
//!
//! The goals are the example's throw's (`ragdoll`); a step's cost depends on how the limbs
//! meet the floor, which any change of a solve's rounding moves (the trajectory is
//! chaotic), so one throw's mean and worst step move by several percent with changes that
//! do not change the cost of a step. Over these throws they move less, and their spread is
//! what a user's own throws will see. Only the time-stepping stepper and the free RK4 step
//! are timed (the event stepper takes a second a throw in `f64`).

use crate::{Measured, Row};

/// The scene's name.
pub const SCENE: &str = "ragdoll_throws";

/// The rows of one stepper over the throws (`each`, one per throw) as one: the mean step and
/// the free step averaged over the throws, the worst step the worst of any, the depth and
/// energy gain the largest, the contact steps summed; the note gives the range of the
/// throws' own ratios. The medians over rounds are left out (they are per throw).
pub fn spread(each: &[Row]) -> Option<Row> {
    let first = each.first()?;
    let average = |f: fn(&Row) -> Option<f64>| -> Option<f64> {
        let xs: Option<Vec<f64>> = each.iter().map(f).collect();
        xs.map(|xs| xs.iter().sum::<f64>() / xs.len() as f64)
    };
    let range = |f: &dyn Fn(&Row) -> Option<f64>| -> Option<(f64, f64)> {
        each.iter()
            .map(f)
            .try_fold((f64::INFINITY, 0.0_f64), |(lo, hi), x| {
                x.map(|x| (lo.min(x), hi.max(x)))
            })
    };
    let mean_ratio = range(&|r| r.mean_ratio);
    let worst_ratio = range(&|r| r.worst_ns.zip(r.free_rk4_ns).map(|(w, f)| w / f));
    let measured: Option<Vec<&Measured>> = each.iter().map(|r| r.measured.as_ref()).collect();
    let measured = measured.map(|m| Measured {
        depth: m.iter().map(|m| m.depth).fold(0.0, f64::max),
        limit_depth: m
            .iter()
            .map(|m| m.limit_depth)
            .try_fold(0.0_f64, |d, x| x.map(|x| d.max(x))),
        energy_gain: m
            .iter()
            .map(|m| m.energy_gain)
            .fold(f64::NEG_INFINITY, f64::max),
        contact_steps: m.iter().map(|m| m.contact_steps).sum(),
        note: match (mean_ratio, worst_ratio) {
            (Some((a, b)), Some((c, d))) => format!(
                "{} throws: mean / free {a:.2} to {b:.2}, worst / free {c:.1} to {d:.1}",
                each.len()
            ),
            _ => format!("{} throws", each.len()),
        },
    });
    let mean_ns = average(|r| r.mean_ns);
    let free_rk4_ns = average(|r| r.free_rk4_ns);
    Some(Row {
        scene: SCENE,
        stepper: first.stepper,
        scalar: first.scalar,
        mean_ns,
        median_mean_ns: None,
        worst_ns: range(&|r| r.worst_ns).map(|(_, hi)| hi),
        median_worst_ns: None,
        free_rk4_ns,
        free_median_ns: None,
        mean_ratio: average(|r| r.mean_ratio),
        median_ratio: None,
        rounds: first.rounds,
        measured,
        failure: each.iter().find_map(|r| r.failure.clone()),
    })
}
