//! `cargo xtask mutants`: mutation testing of the numerical core with `cargo-mutants`.
//!
//! Each [`Area`] of the numerical core (the integrators' steps and tableaux, the systems'
//! accelerations, the constraint solve and its stabilization, the impact law, `fast_trig`, the
//! automatic path, the laws and forces, the lanes, the scenes, the clocks, the drivers and
//! the exact solutions) is mutated on its own, and each mutant runs only the test binaries
//! that exercise that area. The outcomes are tallied per file (killed, survived, timed out,
//! unviable, equivalent) into `target/mutants/report.md`; a surviving mutant is either killed
//! by a new test or recorded, with the reason, in [`EQUIVALENT_LIST`]. Not part of
//! `cargo xtask ci`.
//!
//! Every `.rs` file of `lagrange-core`, `lagrange-integrators`, `lagrange-systems` and
//! `lagrange-world` is in an area or in [`NOT_MUTATED`] with the reason; `--list` fails on a
//! file in neither.
//!
//! The whole run: 8,063 mutants (1,047 of them in `world` and `world-step`, issue 34's, not
//! yet run). The first fourteen areas (4,222 mutants) took about two hours
//! on two cores when they were set up. The areas added with issue 32 (1,839 mutants), each
//! one's full run on this two-core machine while another developer's builds ran beside it
//! (wall time of `cargo xtask mutants --area NAME`, baseline included; an idle machine takes
//! about half):
//!
//! ```text
//! area          mutants   full run
//! automatic         518    2363 s   (jet, dual, lagrangian, jacobian)
//! laws              171     751 s   (mechanism, forces, controlled, free_law, state, scalar,
//!                                    validate, error, constraints/mod, constraints/set)
//! scalar-trig        27      74 s   (scalar_trig, with libm-trig)
//! lanes              96     322 s
//! scenes            225     808 s   (scene, bank, banks, sleep)
//! clocks            201     246 s   (clock, frame_clock, fixed_timestep)
//! drivers           128     532 s   (integrator, projected, adaptive/settings)
//! exact             473     852 s   (exact, exact/*)
//! ```
//!
//! The contact areas (among the first fourteen), re-run since the impulse stepper was written,
//! timed the same way, with other builds and the measurement of the area's survivors beside
//! the run (a load average of 14 on the two cores at its height):
//!
//! ```text
//! area              mutants   full run
//! contact-laws          213    4581 s   (lcp, contacts, model)
//! contact-laws          242    3579 s   (and lcp/relaxed; again, a load of 8-9)
//! contact-steppers      409    6073 s   (contact_stepper, impulse_stepper/*; two jobs)
//! generated             108     400 s   (closed_form, parameters, agreement)
//! exact                 473    1164 s   (again, a load of 8-9)
//! bodies                 19      44 s   (core links)
//! rigid-body            198     200 s   (rigid_body, systems links)
//! ```
//!
//! ```text
//! cargo xtask mutants                       every area
//! cargo xtask mutants --area rk,adaptive    some areas
//! cargo xtask mutants --list                the areas and how many mutants each holds
//! cargo xtask mutants --iterate             skip the mutants caught by the last run
//! cargo xtask mutants --report              tally the last run again (after editing the list)
//! cargo xtask mutants --since REV           only the lines changed since REV, under
//!                                           target/mutants/since (a change's own run)
//! ```

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use crate::cmd;

/// The pinned `cargo-mutants`, installed with `cargo install --locked` when missing.
const CARGO_MUTANTS: &str = "cargo-mutants";
const CARGO_MUTANTS_VERSION: &str = "27.1.0";

/// The committed list of surviving mutants that are equivalent to the original code.
const EQUIVALENT_LIST: &str = "xtask/mutants-equivalent.txt";

/// Where `--since` writes the change it mutates, under its own output directory.
const SINCE_DIFF: &str = "since.diff";

/// The kill rate each file of the numerical core must reach, over its non-equivalent viable
/// mutants (a timed-out mutant counts as killed: the run detected it).
const GOAL: f64 = 0.9;

/// A mutant's tests may run this many times as long as the area's unmutated tests before it
/// counts as timed out (detected): a clean run slowed by the other job is not taken for a
/// detection, and a mutant that makes an adaptive pair crawl at tiny steps does not hold a job
/// for long (with a fixed 30 s, the adaptive area's 50-odd such mutants took half its time).
const TEST_TIMEOUT_FACTOR: f64 = 5.0;

/// The shortest timeout, seconds: the start of a test binary and cargo's own work.
const TEST_TIMEOUT_MIN_S: f64 = 10.0;

/// Seconds a mutant's build may take (the baseline is ours, so cargo-mutants cannot scale it).
const BUILD_TIMEOUT_S: &str = "600";

/// A part of the numerical core, mutated on its own and tested by its own test binaries.
struct Area {
    /// Name for `--area` and the output directory.
    name: &'static str,
    /// The package whose files are mutated.
    package: &'static str,
    /// The files mutated (globs relative to the root).
    files: &'static [&'static str],
    /// Only mutants whose name matches this regex (the functions of the area), if any.
    only: Option<&'static str>,
    /// The package whose test binaries run for each mutant: `lagrange-tests`, or the mutated
    /// package itself when its own integration tests suffice (a build of one crate, not five).
    test_package: &'static str,
    /// Arguments of `cargo test -p <test_package>` for each mutant: the test binaries to run.
    tests: &'static [&'static str],
    /// Also run the mutated package's own unit tests (`--lib`): for private kernels tested
    /// where they live (the step-size controller's `log2` and `exp2`, Newton's hand-over from
    /// fixed-point iteration). Costs a second build of the mutated crate per mutant.
    unit_tests: bool,
    /// Build the mutants at `opt-level = 1` rather than 0: only where the tests need it (the
    /// exhaustive sweeps of `fast_trig`). Unoptimised, a mutant of a system rebuilds in under
    /// 2 s and its tests run in at most 6 s; at `opt-level = 1` the rebuild alone took 10 s
    /// (the monomorphised integrators and systems in every test binary are optimised again).
    optimised: bool,
}

/// The dependencies (libm, nalgebra's and proptest's non-generic code) optimised fully: they
/// build once per run, and at `opt-level = 0` libm's sines made the chains' tests take a
/// quarter longer (7.4-9.0 s against 5.9-6.0 s, measured beside a mutation run).
const DEPENDENCIES_OPTIMISED: &str = "profile.dev.package.\"*\".opt-level=3";

impl Area {
    /// The dev profile the area's mutants (and its baseline) build in: without debug
    /// information (a third of a link), the workspace optimised only where
    /// [`Area::optimised`] asks, the dependencies always ([`DEPENDENCIES_OPTIMISED`]; the
    /// caller passes it to cargo).
    fn profile<'c>(&self, c: &'c mut Command) -> &'c mut Command {
        c.env("CARGO_PROFILE_DEV_DEBUG", "0").env(
            "CARGO_PROFILE_DEV_OPT_LEVEL",
            if self.optimised { "1" } else { "0" },
        )
    }
}

