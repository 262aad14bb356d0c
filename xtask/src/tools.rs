//! Tools a task needs on the machine: command-line tools from crates.io ([`CargoTool`],
//! found on `PATH` or in cargo's bin directory, else installed once, pinned, with their lock
//! files) and Debian packages ([`AptTool`], installed by `apt-get`); and [`prefetch`], which
//! installs the missing ones in the background while `cargo xtask ci`'s first steps build.

use std::fs::File;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::thread::JoinHandle;
use std::time::Instant;

use crate::cmd;

/// A command-line tool installed by `cargo install`.
pub struct CargoTool {
    /// Its crate and binary name.
    pub name: &'static str,
    /// The pinned version.
    pub version: &'static str,
    /// Further `cargo install` arguments (features; `--debug` where speed does not matter).
    pub install_args: &'static [&'static str],
}

impl CargoTool {
    /// The tool's path: on `PATH`, else in cargo's bin directory, else `None`.
    pub fn find(&self) -> Option<PathBuf> {
        let on_path = PathBuf::from(self.name);
        if works(&on_path, &["--version"]) {
            return Some(on_path);
        }
        cargo_bin_dir()
            .map(|dir| dir.join(self.name))
            .filter(|path| works(path, &["--version"]))
    }

    /// The tool's path, installing it first when it is missing.
    pub fn ensure(&self) -> Result<PathBuf, String> {
        if let Some(path) = self.find() {
            return Ok(path);
        }
        println!("{} is missing: installing it from crates.io", self.name);
        let clock = Instant::now();
        cmd::run(&mut self.install())?;
        println!(
            "{} installed in {:.0} s",
            self.name,
            clock.elapsed().as_secs_f64()
        );
        self.find()
            .ok_or_else(|| format!("{} was installed but does not run", self.name))
    }

    /// The `cargo install` command.
    fn install(&self) -> Command {
        let mut c = cmd::cargo();
        c.args(["install", "--locked", "--version", self.version])
            .args(self.install_args)
            .arg(self.name);
        c
    }
}

/// A program from a Debian package, installed by `apt-get` (as root) when it does not run.
pub struct AptTool {
    /// The program, run with `--version` to tell that it is there.
    pub program: &'static str,
    /// The package it is in.
    pub package: &'static str,
}

impl AptTool {
    /// Whether the program runs.
    pub fn present(&self) -> bool {
        works(Path::new(self.program), &["--version"])
    }

    /// Installs the package when the program does not run.
    pub fn ensure(&self) -> Result<(), String> {
        if self.present() {
            return Ok(());
        }
        println!(
            "{} is missing: installing Debian's package {}",
            self.program, self.package
        );
        let clock = Instant::now();
        for mut command in apt_install(&[self.package]) {
            cmd::run(&mut command)?;
        }
        if self.present() {
            println!(
                "{} installed in {:.0} s",
                self.program,
                clock.elapsed().as_secs_f64()
            );
            Ok(())
        } else {
            Err(format!(
                "{} still does not run after apt-get install",
                self.program
            ))
        }
    }
}

/// `apt-get update`, then `apt-get install` of `packages` (quiet, no recommends).
fn apt_install(packages: &[&str]) -> [Command; 2] {
    let mut update = Command::new("apt-get");
    update.args(["update", "-qq"]);
    let mut install = Command::new("apt-get");
    install
        .env("DEBIAN_FRONTEND", "noninteractive")
        .args(["install", "-y", "-qq", "--no-install-recommends"])
        .args(packages);
    [update, install]
}

