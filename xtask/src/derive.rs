//! `cargo xtask derive`: the origin's workflow as a tool. Write `T` and `V` with SymPy in a
//! spec, let SymPy derive the Euler-Lagrange equations, and get a `no_std` Rust mechanism.
//!
//! ```text
//! cargo xtask derive SPEC.py [--out FILE.rs] [--name TypeName] [--tests]
//! cargo xtask derive --check
//! ```
//!
//! The derivation is `xtask/derive/derive.py` (its docstring is the spec convention), run by
//! the pinned SymPy of a virtual environment made once under `target/lagrange-derive/venv`.
//! The output is formatted by rustfmt and written only when every step succeeded, through a
//! temporary file renamed into place, so a failure leaves no partial file. Without `--out`
//! it goes to stdout. `--tests` adds a test module that checks the type against the automatic
//! path (it needs the `lagrange-tests` crate, so it is for files inside this workspace).
//!
//! `--check` (part of `cargo xtask ci`): regenerates every committed mechanism of
//! [`GENERATED`] and compares it byte for byte with the file, then runs this command on each
//! bad spec of [`BAD_INPUT`] and checks that it fails with a non-zero status, a message naming
//! the problem, and no file written.

use crate::cmd;
use crate::venv::Venv;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// The derivation script, relative to the workspace root.
const SCRIPT: &str = "xtask/derive/derive.py";

/// SymPy and its one dependency, pinned: regeneration must give the same bytes.
const PACKAGES: [&str; 2] = ["sympy==1.14.0", "mpmath==1.3.0"];

/// The check that the environment holds the pinned versions.
const PROBE: &str = "import sympy, mpmath; \
                     assert sympy.__version__ == '1.14.0' and mpmath.__version__ == '1.3.0'";

/// The committed mechanisms: spec, generated file (both relative to the workspace root).
/// Each is generated with `--tests`.
pub const GENERATED: [(&str, &str); 6] = [
    (
        "derive/specs/pendulum.py",
        "derive/generated/src/pendulum.rs",
    ),
    (
        "derive/specs/double_pendulum.py",
        "derive/generated/src/double_pendulum.rs",
    ),
    (
        "derive/specs/spring_cart_pendulum.py",
        "derive/generated/src/spring_cart_pendulum.rs",
    ),
    (
        "derive/specs/triple_pendulum.py",
        "derive/generated/src/triple_pendulum.rs",
    ),
    (
        "derive/specs/kapitza_pendulum.py",
        "derive/generated/src/kapitza_pendulum.rs",
    ),
    (
        "derive/specs/cartesian_pendulum.py",
        "derive/generated/src/cartesian_pendulum.rs",
    ),
];

/// Specs that must be refused: the spec, and what the message must say.
pub const BAD_INPUT: [(&str, &str); 9] = [
    ("xtask/derive/bad/syntax_error.py", "syntax error"),
    ("xtask/derive/bad/unknown_symbol.py", "unknown symbol `k`"),
    (
        "xtask/derive/bad/undefined_name.py",
        "name 'k' is not defined",
    ),
    (
        "xtask/derive/bad/unknown_coordinate.py",
        "not listed in q (an unknown coordinate)",
    ),
    (
        "xtask/derive/bad/not_quadratic.py",
        "T is not quadratic in the velocities",
    ),
    (
        "xtask/derive/bad/singular_mass.py",
        "the mass matrix d2T/dq'2 is singular",
    ),
    (
        "xtask/derive/bad/unsupported_function.py",
        "unsupported function sinh",
    ),
    (
        "xtask/derive/bad/unsupported_power.py",
        "only integer and half-integer exponents",
    ),
    ("xtask/derive/bad/bad_default.py", "is not > 0 (positive)"),
];

/// One derivation: what `cargo xtask derive` was asked.
struct Job {
    spec: String,
    out: Option<String>,
    name: Option<String>,
    tests: bool,
}

