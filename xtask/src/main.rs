//! `cargo xtask`: the project's automation, in Rust so that it runs wherever cargo does.
//!
//! - `demo`: runs the examples of `examples/` (the origin's pendulum and a chaotic double
//!   pendulum with every integrator, your own mechanism, every standard mechanism, constraints,
//!   impacts, a game loop), their plots under `target/lagrange-demo/`.
//! - `test`: host tests of every crate, f32 and f64, the long runs (`#[ignore]`d) in release.
//! - `bench`: run time against error (`benches/src/work_precision`): every integrator on the
//!   standard problems, CSV, Markdown and SVG work-precision plots under
//!   `target/lagrange-bench/` (not part of `ci`). `--quick` for a smoke run. `--scene`: the
//!   cost of a scene's frame against the fraction awake and against plain loops, and the
//!   constant-mass skip (`scene.csv`, `scene.md`). `--automatic`: ns per automatic
//!   acceleration against the hand-derived and generated ones (`automatic.csv`, `automatic.md`).
//!   `--contacts`: ns per step of the contact steppers (thrown ragdoll, the same thrown
//!   sixteen other ways, double pendulum on the floor, bouncing ball) against a free RK4
//!   step and against rapier2d, with depth and energy gain (`contacts.csv`,
//!   `contacts.md`). `--world`: ns per step of
//!   `lagrange_world::World` (pyramids of boxes, a pit of 1,000 balls, piles of ragdolls awake
//!   and asleep) against rapier2d on the same scenes, with bodies awake and depth
//!   (`world.csv`, `world.md`).
//! - `cross`: builds of the library crates for the Cortex-M4F, M0+, M33 and RV32IMAC, with and
//!   without `defmt`, a linked no_std binary with no allocator, with its size, and the embassy
//!   example (`embedded/embassy-cartpole`, an nRF52840 application) linted and built.
//! - `qemu`: the firmware on emulated cores (Cortex-M4F, M33, M0, RV32IMAC, RV32IMAFC), its
//!   defmt log compared bit for bit with the host, instructions per step, stack and `.text`
//!   sizes per core and side by side, the panic-free image on each; installs QEMU and
//!   `defmt-print` when missing.
//! - `trig-fit`: derives the polynomials and constants of `lagrange_core::fast_trig` and
//!   checks the library's against them.
//! - `derive SPEC.py [--out FILE.rs] [--name TypeName] [--tests]`: the installable
//!   `lagrange-derive` command (the same code, as a library): SymPy derives the
//!   Euler-Lagrange equations of a spec's `T` and `V` and this writes a `no_std` Rust
//!   mechanism; `derive --check` regenerates the committed ones under `derive/generated/`,
//!   checks that bad specs and bad uses are refused, and builds the odd-name specs of
//!   `derive/odd/` in a scratch crate with clippy, rustfmt and their tests.
//! - `mutants`: mutation testing of the numerical core with `cargo-mutants`, a report per file
//!   under `target/mutants/` (hours; not part of `ci`).
//! - `fuzz [CALLS] [--seed S]`: the hostile-input campaign (`tests/tests/hostile`) in release,
//!   10^7 calls by default (its 10^5-call run is part of `test` and `ci`).
//! - `web`: the interactive page, the library compiled to WebAssembly (with SIMD and
//!   without, the page loading the first where the browser has it), written to
//!   `target/lagrange-web/` and served on 127.0.0.1 (`--no-serve`: build only; `--test`: drive
//!   it in headless Chromium and compare its scenario's bits, from both modules, with the
//!   host's and QEMU's).
//! - `publish`: the library crates' docs (rustdoc warnings denied) and packages, each verified
//!   against the others' packaged files.
//! - `guide [--figures]`: the user's guide (mdBook, `guide/`) built into `target/guide/`, its
//!   links checked; `--figures` makes its plots and screenshot again.
//! - `ci`: format check, clippy with `-D warnings`, the library crates' docs (warnings denied)
//!   and packages, test, `derive --check`, cross, qemu, web --test, guide.

mod cdp;
mod cmd;
mod cross;
mod demo;
mod derive;
mod fuzz;
mod guide;
mod mutants;
mod publish;
mod qemu;
mod test_binaries;
mod tools;
mod trig_fit;
mod web;