/// The areas, in the order they run.
const AREAS: [Area; 29] = [
    Area {
        name: "explicit",
        package: "lagrange-integrators",
        test_package: "lagrange-tests",
        files: &[
            "lagrange-integrators/src/rk4.rs",
            "lagrange-integrators/src/explicit_euler.rs",
            "lagrange-integrators/src/semi_implicit_euler.rs",
            "lagrange-integrators/src/velocity_verlet.rs",
            "lagrange-integrators/src/stormer_verlet.rs",
            "lagrange-integrators/src/yoshida.rs",
        ],
        only: None,
        tests: &[
            "--test",
            "convergence",
            "--test",
            "driven",
            "--test",
            "origin_pendulum",
            "--test",
            "forces_and_energy",
            "--test",
            "step_time",
            "--test",
            "lanes",
            "--test",
            "work_counts",
            "--test",
            "unobserved_runs",
            "--test",
            "bad_input",
        ],
        unit_tests: false,
        optimised: false,
    },
    Area {
        name: "implicit",
        package: "lagrange-integrators",
        test_package: "lagrange-tests",
        files: &[
            "lagrange-integrators/src/implicit_rk.rs",
            "lagrange-integrators/src/implicit_midpoint.rs",
            "lagrange-integrators/src/gauss_legendre.rs",
            "lagrange-integrators/src/backward_euler.rs",
            "lagrange-integrators/src/radau_iia.rs",
            "lagrange-integrators/src/newton.rs",
            "lagrange-integrators/src/variational.rs",
        ],
        only: None,
        tests: &[
            "--test",
            "convergence",
            "--test",
            "driven",
            "--test",
            "implicit",
            "--test",
            "stiff",
            "--test",
            "step_time",
            "--test",
            "work_counts",
        ],
        unit_tests: true,
        optimised: false,
    },
    Area {
        name: "adaptive",
        package: "lagrange-integrators",
        test_package: "lagrange-tests",
        files: &[
            "lagrange-integrators/src/adaptive/embedded.rs",
            "lagrange-integrators/src/adaptive/dopri5.rs",
            "lagrange-integrators/src/adaptive/dop853.rs",
            "lagrange-integrators/src/adaptive/sums.rs",
            "lagrange-integrators/src/adaptive/nystrom.rs",
            "lagrange-integrators/src/adaptive/hermite.rs",
            "lagrange-integrators/src/adaptive/nystrom64.rs",
            "lagrange-integrators/src/adaptive/nystrom86.rs",
            "lagrange-integrators/src/adaptive/nystrom1210.rs",
            "lagrange-integrators/src/adaptive/verner76.rs",
            "lagrange-integrators/src/adaptive/verner98.rs",
            "lagrange-integrators/src/adaptive/controller.rs",
            "lagrange-integrators/src/adaptive/energy.rs",
        ],
        only: None,
        tests: &[
            "--test",
            "adaptive",
            "--test",
            "high_order_pairs",
            "--test",
            "energy_projection",
            "--test",
            "driven",
            "--test",
            "kepler",
            "--test",
            "work_counts",
            "--test",
            "issue15",
        ],
        unit_tests: true,
        optimised: false,
    },
    Area {
        name: "contact-laws",
        package: "lagrange-core",
        test_package: "lagrange-tests",
        files: &[
            "lagrange-core/src/constraints/contact/lcp.rs",
            "lagrange-core/src/constraints/contact/lcp/relaxed.rs",
            "lagrange-core/src/constraints/contact/contacts.rs",
            "lagrange-core/src/constraints/contact/model.rs",
        ],
        only: None,
        tests: &[
            "--test",
            "impact_law",
            "--test",
            "bouncing_ball",
            "--test",
            "double_pendulum_floor",
            "--test",
            "friction",
            "--test",
            "contact_promises",
            "--test",
            "impulse_stepper",
        ],
        unit_tests: true,
        optimised: false,
    },
    Area {
        name: "contact-steppers",
        package: "lagrange-integrators",
        test_package: "lagrange-tests",
        files: &[
            "lagrange-integrators/src/contact_stepper.rs",
            "lagrange-integrators/src/impulse_stepper/mod.rs",
            "lagrange-integrators/src/impulse_stepper/step.rs",
            "lagrange-integrators/src/impulse_stepper/rows.rs",
            "lagrange-integrators/src/impulse_stepper/solve.rs",
            "lagrange-integrators/src/impulse_stepper/energy.rs",
            "lagrange-integrators/src/impulse_stepper/settings.rs",
            "lagrange-integrators/src/impulse_stepper/report.rs",
        ],
        only: None,
        tests: &[
            "--test",
            "bouncing_ball",
            "--test",
            "double_pendulum_floor",
            "--test",
            "pendulum_wall",
            "--test",
            "friction",
            "--test",
            "contact_promises",
            "--test",
            "impulse_stepper",
        ],
        // The impulse stepper's rows taken again at rest are tested where they live (a
        // stepper made to fill every step, bit for bit; another mass at the same place).
        unit_tests: true,
        optimised: false,
    },
    Area {
        name: "impacts",
        package: "lagrange-core",
        test_package: "lagrange-tests",
        files: &["lagrange-core/src/constraints/contact/impulse.rs"],
        only: None,
        tests: &[
            "--test",
            "impact_law",
            "--test",
            "bouncing_ball",
            "--test",
            "double_pendulum_floor",
            "--test",
            "pendulum_wall",
            "--test",
            "friction",
        ],
        unit_tests: false,
        optimised: false,
    },
    Area {
        name: "constraints",
        package: "lagrange-core",
        test_package: "lagrange-tests",
        files: &[
            "lagrange-core/src/constraints/constrained.rs",
            "lagrange-core/src/constraints/schur.rs",
            "lagrange-core/src/constraints/projection.rs",
        ],
        only: None,
        tests: &[
            "--test",
            "cartesian_pendulum",
            "--test",
            "constraints_automatic",
            "--test",
            "constrained_forces",
            "--test",
            "four_bar_linkage",
            "--test",
            "rolling_disk",
            "--test",
            "constrained_laws",
            "--test",
            "constraints_bad_input",
            "--test",
            "constraints_three_rows",
        ],
        unit_tests: false,
        optimised: false,
    },
    Area {
        name: "fast-trig",
        package: "lagrange-core",
        test_package: "lagrange-core",
        files: &["lagrange-core/src/fast_trig.rs"],
        only: None,
        tests: &["--test", "fast_trig"],
        unit_tests: false,
        optimised: true,
    },
    Area {
        name: "systems-one",
        package: "lagrange-systems",
        test_package: "lagrange-tests",
        files: &[
            "lagrange-systems/src/simple_pendulum.rs",
            "lagrange-systems/src/falling_particle.rs",
            "lagrange-systems/src/spring_mass_damper.rs",
            "lagrange-systems/src/bead_on_rotating_hoop.rs",
        ],
        only: Some(ACCELERATIONS),
        tests: SYSTEM_TESTS,
        unit_tests: false,
        optimised: false,
    },
    Area {
        name: "systems-two",
        package: "lagrange-systems",
        test_package: "lagrange-tests",
        files: &[
            "lagrange-systems/src/double_pendulum.rs",
            "lagrange-systems/src/elastic_pendulum.rs",
            "lagrange-systems/src/spherical_pendulum.rs",
            "lagrange-systems/src/cart_pole.rs",
            "lagrange-systems/src/acrobot.rs",
            "lagrange-systems/src/swinging_atwood.rs",
            "lagrange-systems/src/kepler.rs",
        ],
        only: Some(ACCELERATIONS),
        tests: SYSTEM_TESTS,
        unit_tests: false,
        optimised: false,
    },
    Area {
        // The two-coordinate systems' shared solves, tested where they live: their callers
        // check first (a radius, a determinant), so the helpers' own checks need tests of
        // their own; a build of one crate per mutant.
        name: "small-solve",
        package: "lagrange-systems",
        test_package: "lagrange-systems",
        files: &["lagrange-systems/src/small_solve.rs"],
        only: None,
        tests: &["--lib"],
        unit_tests: false,
        optimised: false,
    },
    Area {
        name: "systems-chains",
        package: "lagrange-systems",
        test_package: "lagrange-tests",
        files: &[
            "lagrange-systems/src/n_link_pendulum.rs",
            "lagrange-systems/src/cartesian_pendulum.rs",
            "lagrange-systems/src/four_bar_linkage.rs",
            "lagrange-systems/src/rolling_disk.rs",
        ],
        only: Some(ACCELERATIONS),
        tests: &[
            "--test",
            "mechanisms_automatic",
            "--test",
            "mechanisms_reference",
            "--test",
            "mechanisms_physics",
            "--test",
            "four_bar_linkage",
            "--test",
            "rolling_disk",
            "--test",
            "cartesian_pendulum",
            "--test",
            "constraints_automatic",
            "--test",
            "constrained_forces",
        ],
        unit_tests: false,
        optimised: false,
    },
    Area {
        name: "ragdoll",
        package: "lagrange-systems",
        test_package: "lagrange-tests",
        files: &[
            "lagrange-systems/src/ragdoll.rs",
            "lagrange-systems/src/ragdoll_contacts.rs",
        ],
        only: Some(RAGDOLL),
        tests: &["--test", "ragdoll"],
        unit_tests: false,
        optimised: false,
    },
    Area {
        name: "core-solves",
        package: "lagrange-core",
        test_package: "lagrange-tests",
        files: &[
            "lagrange-core/src/cholesky.rs",
            "lagrange-core/src/tree_factor.rs",
            "lagrange-core/src/constraints/automatic.rs",
            "lagrange-core/src/constraints/contact/active_rows.rs",
        ],
        only: None,
        tests: &[
            "--test",
            "ragdoll",
            "--test",
            "automatic_euler_lagrange",
            "--test",
            "constant_mass",
            "--test",
            "constraints_automatic",
            "--test",
            "constraints_three_rows",
            "--test",
            "bouncing_ball",
            "--test",
            "double_pendulum_floor",
            "--test",
            "pendulum_wall",
            "--test",
            "friction",
            "--test",
            "impact_law",
            "--test",
            "automatic_exactness",
        ],
        unit_tests: true,
        optimised: false,
    },
    Area {
        // The automatic path's tape (reverse mode for long mechanisms, with its sine and
        // cosine nodes by angle) and the memo of sines and cosines its jets share: tested where they live (the tape against the jet) by
        // `lagrange-core`'s unit tests; a build of one crate per mutant.
        name: "tape",
        package: "lagrange-core",
        test_package: "lagrange-core",
        files: &[
            "lagrange-core/src/tape/mod.rs",
            "lagrange-core/src/tape/sweep.rs",
            "lagrange-core/src/tape/terms.rs",
            "lagrange-core/src/tape/trig.rs",
            "lagrange-core/src/trig_memo.rs",
        ],
        only: None,
        tests: &["--lib"],
        unit_tests: false,
        optimised: false,
    },
    Area {
        name: "events",
        package: "lagrange-integrators",
        test_package: "lagrange-tests",
        files: &["lagrange-integrators/src/adaptive/events.rs"],
        only: None,
        tests: &[
            "--test",
            "adaptive",
            "--test",
            "high_order_pairs",
            "--test",
            "energy_projection",
        ],
        unit_tests: false,
        optimised: false,
    },
    Area {
        // The automatic path: the jets and dual numbers that differentiate a Lagrangian, the
        // Euler-Lagrange law built on them, and the Jacobian by differences they are checked
        // against. Their own unit tests, then the law against the hand-written systems.
        name: "automatic",
        package: "lagrange-core",
        test_package: "lagrange-tests",
        files: &[
            "lagrange-core/src/jet.rs",
            "lagrange-core/src/dual.rs",
            "lagrange-core/src/lagrangian.rs",
            "lagrange-core/src/jacobian.rs",
        ],
        only: None,
        tests: &[
            "--test",
            "automatic_euler_lagrange",
            "--test",
            "automatic_exactness",
            "--test",
            "automatic_tape",
            "--test",
            "mechanisms_automatic",
            "--test",
            "derivatives",
        ],
        unit_tests: true,
        optimised: false,
    },
    Area {
        // The laws around a mechanism: its trait's default methods, the forces and inputs,
        // the state and its checks, the parameter validation and the errors it names.
        name: "laws",
        package: "lagrange-core",
        test_package: "lagrange-tests",
        files: &[
            "lagrange-core/src/mechanism.rs",
            "lagrange-core/src/forces.rs",
            "lagrange-core/src/controlled.rs",
            "lagrange-core/src/free_law.rs",
            "lagrange-core/src/state.rs",
            "lagrange-core/src/scalar.rs",
            "lagrange-core/src/validate.rs",
            "lagrange-core/src/error.rs",
            "lagrange-core/src/constraints/mod.rs",
            "lagrange-core/src/constraints/set.rs",
        ],
        only: None,
        tests: &[
            "--test",
            "forces_and_energy",
            "--test",
            "law_force",
            "--test",
            "one_law",
            "--test",
            "bad_input",
            "--test",
            "mechanisms_bad_input",
            "--test",
            "constraints_bad_input",
            "--test",
            "constrained_forces",
            "--test",
            "driven",
            "--test",
            "issue15",
            "--test",
            "derivatives",
            "--test",
            "law_parts",
        ],
        unit_tests: true,
        optimised: false,
    },
    Area {
        // The f64 sines and cosines and the f32 ones of the `libm-trig` feature, checked bit
        // for bit against libm by `lagrange-core`'s unit tests with that feature on (without
        // it the f32 ones are `fast_trig`'s, an area of its own).
        name: "scalar-trig",
        package: "lagrange-core",
        test_package: "lagrange-core",
        files: &["lagrange-core/src/scalar_trig.rs"],
        only: None,
        tests: &["--lib", "--features", "libm-trig"],
        unit_tests: false,
        optimised: false,
    },
    Area {
        name: "lanes",
        package: "lagrange-core",
        test_package: "lagrange-tests",
        files: &["lagrange-core/src/lanes.rs", "lagrange-core/src/gather.rs"],
        only: None,
        tests: &["--test", "lanes", "--test", "lanes_diverging"],
        unit_tests: true,
        optimised: false,
    },
    Area {
        name: "scenes",
        package: "lagrange-integrators",
        test_package: "lagrange-tests",
        files: &[
            "lagrange-integrators/src/scene.rs",
            "lagrange-integrators/src/scene/awake.rs",
            "lagrange-integrators/src/scene/bank.rs",
            "lagrange-integrators/src/scene/banks.rs",
            "lagrange-integrators/src/scene/columns.rs",
            "lagrange-integrators/src/scene/layout.rs",
            "lagrange-integrators/src/scene/sleep.rs",
            "lagrange-integrators/src/scene/slot.rs",
            "lagrange-integrators/src/scene/states.rs",
        ],
        only: None,
        tests: &[
            "--test",
            "scene_bits",
            "--test",
            "scene_errors",
            "--test",
            "scene_order",
            "--test",
            "scene_sleep",
            "--test",
            "scene_wake",
            "--test",
            "scene_bank",
            "--test",
            "lanes",
            "--test",
            "lanes_diverging",
            "--test",
            "scene_lanes_bits",
        ],
        unit_tests: false,
        optimised: false,
    },
    Area {
        // Simulated time: the exact step clock every integrator keeps, the frame clock of a
        // real-time loop, and the fixed-timestep driver on it.
        name: "clocks",
        package: "lagrange-integrators",
        test_package: "lagrange-tests",
        files: &[
            "lagrange-integrators/src/clock.rs",
            "lagrange-integrators/src/frame_clock.rs",
            "lagrange-integrators/src/fixed_timestep.rs",
        ],
        only: None,
        tests: &[
            "--test",
            "clocks",
            "--test",
            "fixed_timestep",
            "--test",
            "issue15",
            "--test",
            "scene_bits",
            "--test",
            "step_time",
        ],
        unit_tests: false,
        optimised: false,
    },
    Area {
        // What every integrator shares (the trait's default runs, the failure and work
        // records), the projection after each step, and the adaptive settings.
        name: "drivers",
        package: "lagrange-integrators",
        test_package: "lagrange-tests",
        files: &[
            "lagrange-integrators/src/integrator.rs",
            "lagrange-integrators/src/projected.rs",
            "lagrange-integrators/src/adaptive/settings.rs",
        ],
        only: None,
        tests: &[
            "--test",
            "one_law",
            "--test",
            "constrained_forces",
            "--test",
            "cartesian_pendulum",
            "--test",
            "constraints_bad_input",
            "--test",
            "bad_input",
            "--test",
            "work_counts",
            "--test",
            "unobserved_runs",
            "--test",
            "adaptive",
            "--test",
            "issue15",
            "--test",
            "step_time",
            "--test",
            "clocks",
        ],
        unit_tests: false,
        optimised: false,
    },
    Area {
        // The exact solutions every integrator is measured against.
        name: "exact",
        package: "lagrange-systems",
        test_package: "lagrange-tests",
        files: &[
            "lagrange-systems/src/exact.rs",
            "lagrange-systems/src/exact/damped_oscillator.rs",
            "lagrange-systems/src/exact/driven_oscillator.rs",
            "lagrange-systems/src/exact/kepler.rs",
        ],
        only: None,
        tests: &[
            "--test",
            "exact_solutions",
            "--test",
            "spring_mass_damper",
            "--test",
            "driven",
            "--test",
            "kepler",
            "--test",
            "origin_pendulum",
            "--test",
            "issue15",
            "--test",
            "mechanisms_bad_input",
        ],
        unit_tests: true,
        optimised: false,
    },
    Area {
        // Where a mechanism's links are (issue 34's bodies): the pose and the point Jacobian
        // by dual numbers. Not yet run.
        name: "bodies",
        package: "lagrange-core",
        test_package: "lagrange-tests",
        files: &["lagrange-core/src/links.rs"],
        only: None,
        tests: &["--test", "rigid_body", "--test", "links"],
        unit_tests: false,
        optimised: false,
    },
    Area {
        // The free rigid body and the standard chains' links (issue 34): its law, its
        // constructors, its hand-derived link point; the chains' link poses. Not yet run.
        name: "rigid-body",
        package: "lagrange-systems",
        test_package: "lagrange-tests",
        files: &[
            "lagrange-systems/src/rigid_body.rs",
            "lagrange-systems/src/links.rs",
        ],
        only: None,
        // `lanes`: the body gathered into lanes (its `Gather`).
        tests: &["--test", "rigid_body", "--test", "links", "--test", "lanes"],
        unit_tests: false,
        optimised: false,
    },
    Area {
        // Collision geometry (issue 34): shapes, manifolds, the collision of two shapes and of
        // a shape with a half-plane, rows against planes, the broad phase. Not yet run.
        name: "world",
        package: "lagrange-world",
        test_package: "lagrange-tests",
        files: &[
            "lagrange-world/src/broad.rs",
            "lagrange-world/src/collide.rs",
            "lagrange-world/src/manifold.rs",
            "lagrange-world/src/one_of.rs",
            "lagrange-world/src/pair.rs",
            "lagrange-world/src/plane_contacts.rs",
            "lagrange-world/src/query.rs",
            "lagrange-world/src/shape.rs",
            "lagrange-world/src/shape_pairs.rs",
            "lagrange-world/src/vec2.rs",
        ],
        only: None,
        tests: &[
            "--test",
            "collide",
            "--test",
            "plane_contacts",
            "--test",
            "broad_phase",
            "--test",
            "shape_queries",
            "--test",
            "pairs",
            "--test",
            "world_mixed",
        ],
        unit_tests: false,
        optimised: false,
    },
    Area {
        // The world (issue 34): bodies, shapes on their links, contacts between them solved
        // by sequential impulses, islands, sleep, events and queries. Not yet run.
        name: "world-step",
        package: "lagrange-world",
        test_package: "lagrange-tests",
        files: &[
            "lagrange-world/src/world/mod.rs",
            "lagrange-world/src/world/block.rs",
            "lagrange-world/src/world/bodies.rs",
            "lagrange-world/src/world/detect.rs",
            "lagrange-world/src/world/islands.rs",
            "lagrange-world/src/world/limits.rs",
            "lagrange-world/src/world/lists.rs",
            "lagrange-world/src/world/locks.rs",
            "lagrange-world/src/world/merge.rs",
            "lagrange-world/src/world/mobilities.rs",
            "lagrange-world/src/world/outran.rs",
            "lagrange-world/src/world/own.rs",
            "lagrange-world/src/world/places.rs",
            "lagrange-world/src/world/profile.rs",
            "lagrange-world/src/world/rows.rs",
            "lagrange-world/src/world/settings.rs",
            "lagrange-world/src/world/solve.rs",
            "lagrange-world/src/world/twins.rs",
            "lagrange-world/src/sweep.rs",
        ],
        only: None,
        tests: &[
            "--test",
            "world",
            "--test",
            "world_pile",
            "--test",
            "world_fast",
        ],
        unit_tests: true,
        optimised: false,
    },
    Area {
        // What every generated mechanism uses (issue 36): the closed-form solves and
        // `closed_form_mechanism!`, `parameters!` (validated constructors), and the agreement
        // check its test module calls. Tested by the generated mechanisms' own test modules
        // and their comparison with the hand-derived ones, and by the core's unit tests.
        // Not yet run: its kill rate is still to be measured.
        name: "generated",
        package: "lagrange-core",
        test_package: "lagrange-generated",
        files: &[
            "lagrange-core/src/closed_form.rs",
            "lagrange-core/src/parameters.rs",
            "lagrange-core/src/agreement.rs",
        ],
        only: None,
        // `--lib` (from `unit_tests`) runs the unit tests of both packages.
        tests: &["--test", "hand_derived"],
        unit_tests: true,
        optimised: false,
    },
];

