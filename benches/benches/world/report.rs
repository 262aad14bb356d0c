//! The world bench's CSV and Markdown report, with issue 34's goals and whether each is
//! met.

use std::fmt::Write as _;

use crate::Row;

/// `x` with `digits` decimals, or empty.
fn cell(x: Option<f64>, digits: usize) -> String {
    x.map_or_else(String::new, |x| format!("{x:.digits$}"))
}

/// `x` in scientific notation, or empty.
fn sci(x: Option<f64>) -> String {
    x.map_or_else(String::new, |x| format!("{x:.3e}"))
}

/// The CSV: `scene,engine,scalar,bodies,awake,ns_per_step,max_penetration`.
pub fn csv(rows: &[Row]) -> String {
    let mut out = String::from("scene,engine,scalar,bodies,awake,ns_per_step,max_penetration\n");
    for r in rows {
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{}",
            r.scene,
            r.engine,
            r.scalar,
            r.bodies,
            cell(r.awake, 1),
            cell(r.ns_per_step, 0),
            sci(r.depth),
        );
    }
    out
}

/// The row of `scene`, `engine`, `scalar`.
fn find<'a>(rows: &'a [Row], scene: &str, engine: &str, scalar: &str) -> Option<&'a Row> {
    rows.iter()
        .find(|r| r.scene == scene && r.engine == engine && r.scalar == scalar)
}

/// "met", "**NOT met**" or "no figure": whether `x` is at most `bound`.
fn at_most(x: Option<f64>, bound: f64) -> &'static str {
    match x {
        Some(x) if x <= bound => "met",
        Some(_) => "**NOT met**",
        None => "no figure",
    }
}

/// The scenes, in the report's order.
const SCENES: [&str; 7] = [
    "pyramid_55",
    "pyramid_210",
    "balls_1000",
    "ragdolls_10",
    "ragdolls_50",
    "ragdolls_10_asleep",
    "ragdolls_50_asleep",
];

/// The goals: each line what, the figure, the verdict.
fn goals(rows: &[Row]) -> Vec<(String, String, &'static str)> {
    let mut out = Vec::new();
    for scene in SCENES {
        let peer = find(rows, scene, "rapier2d", "f32");
        for scalar in ["f32", "f64"] {
            let ours = find(rows, scene, "lagrange", scalar);
            let pick = |r: Option<&Row>, f: fn(&Row) -> Option<f64>| r.and_then(f);
            let ratio = pick(ours, |r| r.ns_per_step)
                .zip(pick(peer, |r| r.ns_per_step))
                .map(|(a, b)| a / b);
            let medians = pick(ours, |r| r.median_ns)
                .zip(pick(peer, |r| r.median_ns))
                .map(|(a, b)| a / b);
            let what = if scalar == "f32" {
                format!("{scene}: lagrange f32 ns per step <= rapier2d's")
            } else {
                format!("{scene}: lagrange f64 ns per step <= rapier2d's (f32; for information)")
            };
            // An asleep scene whose rapier2d bodies did not fall asleep is no like-for-like
            // comparison: say so beside the figure.
            let unlike =
                scene.ends_with("_asleep") && peer.and_then(|r| r.awake).is_some_and(|a| a > 0.0);
            out.push((
                what,
                format!(
                    "{}x (medians: {}x){}",
                    cell(ratio, 2),
                    cell(medians, 2),
                    if unlike {
                        "; rapier2d's bodies were not all asleep, so not like for like"
                    } else {
                        ""
                    }
                ),
                at_most(ratio, 1.0),
            ));
        }
    }
    for dolls in ["ragdolls_10", "ragdolls_50"] {
        let asleep = format!("{dolls}_asleep");
        for (engine, scalar) in [
            ("lagrange", "f32"),
            ("lagrange", "f64"),
            ("rapier2d", "f32"),
        ] {
            let awake = find(rows, dolls, engine, scalar);
            let sleeping = find(rows, &asleep, engine, scalar);
            let ratio = awake
                .and_then(|r| r.ns_per_step)
                .zip(sleeping.and_then(|r| r.ns_per_step))
                .map(|(a, s)| a / s);
            let still = sleeping.and_then(|r| r.awake).unwrap_or(f64::NAN);
            let verdict = match ratio {
                _ if engine == "rapier2d" => "for comparison",
                _ if still != 0.0 => "no figure (not all asleep)",
                Some(x) if x >= 20.0 => "met",
                Some(_) => "**NOT met**",
                None => "no figure",
            };
            out.push((
                format!("{dolls} {engine} {scalar}: asleep >= 20x cheaper than awake"),
                format!("{}x (awake while asleep: {still:.1})", cell(ratio, 1)),
                verdict,
            ));
        }
    }
    out
}