impl Job {
    /// The command that makes this file, as its header shows it.
    fn command(&self) -> String {
        let mut c = format!("cargo xtask derive {}", self.spec);
        if let Some(name) = &self.name {
            c.push_str(&format!(" --name {name}"));
        }
        if self.tests {
            c.push_str(" --tests");
        }
        if let Some(out) = &self.out {
            c.push_str(&format!(" --out {out}"));
        }
        c
    }
}

/// `cargo xtask derive ARGS`.
pub fn run(args: &[String]) -> Result<(), String> {
    if args.iter().any(|a| a == "--check") {
        return check();
    }
    let job = parse(args)?;
    let python = environment()?;
    let code = generate(&python, &job, None)?;
    match &job.out {
        Some(out) => {
            write_atomically(Path::new(out), &code)?;
            println!("derive: wrote {out}");
            Ok(())
        }
        None => std::io::stdout()
            .write_all(code.as_bytes())
            .map_err(|e| e.to_string()),
    }
}

/// The job of the command line.
fn parse(args: &[String]) -> Result<Job, String> {
    let usage = "usage: cargo xtask derive SPEC.py [--out FILE.rs] [--name TypeName] [--tests]\n       cargo xtask derive --check";
    let mut job = Job {
        spec: String::new(),
        out: None,
        name: None,
        tests: false,
    };
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--out" => job.out = Some(it.next().ok_or(usage)?.clone()),
            "--name" => job.name = Some(it.next().ok_or(usage)?.clone()),
            "--tests" => job.tests = true,
            s if s.starts_with('-') || !job.spec.is_empty() => {
                return Err(format!("unexpected argument `{s}`\n{usage}"))
            }
            s => job.spec = s.to_string(),
        }
    }
    if job.spec.is_empty() {
        return Err(usage.to_string());
    }
    Ok(job)
}

/// The virtual environment's Python, with the pinned SymPy.
fn environment() -> Result<PathBuf, String> {
    Venv {
        dir: cmd::project_root().join("target/lagrange-derive/venv"),
        packages: &PACKAGES,
        probe: PROBE,
        user: "derive",
    }
    .python()
}

/// Runs the derivation of `job` (from `dir`, or the current directory) and formats it.
fn generate(python: &Path, job: &Job, dir: Option<&Path>) -> Result<String, String> {
    let script = cmd::project_root().join(SCRIPT);
    let mut c = Command::new(python);
    c.arg(&script)
        .arg(&job.spec)
        .args(["--source", &job.spec, "--command", &job.command()])
        // Python's string hashing must not vary between runs: the output is deterministic.
        .env("PYTHONHASHSEED", "0")
        .env("PYTHONDONTWRITEBYTECODE", "1");
    if let Some(name) = &job.name {
        c.args(["--name", name]);
    }
    if job.tests {
        c.arg("--tests");
    }
    if let Some(dir) = dir {
        c.current_dir(dir);
    }
    let out = c
        .output()
        .map_err(|e| format!("could not run {}: {e}", python.display()))?;
    if !out.status.success() {
        return Err(String::from_utf8_lossy(&out.stderr).trim_end().to_string());
    }
    rustfmt(&String::from_utf8_lossy(&out.stdout))
}

/// `code` formatted as `cargo fmt` would.
fn rustfmt(code: &str) -> Result<String, String> {
    let mut child = Command::new("rustfmt")
        .args(["--edition", "2021"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("could not run rustfmt: {e}"))?;
    child
        .stdin
        .take()
        .ok_or("rustfmt: no stdin")?
        .write_all(code.as_bytes())
        .map_err(|e| format!("rustfmt: {e}"))?;
    let out = child
        .wait_with_output()
        .map_err(|e| format!("rustfmt: {e}"))?;
    if out.status.success() {
        Ok(String::from_utf8_lossy(&out.stdout).into_owned())
    } else {
        Err(format!(
            "rustfmt refused the generated code (a bug of derive.py):\n{}",
            String::from_utf8_lossy(&out.stderr)
        ))
    }
}

/// Writes `code` to `path` through a temporary file beside it, renamed into place: a reader
/// sees the old file or the whole new one, never a part.
fn write_atomically(path: &Path, code: &str) -> Result<(), String> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    std::fs::write(&tmp, code).map_err(|e| format!("cannot write {}: {e}", tmp.display()))?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        format!("cannot write {}: {e}", path.display())
    })
}