use std::process::ExitCode;

fn main() -> ExitCode {
    let task = std::env::args().nth(1).unwrap_or_default();
    let result = match task.as_str() {
        "demo" => demo::run(),
        "test" => test().and(long_test()),
        "cross" => cross::run(&std::env::args().skip(2).collect::<Vec<_>>()),
        "bench" => bench(&std::env::args().skip(2).collect::<Vec<_>>()),
        "qemu" => qemu::run(&std::env::args().skip(2).collect::<Vec<_>>()),
        "mutants" => mutants::run(&std::env::args().skip(2).collect::<Vec<_>>()),
        "derive" => derive::run(&std::env::args().skip(2).collect::<Vec<_>>()),
        "fuzz" => fuzz::run(&std::env::args().skip(2).collect::<Vec<_>>()),
        "web" => web::run(&std::env::args().skip(2).collect::<Vec<_>>()),
        "publish" => publish::run(),
        "guide" => guide::run(&std::env::args().skip(2).collect::<Vec<_>>()),
        "ci" => ci(),
        "trig-fit" => trig_fit::run(),
        _ => {
            eprintln!(
                "usage: cargo xtask <demo | test | cross | bench | qemu | derive | web | guide | mutants | fuzz | trig-fit | ci>"
            );
            return ExitCode::from(2);
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask {task} failed:\n{e}");
            ExitCode::FAILURE
        }
    }
}

/// The work-precision bench, optimised like xtask itself (it lives in `benches/` so that its
/// dependencies, `ode_solvers` among them, are not built by every `cargo xtask`).
const BENCH: [&str; 11] = [
    "run",
    "--quiet",
    "--profile",
    "xtask",
    "-p",
    "lagrange-benches",
    "--features",
    "bench-bins",
    "--bin",
    "work-precision",
    "--",
];

/// The scene bench (`--scene`), run like the work-precision bench.
const SCENE_BENCH: [&str; 11] = [
    "run",
    "--quiet",
    "--profile",
    "xtask",
    "-p",
    "lagrange-benches",
    "--features",
    "bench-bins",
    "--bin",
    "scene-cost",
    "--",
];

/// The automatic-path bench (`--automatic`), run like the work-precision bench.
const AUTOMATIC_BENCH: [&str; 11] = [
    "run",
    "--quiet",
    "--profile",
    "xtask",
    "-p",
    "lagrange-benches",
    "--features",
    "bench-bins",
    "--bin",
    "automatic-cost",
    "--",
];

/// The contacts bench (`--contacts`): a `[[bench]]` target, so that its peer (rapier2d) is a
/// dev-dependency of `lagrange-benches` only; `cargo bench` builds it in the bench profile
/// (release).
const CONTACTS_BENCH: [&str; 7] = [
    "bench",
    "--quiet",
    "-p",
    "lagrange-benches",
    "--bench",
    "contacts",
    "--",
];

/// The world bench (`--world`): a `[[bench]]` target as the contacts bench, for the same
/// reason (rapier2d is its peer).
const WORLD_BENCH: [&str; 7] = [
    "bench",
    "--quiet",
    "-p",
    "lagrange-benches",
    "--bench",
    "world",
    "--",
];

/// `cargo xtask bench [--scene | --automatic | --contacts | --world] ...`: the
/// work-precision bench, or with `--scene` the scene bench, with `--automatic` the
/// automatic-path bench, with `--contacts` the contacts bench, with `--world` the world
/// bench, with the other flags passed on.
fn bench(args: &[String]) -> Result<(), String> {
    let which: &[&str] = if args.iter().any(|a| a == "--scene") {
        &SCENE_BENCH
    } else if args.iter().any(|a| a == "--automatic") {
        &AUTOMATIC_BENCH
    } else if args.iter().any(|a| a == "--contacts") {
        &CONTACTS_BENCH
    } else if args.iter().any(|a| a == "--world") {
        &WORLD_BENCH
    } else {
        &BENCH
    };
    cmd::run(cmd::cargo().args(which).args(args))
}

