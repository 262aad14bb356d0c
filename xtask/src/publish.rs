//! The publishable crates as they would be published: their documentation with rustdoc's
//! warnings denied, and their packages, each built from its packaged files against the
//! others' packages.

use std::path::{Path, PathBuf};

use crate::cmd;

/// The publishable crates, as `cargo -p` arguments: the four libraries and the
/// `lagrange-derive` command (its package must carry `derive.py`, which it includes).
const LIBRARIES: [&str; 10] = [
    "-p",
    "lagrange-core",
    "-p",
    "lagrange-integrators",
    "-p",
    "lagrange-systems",
    "-p",
    "lagrange-world",
    "-p",
    "lagrange-derive",
];

/// The crate names of [`LIBRARIES`].
fn names() -> impl Iterator<Item = &'static str> {
    LIBRARIES.iter().copied().filter(|a| *a != "-p")
}

/// Documents and packages the library crates; both run, and both failures are reported.
pub fn run() -> Result<(), String> {
    let doc = cmd::run(
        cmd::cargo()
            .env("RUSTDOCFLAGS", "-D warnings")
            .args(["doc", "--quiet", "--no-deps", "--all-features"])
            .args(LIBRARIES),
    );
    let target = cmd::project_root().join("target").join("publish");
    let package = clear_stale_extractions()
        .and_then(|()| clear_stale_builds(&target))
        .and_then(|()| {
            cmd::run(
                cmd::cargo()
                    .args(["package", "--quiet", "--allow-dirty", "--target-dir"])
                    .arg(&target)
                    .args(LIBRARIES),
            )
        });
    doc.and(package)
}

/// Removes earlier extractions of our own packages from cargo's local-registry sources.
///
/// Packaging several crates of a workspace publishes them into a temporary local registry
/// (`target/package/tmp-registry`) and verifies each against the others from there. Cargo
/// unpacks those `.crate` files under `$CARGO_HOME/registry/src/-<hash of the registry's
/// path>/NAME-VERSION` and never unpacks again once that directory is marked done. The
/// version does not change between commits, so a second run in the same checkout verified
/// `lagrange-systems` against the `lagrange-core` of an older run, and failed on every API
/// added since. Local registries are the source directories whose name starts with `-` (their
/// URL has no host); only our crates' directories there are removed.
fn clear_stale_extractions() -> Result<(), String> {
    let sources = cargo_home().join("registry").join("src");
    let Ok(registries) = std::fs::read_dir(&sources) else {
        return Ok(()); // nothing was ever unpacked
    };
    for registry in registries.flatten() {
        if !registry.file_name().to_string_lossy().starts_with('-') {
            continue;
        }
        let Ok(crates) = std::fs::read_dir(registry.path()) else {
            continue;
        };
        for unpacked in crates.flatten() {
            let name = unpacked.file_name().to_string_lossy().into_owned();
            let ours = names().any(|lib| {
                name.strip_prefix(lib)
                    .and_then(|rest| rest.strip_prefix('-'))
                    .is_some_and(|version| version.starts_with(|c: char| c.is_ascii_digit()))
            });
            if ours {
                std::fs::remove_dir_all(unpacked.path()).map_err(|e| {
                    format!(
                        "removing the stale unpacked package {}: {e}",
                        unpacked.path().display()
                    )
                })?;
            }
        }
    }
    Ok(())
}

/// Removes the verification builds of our packages from `target` (the packaging's own target
/// directory).
///
/// Cargo takes a registry package's sources as immutable: a build of `lagrange-core 0.1.0`
/// from the local registry is never rebuilt however its files change. Packaging runs in a
/// target directory of its own, where every `lagrange-*` unit comes from that registry, so
/// their fingerprints can go by name; the dependencies' builds stay.
fn clear_stale_builds(target: &Path) -> Result<(), String> {
    let fingerprints = target.join("debug").join(".fingerprint");
    let Ok(units) = std::fs::read_dir(&fingerprints) else {
        return Ok(()); // never built
    };
    for unit in units.flatten() {
        if unit.file_name().to_string_lossy().starts_with("lagrange-") {
            std::fs::remove_dir_all(unit.path()).map_err(|e| {
                format!(
                    "removing the stale fingerprint {}: {e}",
                    unit.path().display()
                )
            })?;
        }
    }
    Ok(())
}

/// Cargo's home: `$CARGO_HOME`, else `~/.cargo`.
fn cargo_home() -> PathBuf {
    match std::env::var_os("CARGO_HOME") {
        Some(home) => PathBuf::from(home),
        None => PathBuf::from(std::env::var_os("HOME").unwrap_or_default()).join(".cargo"),
    }
}
