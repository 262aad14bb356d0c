//! One derivation: the carried script run by the environment's Python on a spec, its output
//! formatted by `rustfmt`.

use crate::args::Job;
use crate::SCRIPT;
use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};

/// The Rust file that `job`'s spec gives, formatted, run by `python` (the environment's).
///
/// `spec_path` is what the header records as the spec's path (relative to the output's
/// folder), `file_name` the output's name for the header's command.
///
/// # Errors
/// The script's message when the spec is refused (it names the problem), or why Python or
/// rustfmt could not run.
pub fn derive(
    python: &Path,
    job: &Job,
    spec_path: &str,
    file_name: &str,
) -> Result<String, String> {
    let mut c = Command::new(python);
    // `-` reads the script from stdin: nothing is written beside the environment.
    c.args([
        "-",
        &job.spec,
        "--spec-path",
        spec_path,
        "--file-name",
        file_name,
    ])
    // Python's string hashing must not vary between runs: the output is deterministic.
    .env("PYTHONHASHSEED", "0")
    .env("PYTHONDONTWRITEBYTECODE", "1")
    .env("PYTHONIOENCODING", "utf-8");
    if let Some(name) = &job.name {
        c.args(["--name", name]);
    }
    if job.tests {
        c.arg("--tests");
    }
    let out = piped(&mut c, SCRIPT, "python")?;
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        return Err(if stderr.contains("error: ") {
            stderr.trim_end().to_string()
        } else {
            format!(
                "error: the derivation failed (a bug of lagrange-derive: please report it with \
                 the spec):\n{}",
                stderr.trim_end()
            )
        });
    }
    rustfmt(&String::from_utf8_lossy(&out.stdout))
}

/// `code` formatted as `cargo fmt` formats it (edition 2021, default style).
///
/// # Errors
/// When rustfmt is missing or refuses the code.
pub fn rustfmt(code: &str) -> Result<String, String> {
    let mut c = Command::new("rustfmt");
    c.args(["--edition", "2021"]);
    let out = piped(&mut c, code, "rustfmt").map_err(|e| {
        format!(
            "{e} (lagrange-derive formats its output with rustfmt: `rustup component add rustfmt`)"
        )
    })?;
    if out.status.success() {
        Ok(String::from_utf8_lossy(&out.stdout).into_owned())
    } else {
        Err(format!(
            "error: rustfmt refused the generated code (a bug of lagrange-derive: please report \
             it with the spec):\n{}",
            String::from_utf8_lossy(&out.stderr).trim_end()
        ))
    }
}

/// Runs `c` with `input` on its stdin, collecting stdout and stderr.
fn piped(c: &mut Command, input: &str, what: &str) -> Result<std::process::Output, String> {
    let mut child = c
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("error: cannot run {what}: {e}"))?;
    let mut stdin = child
        .stdin
        .take()
        .ok_or(format!("error: {what}: no stdin"))?;
    // Written from a thread: a child that fills its stdout before reading all of stdin must
    // not block us both.
    let input = input.to_string();
    let writer = std::thread::spawn(move || stdin.write_all(input.as_bytes()));
    let out = child
        .wait_with_output()
        .map_err(|e| format!("error: {what}: {e}"))?;
    match writer.join() {
        Ok(Ok(())) => Ok(out),
        // The child stopped reading: its own message says why.
        Ok(Err(_)) if !out.status.success() => Ok(out),
        Ok(Err(e)) => Err(format!("error: {what}: {e}")),
        Err(_) => Err(format!("error: {what}: the writer thread failed")),
    }
}
