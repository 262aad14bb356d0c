//! Python virtual environments under `target/`, made once and then reused: SciPy for `cargo
//! xtask bench --peers`. (`lagrange-derive` makes its SymPy environment its own way, in the
//! user's cache folder.)

use std::path::{Path, PathBuf};
use std::process::Command;

/// A virtual environment: where it lives, what it holds, and how to tell that it is ready.
pub struct Venv<'a> {
    /// Its directory, under `target/`.
    pub dir: PathBuf,
    /// What `pip install` is given: packages, pinned where results depend on the version.
    pub packages: &'a [&'a str],
    /// Python code that runs without error once the packages are installed at the right
    /// versions (an import, a version assertion).
    pub probe: &'a str,
    /// What needs it, for the messages (`derive`, `--peers`).
    pub user: &'a str,
}

impl Venv<'_> {
    /// The environment's Python, after creating the environment and installing the packages
    /// when the probe fails (once: later calls find it ready).
    ///
    /// # Errors
    /// When `python3` (with `venv`) is missing, or pip or the probe fails; the message names
    /// the command and carries its stderr.
    pub fn python(&self) -> Result<PathBuf, String> {
        let python = self.dir.join("bin").join("python");
        if self.ready(&python) {
            return Ok(python);
        }
        // On stderr: `cargo xtask derive` without `--out` writes its code to stdout.
        eprintln!(
            "{}: creating {} with {}",
            self.user,
            self.dir.display(),
            self.packages.join(" ")
        );
        run_checked(
            Command::new("python3")
                .args(["-m", "venv", "--clear"])
                .arg(&self.dir),
        )
        .map_err(|e| format!("{} needs python3 with venv: {e}", self.user))?;
        run_checked(
            Command::new(&python)
                .args([
                    "-m",
                    "pip",
                    "install",
                    "--quiet",
                    "--disable-pip-version-check",
                ])
                .args(self.packages),
        )?;
        if self.ready(&python) {
            Ok(python)
        } else {
            Err(format!(
                "{}: {} is not usable after installing {}",
                self.user,
                self.dir.display(),
                self.packages.join(" ")
            ))
        }
    }

    /// Whether `python` runs the probe.
    fn ready(&self, python: &Path) -> bool {
        Command::new(python)
            .args(["-c", self.probe])
            .output()
            .is_ok_and(|o| o.status.success())
    }
}

/// Runs `cmd`, failing with its stderr.
pub fn run_checked(cmd: &mut Command) -> Result<(), String> {
    let out = cmd.output().map_err(|e| format!("{cmd:?}: {e}"))?;
    if out.status.success() {
        Ok(())
    } else {
        Err(format!(
            "{cmd:?} failed: {}",
            String::from_utf8_lossy(&out.stderr)
        ))
    }
}