/// The crates whose every source file is in an [`Area`] or in [`NOT_MUTATED`].
const MUTATED_CRATES: [&str; 4] = [
    "lagrange-core",
    "lagrange-integrators",
    "lagrange-systems",
    "lagrange-world",
];

/// The source files of [`MUTATED_CRATES`] in no [`Area`], each with the reason: nothing in them
/// that a mutant could change (modules and re-exports only), or an area still to come.
/// `--list` fails on a file that is in neither this table nor an area.
const NOT_MUTATED: [(&str, &str); 8] = [
    ("lagrange-core/src/lib.rs", "modules and re-exports only"),
    ("lagrange-world/src/lib.rs", "modules and re-exports only"),
    ("lagrange-core/src/prelude.rs", "re-exports only"),
    (
        "lagrange-integrators/src/lib.rs",
        "modules and re-exports only",
    ),
    ("lagrange-integrators/src/prelude.rs", "re-exports only"),
    (
        "lagrange-integrators/src/adaptive/mod.rs",
        "modules and re-exports only",
    ),
    ("lagrange-systems/src/lib.rs", "modules and re-exports only"),
    (
        "lagrange-core/src/constraints/contact/mod.rs",
        "modules and re-exports only",
    ),
];

/// The `.rs` files under `dir`, as paths relative to `root` with `/` between parts, sorted.
fn sources(root: &Path, dir: &str) -> Result<Vec<String>, String> {
    let mut found = Vec::new();
    let mut pending = vec![root.join(dir)];
    while let Some(d) = pending.pop() {
        let entries = std::fs::read_dir(&d).map_err(|e| format!("{}: {e}", d.display()))?;
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                pending.push(path);
            } else if path.extension().is_some_and(|x| x == "rs") {
                let relative = path.strip_prefix(root).map_err(|e| e.to_string())?;
                let parts: Vec<_> = relative.iter().map(|p| p.to_string_lossy()).collect();
                found.push(parts.join("/"));
            }
        }
    }
    found.sort();
    Ok(found)
}

