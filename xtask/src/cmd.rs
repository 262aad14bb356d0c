//! Running cargo and other commands: echo each, keep going on failure, report every failure.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The workspace root (the parent of this crate's manifest directory).
pub fn project_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
}

/// The cargo that runs this xtask.
pub fn cargo() -> Command {
    let mut c = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    c.current_dir(project_root());
    c
}

/// Echoes and runs `command`; `Err` names it when it fails or cannot start.
pub fn run(command: &mut Command) -> Result<(), String> {
    let shown = format!("{command:?}").replace('"', "");
    println!("$ {shown}");
    match command.status() {
        Ok(s) if s.success() => Ok(()),
        Ok(s) => Err(format!("failed ({s}): {shown}")),
        Err(e) => Err(format!("could not start ({e}): {shown}")),
    }
}

/// Runs `cargo ARGS` for each entry, all of them, and reports every failure together.
pub fn run_all(steps: &[&[&str]]) -> Result<(), String> {
    let failures: Vec<String> = steps
        .iter()
        .filter_map(|args| run(cargo().args(*args)).err())
        .collect();
    if failures.is_empty() {
        Ok(())
    } else {
        Err(failures.join("\n"))
    }
}
