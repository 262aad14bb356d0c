//! The contacts bench's CSV and Markdown report, with the goals and whether each
//! is met.

use std::fmt::Write as _;

use crate::{peer::CAPSULE_RADIUS, Row};

/// `x` with `digits` decimals, or empty.
fn cell(x: Option<f64>, digits: usize) -> String {
    x.map_or_else(String::new, |x| format!("{x:.digits$}"))
}

/// `x` in scientific notation, or empty.
fn sci(x: Option<f64>) -> String {
    x.map_or_else(String::new, |x| format!("{x:.3e}"))
}

/// The CSV: `scene,stepper,scalar,mean_ns,worst_ns,free_rk4_ns,max_penetration,max_energy_gain`.
pub fn csv(rows: &[Row]) -> String {
    let mut out = String::from(
        "scene,stepper,scalar,mean_ns,worst_ns,free_rk4_ns,max_penetration,max_energy_gain\n",
    );
    for r in rows.iter().filter(|r| r.stepper != crate::RAPIER_SLEEPING) {
        let m = r.measured.as_ref();
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{}",
            r.scene,
            r.stepper,
            r.scalar,
            cell(r.mean_ns, 0),
            cell(r.worst_ns, 0),
            cell(r.free_rk4_ns, 0),
            sci(m.map(|m| m.depth)),
            sci(m.map(|m| m.energy_gain).filter(|g| g.is_finite())),
        );
    }
    out
}

/// The row of `scene`, `stepper`, `scalar`.
fn find<'a>(rows: &'a [Row], scene: &str, stepper: &str, scalar: &str) -> Option<&'a Row> {
    rows.iter()
        .find(|r| r.scene == scene && r.stepper == stepper && r.scalar == scalar)
}

/// "met" or "NOT met", or "no figure".
fn verdict(x: Option<f64>, bound: f64) -> &'static str {
    match x {
        Some(x) if x <= bound => "met",
        Some(_) => "**NOT met**",
        None => "no figure",
    }
}

/// The goals: each line what, the figure, the bound, the verdict.
fn goals(rows: &[Row]) -> Vec<(String, String, &'static str)> {
    let mut out = Vec::new();
    for scene in ["ragdoll", "double_pendulum"] {
        for stepper in ["time_stepping", crate::EVENT] {
            for scalar in ["f32", "f64"] {
                let Some(r) = find(rows, scene, stepper, scalar) else {
                    continue;
                };
                let worst = r.worst_ns.zip(r.free_rk4_ns).map(|(w, f)| w / f);
                let median_worst = r.median_worst_ns.zip(r.free_median_ns).map(|(w, f)| w / f);
                out.push((
                    format!("{scene} {stepper} {scalar}: mean step <= 2x free RK4"),
                    format!(
                        "{} (medians: {})",
                        cell(r.mean_ratio, 2),
                        cell(r.median_ratio, 2)
                    ),
                    verdict(r.mean_ratio, 2.0),
                ));
                out.push((
                    format!("{scene} {stepper} {scalar}: worst step <= 5x free RK4"),
                    format!("{} (medians: {})", cell(worst, 1), cell(median_worst, 1)),
                    verdict(worst, 5.0),
                ));
            }
        }
    }
    let peer = find(rows, "ragdoll", "rapier2d", "f32");
    let sleeping = find(rows, "ragdoll", crate::RAPIER_SLEEPING, "f32");
    for stepper in ["time_stepping", crate::EVENT] {
        let ours = find(rows, "ragdoll", stepper, "f32");
        let ratio = |theirs: Option<&Row>, pick: fn(&Row) -> Option<f64>| {
            ours.and_then(pick)
                .zip(theirs.and_then(pick))
                .map(|(a, b)| a / b)
        };
        let (fastest, medians) = (
            ratio(peer, |r| r.mean_ns),
            ratio(peer, |r| r.median_mean_ns),
        );
        out.push((
            format!("ragdoll {stepper} f32: mean step <= 0.5x rapier2d's"),
            format!("{} (medians: {})", cell(fastest, 2), cell(medians, 2)),
            verdict(fastest, 0.5),
        ));
        let depth = |r: Option<&Row>| r.and_then(|r| r.measured.as_ref()).map(|m| m.depth);
        let (a, b) = (depth(ours), depth(peer));
        out.push((
            format!("ragdoll {stepper} f32: deepest penetration <= rapier2d's"),
            format!(
                "{} mm against {} mm",
                cell(a.map(|x| x * 1e3), 3),
                cell(b.map(|x| x * 1e3), 3)
            ),
            match (a, b) {
                (Some(a), Some(b)) if a <= b => "met",
                (Some(_), Some(_)) => "**NOT met**",
                _ => "no figure",
            },
        ));
        if stepper == "time_stepping" {
            let (fastest, medians) = (
                ratio(sleeping, |r| r.mean_ns),
                ratio(sleeping, |r| r.median_mean_ns),
            );
            out.push((
                "ragdoll time_stepping f32: mean step <= 0.5x rapier2d's with sleeping \
                 allowed (for comparison)"
                    .to_string(),
                format!("{} (medians: {})", cell(fastest, 2), cell(medians, 2)),
                verdict(fastest, 0.5),
            ));
        }
    }
    out
}