/// Host tests of the whole workspace: unit, integration and doc tests, f32 and f64 alike. One
/// command: the page's tests run apart (`-p lagrange-web`) unified their dependencies'
/// features otherwise, and built them, and the page again for the doc tests, once more (the
/// tests and doc tests steps took 1 min longer loaded). Every target but the benches: the
/// criterion bench's run in test mode (each benchmark once) built it and the peers that are
/// dev-dependencies of the bench crate (rapier2d and its own nalgebra: 40 s of a core, a
/// tenth of the step's build) to check what the checks' clippy already compiles. `--tests`
/// rather than `--lib --bins --tests`: it keeps to the targets whose `test` flag is set (the
/// page's and the bench crate's libraries have none to run), which `--lib` would build.
const TEST: [&str; 4] = ["--workspace", "--tests", "--examples", "--quiet"];

/// `cargo test` of [`TEST`], its binaries run two at a time ([`test_binaries`]).
fn test() -> Result<(), String> {
    test_binaries::run(&TEST, &["--quiet"])
}

/// Static checks run before the tests. The benches behind `bench --contacts` and `bench
/// --world` are `bench = false` (a plain `cargo bench` runs only the criterion ones), and the
/// bench binaries need the feature `bench-bins` (so that the tests do not build them), which
/// `--all-targets` leaves out: they are named.
const CHECKS: [&[&str]; 3] = [
    &["fmt", "--all", "--", "--check"],
    &[
        "clippy",
        "--workspace",
        "--all-targets",
        "--quiet",
        "--",
        "-D",
        "warnings",
    ],
    &[
        "clippy",
        "-p",
        "lagrange-benches",
        "--features",
        "bench-bins",
        "--bins",
        "--bench",
        "contacts",
        "--bench",
        "world",
        "--quiet",
        "--",
        "-D",
        "warnings",
    ],
];

/// Doc tests are not part of `--tests`. The whole workspace, as the tests: a package's doc
/// tests build its dev-dependencies (the bench crate's peers, 24 s here once the tests step
/// no longer built them), but leaving the bench crate out unified its dependencies' features
/// otherwise (ode_solvers' nalgebra) and built every crate again (109 s loaded).
const DOC_TEST: [&[&str]; 1] = [&["test", "--workspace", "--doc", "--quiet"]];

