//! The Python that runs the derivation: a virtual environment with the pinned SymPy, made once
//! in the user's cache folder with the `python3` found on the `PATH`, then reused.
//!
//! - Where: `$LAGRANGE_DERIVE_CACHE`, else the platform's cache folder (`$XDG_CACHE_HOME` or
//!   `~/.cache` on Linux, `~/Library/Caches` on macOS, `%LOCALAPPDATA%` on Windows) joined with
//!   `lagrange-derive`; in it, one folder per set of pins.
//! - With what: `$LAGRANGE_DERIVE_PYTHON`, else `python3`, else `python`, of version 3.9 or
//!   newer (SymPy 1.14's minimum).
//! - How: the environment is made and filled in a folder of its own, then renamed into place,
//!   so that a run that stops half-way, or two runs at once, never leave a broken one.

use crate::PACKAGES;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Python code that succeeds only in an environment with the pinned versions.
const PROBE: &str = "import sympy, mpmath; \
                     assert sympy.__version__ == '1.14.0' and mpmath.__version__ == '1.3.0'";

/// The environment's folder: the cache folder, then one folder per set of pins.
///
/// # Errors
/// When no cache folder is known (no `HOME`, `XDG_CACHE_HOME`, `LOCALAPPDATA` or
/// `LAGRANGE_DERIVE_CACHE`).
pub fn folder() -> Result<PathBuf, String> {
    let var = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    let root = if let Some(dir) = var("LAGRANGE_DERIVE_CACHE") {
        dir
    } else {
        let base = if cfg!(windows) {
            var("LOCALAPPDATA")
        } else if cfg!(target_os = "macos") {
            var("HOME").map(|h| h.join("Library").join("Caches"))
        } else {
            var("XDG_CACHE_HOME")
                .filter(|p| p.is_absolute())
                .or_else(|| var("HOME").map(|h| h.join(".cache")))
        };
        base.ok_or(
            "error: lagrange-derive has no cache folder for its Python environment (HOME is not set): \
             set LAGRANGE_DERIVE_CACHE to a folder",
        )?
        .join("lagrange-derive")
    };
    Ok(root.join(PACKAGES.join("-").replace("==", "-")))
}

/// The environment's Python, after making the environment when it is missing or broken.
///
/// # Errors
/// When no Python 3.9+ is found, `venv` fails, or pip cannot install the packages: the
/// message says which, and what to do.
pub fn python() -> Result<PathBuf, String> {
    let dir = folder()?;
    let python = interpreter(&dir);
    if ready(&python) {
        return Ok(python);
    }
    let base = base_python()?;
    if let Some(parent) = dir.parent() {
        std::fs::create_dir_all(parent)
            .map_err(|e| format!("error: cannot create {}: {e}", parent.display()))?;
    }
    let mut fresh = dir.clone().into_os_string();
    fresh.push(format!(".making-{}", std::process::id()));
    let fresh = PathBuf::from(fresh);
    let made = make(&base, &fresh);
    if let Err(e) = made {
        let _ = std::fs::remove_dir_all(&fresh);
        return Err(e);
    }
    // Another run may have finished first: then its environment is used and ours dropped;
    // a broken one (a run stopped half-way before this scheme) is replaced.
    if !ready(&python) {
        let _ = std::fs::remove_dir_all(&dir);
        let _ = std::fs::rename(&fresh, &dir);
    }
    let _ = std::fs::remove_dir_all(&fresh);
    if ready(&python) {
        Ok(python)
    } else {
        Err(format!(
            "error: {} is not usable after installing {}: remove it and run again",
            dir.display(),
            PACKAGES.join(" ")
        ))
    }
}

/// Makes the environment in `dir` with `base` and installs the packages.
fn make(base: &Path, dir: &Path) -> Result<(), String> {
    eprintln!(
        "lagrange-derive: making its Python environment (once): {} with {}",
        dir.display(),
        PACKAGES.join(" ")
    );
    let venv = Command::new(base)
        .args(["-m", "venv", "--clear"])
        .arg(dir)
        .output()
        .map_err(|e| format!("error: cannot run {}: {e}", base.display()))?;
    if !venv.status.success() {
        return Err(format!(
            "error: `{} -m venv` failed (on Debian and Ubuntu, install python3-venv):\n{}",
            base.display(),
            String::from_utf8_lossy(&venv.stderr).trim_end()
        ));
    }
    // The environment is renamed afterwards: pip runs as a module, never by its script, whose
    // first line names the folder it was made in.
    let pip = Command::new(interpreter(dir))
        .args([
            "-m",
            "pip",
            "install",
            "--quiet",
            "--disable-pip-version-check",
        ])
        .args(PACKAGES)
        .output()
        .map_err(|e| format!("error: cannot run pip: {e}"))?;
    if !pip.status.success() || !ready(&interpreter(dir)) {
        return Err(format!(
            "error: pip could not install {} (it needs them once: network access to \
             PyPI, or PIP_INDEX_URL / PIP_FIND_LINKS for a mirror or a folder of wheels):\n{}",
            PACKAGES.join(" "),
            String::from_utf8_lossy(&pip.stderr).trim_end()
        ));
    }
    Ok(())
}

/// The Python of the environment in `dir`.
fn interpreter(dir: &Path) -> PathBuf {
    if cfg!(windows) {
        dir.join("Scripts").join("python.exe")
    } else {
        dir.join("bin").join("python")
    }
}

/// Whether `python` runs the probe.
fn ready(python: &Path) -> bool {
    python.exists()
        && Command::new(python)
            .args(["-c", PROBE])
            .output()
            .is_ok_and(|o| o.status.success())
}

/// The Python that makes the environment: the first of `$LAGRANGE_DERIVE_PYTHON`, `python3`
/// and `python` that is Python 3.9 or newer.
fn base_python() -> Result<PathBuf, String> {
    let chosen = std::env::var_os("LAGRANGE_DERIVE_PYTHON").filter(|v| !v.is_empty());
    let candidates: Vec<PathBuf> = match &chosen {
        Some(p) => vec![PathBuf::from(p)],
        None => vec!["python3".into(), "python".into()],
    };
    let mut seen = Vec::new();
    for c in &candidates {
        let version = Command::new(c)
            .args(["-c", "import sys; print('%d.%d' % sys.version_info[:2])"])
            .output();
        match version {
            Ok(o) if o.status.success() => {
                let v = String::from_utf8_lossy(&o.stdout).trim().to_string();
                if recent(&v) {
                    return Ok(c.clone());
                }
                seen.push(format!("{} is Python {v}", c.display()));
            }
            Ok(_) => seen.push(format!("{} does not run", c.display())),
            Err(_) => seen.push(format!("{} is not found", c.display())),
        }
    }
    Err(format!(
        "error: lagrange-derive needs Python 3.9 or newer to run SymPy, once to make its environment, \
         and found none ({}). Install Python 3 (with its venv module), or set \
         LAGRANGE_DERIVE_PYTHON to a python3.",
        seen.join(", ")
    ))
}

/// Whether `major.minor` is 3.9 or newer.
fn recent(version: &str) -> bool {
    let mut parts = version.split('.').map(|p| p.parse::<u32>().unwrap_or(0));
    let (major, minor) = (parts.next().unwrap_or(0), parts.next().unwrap_or(0));
    (major, minor) >= (3, 9)
}

#[cfg(test)]
mod tests {
    #[test]
    fn versions() {
        assert!(super::recent("3.9"));
        assert!(super::recent("3.12"));
        assert!(!super::recent("3.8"));
        assert!(!super::recent("2.7"));
        assert!(!super::recent("garbage"));
    }
}