/// The Markdown report: the table, the goals, the notes.
pub fn markdown(quick: bool, rows: &[Row], agreement: f64, seconds: f64) -> String {
    let mut md = String::from("# Contacts: ns per step, depth and energy\n\n");
    let machine = std::thread::available_parallelism().map_or(0, std::num::NonZero::get);
    let rounds = rows.first().map_or(0, |r| r.rounds);
    let _ = writeln!(
        md,
        "{}{rounds} round(s) in one process on a machine with {machine} core(s), \
         {seconds:.0} s in all. mean: the fastest round's time per step of a whole run; \
         worst: the slowest step of each step's fastest time over the rounds (the runs are \
         deterministic, so this is the worst step's own work, without the machine's \
         preemptions); free RK4: the fastest round's mean of a free RK4 step of the same \
         mechanism. The medians beside them: of the rounds' means, of the rounds' slowest \
         steps, of the per-round ratios to the free step. Depth: deepest floor penetration, \
         mm; limits: deepest joint-limit violation, mrad. Energy gain: the largest \
         `E(end) - max(E(start), E(free step))` over the steps the contacts changed, J \
         (negative: none gained).\n",
        if quick {
            "**Quick run** (not for figures): "
        } else {
            ""
        }
    );
    md.push_str(
        "| scene | stepper | scalar | mean ns | worst ns | free RK4 ns | mean / free | \
         worst / free | median mean ns | median worst ns | median mean / free | depth mm | \
         limits mrad | energy gain J | contact steps | notes |\n\
         |---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n",
    );
    for r in rows {
        let m = r.measured.as_ref();
        let worst_ratio = r.worst_ns.zip(r.free_rk4_ns).map(|(w, f)| w / f);
        let mut notes = m.map(|m| m.note.clone()).unwrap_or_default();
        if let Some(f) = &r.failure {
            notes = format!("{notes} {f}").trim().to_string();
        }
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.scene,
            r.stepper,
            r.scalar,
            cell(r.mean_ns, 0),
            cell(r.worst_ns, 0),
            cell(r.free_rk4_ns, 0),
            cell(r.mean_ratio, 2),
            cell(worst_ratio, 1),
            cell(r.median_mean_ns, 0),
            cell(r.median_worst_ns, 0),
            cell(r.median_ratio, 2),
            cell(m.map(|m| m.depth * 1e3), 3),
            cell(m.and_then(|m| m.limit_depth).map(|d| d * 1e3), 3),
            sci(m.map(|m| m.energy_gain).filter(|g| g.is_finite())),
            m.map_or_else(String::new, |m| m.contact_steps.to_string()),
            notes,
        );
    }
    md.push_str("\n## Goals\n\n| goal | figure | verdict |\n|---|---|---|\n");
    for (what, figure, verdict) in goals(rows) {
        let _ = writeln!(md, "| {what} | {figure} | {verdict} |");
    }
    let _ = writeln!(
        md,
        "\nVerdicts on the fastest rounds and each step's fastest time (the medians beside \
         them: on a loaded machine a round's slowest step is usually a preemption).\n\n\
         rapier2d: the same ten links (masses, lengths, `m L^2 / 12`), joints at lagrange's \
         points with its limits, joint damping 0.5 N m s/rad (rapier's per-DoF multibody \
         damping, none on the root), capsules of radius {:.0} mm, a cuboid ground whose top \
         is y = 0, friction 0.8 and restitution 0.3 on every collider, self-contacts off (as \
         lagrange's links), sleeping off (lagrange's steppers do not sleep; a scene would; \
         `rapier2d_sleeping` is timed with rapier's default sleeping, for comparison), \
         default integration parameters but dt = 1/240 s, `f32`. Before anything touches, its \
         free flight follows lagrange's (RK4, same dt) to {:.2} mm in 60 steps. Its depth is \
         that of its contact manifolds (the poses at the start of each step); the note gives \
         the capsules' exact depth after each step.",
        CAPSULE_RADIUS * 1e3,
        agreement * 1e3
    );
    md
}