/// The files of `files` that are in no area and not in [`NOT_MUTATED`], and the entries of
/// either that name no file of `files` or are in both: empty when every file is accounted for.
fn unaccounted(files: &[String]) -> Vec<String> {
    let in_area = |f: &str| AREAS.iter().any(|a| a.files.contains(&f));
    let excused = |f: &str| NOT_MUTATED.iter().any(|(n, _)| *n == f);
    let mut problems: Vec<String> = files
        .iter()
        .filter(|f| !in_area(f) && !excused(f))
        .map(|f| format!("{f}: in no area and not in NOT_MUTATED"))
        .collect();
    let named = AREAS
        .iter()
        .flat_map(|a| a.files.iter())
        .chain(NOT_MUTATED.iter().map(|(n, _)| n));
    for n in named {
        if !files.iter().any(|f| f == n) {
            problems.push(format!("{n}: named in mutants.rs but not a source file"));
        } else if in_area(n) && excused(n) {
            problems.push(format!("{n}: both in an area and in NOT_MUTATED"));
        }
    }
    problems.sort();
    problems.dedup();
    problems
}

/// `Err` naming every source file of [`MUTATED_CRATES`] that [`unaccounted`] finds.
fn check_accounted(root: &Path) -> Result<(), String> {
    let mut files = Vec::new();
    for c in MUTATED_CRATES {
        files.extend(sources(root, &format!("{c}/src"))?);
    }
    let problems = unaccounted(&files);
    if problems.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "source files not accounted for in xtask/src/mutants.rs (add each to an area, \
             or to NOT_MUTATED with its reason):\n  {}",
            problems.join("\n  ")
        ))
    }
}

