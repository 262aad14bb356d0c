//! Tools from crates.io that a task needs on the machine: found on `PATH` or in cargo's bin
//! directory, else installed once, pinned, with their lock files.

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::cmd;
use crate::qemu::works;

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
        cmd::run(
            cmd::cargo()
                .args(["install", "--locked", "--version", self.version])
                .args(self.install_args)
                .arg(self.name),
        )?;
        println!(
            "{} installed in {:.0} s",
            self.name,
            clock.elapsed().as_secs_f64()
        );
        self.find()
            .ok_or_else(|| format!("{} was installed but does not run", self.name))
    }
}

/// Cargo's bin directory: `$CARGO_HOME/bin`, else `~/.cargo/bin`.
fn cargo_bin_dir() -> Option<PathBuf> {
    std::env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|home| Path::new(&home).join(".cargo")))
        .map(|home| home.join("bin"))
}
