//! The command: a derivation written or checked, or generated files updated or checked from
//! their headers.

use crate::args::{parse, Command, Job, Mode, HELP};
use crate::output::{first_difference, may_write, relative_to_output, write_atomically};
use crate::{environment, generate, header};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Runs the command line `args` (without the program's name).
///
/// # Errors
/// Every failure, as the message to print: a refused spec, a stale file under `--check`, an
/// `--out` that may not be written, a missing Python.
pub fn run(args: &[String]) -> Result<(), String> {
    match parse(args)? {
        Command::Help => {
            print!("{HELP}");
            Ok(())
        }
        Command::Version => {
            println!("lagrange-derive {}", env!("CARGO_PKG_VERSION"));
            Ok(())
        }
        Command::Derive(job) => derive_job(&job),
        Command::Files(files, mode) => {
            let failures: Vec<String> = files
                .iter()
                .filter_map(|f| check_file(Path::new(f), mode).err())
                .collect();
            if failures.is_empty() {
                Ok(())
            } else {
                Err(failures.join("\n"))
            }
        }
    }
}

/// Regenerates (`Write`) or checks (`Check`) the generated file `path` from the spec and
/// options its header records.
///
/// # Errors
/// When the file is not lagrange-derive's, its spec is refused, or (`Check`) it differs from
/// its regeneration.
pub fn check_file(path: &Path, mode: Mode) -> Result<(), String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("error: cannot read {}: {e}", path.display()))?;
    let recorded = header::read(&text).map_err(|e| format!("error: {}: {e}", path.display()))?;
    let folder = path.parent().unwrap_or(Path::new(""));
    let spec: PathBuf = folder.join(&recorded.spec);
    derive_job(&Job {
        spec: spec.display().to_string(),
        out: Some(path.display().to_string()),
        name: recorded.name,
        tests: recorded.tests,
        force: false,
        mode,
    })
}

/// Derives one job: refuses a forbidden `--out` before any work, then writes or compares.
fn derive_job(job: &Job) -> Result<(), String> {
    let spec = Path::new(&job.spec);
    let out = job.out.as_deref().map(Path::new);
    if let Some(out) = out {
        may_write(spec, out, job.force || job.mode == Mode::Check)?;
    } else if job.mode == Mode::Check {
        return Err("error: --check with a spec needs --out FILE.rs, the file to compare".into());
    }
    if !spec.is_file() {
        return Err(format!("error: {}: no such spec file", spec.display()));
    }
    let python = environment::python()?;
    let (spec_path, file_name) = match out {
        Some(out) => (
            relative_to_output(spec, out),
            out.file_name()
                .map_or("FILE.rs".into(), |n| n.to_string_lossy().into_owned()),
        ),
        None => (job.spec.replace('\\', "/"), "FILE.rs".to_string()),
    };
    let code = generate::derive(&python, job, &spec_path, &file_name)?;
    match (out, job.mode) {
        (None, _) => std::io::stdout()
            .write_all(code.as_bytes())
            .map_err(|e| format!("error: stdout: {e}")),
        (Some(out), Mode::Write) => {
            write_atomically(out, &code)?;
            eprintln!("lagrange-derive: wrote {}", out.display());
            Ok(())
        }
        (Some(out), Mode::Check) => {
            let committed = std::fs::read_to_string(out).unwrap_or_default();
            match first_difference(&code, &committed) {
                None => {
                    eprintln!("lagrange-derive: {} is up to date", out.display());
                    Ok(())
                }
                Some(line) => Err(format!(
                    "error: {} differs from what {} gives (first at line {line}): regenerate it \
                     with `lagrange-derive --update {}`",
                    out.display(),
                    spec.display(),
                    out.display()
                )),
            }
        }
    }
}
