//! Running cargo and other commands: echo each, keep going on failure, report every failure.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The workspace root (the parent of this crate's manifest directory).
pub fn project_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
}

/// Whether a task's arguments ask for its short form (`--short`, `cargo xtask ci`'s); an
/// error naming the task for anything else.
pub fn short_form(task: &str, args: &[String]) -> Result<bool, String> {
    match args {
        [] => Ok(false),
        [flag] if flag == "--short" => Ok(true),
        _ => Err(format!("usage: cargo xtask {task} [--short], not {args:?}")),
    }
}

/// A child that is waited for with a limit ([`overdue`]) may take this many times the limit
/// in wall time when its CPU time cannot be read or it is blocked.
pub const WALL_FACTOR: u64 = 10;

/// Whether the process `pid`, running for `wall`, has overrun `limit`: used `limit` of CPU
/// time (user and system, from `/proc/PID/stat`), so that a loaded machine, which slows a
/// child down in wall time, cannot make it overrun; or, where that cannot be read (not
/// Linux) or the child waits without using the CPU, `WALL_FACTOR` times `limit` of wall
/// time. A limit only turns a hang into a failure.
pub fn overdue(pid: u32, wall: std::time::Duration, limit: std::time::Duration) -> bool {
    if wall.as_secs_f64() > (WALL_FACTOR as f64) * limit.as_secs_f64() {
        return true;
    }
    if wall <= limit {
        return false;
    }
    let cpu = std::fs::read_to_string(format!("/proc/{pid}/stat"))
        .ok()
        .and_then(|stat| {
            // Fields after the command name (in parentheses, which may hold spaces): utime
            // and stime are the 12th and 13th, in clock ticks of 1/100 s.
            let after = stat.get(stat.rfind(')')? + 1..)?.to_string();
            let fields: Vec<f64> = after
                .split_whitespace()
                .skip(11)
                .take(2)
                .filter_map(|f| f.parse().ok())
                .collect();
            (fields.len() == 2).then(|| (fields[0] + fields[1]) / 100.0)
        });
    cpu.is_none_or(|cpu| cpu > limit.as_secs_f64())
}

/// The cargo that runs this xtask.
pub fn cargo() -> Command {
    let mut c = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    c.current_dir(project_root());
    c
}

/// A command as [`run`] echoes it (without the quotes `Debug` puts around each word).
pub fn shown(command: &Command) -> String {
    format!("{command:?}").replace('"', "")
}

/// Echoes and runs `command`; `Err` names it when it fails or cannot start.
pub fn run(command: &mut Command) -> Result<(), String> {
    let shown = shown(command);
    println!("$ {shown}");
    let start = std::time::Instant::now();
    let status = command.status();
    // Each command's wall time, so that a CI run's log says where its minutes went.
    let seconds = start.elapsed().as_secs_f64();
    if seconds >= 1.0 {
        println!("  ({seconds:.0} s)");
    }
    match status {
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