/// `cargo xtask derive --check`: the committed files regenerate to the same bytes, and every
/// bad spec is refused properly. Every failure is reported.
pub fn check() -> Result<(), String> {
    println!("$ cargo xtask derive --check");
    let root = cmd::project_root();
    let python = environment()?;
    let mut failures = Vec::new();
    for (spec, file) in GENERATED {
        let job = Job {
            spec: spec.to_string(),
            out: Some(file.to_string()),
            name: None,
            tests: true,
        };
        let fresh = match generate(&python, &job, Some(&root)) {
            Ok(code) => code,
            Err(e) => {
                failures.push(e);
                continue;
            }
        };
        let committed = std::fs::read_to_string(root.join(file)).unwrap_or_default();
        if fresh == committed {
            println!("   {file}: regenerated, identical");
        } else {
            let line = fresh
                .lines()
                .zip(committed.lines())
                .position(|(a, b)| a != b)
                .unwrap_or_else(|| fresh.lines().count().min(committed.lines().count()));
            failures.push(format!(
                "{file} differs from its regeneration (first at line {}): run `{}`",
                line + 1,
                job.command()
            ));
        }
    }
    failures.extend(bad_input(&root));
    if failures.is_empty() {
        println!("derive --check: all passed");
        Ok(())
    } else {
        Err(format!("derive --check:\n{}", failures.join("\n")))
    }
}

/// Runs this very command on each bad spec; returns what went wrong.
fn bad_input(root: &Path) -> Vec<String> {
    let dir = root.join("target/lagrange-derive/bad-input");
    if let Err(e) = std::fs::create_dir_all(&dir) {
        return vec![format!("cannot create {}: {e}", dir.display())];
    }
    let exe = match std::env::current_exe() {
        Ok(exe) => exe,
        Err(e) => return vec![format!("cannot find the xtask executable: {e}")],
    };
    let mut failures = Vec::new();
    for (i, (spec, expected)) in BAD_INPUT.iter().enumerate() {
        let out = dir.join(format!("out{i}.rs"));
        // Half of the runs find a file already there, which must be left as it was.
        let before = (i % 2 == 1).then_some("// a file that a failed derivation must not touch\n");
        let _ = std::fs::remove_file(&out);
        if let Some(text) = before {
            if let Err(e) = std::fs::write(&out, text) {
                failures.push(format!("cannot write {}: {e}", out.display()));
                continue;
            }
        }
        let run = Command::new(&exe)
            .arg("derive")
            .arg(spec)
            .arg("--out")
            .arg(&out)
            .current_dir(root)
            .output();
        let run = match run {
            Ok(run) => run,
            Err(e) => {
                failures.push(format!("{spec}: could not run xtask: {e}"));
                continue;
            }
        };
        let stderr = String::from_utf8_lossy(&run.stderr);
        let after = std::fs::read_to_string(&out).ok();
        let problem = if run.status.success() {
            Some("exit status 0".to_string())
        } else if !stderr.contains(expected) {
            Some(format!("message does not say `{expected}`"))
        } else if after.as_deref() != before {
            Some(match before {
                Some(_) => "the existing file was changed".to_string(),
                None => "a file was written".to_string(),
            })
        } else {
            None
        };
        let message = stderr.lines().find(|l| l.contains("error: ")).unwrap_or("");
        match problem {
            None => println!("   {spec}: refused ({})", message.trim()),
            Some(p) => failures.push(format!("{spec}: {p}; stderr:\n{stderr}")),
        }
    }
    failures
}
