//! `scene.csv` and `scene.md`.

use super::constant_mass::Skip;
use super::{Ratio, Row};
use std::fmt::Write;

/// Every row, in the columns.
pub fn csv(rows: &[Row]) -> String {
    let mut out =
        String::from("scene,layout,instances,awake_fraction,integrator,scalar,ns_per_frame\n");
    for r in rows {
        let _ = writeln!(
            out,
            "{},{},{},{:.4},{},{},{:.1}",
            r.scene,
            r.layout,
            r.instances,
            r.awake_fraction,
            r.integrator,
            r.scalar,
            r.ns_per_frame
        );
    }
    out
}

/// The report: the rows (with ns per awake instance), the ratios against their goals, and
/// the constant-mass skip.
pub fn markdown(quick: bool, rows: &[Row], ratios: &[Ratio], skip: &[Skip]) -> String {
    let mut out = String::from("# Scenes: what a frame costs\n\n");
    if quick {
        out.push_str("A `--quick` smoke run: small timing budgets, noisy figures.\n\n");
    }
    out.push_str(
        "Median wall time per frame (one fixed step of 1/120 s per frame), on a shared \
         machine: compare within a run, as ratios.\n\n\
         | scene | layout | instances | awake | integrator | scalar | ns per frame | ns per awake instance |\n\
         |---|---|---:|---:|---|---|---:|---:|\n",
    );
    for r in rows {
        let awake = (r.awake_fraction * r.instances as f64).round().max(1.0);
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.1}% | {} | {} | {:.0} | {:.1} |",
            r.scene,
            r.layout,
            r.instances,
            r.awake_fraction * 100.0,
            r.integrator,
            r.scalar,
            r.ns_per_frame,
            r.ns_per_frame / awake
        );
    }
    out.push_str(
        "\n## Ratios against the goals\n\nEach the median of per-pair ratios, the two sides \
         timed alternately.\n\n| ratio | measured | goal | met |\n|---|---:|---|---|\n",
    );
    for r in ratios {
        let _ = writeln!(
            out,
            "| {} | {:.3} | {} | {} |",
            r.what,
            r.ratio,
            r.goal,
            if r.met { "yes" } else { "**no**" }
        );
    }
    out.push_str(
        "\n## The constant-mass skip\n\nA spring chain written as a `Lagrangian`, through \
         `EulerLagrange`, with `CONSTANT_MASS` claimed (the mass matrix factored once, `T` not \
         differentiated in the right-hand side) and not; the largest difference of the two \
         accelerations in ulps of their size (goal: within 4).\n\n\
         | N | scalar | ns per acceleration, skip | without | speed-up | ulps apart |\n\
         |---:|---|---:|---:|---:|---:|\n",
    );
    for s in skip {
        let _ = writeln!(
            out,
            "| {} | {} | {:.1} | {:.1} | {:.2}x | {} |",
            s.n,
            s.scalar,
            s.with,
            s.without,
            s.without / s.with,
            s.ulps
        );
    }
    out
}
