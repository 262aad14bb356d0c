//! `cargo xtask cross`: the library crates (and the generated mechanisms) built for every
//! core of [`TARGETS`] (Cortex-M4F, M0+, M33, RV32IMAC), and the size of a linked `no_std`
//! binary that uses them with no global allocator (on the M4F). That no stepping code keeps a
//! panic path on any of them is `cargo xtask qemu`'s check (the panic-free image, linked for
//! each core).
//!
//! Each library crate is built on its own with `-p`, so that workspace feature unification (a
//! `std` feature turned on by `tests` or `xtask`) cannot hide a `no_std` failure. The smoke
//! binary in `embedded/smoke` is a standalone crate: its `.cargo/config.toml` (target and
//! `-Tlink.x`) is only read when cargo runs from that directory.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::cmd;

/// The mechanisms `cargo xtask derive` generated (`derive/generated`), built for [`TARGET`]
/// too: generated code must be `no_std` like the library (it has no features).
const GENERATED: &str = "lagrange-generated";

/// The embedded target of the smoke binary (and of the Cortex-M4F firmware).
pub(crate) const TARGET: &str = "thumbv7em-none-eabihf";

/// Every target the library crates are built for: the Cortex-M4F (single-precision FPU), the
/// Cortex-M0+ (ARMv6-M: no FPU, no divide instruction), the Cortex-M33 (ARMv8-M mainline,
/// single-precision FPU) and RV32IMAC (no FPU).
pub(crate) const TARGETS: [&str; 4] = [
    TARGET,
    "thumbv6m-none-eabi",
    "thumbv8m.main-none-eabihf",
    "riscv32imac-unknown-none-elf",
];

/// The library crates, each built for [`TARGET`] with every entry of [`FEATURE_SETS`] and for
/// the other [`TARGETS`] with the last (`defmt` on top of the defaults: the same code and the
/// derives, so that a build more per target and crate would check nothing new there; the
/// default set alone is built for them by `cargo xtask qemu`'s firmware).
const CRATES: [&str; 4] = [
    "lagrange-core",
    "lagrange-integrators",
    "lagrange-systems",
    "lagrange-world",
];

/// The extra cargo arguments of each feature set: default features, then `defmt` on top.
const FEATURE_SETS: [&[&str]; 2] = [&[], &["--features", "defmt"]];

/// The smoke firmware's directory, relative to the project root.
const SMOKE_DIR: &str = "embedded/smoke";

/// The smoke firmware's binary name (its package name).
const SMOKE_BIN: &str = "lagrange-smoke";

/// The embassy example's directory (an nRF52840 application: `cargo xtask cross` builds it,
/// checks its format and lints it; QEMU has no nRF52 board to run it on).
const EMBASSY_DIR: &str = "embedded/embassy-cartpole";

/// The embassy example's binary name.
const EMBASSY_BIN: &str = "lagrange-embassy-cartpole";

/// The sections whose sizes are reported.
const SECTIONS: [&str; 4] = [".text", ".rodata", ".data", ".bss"];

/// Installs the target if needed, builds the matrix and the smoke binary, and prints its size;
/// every step runs and every failure is reported at the end.
///
/// `--short` (`cargo xtask ci`'s form): the matrix checked (`cargo check`: the same errors
/// for a library, without its code generation, which `cargo xtask qemu --short`'s firmware
/// does on the M4F and the M0), and the embassy example formatted and linted but not built (its
/// release build links embassy-nrf with fat LTO: a fifth of the step).
pub fn run(args: &[String]) -> Result<(), String> {
    let short = cmd::short_form("cross", args)?;
    let verb = if short { "check" } else { "build" };
    let mut failures = Vec::new();
    for target in TARGETS {
        if let Err(e) = ensure_rustup_target(target) {
            failures.push(e);
            continue;
        }
        let sets = if target == TARGET {
            &FEATURE_SETS[..]
        } else {
            &FEATURE_SETS[FEATURE_SETS.len() - 1..]
        };
        for krate in CRATES {
            for &features in sets {
                let built = cmd::run(
                    cmd::cargo()
                        .args([verb, "--quiet", "-p", krate, "--target", target])
                        .args(features),
                );
                if let Err(e) = built {
                    failures.push(e);
                }
            }
        }
        if let Err(e) =
            cmd::run(cmd::cargo().args([verb, "--quiet", "-p", GENERATED, "--target", target]))
        {
            failures.push(e);
        }
    }
    match build_smoke() {
        Ok(elf) => match section_sizes(&elf) {
            Ok(sizes) => print_sizes(&elf, &sizes),
            Err(e) => failures.push(format!("{}: {e}", elf.display())),
        },
        Err(e) => failures.push(e),
    }
    let clock = std::time::Instant::now();
    match build_embassy(!short) {
        Ok(Some(elf)) => match section_sizes(&elf) {
            Ok(sizes) => print_sizes(&elf, &sizes),
            Err(e) => failures.push(format!("{}: {e}", elf.display())),
        },
        Ok(None) => {}
        Err(e) => failures.push(e),
    }
    println!(
        "embassy example: linted{} in {:.0} s",
        if short { "" } else { " and built" },
        clock.elapsed().as_secs_f64()
    );
    if failures.is_empty() {
        println!("xtask cross: all builds passed");
        Ok(())
    } else {
        Err(failures.join("\n"))
    }
}