/// The Markdown report: the table, the goals, the notes.
pub fn markdown(quick: bool, rows: &[Row], seconds: f64) -> String {
    let mut md = String::from("# World: ns per step against rapier2d\n\n");
    let machine = std::thread::available_parallelism().map_or(0, std::num::NonZero::get);
    let rounds = rows.first().map_or(0, |r| r.rounds);
    let _ = writeln!(
        md,
        "{}{rounds} round(s) in one process on a machine with {machine} core(s), \
         {seconds:.0} s in all, at 60 Hz. ns/step: the fastest round's time per step of a \
         whole run (median over rounds beside it). awake: mean over the steps of the bodies \
         awake after each. depth: the deepest overlap after any step, mm (lagrange: found \
         again from outside; rapier2d: its contact manifolds). contacts, islands: means \
         over the steps of lagrange's `WorldReport`. free ... sleep: where a lagrange step's \
         time goes, ns a step, the means of the `World`'s own profile (`WorldReport::profile`, \
         its clock reading nanoseconds) over the untimed run (see the notes).\n",
        if quick {
            "**Quick run** (not for figures): "
        } else {
            ""
        }
    );
    md.push_str(
        "| scene | engine | scalar | bodies | awake | ns/step | median ns/step | depth mm | \
         contacts | islands | free | broad | narrow | solve | drift | sleep | notes |\n\
         |---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n",
    );
    for r in rows {
        let p = &r.probe;
        let part = |k: usize| p.parts_ns.map(|parts| parts[k]);
        let mut notes = r.note.clone();
        if let Some(f) = &r.failure {
            notes = format!("{notes} FAILED: {f}").trim().to_string();
        }
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.scene,
            r.engine,
            r.scalar,
            r.bodies,
            cell(r.awake, 1),
            cell(r.ns_per_step, 0),
            cell(r.median_ns, 0),
            cell(r.depth.map(|d| d * 1e3), 2),
            cell(p.contacts, 0),
            cell(p.islands, 1),
            cell(part(0), 0),
            cell(part(1), 0),
            cell(part(2), 0),
            cell(part(3), 0),
            cell(part(4), 0),
            cell(part(5), 0),
            notes,
        );
    }
    md.push_str("\n## Goals\n\n| goal | figure | verdict |\n|---|---|---|\n");
    for (what, figure, verdict) in goals(rows) {
        let _ = writeln!(md, "| {what} | {figure} | {verdict} |");
    }
    md.push_str(
        "\nRatios are lagrange's ns per step over rapier2d's (or awake over asleep), on the \
         fastest rounds; the medians' ratio beside them.\n\n\
         ## Where lagrange's time goes\n\n\
         Each lagrange row's last six columns are the `World`'s own profile \
         (`World::set_clock` given a nanosecond clock; `WorldReport::profile`), averaged over \
         the untimed run after the timed rounds: free (each awake body's own law, and the \
         copy of the bodies a failed step is rolled back to), broad (every shape's box, \
         grown by the margin and how far its body moves, and the sweep and prune), narrow \
         (each pair's manifold, the half-planes', the bodies' own rows such as joint limits, \
         and every contact point's rows: Jacobians and mobilities through the bodies' mass \
         solves), solve (the impulses' sweeps, the energy guard), drift (the split impulses \
         and the move), sleep (islands, sleeping, events). Their sum is a little above \
         ns/step (eight clock reads a step, and a run that is not the fastest round).\n\n\
         ## Peer\n\n\
         rapier2d 0.36 (`f32`; its `f64` build is the separate crate `rapier2d-f64`, not a \
         dependency here), default features, the bench profile (release, thin LTO, one \
         codegen unit), one thread (no `parallel`), default integration parameters but \
         dt = 1/60 s: 4 solver iterations (lagrange: 8 sweeps), allowed linear error 5 mm \
         and prediction distance 2 cm (lagrange's slop and margin). Boxes and balls as \
         cuboids and balls of the same mass and inertia; the floor and walls as fixed slabs \
         whose faces are lagrange's half-planes; ragdolls as multibodies with the same \
         links, limits, joint damping and capsules, self-contacts off (the contacts bench's \
         builder, shared). Sleeping is off in the awake scenes (`can_sleep(false)`), on with \
         rapier's own thresholds in the asleep ones.\n",
    );
    md
}