/// The mutants of a system that change how it moves: its equations (mass matrix, right-hand
/// side, forces, solves, accelerations, constraint rows) and the private helpers they call.
/// Constructors, accessors, energies and conversions are tested elsewhere and left out.
const ACCELERATIONS: &str = "impl Mechanism|impl Constraints|small_solve|::terms|::det\\b|\
                             ::tension_solve|::solve_mass_from|::rhs_from|::phi_from|\
                             ::jacobian_from|::velocity_product_from|::solve_with|::inertias|\
                             ::weights|solve_diagonal2|solve_sym2";

/// The ragdoll's [`ACCELERATIONS`]: its articulated-body law and the spatial algebra it
/// runs on, its energies (the automatic path's oracle for that law), and its contact rows.
const RAGDOLL: &str = "impl Mechanism|impl Lagrangian|impl Constraints|impl Contacts|\
                       ::articulated|solve3|inertia_at|cross_motion|cross_force|\\bdot\\b|\
                       ::segments|Pose<S>::point|::pose\\b|\\bscale\\b|\\badd\\b|torso_axis|\
                       ::world_point|::rates|::outward|::point_jacobians|::floor_points|::limits";

/// The test binaries of the systems' areas.
const SYSTEM_TESTS: &[&str] = &[
    "--test",
    "mechanisms_bad_input",
    "--test",
    "mechanisms_automatic",
    "--test",
    "mechanisms_reference",
    "--test",
    "mechanisms_physics",
    "--test",
    "mechanisms_energy",
];

/// The outcome classes of `cargo-mutants`, by the file it lists them in.
const OUTCOMES: [(&str, Outcome); 5] = [
    ("caught.txt", Outcome::Killed),
    // With `--iterate`: the mutants an earlier run caught *or found unviable*, not run again;
    // those in the area's [`UNVIABLE_LEDGER`] count as unviable, the others as killed.
    ("previously_caught.txt", Outcome::Killed),
    ("missed.txt", Outcome::Survived),
    ("timeout.txt", Outcome::TimedOut),
    ("unviable.txt", Outcome::Unviable),
];