/// Runs `rustup target add` for [`TARGET`] when `rustup target list --installed` lacks it.
///
/// Without a working `rustup` (a toolchain from a distribution, say) it warns and goes on:
/// the builds then show whether the target is there.
pub(crate) fn ensure_target() -> Result<(), String> {
    ensure_rustup_target(TARGET)
}

/// Runs `rustup target add TARGET` when `rustup target list --installed` lacks it (a warning
/// only without a working `rustup`).
pub(crate) fn ensure_rustup_target(target: &str) -> Result<(), String> {
    let mut list = Command::new("rustup");
    list.args(["target", "list", "--installed"]);
    println!("$ {}", cmd::shown(&list));
    let installed = match list.output() {
        Ok(out) if out.status.success() => String::from_utf8_lossy(&out.stdout).into_owned(),
        Ok(out) => {
            println!(
                "warning: `rustup target list` failed ({}); not installing {target}",
                out.status
            );
            return Ok(());
        }
        Err(e) => {
            println!("warning: could not run rustup ({e}); not installing {target}");
            return Ok(());
        }
    };
    if installed.lines().any(|line| line.trim() == target) {
        Ok(())
    } else {
        cmd::run(Command::new("rustup").args(["target", "add", target]))
    }
}

/// Builds the smoke firmware in release and returns the path of its ELF.
///
/// Cargo runs from the crate's directory so that its `.cargo/config.toml` applies; the target
/// and target directory are also passed explicitly, so that `CARGO_BUILD_TARGET` or
/// `CARGO_TARGET_DIR` in the environment cannot move the ELF.
fn build_smoke() -> Result<PathBuf, String> {
    let dir = cmd::project_root().join(SMOKE_DIR);
    let target_dir = dir.join("target");
    cmd::run(
        cmd::cargo()
            .current_dir(&dir)
            .args(["build", "--quiet", "--release", "--target", TARGET])
            .arg("--target-dir")
            .arg(&target_dir),
    )?;
    Ok(target_dir.join(TARGET).join("release").join(SMOKE_BIN))
}

/// Checks the embassy example's format, lints it (`-D warnings`; it is outside the host
/// workspace, so `cargo xtask ci`'s fmt and clippy do not see it) and, with `build`, builds
/// it in release: the path of its ELF. Its target comes from its `.cargo/config.toml` and is
/// passed too.
fn build_embassy(build: bool) -> Result<Option<PathBuf>, String> {
    let dir = cmd::project_root().join(EMBASSY_DIR);
    let target_dir = dir.join("target");
    let fmt = cmd::run(
        cmd::cargo()
            .current_dir(&dir)
            .args(["fmt", "--", "--check"]),
    );
    let clippy = cmd::run(
        cmd::cargo()
            .current_dir(&dir)
            .args(["clippy", "--quiet", "--release", "--target", TARGET])
            .arg("--target-dir")
            .arg(&target_dir)
            .args(["--", "-D", "warnings"]),
    );
    fmt.and(clippy)?;
    if !build {
        return Ok(None);
    }
    cmd::run(
        cmd::cargo()
            .current_dir(&dir)
            .args(["build", "--quiet", "--release", "--target", TARGET])
            .arg("--target-dir")
            .arg(&target_dir),
    )?;
    Ok(Some(
        target_dir.join(TARGET).join("release").join(EMBASSY_BIN),
    ))
}

/// Prints each of [`SECTIONS`] with its size in bytes.
fn print_sizes(elf: &Path, sizes: &[(&str, Option<u32>)]) {
    println!("{} ({TARGET}, release):", elf.display());
    for (name, size) in sizes {
        match size {
            Some(bytes) => println!("  {name:<8} {bytes:>8} B"),
            None => println!("  {name:<8} {:>8}", "absent"),
        }
    }
}

