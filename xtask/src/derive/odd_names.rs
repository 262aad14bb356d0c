//! The odd-name specs of `derive/odd/` (the paper's names `M`, `s`, Greek letters, a time
//! `t` with assumptions, Rust and Python keywords, the generated code's own names, runs of
//! underscores, long and short names, many parameters, docs that Markdown could misread)
//! derived as a user derives them: by the command installed with `cargo install --path
//! lagrange-derive`, run in a scratch crate outside the workspace that depends on
//! `lagrange-core` alone (and on `lagrange-integrators` for its own test, which steps each
//! with RK4 in `f32` and `f64`). It must pass `cargo clippy --all-targets -- -D warnings`,
//! `cargo fmt --check` and its tests (the generated ones against the automatic path); the
//! files must check as up to date from another folder, named by their paths alone.

use crate::cmd;
use std::path::Path;

/// The specs (relative to the workspace root), their type names and dimensions.
const SPECS: [(&str, &str, usize); 4] = [
    ("derive/odd/wedge.py", "Wedge", 2),
    ("derive/odd/odd_names.py", "OddNames", 2),
    ("derive/odd/driven.py", "Driven", 1),
    ("derive/odd/keywords.py", "Keywords", 2),
];

/// Derives the specs into the scratch crate and checks it; returns what went wrong.
pub fn check(root: &Path) -> Vec<String> {
    match build(root) {
        Ok(()) => Vec::new(),
        Err(e) => vec![format!("odd names: {e}")],
    }
}

/// The whole check, stopping at the first failure (each step needs the one before).
fn build(root: &Path) -> Result<(), String> {
    let krate = root.join("target/lagrange-derive/odd-names");
    let _ = std::fs::remove_dir_all(&krate);
    let src = krate.join("src");
    std::fs::create_dir_all(krate.join("tests")).map_err(|e| e.to_string())?;
    std::fs::create_dir_all(&src).map_err(|e| e.to_string())?;
    write(&krate.join("Cargo.toml"), &manifest(root))?;
    write(&src.join("lib.rs"), &lib())?;
    write(&krate.join("tests/step.rs"), &step_test())?;
    // The command as a user gets it: installed by `cargo install --path`, run in their crate.
    let install = root.join("target/lagrange-derive/install");
    cmd::run(
        cmd::cargo()
            .args([
                "install",
                "--quiet",
                "--force",
                "--path",
                "lagrange-derive",
                "--root",
            ])
            .arg(&install)
            .arg("--target-dir")
            .arg(root.join("target")),
    )?;
    let installed = install
        .join("bin")
        .join(format!("lagrange-derive{}", std::env::consts::EXE_SUFFIX));
    for (spec, _, _) in SPECS {
        let out = format!("src/{}", module(spec));
        let started = std::time::Instant::now();
        let mut derive = std::process::Command::new(&installed);
        derive
            .arg(root.join(spec))
            .args(["--tests", "--out", &out])
            .current_dir(&krate);
        cmd::run(&mut derive)?;
        println!(
            "   {spec}: derived in {:.1} s",
            started.elapsed().as_secs_f64()
        );
    }
    // The header's spec path is relative to the file: the command, run from another folder
    // with the files' paths alone, finds every spec and finds every file up to date.
    let exe = std::env::current_exe().map_err(|e| format!("cannot find xtask: {e}"))?;
    let mut from_elsewhere = std::process::Command::new(exe);
    from_elsewhere
        .args(["derive", "--check"])
        .args(SPECS.iter().map(|(spec, _, _)| src.join(module(spec))))
        .current_dir(std::env::temp_dir());
    cmd::run(&mut from_elsewhere)?;
    let target = root.join("target");
    let cargo = |args: &[&str]| {
        let mut c = cmd::cargo();
        c.current_dir(&krate)
            .env("CARGO_TARGET_DIR", &target)
            .args(args);
        cmd::run(&mut c)
    };
    cargo(&["fmt", "--check"])?;
    cargo(&["clippy", "--quiet", "--all-targets", "--", "-D", "warnings"])?;
    cargo(&["test", "--quiet"])
}

/// The module file of a spec: its file stem.
fn module(spec: &str) -> String {
    let stem = Path::new(spec)
        .file_stem()
        .map_or("spec".into(), |s| s.to_string_lossy().into_owned());
    format!("{stem}.rs")
}

/// Writes `text` to `path`.
fn write(path: &Path, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// The scratch crate's manifest: a workspace of its own, lagrange-core and (for its test)
/// lagrange-integrators by path, lints as strict as a careful user's.
fn manifest(root: &Path) -> String {
    let path = |c: &str| root.join(c).display().to_string().replace('\\', "/");
    format!(
        "[package]\nname = \"odd-names\"\nversion = \"0.0.0\"\nedition = \"2021\"\npublish = false\n\n\
         [dependencies]\nlagrange-core = {{ path = \"{}\" }}\n\n\
         [dev-dependencies]\nlagrange-integrators = {{ path = \"{}\" }}\n\n\
         [lints.rust]\nmissing_docs = \"warn\"\n\n[workspace]\n",
        path("lagrange-core"),
        path("lagrange-integrators")
    )
}

/// The scratch crate's `lib.rs`: no_std, one module per spec.
fn lib() -> String {
    let mut s = String::from(
        "//! Mechanisms derived by lagrange-derive from odd-name specs.\n\n#![no_std]\n\n",
    );
    for (spec, name, _) in SPECS {
        let m = module(spec);
        let m = m.trim_end_matches(".rs");
        s.push_str(&format!("mod {m};\npub use {m}::{name};\n"));
    }
    s
}

/// The scratch crate's own test: each mechanism stepped by RK4 in `f32` and `f64` from its
/// default parameters, ending finite.
fn step_test() -> String {
    let mut s = String::from(
        "//! Each derived mechanism stepped by RK4 in f32 and f64.\n\n\
         use lagrange_core::State;\n\
         use lagrange_integrators::{Integrator, Rk4};\n",
    );
    for (_, name, n) in SPECS {
        for t in ["f32", "f64"] {
            let q = vec!["0.3"; n].join(", ");
            let qd = vec!["0.1"; n].join(", ");
            s.push_str(&format!(
                "\n#[test]\nfn {snake}_{t}() -> Result<(), lagrange_core::Error> {{\n    \
                 let m = odd_names::{name}::<{t}>::default();\n    \
                 let start = State::new(0.0, [{q}], [{qd}]);\n    \
                 let end = Rk4.integrate(&m, &start, 1e-4, 2_000)?;\n    \
                 assert!(end.q.iter().chain(end.qd.iter()).all(|x| x.is_finite()));\n    \
                 assert!((end.t - 0.2).abs() < 1e-3);\n    \
                 Ok(())\n}}\n",
                snake = snake(name)
            ));
        }
    }
    s
}

/// `CamelCase` as `snake_case`.
fn snake(name: &str) -> String {
    let mut s = String::new();
    for (i, c) in name.chars().enumerate() {
        if c.is_uppercase() && i > 0 {
            s.push('_');
        }
        s.push(c.to_ascii_lowercase());
    }
    s
}