/// Every mutant of an area found unviable since its last full run, one per line, beside the
/// area's `mutants.out`: cargo-mutants keeps only the last run's `unviable.txt`, and with
/// `--iterate` lists the earlier unviable mutants among the previously caught.
const UNVIABLE_LEDGER: &str = "unviable-ledger.txt";

/// Adds the last run's unviable mutants of the area in `dir` to its ledger.
fn update_ledger(dir: &Path) -> Result<(), String> {
    let ledger = dir.join(UNVIABLE_LEDGER);
    let mut names: std::collections::BTreeSet<String> = read_lines(&ledger).collect();
    names.extend(read_lines(&dir.join("mutants.out").join("unviable.txt")));
    let text: String = names.iter().map(|n| format!("{n}\n")).collect();
    std::fs::write(&ledger, text).map_err(|e| format!("{}: {e}", ledger.display()))
}

/// The non-empty lines of a file (none if it is missing).
fn read_lines(path: &Path) -> impl Iterator<Item = String> {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .map(String::from)
        .collect::<Vec<_>>()
        .into_iter()
}

/// What happened to one mutant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Outcome {
    Killed,
    Survived,
    TimedOut,
    Unviable,
}

/// The tally of one file.
#[derive(Debug, Default, Clone, Copy)]
struct Tally {
    killed: u32,
    survived: u32,
    timed_out: u32,
    unviable: u32,
    equivalent: u32,
}

impl Tally {
    /// Killed (timeouts included) over the non-equivalent viable mutants; 1 when there are none.
    fn rate(&self) -> f64 {
        let detected = f64::from(self.killed + self.timed_out);
        let counted = detected + f64::from(self.survived);
        if counted == 0.0 {
            1.0
        } else {
            detected / counted
        }
    }
}

/// Options of one invocation.
struct Options {
    areas: Vec<&'static Area>,
    jobs: String,
    iterate: bool,
    list: bool,
    report_only: bool,
    /// Mutate only the lines changed since this git revision (`--since REV`).
    since: Option<String>,
}

fn options(args: &[String]) -> Result<Options, String> {
    let mut o = Options {
        areas: AREAS.iter().collect(),
        jobs: "2".into(),
        iterate: false,
        list: false,
        report_only: false,
        since: None,
    };
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--area" => {
                let names = it
                    .next()
                    .ok_or("--area needs names, e.g. --area rk,adaptive")?;
                o.areas = names
                    .split(',')
                    .map(|n| {
                        AREAS
                            .iter()
                            .find(|a| a.name == n)
                            .ok_or_else(|| format!("no area {n}; see --list"))
                    })
                    .collect::<Result<_, _>>()?;
            }
            "--jobs" => o.jobs = it.next().ok_or("--jobs needs a number")?.clone(),
            "--iterate" => o.iterate = true,
            "--list" => o.list = true,
            "--report" => o.report_only = true,
            "--since" => o.since = Some(it.next().ok_or("--since needs a git revision")?.clone()),
            other => return Err(format!("unknown option {other}")),
        }
    }
    Ok(o)
}

/// Runs the mutation tests and writes the report.
pub fn run(args: &[String]) -> Result<(), String> {
    let o = options(args)?;
    ensure_cargo_mutants()?;
    let root = cmd::project_root();
    let mut out = root.join("target").join("mutants");
    // A change's mutants are a run of their own: its outcomes must not replace the last full
    // run's, which the report of the whole core reads.
    if let Some(rev) = &o.since {
        out = out.join("since");
        std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
        let diff = Command::new("git")
            .args(["diff", rev, "--", "*.rs"])
            .current_dir(&root)
            .output()
            .map_err(|e| format!("git diff {rev}: {e}"))?;
        if !diff.status.success() {
            return Err(format!(
                "git diff {rev}: {}",
                String::from_utf8_lossy(&diff.stderr)
            ));
        }
        std::fs::write(out.join(SINCE_DIFF), &diff.stdout)
            .map_err(|e| format!("{SINCE_DIFF}: {e}"))?;
    }
    if o.list {
        check_accounted(&root)?;
        for area in &o.areas {
            let n = mutants_command(area, &out, &o, None)
                .output()
                .map_err(|e| format!("cargo mutants --list: {e}"))?;
            let count = String::from_utf8_lossy(&n.stdout).lines().count();
            println!("{:<16} {count:>5} mutants in {:?}", area.name, area.files);
        }
        for (file, reason) in NOT_MUTATED {
            println!("{:<16} {file}: {reason}", "(no area)");
        }
        return Ok(());
    }
    if !o.report_only {
        for area in &o.areas {
            let dir = out.join(area.name);
            std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
            let start = Instant::now();
            // cargo-mutants' own baseline runs the area's tests in the mutated package, where
            // they are not: this is the baseline instead, and must pass for the run to mean
            // anything (a mutant that fails tests that already fail is not killed by them).
            // Built first, then timed alone: the time of the tests sets the mutants' timeout.
            let baseline = |build: bool| {
                let mut c = cmd::cargo();
                area.profile(&mut c)
                    .args(["test", "--quiet", "--config", DEPENDENCIES_OPTIMISED])
                    .args(["-p", area.test_package])
                    .args(area.tests);
                if area.unit_tests {
                    c.args(["-p", area.package, "--lib"]);
                }
                if build {
                    c.arg("--no-run");
                }
                cmd::run(&mut c)
                    .map_err(|e| format!("area {}: the unmutated tests fail: {e}", area.name))
            };
            baseline(true)?;
            let tests = Instant::now();
            baseline(false)?;
            let timeout = (tests.elapsed().as_secs_f64() * TEST_TIMEOUT_FACTOR)
                .max(TEST_TIMEOUT_MIN_S)
                .ceil();
            println!("area {}: test timeout {timeout} s", area.name);
            // Before the run moves the last one's outcomes aside, its unviable mutants join the
            // ledger (a full run starts it over); after it, this run's.
            if o.iterate {
                update_ledger(&dir)?;
            } else {
                std::fs::remove_file(dir.join(UNVIABLE_LEDGER)).ok();
            }
            // A surviving mutant is a finding, not a failure of the command: the report says.
            let status = cmd::run(&mut mutants_command(area, &out, &o, Some(timeout)));
            update_ledger(&dir)?;
            println!(
                "area {}: {:.0} s ({})",
                area.name,
                start.elapsed().as_secs_f64(),
                status.err().unwrap_or_else(|| "every mutant killed".into())
            );
        }
    }
    report(&root, &out, &o.areas)
}