/// The size of each of [`SECTIONS`] in the ELF file at `path` (`None` when it has none).
///
/// # Errors
/// When the file cannot be read or parsed, or was not linked with the runtime's `link.x` (no
/// `.vector_table` of cortex-m-rt's nor `.init.rust` of riscv-rt's, or an empty `.text`):
/// `RUSTFLAGS` in the environment, for one, replaces the `-Tlink.x` of
/// `embedded/smoke/.cargo/config.toml`, and the linker then silently drops every section.
pub(crate) fn section_sizes(path: &Path) -> Result<Vec<(&'static str, Option<u32>)>, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read: {e}"))?;
    let sections = elf32_sections(&bytes)?;
    let size_of = |wanted: &str| {
        sections
            .iter()
            .find(|(name, _)| name == wanted)
            .map(|&(_, size)| size)
    };
    let runtime = size_of(".vector_table").or(size_of(".init.rust"));
    if runtime.is_none() || size_of(".text").unwrap_or(0) == 0 {
        return Err(
            "no .vector_table (cortex-m-rt) or .init.rust (riscv-rt), or an empty .text: not \
             linked with the runtime's link.x (RUSTFLAGS, when set, overrides \
             embedded/smoke/.cargo/config.toml's -Tlink.x)"
                .into(),
        );
    }
    Ok(SECTIONS
        .iter()
        .map(|&wanted| (wanted, size_of(wanted)))
        .collect())
}

/// Name and size of every section of a little-endian ELF32 image, from its section headers.
fn elf32_sections(elf: &[u8]) -> Result<Vec<(String, u32)>, String> {
    /// `e_ident`: magic, `ELFCLASS32`, `ELFDATA2LSB`.
    const IDENT: [u8; 6] = [0x7f, b'E', b'L', b'F', 1, 1];
    /// Offset of `e_shoff` in the ELF32 header.
    const E_SHOFF: usize = 0x20;
    /// Offset of `e_shentsize`.
    const E_SHENTSIZE: usize = 0x2e;
    /// Offset of `e_shnum`.
    const E_SHNUM: usize = 0x30;
    /// Offset of `e_shstrndx`.
    const E_SHSTRNDX: usize = 0x32;
    /// Offset of `sh_name` in an ELF32 section header.
    const SH_NAME: usize = 0x00;
    /// Offset of `sh_offset`.
    const SH_OFFSET: usize = 0x10;
    /// Offset of `sh_size`.
    const SH_SIZE: usize = 0x14;
    /// The smallest valid `e_shentsize`.
    const SH_MIN_SIZE: usize = 0x28;

    if elf.get(..IDENT.len()) != Some(&IDENT[..]) {
        return Err("not a little-endian ELF32 file".into());
    }
    let shoff = to_usize(read_u32(elf, E_SHOFF)?)?;
    let shentsize = usize::from(read_u16(elf, E_SHENTSIZE)?);
    let shnum = usize::from(read_u16(elf, E_SHNUM)?);
    let shstrndx = usize::from(read_u16(elf, E_SHSTRNDX)?);
    if shentsize < SH_MIN_SIZE {
        return Err(format!(
            "section header entry size {shentsize} is too small"
        ));
    }
    let header = |index: usize| -> Result<usize, String> {
        index
            .checked_mul(shentsize)
            .and_then(|offset| offset.checked_add(shoff))
            .ok_or_else(|| "section header offset overflows".to_string())
    };
    let strtab = header(shstrndx)?;
    let names = to_usize(read_u32(elf, strtab + SH_OFFSET)?)?;
    (0..shnum)
        .map(|index| {
            let at = header(index)?;
            let name_at = names
                .checked_add(to_usize(read_u32(elf, at + SH_NAME)?)?)
                .ok_or("section name offset overflows")?;
            let name = elf
                .get(name_at..)
                .and_then(|rest| rest.split(|&b| b == 0).next())
                .ok_or_else(|| format!("section name at {name_at} is out of bounds"))?;
            Ok((
                String::from_utf8_lossy(name).into_owned(),
                read_u32(elf, at + SH_SIZE)?,
            ))
        })
        .collect()
}

/// The little-endian `u16` at `offset`.
fn read_u16(bytes: &[u8], offset: usize) -> Result<u16, String> {
    bytes
        .get(offset..)
        .and_then(|rest| rest.first_chunk::<2>())
        .map(|b| u16::from_le_bytes(*b))
        .ok_or_else(|| format!("truncated at byte {offset}"))
}

/// The little-endian `u32` at `offset`.
fn read_u32(bytes: &[u8], offset: usize) -> Result<u32, String> {
    bytes
        .get(offset..)
        .and_then(|rest| rest.first_chunk::<4>())
        .map(|b| u32::from_le_bytes(*b))
        .ok_or_else(|| format!("truncated at byte {offset}"))
}

/// A file offset as an index.
fn to_usize(value: u32) -> Result<usize, String> {
    usize::try_from(value).map_err(|e| format!("offset {value}: {e}"))
}