/// Long runs (10^6 steps and more) are `#[ignore]`d in the quick debug test run and run here,
/// optimised (profile `long-test`: the release build without its link-time optimisation and
/// in parallel codegen units, since each of the dozen test binaries is built for one run of a
/// few seconds; the bits are the same, IEEE-754 operations only). They live in the `tests`
/// crate (so the bench crate's heavy dependencies are not built optimised for them) and, for
/// `fast_trig`'s exhaustive sweep, in `lagrange-core`'s own tests; only the test targets that
/// hold an `#[ignore]`d test are built optimised (found by reading the test directories), not
/// all seventy. One build of both packages' targets, their binaries run two at a time.
fn long_test() -> Result<(), String> {
    let mut args: Vec<String> = ["--profile", "long-test", "--quiet"]
        .map(String::from)
        .to_vec();
    for (package, dir) in LONG_TEST_DIRS {
        args.extend(["-p".to_string(), package.to_string()]);
        for target in targets_with_ignored(&cmd::project_root().join(dir))? {
            args.extend(["--test".to_string(), target]);
        }
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    test_binaries::run(&args, &["--quiet", "--ignored"])
}

/// The packages whose integration tests hold long runs, and their test directories.
const LONG_TEST_DIRS: [(&str, &str); 2] = [
    ("lagrange-tests", "tests/tests"),
    ("lagrange-core", "lagrange-core/tests"),
];

/// The test targets of `dir` (a file `NAME.rs`, or a directory `NAME/` with its `main.rs` and
/// modules) with a line that starts with `#[ignore` (an attribute, not a comment), sorted.
fn targets_with_ignored(dir: &std::path::Path) -> Result<Vec<String>, String> {
    let read = |p: &std::path::Path| std::fs::read_to_string(p).unwrap_or_default();
    let mut targets = Vec::new();
    let entries = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    for entry in entries.flatten() {
        let path = entry.path();
        let (name, sources) = if path.is_dir() {
            let files = std::fs::read_dir(&path)
                .map_err(|e| format!("{}: {e}", path.display()))?
                .flatten()
                .map(|f| f.path())
                .filter(|f| f.extension().is_some_and(|x| x == "rs"))
                .collect::<Vec<_>>();
            (entry.file_name(), files)
        } else if path.extension().is_some_and(|x| x == "rs") {
            (path.file_stem().unwrap_or_default().to_owned(), vec![path])
        } else {
            continue;
        };
        let ignores = |f: &std::path::PathBuf| {
            read(f)
                .lines()
                .any(|l| l.trim_start().starts_with("#[ignore"))
        };
        if sources.iter().any(ignores) {
            targets.push(name.to_string_lossy().into_owned());
        }
    }
    targets.sort();
    Ok(targets)
}

/// A step of CI: what it is called in the log, whether it needs the tools [`ci`] installs
/// in the background, and what it runs.
type Step<'a> = (&'a str, bool, &'a dyn Fn() -> Result<(), String>);

/// The Debian packages of CI's steps: the Arm cores' emulator (`qemu --short`) and the
/// browser (`web`).
static CI_PACKAGES: [tools::AptTool; 2] = [qemu::QEMU_ARM, web::CHROMIUM];

/// The crates.io tools of CI's steps: the firmware log's decoder (`qemu`) and mdBook
/// (`guide`).
static CI_CRATES: [&tools::CargoTool; 2] = [&qemu::DEFMT_PRINT, &guide::MDBOOK];

/// Everything CI checks; every step runs and every failure is reported at the end, with
/// each step's wall time (CI's budget is 20 minutes on an idle 2-core machine). The tools
/// the later steps need are installed in the background from the start
/// ([`tools::prefetch`]); the first step that needs one waits for them.
fn ci() -> Result<(), String> {
    let mut prefetch = Some(tools::prefetch(&CI_PACKAGES, &CI_CRATES));
    let steps: [Step; 10] = [
        ("checks", false, &|| cmd::run_all(&CHECKS)),
        ("publish", false, &publish::run),
        ("tests", false, &test),
        ("doc tests", false, &|| cmd::run_all(&DOC_TEST)),
        ("long tests", false, &long_test),
        ("derive", false, &derive::check),
        ("cross", false, &|| cross::run(&["--short".to_string()])),
        ("qemu", true, &|| qemu::run(&["--short".to_string()])),
        ("web", true, &|| web::run(&["--test".to_string()])),
        ("guide", true, &|| guide::run(&[])),
    ];
    let mut failures = Vec::new();
    let mut times = Vec::new();
    for (name, needs_tools, step) in steps {
        let start = std::time::Instant::now();
        if needs_tools {
            // A failed install is only reported: the step installs what is still missing.
            match prefetch.take().map(std::thread::JoinHandle::join) {
                Some(Ok(Ok(done))) => println!("xtask ci: tools in the background: {done}"),
                Some(Ok(Err(e))) => println!("xtask ci: tools in the background: {e}"),
                Some(Err(_)) => println!("xtask ci: the tools' thread panicked"),
                None => {}
            }
        }
        if let Err(e) = step() {
            failures.push(e);
        }
        times.push(format!("{name} {:.0} s", start.elapsed().as_secs_f64()));
    }
    println!("xtask ci: {}", times.join(", "));
    if failures.is_empty() {
        println!("xtask ci: all steps passed");
        Ok(())
    } else {
        Err(failures.join("\n"))
    }
}

#[cfg(test)]
mod tests {
    /// The long runs are found where they are: the stress suite (a directory target) and the
    /// files with an `#[ignore]`d test, not the campaign, whose `ignore` is only a word.
    #[test]
    fn long_runs_are_found() -> Result<(), String> {
        let root = crate::cmd::project_root();
        let core = super::targets_with_ignored(&root.join("lagrange-core/tests"))?;
        assert_eq!(core, ["fast_trig"]);
        let targets = super::targets_with_ignored(&root.join("tests/tests"))?;
        for expected in ["stress", "long_run_energy"] {
            assert!(
                targets.iter().any(|t| t == expected),
                "{expected} in {targets:?}"
            );
        }
        assert!(
            !targets.iter().any(|t| t == "hostile" || t == "lanes"),
            "{targets:?}"
        );
        Ok(())
    }
}