/// `cargo mutants` for one area, its outcomes under `out/<area>/mutants.out`, each mutant's
/// tests stopped after `timeout` seconds; with no timeout, only listing the mutants.
fn mutants_command(area: &Area, out: &Path, o: &Options, timeout: Option<f64>) -> Command {
    let mut c = cmd::cargo();
    area.profile(&mut c);
    c.args(["mutants", "--package", area.package]);
    c.arg(format!("--cargo-arg=--config={DEPENDENCIES_OPTIMISED}"));
    for f in area.files {
        c.args(["--file", f]);
    }
    if let Some(re) = area.only {
        c.args(["--re", re]);
    }
    if o.since.is_some() {
        c.arg("--in-diff").arg(out.join(SINCE_DIFF));
    }
    let Some(timeout) = timeout else {
        c.arg("--list");
        return c;
    };
    c.args(["--test-package", area.test_package, "--jobs", &o.jobs]);
    if area.unit_tests {
        c.args(["--test-package", area.package, "--cargo-arg=--lib"]);
    }
    c.args(["--timeout", &timeout.to_string()]);
    c.args(["--build-timeout", BUILD_TIMEOUT_S]);
    c.arg("--baseline=skip");
    c.args(["--cap-lints", "true", "--no-shuffle"]);
    c.arg("--output").arg(out.join(area.name));
    if o.iterate {
        c.arg("--iterate");
    }
    // As cargo arguments, not test arguments: cargo-mutants' build phase then builds only
    // the area's test binaries (with `-- --test ..` it built all sixty of lagrange-tests for
    // every mutant, most of a mutant's time).
    for a in area.tests {
        c.arg(format!("--cargo-arg={a}"));
    }
    c
}

/// Installs the pinned `cargo-mutants` when `cargo mutants` is not there.
fn ensure_cargo_mutants() -> Result<(), String> {
    let present = cmd::cargo()
        .args(["mutants", "--version"])
        .output()
        .is_ok_and(|o| {
            o.status.success() && String::from_utf8_lossy(&o.stdout).contains(CARGO_MUTANTS_VERSION)
        });
    if present {
        return Ok(());
    }
    cmd::run(cmd::cargo().args([
        "install",
        "--locked",
        &format!("{CARGO_MUTANTS}@{CARGO_MUTANTS_VERSION}"),
    ]))
}

/// One mutant as the equivalent list names it: the file, the mutation as `cargo-mutants`
/// names it without its position, and the mutated source line (trimmed), so that an entry
/// survives edits that move the line.
#[derive(Debug, PartialEq, Eq, Clone)]
struct Key {
    file: String,
    mutation: String,
    line: String,
}

impl Key {
    /// The start of this mutant's entry in the list: `file | mutation | line | `. Matched as a
    /// prefix, not split on ` | `: a mutation (`replace | with ^`) or a line may hold one.
    fn prefix(&self) -> String {
        format!("{} | {} | {} | ", self.file, self.mutation, self.line)
    }
}

/// The entries of [`EQUIVALENT_LIST`] (comments and blank lines aside), each with a reason.
fn equivalents(root: &Path) -> Result<Vec<String>, String> {
    let path = root.join(EQUIVALENT_LIST);
    let text = std::fs::read_to_string(&path).unwrap_or_default();
    let mut entries = Vec::new();
    for (n, raw) in text.lines().enumerate() {
        let entry = raw.trim();
        if entry.is_empty() || entry.starts_with('#') {
            continue;
        }
        if entry.matches(" | ").count() < 3 {
            return Err(format!(
                "{EQUIVALENT_LIST}:{}: expected `file | mutation | source line | reason`",
                n + 1
            ));
        }
        entries.push(entry.to_string());
    }
    Ok(entries)
}

/// The key of a mutant as `cargo-mutants` lists it (`file:line:col: mutation`), with the
/// source line read from `root`.
fn key_of(root: &Path, listed: &str) -> Option<Key> {
    let (file, rest) = listed.split_once(':')?;
    let (line, rest) = rest.split_once(':')?;
    let (_col, mutation) = rest.split_once(": ")?;
    let number: usize = line.parse().ok()?;
    let source = std::fs::read_to_string(root.join(file)).ok()?;
    let text = source
        .lines()
        .nth(number.checked_sub(1)?)?
        .trim()
        .to_string();
    Some(Key {
        file: file.into(),
        mutation: mutation.into(),
        line: text,
    })
}

/// Tallies the outcomes of `areas` per file, writes `out/report.md` and prints it; `Err` when a
/// file misses [`GOAL`].
fn report(root: &Path, out: &Path, areas: &[&Area]) -> Result<(), String> {
    let equivalent = equivalents(root)?;
    let mut used = vec![false; equivalent.len()];
    let mut files: BTreeMap<String, Tally> = BTreeMap::new();
    let mut survivors: Vec<String> = Vec::new();
    for area in areas {
        let dir: PathBuf = out.join(area.name).join("mutants.out");
        if !dir.exists() {
            continue;
        }
        let unviable: std::collections::BTreeSet<String> =
            read_lines(&out.join(area.name).join(UNVIABLE_LEDGER)).collect();
        for (list, outcome) in OUTCOMES {
            for listed in read_lines(&dir.join(list)) {
                let listed = listed.as_str();
                let file = listed.split(':').next().unwrap_or_default().to_string();
                let tally = files.entry(file).or_default();
                let outcome = if list == "previously_caught.txt" && unviable.contains(listed) {
                    Outcome::Unviable
                } else {
                    outcome
                };
                match outcome {
                    Outcome::Killed => tally.killed += 1,
                    Outcome::TimedOut => tally.timed_out += 1,
                    Outcome::Unviable => tally.unviable += 1,
                    Outcome::Survived => {
                        let known = key_of(root, listed).and_then(|k| {
                            let prefix = k.prefix();
                            equivalent.iter().position(|e| e.starts_with(&prefix))
                        });
                        if let Some(i) = known {
                            used[i] = true;
                            tally.equivalent += 1;
                        } else {
                            tally.survived += 1;
                            survivors.push(listed.to_string());
                        }
                    }
                }
            }
        }
    }
    let mut md = String::from(
        "# Mutation testing of the numerical core (cargo xtask mutants)\n\n\
         | file | killed | survived | timed out | unviable | equivalent | kill rate |\n\
         |---|---:|---:|---:|---:|---:|---:|\n",
    );
    let mut short = Vec::new();
    for (file, t) in &files {
        let _ = writeln!(
            md,
            "| {file} | {} | {} | {} | {} | {} | {:.1}% |",
            t.killed,
            t.survived,
            t.timed_out,
            t.unviable,
            t.equivalent,
            100.0 * t.rate()
        );
        if t.rate() < GOAL {
            short.push(format!("{file} ({:.1}%)", 100.0 * t.rate()));
        }
    }
    if !survivors.is_empty() {
        md.push_str(
            "\n## Surviving mutants (kill them with a test, or record them as equivalent)\n\n",
        );
        for s in &survivors {
            let _ = writeln!(md, "- {s}");
        }
    }
    md.push_str(&run_times(out, areas));
    let stale: Vec<&String> = equivalent
        .iter()
        .zip(&used)
        .filter(|(_, u)| !**u)
        .map(|(e, _)| e)
        .collect();
    if !stale.is_empty() {
        md.push_str("\n## Entries of the equivalent list no survivor matched this run\n\n");
        for e in stale {
            let _ = writeln!(md, "- {e}");
        }
    }
    let path = out.join("report.md");
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    std::fs::write(&path, &md).map_err(|e| format!("{}: {e}", path.display()))?;
    println!("{md}\nwritten to {}", path.display());
    if short.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "below the {:.0}% goal: {}",
            100.0 * GOAL,
            short.join(", ")
        ))
    }
}

