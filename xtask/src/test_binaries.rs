//! `cargo test`, with its test binaries run two at a time.
//!
//! Cargo runs a workspace's test binaries one after another. Most of this workspace's hold a
//! few tests, or one long one, so a core idled through most of the runs: the tests step ran
//! its 100 binaries in 101 s with a core idle for roughly a third of it (two cores),
//! the long tests likewise. Here cargo builds them (`--no-run`, its JSON messages naming
//! each test executable), and they run [`AT_ONCE`] at a time, each as cargo would run it (in
//! its package's directory, with `CARGO_MANIFEST_DIR`), its output printed whole when it
//! ends, every failure reported at the end. The tests inside a binary still run in parallel
//! as libtest runs them.

use std::path::PathBuf;
use std::process::{Command, Output};
use std::sync::{Mutex, PoisonError};
use std::time::Instant;

use crate::cmd;

/// Test binaries running at once.
const AT_ONCE: usize = 2;

/// A test executable cargo built, and the directory of its package.
struct Binary {
    executable: PathBuf,
    package_dir: PathBuf,
}

/// Builds the test binaries of `cargo test ARGS` and runs them with `run_args` (as `cargo
/// test ARGS -- RUN_ARGS` would), [`AT_ONCE`] at a time; `Err` names every binary that
/// failed, or the build.
pub fn run(args: &[&str], run_args: &[&str]) -> Result<(), String> {
    let binaries = build(args)?;
    let queue = Mutex::new(binaries.iter());
    let failures = Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..AT_ONCE {
            scope.spawn(|| {
                // A poisoned lock still holds what it held: no binary is skipped and no
                // failure lost.
                let next = || queue.lock().unwrap_or_else(PoisonError::into_inner).next();
                while let Some(binary) = next() {
                    if let Err(e) = run_one(binary, run_args) {
                        failures
                            .lock()
                            .unwrap_or_else(PoisonError::into_inner)
                            .push(e);
                    }
                }
            });
        }
    });
    let failures = failures
        .into_inner()
        .unwrap_or_else(PoisonError::into_inner);
    if failures.is_empty() {
        Ok(())
    } else {
        Err(failures.join("\n"))
    }
}

/// `cargo test ARGS --no-run`, its diagnostics shown: the test executables it built.
fn build(args: &[&str]) -> Result<Vec<Binary>, String> {
    let mut command = cmd::cargo();
    command
        .arg("test")
        .args(args)
        .args(["--no-run", "--message-format=json-render-diagnostics"]);
    let shown = cmd::shown(&command);
    println!("$ {shown}");
    let start = Instant::now();
    let output = command
        .stderr(std::process::Stdio::inherit())
        .output()
        .map_err(|e| format!("could not start ({e}): {shown}"))?;
    println!("  ({:.0} s)", start.elapsed().as_secs_f64());
    let messages = String::from_utf8_lossy(&output.stdout);
    // Compiler errors are rendered on stderr; stdout holds only the JSON messages.
    if !output.status.success() {
        return Err(format!("failed ({}): {shown}", output.status));
    }
    Ok(messages.lines().filter_map(test_executable).collect())
}

/// The test executable a line of cargo's JSON messages names: a `compiler-artifact` built
/// in test mode with an executable (a test, a library's or binary's unit tests, a bench).
fn test_executable(line: &str) -> Option<Binary> {
    if !line.contains(r#""reason":"compiler-artifact""#) {
        return None;
    }
    // The profile's flag, not the target's (whether `cargo test` tests it by default).
    let profile = line.split(r#""profile":{"#).nth(1)?.split('}').next()?;
    if !profile.contains(r#""test":true"#) {
        return None;
    }
    let executable = string_field(line, "executable")?;
    let manifest = PathBuf::from(string_field(line, "manifest_path")?);
    Some(Binary {
        executable: PathBuf::from(executable),
        package_dir: manifest.parent()?.to_path_buf(),
    })
}

/// The value of the string field `name` of a JSON line (paths: no escapes but `\\` and
/// `\"`, which are undone).
fn string_field(line: &str, name: &str) -> Option<String> {
    let key = format!(r#""{name}":""#);
    let start = line.find(&key)? + key.len();
    let mut value = String::new();
    let mut chars = line[start..].chars();
    while let Some(c) = chars.next() {
        match c {
            '"' => return Some(value),
            '\\' => value.push(chars.next()?),
            c => value.push(c),
        }
    }
    None
}

/// Runs one test binary as cargo would and prints its output when it ends.
fn run_one(binary: &Binary, run_args: &[&str]) -> Result<(), String> {
    let mut command = Command::new(&binary.executable);
    command
        .args(run_args)
        .current_dir(&binary.package_dir)
        .env("CARGO_MANIFEST_DIR", &binary.package_dir);
    let shown = cmd::shown(&command);
    let start = Instant::now();
    let output = command.output();
    let seconds = start.elapsed().as_secs_f64();
    // One print of the whole, so that the two binaries' lines do not interleave.
    let mut text = format!("$ {shown}  ({seconds:.1} s)\n");
    if let Ok(Output { stdout, stderr, .. }) = &output {
        text.push_str(&String::from_utf8_lossy(stdout));
        text.push_str(&String::from_utf8_lossy(stderr));
    }
    print!("{text}");
    match output {
        Ok(o) if o.status.success() => Ok(()),
        Ok(o) => Err(format!("failed ({}): {shown}", o.status)),
        Err(e) => Err(format!("could not start ({e}): {shown}")),
    }
}

#[cfg(test)]
mod tests {
    /// A test artifact's line gives its executable and package directory; a library built
    /// as a dependency (no executable, not a test), a binary built to run (its target tested
    /// by default, its profile not a test's) and a line of another reason give none.
    #[test]
    fn test_executables_are_read_from_cargo_messages() -> Result<(), String> {
        let test = r#"{"reason":"compiler-artifact","package_id":"path+file:///w/tests#0.1.0","manifest_path":"/w/tests/Cargo.toml","target":{"name":"world"},"profile":{"opt_level":"0","test":true},"executable":"/w/target/debug/deps/world-1f2e","fresh":false}"#;
        let binary = super::test_executable(test).ok_or("no test executable")?;
        assert_eq!(
            binary.executable,
            std::path::Path::new("/w/target/debug/deps/world-1f2e")
        );
        assert_eq!(binary.package_dir, std::path::Path::new("/w/tests"));
        let library = r#"{"reason":"compiler-artifact","manifest_path":"/w/core/Cargo.toml","profile":{"test":false},"executable":null}"#;
        assert!(super::test_executable(library).is_none());
        let example = r#"{"reason":"compiler-artifact","manifest_path":"/w/ex/Cargo.toml","target":{"name":"ragdoll","test":true},"profile":{"test":false},"executable":"/w/target/debug/examples/ragdoll"}"#;
        assert!(super::test_executable(example).is_none());
        let finished = r#"{"reason":"build-finished","success":true}"#;
        assert!(super::test_executable(finished).is_none());
        assert_eq!(
            super::string_field(r#"{"a":"x\\y\"z"}"#, "a").as_deref(),
            Some(r#"x\y"z"#)
        );
        Ok(())
    }
}