/// Installs, on a thread of its own, the tools of `apt` and `cargo` that are missing: the
/// packages in one `apt-get` run, then the crates one after another, their output in
/// `target/xtask-tools.log` (a step's own output is not interleaved with theirs). A failure
/// (no root for `apt-get`, no network) stops its own install alone; the thread's result
/// says what it did, or what failed and where the log is. The tasks that need a tool still
/// `ensure` it, and install it themselves where this failed.
///
/// Why: on a fresh machine the installs took 105 s of a CI run's 1,219 (`defmt-print` 40 s
/// and mdBook 36 s to build, QEMU and Chromium 29 s to fetch), one after another, each
/// where its step began; in the background they overlap the tests' runs, which leave a core
/// idle for much of their time.
pub fn prefetch(
    apt: &'static [AptTool],
    cargo: &'static [&'static CargoTool],
) -> JoinHandle<Result<String, String>> {
    std::thread::spawn(move || {
        let clock = Instant::now();
        let log_path = cmd::project_root().join("target").join("xtask-tools.log");
        let packages: Vec<&str> = apt
            .iter()
            .filter(|t| !t.present())
            .map(|t| t.package)
            .collect();
        let crates: Vec<&CargoTool> = cargo
            .iter()
            .copied()
            .filter(|t| t.find().is_none())
            .collect();
        if packages.is_empty() && crates.is_empty() {
            return Ok("every tool was there".into());
        }
        if let Some(dir) = log_path.parent() {
            std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        let log = File::create(&log_path).map_err(|e| format!("{}: {e}", log_path.display()))?;
        // The packages' commands in order (no install without the update), each crate on
        // its own: a failure stops its group only.
        let mut groups: Vec<Vec<Command>> = Vec::new();
        if !packages.is_empty() {
            groups.push(apt_install(&packages).into());
        }
        groups.extend(crates.iter().map(|t| vec![t.install()]));
        let mut failures = Vec::new();
        for group in groups {
            for mut command in group {
                let shown = cmd::shown(&command);
                let (out, err) = (clone(&log, &log_path)?, clone(&log, &log_path)?);
                let failed = match command
                    .stdin(Stdio::null())
                    .stdout(out)
                    .stderr(err)
                    .status()
                {
                    Ok(status) if status.success() => None,
                    Ok(status) => Some(format!("failed ({status}): {shown}")),
                    Err(e) => Some(format!("could not start ({e}): {shown}")),
                };
                if let Some(failure) = failed {
                    failures.push(failure);
                    break;
                }
            }
        }
        if !failures.is_empty() {
            return Err(format!(
                "{}; the output is in {}",
                failures.join("; "),
                log_path.display()
            ));
        }
        let names: Vec<&str> = packages
            .iter()
            .copied()
            .chain(crates.iter().map(|t| t.name))
            .collect();
        Ok(format!(
            "installed {} in {:.0} s",
            names.join(", "),
            clock.elapsed().as_secs_f64()
        ))
    })
}

/// Another handle to `log`, for a child's output.
fn clone(log: &File, path: &Path) -> Result<File, String> {
    log.try_clone()
        .map_err(|e| format!("{}: {e}", path.display()))
}

/// Runs `program` with `args` quietly; `true` when it starts and succeeds.
pub fn works(program: &Path, args: &[&str]) -> bool {
    Command::new(program)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Cargo's bin directory: `$CARGO_HOME/bin`, else `~/.cargo/bin`.
fn cargo_bin_dir() -> Option<PathBuf> {
    std::env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|home| Path::new(&home).join(".cargo")))
        .map(|home| home.join("bin"))
}

#[cfg(test)]
mod tests {
    use super::{prefetch, AptTool, CargoTool};

    /// Tools that run already are not installed again: no `apt-get` (here it would fail on
    /// a package that does not exist), no `cargo install`.
    #[test]
    fn tools_that_run_are_left_alone() -> Result<(), String> {
        static THERE: [AptTool; 1] = [AptTool {
            program: "cargo",
            package: "no-such-package-here",
        }];
        static NONE: [&CargoTool; 0] = [];
        let done = prefetch(&THERE, &NONE)
            .join()
            .map_err(|_| "the thread panicked".to_string())??;
        assert_eq!(done, "every tool was there");
        Ok(())
    }
}