/// The wall time of each area's last run, from cargo-mutants' own record (`start_time` and
/// `end_time` of its `outcomes.json`; the area's baseline test run before it is not
/// included), whether it was a full run or `--iterate`, and the sum of the full runs: what
/// a whole run takes.
fn run_times(out: &Path, areas: &[&Area]) -> String {
    let mut md = String::from(
        "\n## Run time of each area's last run\n\n\
         | area | mutants run | kind | wall time |\n|---|---:|---|---:|\n",
    );
    let (mut total, mut every_full) = (0.0, true);
    for area in areas {
        let dir = out.join(area.name).join("mutants.out");
        let Ok(json) = std::fs::read_to_string(dir.join("outcomes.json")) else {
            every_full = false;
            continue;
        };
        let seconds = json_time(&json, "end_time")
            .zip(json_time(&json, "start_time"))
            .map(|(end, start)| end - start);
        let iterate = dir.join("previously_caught.txt").exists();
        let run: usize = OUTCOMES
            .iter()
            .filter(|(list, _)| *list != "previously_caught.txt")
            .map(|(list, _)| read_lines(&dir.join(list)).count())
            .sum();
        let kind = if iterate { "--iterate" } else { "full" };
        let shown = seconds.map_or("-".to_string(), |s| format!("{s:.0} s"));
        let _ = writeln!(md, "| {} | {run} | {kind} | {shown} |", area.name);
        match seconds {
            Some(s) if !iterate => total += s,
            _ => every_full = false,
        }
    }
    let _ = writeln!(
        md,
        "\nFull runs: {total:.0} s ({:.2} h){}.",
        total / 3600.0,
        if every_full {
            ", every area"
        } else {
            "; some areas' last run was not a full one"
        }
    );
    md
}

/// Seconds since 1970 of the timestamp `"key": "YYYY-MM-DDTHH:MM:SS.fffZ"` in `json`.
fn json_time(json: &str, key: &str) -> Option<f64> {
    let at = json.find(&format!("\"{key}\": \""))? + key.len() + 5;
    let stamp = json.get(at..)?.split('"').next()?;
    let (date, time) = stamp.trim_end_matches('Z').split_once('T')?;
    let mut ymd = date.split('-').map(|x| x.parse::<i64>().ok());
    let (y, m, d) = (ymd.next()??, ymd.next()??, ymd.next()??);
    let mut hms = time.split(':');
    let (h, min) = (
        hms.next()?.parse::<f64>().ok()?,
        hms.next()?.parse::<f64>().ok()?,
    );
    let sec = hms.next()?.parse::<f64>().ok()?;
    // Days from 1970-01-01 to y-m-d in the proleptic Gregorian calendar (March-based years).
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let doy = (153 * ((m + 9) % 12) + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    let days = era * 146_097 + doe - 719_468;
    Some(days as f64 * 86_400.0 + h * 3_600.0 + min * 60.0 + sec)
}

#[cfg(test)]
mod tests {
    use super::{check_accounted, equivalents, json_time, key_of, sources, unaccounted};

    /// Every source file of the four library crates is in an area or in `NOT_MUTATED`, and a
    /// new file in neither is named by the check.
    #[test]
    fn every_source_file_is_accounted_for() -> Result<(), String> {
        let root = crate::cmd::project_root();
        check_accounted(&root)?;
        let mut files = sources(&root, "lagrange-integrators/src")?;
        assert!(files
            .iter()
            .any(|f| f == "lagrange-integrators/src/scene/bank.rs"));
        for c in ["lagrange-core", "lagrange-systems", "lagrange-world"] {
            files.extend(sources(&root, &format!("{c}/src"))?);
        }
        assert_eq!(unaccounted(&files), Vec::<String>::new());
        files.push("lagrange-core/src/new_law.rs".into());
        assert_eq!(
            unaccounted(&files),
            ["lagrange-core/src/new_law.rs: in no area and not in NOT_MUTATED"]
        );
        files.retain(|f| f != "lagrange-core/src/jet.rs");
        assert_eq!(unaccounted(&files).len(), 2, "{:?}", unaccounted(&files));
        Ok(())
    }

    /// An area that runs its package's unit tests does not name `--lib` itself: cargo refuses
    /// the argument twice, and the area's baseline failed before a mutant ran.
    #[test]
    fn no_area_names_lib_twice() {
        for area in super::AREAS {
            assert!(
                !(area.unit_tests && area.tests.contains(&"--lib")),
                "area {}",
                area.name
            );
        }
    }

    /// Timestamps as cargo-mutants writes them: the epoch, a leap day, and a run over midnight
    /// at the end of a year.
    #[test]
    fn timestamps_are_read_as_seconds() {
        let at = |s: &str| json_time(&format!("{{\"t\": \"{s}\"}}"), "t");
        assert_eq!(at("1970-01-01T00:00:00Z"), Some(0.0));
        assert_eq!(at("2000-03-01T00:00:00Z"), Some(951_868_800.0));
        assert_eq!(at("2024-02-29T12:00:00.5Z"), Some(1_709_208_000.5));
        let (a, b) = (at("2026-12-31T23:59:30Z"), at("2027-01-01T00:00:10.25Z"));
        assert_eq!(b.zip(a).map(|(b, a)| b - a), Some(40.25));
        assert_eq!(at("not a time"), None);
    }
    use crate::cmd::project_root;

    /// Every entry of the equivalent list names a file that holds the entry's source line.
    #[test]
    fn equivalent_entries_name_existing_lines() -> Result<(), String> {
        let root = project_root();
        for entry in equivalents(&root)? {
            let file = entry.split(" | ").next().unwrap_or_default();
            let source =
                std::fs::read_to_string(root.join(file)).map_err(|e| format!("{file}: {e}"))?;
            let held = source
                .lines()
                .any(|l| !l.trim().is_empty() && entry.contains(&format!(" | {} | ", l.trim())));
            assert!(held, "no line of {file} is the one of `{entry}`");
        }
        Ok(())
    }

    /// A mutation that holds ` | ` itself (`replace | with ^`) still finds its entry.
    #[test]
    fn a_mutation_with_a_bar_matches_its_entry() -> Result<(), String> {
        let root = project_root();
        let file = "lagrange-integrators/src/adaptive/controller.rs";
        let source = std::fs::read_to_string(root.join(file)).map_err(|e| e.to_string())?;
        let line = source
            .lines()
            .position(|l| l.contains("0x007f_ffff) | 0x3f80_0000"))
            .ok_or("the line of log2 moved")?
            + 1;
        let listed = format!("{file}:{line}:53: replace | with ^ in log2");
        let key = key_of(&root, &listed).ok_or("no key")?;
        assert_eq!(
            equivalents(&root)?
                .iter()
                .filter(|e| e.starts_with(&key.prefix()))
                .count(),
            1
        );
        Ok(())
    }
}
