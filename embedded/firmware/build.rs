//! Puts the memory map of the board the target runs on (`memory/`) where the linker (driven by
//! the runtime's `link.x`: cortex-m-rt's or riscv-rt's) finds it as `memory.x`, and adds
//! defmt's linker script to the one binary that logs with defmt.

use std::env;
use std::fs;
use std::path::PathBuf;

/// The board each target runs on under QEMU (`cargo xtask qemu` has the emulator's side) and
/// its memory map.
const BOARDS: [(&str, &str); 5] = [
    ("thumbv7em-none-eabihf", "memory/mps2-an386.x"),
    ("thumbv6m-none-eabi", "memory/microbit.x"),
    ("thumbv8m.main-none-eabihf", "memory/mps2-an505.x"),
    ("riscv32imac-unknown-none-elf", "memory/riscv-virt.x"),
    ("riscv32imafc-unknown-none-elf", "memory/riscv-virt.x"),
];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let target = env::var("TARGET")?;
    let (_, map) = BOARDS
        .iter()
        .find(|(t, _)| *t == target)
        .ok_or_else(|| format!("no board for target {target} in build.rs"))?;
    let out = PathBuf::from(env::var_os("OUT_DIR").ok_or("OUT_DIR is not set")?);
    fs::copy(map, out.join("memory.x"))?;
    println!("cargo:rustc-link-search={}", out.display());
    // Here rather than in .cargo/config.toml, where a RUSTFLAGS variable would replace them.
    println!("cargo:rustc-link-arg=-Tlink.x");
    println!("cargo:rustc-link-arg-bin=lockstep=-Tdefmt.x");
    println!("cargo:rerun-if-changed=memory");
    println!("cargo:rerun-if-changed=build.rs");
    Ok(())
}
