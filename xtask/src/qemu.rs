//! `cargo xtask qemu`: the firmware of `embedded/firmware` run on emulated cores (Cortex-M4F,
//! M33, M0, RV32IMAC, RV32IMAFC: [`CORES`]), compared bit for bit with the host, with its
//! costs, sizes and stack on each.
//!
//! 1. Installs what is missing: the targets (rustup), `qemu-system-arm` and
//!    `qemu-system-riscv32` (Debian's `qemu-system-arm` and `qemu-system-misc`, by `apt-get`),
//!    `defmt-print` (crates.io, `cargo install --locked` at a pinned version).
//! 2. Builds the firmware in release (opt-level 3, fat LTO) for each core: the lockstep image,
//!    the one-mechanism image, the panic-free image (whose link fails if any panic path is left
//!    in the stepping code on that core; on every core but RV32IMAFC, which `cargo xtask cross`
//!    does not build for); on the M4F also the one-mechanism image with `libm-trig` and the
//!    size images (scene, loop, ragdoll). `--short` (`cargo xtask ci`'s form): the cores of
//!    [`SHORT`], and none of the M4F's images that are only measured.
//! 3. Runs each under QEMU with `-icount shift=0` (one instruction, one nanosecond of virtual
//!    time), semihosting on, inside a timeout: a hang, a panic or a fault fails the run.
//! 4. Decodes the lockstep image's defmt log with `defmt-print`, runs the same
//!    `lagrange_cases::CASES` on the host, and compares every final state bit for bit.
//! 5. Reports instructions per step of every case (counter ticks of a run of `STEPS` steps less
//!    those of a run of none, times instructions per tick as the firmware's calibration loop
//!    measures it), the worst single step of the cases that time their steps (the ragdoll
//!    landing under the impulse stepper, beside its free RK4 step), stack high-water marks and
//!    `.text` sizes, checks the M4F's budgets, and ends with one table of the cores side by
//!    side and what it means for a Cortex-M0+ at 48 MHz stepping at 1 kHz.

use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use lagrange_cases::{
    CASES, KERNELS, KERNEL_CALLS, LANE_INSTANCES, RAGDOLL_FREE, RAGDOLL_ITERATIONS,
    RAGDOLL_LANDING, RAGDOLL_ROWS, SLEEPERS, STEPS,
};

use crate::cmd;
use crate::cross;
use crate::tools::{AptTool, CargoTool};

/// The firmware crate, relative to the project root.
const FIRMWARE_DIR: &str = "embedded/firmware";

/// A core the firmware runs on, and the QEMU board that emulates it.
pub(crate) struct Core {
    /// Its name in the tables.
    name: &'static str,
    /// The Rust target the firmware is built for.
    target: &'static str,
    /// The emulator, and the Debian package it is in.
    emulator: AptTool,
    /// The board's arguments (machine, CPU, memory).
    machine: &'static [&'static str],
    /// The board and counter, for the tables' headings.
    board: &'static str,
    /// Whether the panic-free image is linked and run for it (every core that `cargo xtask
    /// cross` builds the library for).
    panic_free: bool,
}

/// The Cortex-M4F on the MPS2 board with the AN386 image: the core the budgets are for, and
/// the one the size images and `cargo xtask web --test` use.
const M4F: Core = Core {
    name: "M4F",
    target: cross::TARGET,
    emulator: QEMU_ARM,
    machine: &["-machine", "mps2-an386", "-cpu", "cortex-m4"],
    board: "QEMU mps2-an386, SysTick at 25 MHz",
    panic_free: true,
};

/// The Arm cores' emulator.
pub(crate) const QEMU_ARM: AptTool = AptTool {
    program: "qemu-system-arm",
    package: "qemu-system-arm",
};

/// The RISC-V cores' emulator.
pub(crate) const QEMU_RISCV: AptTool = AptTool {
    program: "qemu-system-riscv32",
    package: "qemu-system-misc",
};

/// Every core `cargo xtask qemu` runs, the M4F first.
///
/// The M0 stands for the M0+ (both ARMv6-M: the same instructions, so the same counts; the
/// M0+ takes fewer cycles for some). QEMU's micro:bit is an nRF51 with 256 KiB of flash and
/// 16 KiB of SRAM: both are enlarged (`memory/microbit.x` says to what), so that it runs the
/// lockstep image whole. Every case but the ragdoll landing fits the nRF51's own 16 KiB (7.1 kB
/// of stack at most); the landing's 47.9 kB of stack needs an RP2040's or a larger STM32G0's
/// RAM.
/// The RISC-V cores run on QEMU's `virt` board with no firmware (`-bios none`), counting
/// instructions with `minstret`.
pub(crate) const CORES: [Core; 5] = [
    M4F,
    Core {
        name: "M33",
        target: "thumbv8m.main-none-eabihf",
        emulator: QEMU_ARM,
        machine: &["-machine", "mps2-an505", "-cpu", "cortex-m33"],
        board: "QEMU mps2-an505, SysTick at 20 MHz",
        panic_free: true,
    },
    Core {
        name: "M0",
        target: "thumbv6m-none-eabi",
        emulator: QEMU_ARM,
        machine: &[
            "-machine",
            "microbit",
            "-global",
            "nrf51-soc.flash-size=4194304",
            "-global",
            "nrf51-soc.sram-size=262144",
        ],
        board: "QEMU microbit (nRF51, memory enlarged), SysTick at 16 MHz",
        panic_free: true,
    },
    Core {
        name: "RV32IMAC",
        target: "riscv32imac-unknown-none-elf",
        emulator: QEMU_RISCV,
        machine: &["-machine", "virt", "-bios", "none"],
        board: "QEMU virt, minstret",
        panic_free: true,
    },
    Core {
        name: "RV32IMAFC",
        target: "riscv32imafc-unknown-none-elf",
        emulator: QEMU_RISCV,
        machine: &["-machine", "virt", "-bios", "none"],
        board: "QEMU virt, minstret",
        panic_free: false,
    },
];

/// The emulator's arguments after the board's: no display, monitor or serial (the log goes
/// through semihosting to stdout), and deterministic instruction counting: each instruction
/// advances the virtual clock by 2^0 ns, with no alignment to real time and no sleeping.
const QEMU_ARGS: [&str; 10] = [
    "-display",
    "none",
    "-monitor",
    "none",
    "-serial",
    "none",
    "-semihosting-config",
    "enable=on,target=native",
    "-icount",
    "shift=0,align=off,sleep=off",
];

/// The decoder, installed from crates.io when missing, pinned (1.2.0 decodes defmt 1.x's
/// wire format). Unoptimised (`--debug`): that halves the build (measured here: 1.5 against
/// 2.7 CPU minutes), and decoding a log of a few kilobytes takes no time either way.
pub(crate) const DEFMT_PRINT: CargoTool = CargoTool {
    name: "defmt-print",
    version: "1.2.0",
    install_args: &["--debug"],
};

/// CPU time a QEMU run or a decode may use ([`cmd::overdue`]). The lockstep image runs in
/// under a second of host time here; the limit only turns a hang (a fault loop, a lost exit)
/// into a failure, and counts CPU time so that a busy machine cannot trip it.
const RUN_TIMEOUT: Duration = Duration::from_secs(120);

/// The budget: instructions per step of the `f32` RK4 pendulum on the M4F.
const PENDULUM_RK4_F32_BUDGET: f64 = 600.0;

/// The budget: instructions an asleep instance of a scene costs per frame.
const ASLEEP_BUDGET: f64 = 30.0;

/// The budget: `.text` bytes of the one-mechanism image at opt-level 3.
const ONE_MECHANISM_TEXT_BUDGET: u32 = 8 * 1024;

/// The cores of `cargo xtask ci`'s short form (`cargo xtask qemu --short`): the M4F (the
/// issue's budgets, the page's bits; `f64` in software) and the M0 (no FPU: `f32` in
/// software too, and ARMv6-M's instructions). The others run the same library code through
/// the same compiler's software floats or FPUs: the full command runs them (RV32IMAC 63 s,
/// M33 and RV32IMAFC 68 s together of a run of five on a two-core machine), and `cargo xtask
/// cross --short` checks the library for each in CI. The short form also leaves out the
/// M4F's images that are only measured ([`SIZE_IMAGES`], `libm-trig`).
const SHORT: [&str; 2] = ["M4F", "M0"];

/// Builds, runs, compares and reports on every core of [`CORES`], or with `--short` on those
/// of [`SHORT`]; every step runs and every failure is reported at the end.
pub fn run(args: &[String]) -> Result<(), String> {
    let short = cmd::short_form("qemu", args)?;
    let cores: Vec<&Core> = CORES
        .iter()
        .filter(|core| !short || SHORT.contains(&core.name))
        .collect();
    let clock = Instant::now();
    let mut failures = Vec::new();
    let mut tools: Vec<Result<(), String>> = cores
        .iter()
        .map(|core| cross::ensure_rustup_target(core.target))
        .collect();
    tools.extend(cores.iter().map(|core| core.emulator.ensure()));
    let tools: Result<Vec<()>, String> = tools.into_iter().collect();
    let decoder = match tools.and_then(|_| DEFMT_PRINT.ensure()) {
        Ok(decoder) => decoder,
        Err(e) => return Err(format!("xtask qemu: missing tools: {e}")),
    };
    failures.extend(lint().err());
    let mut rows = Vec::new();
    for core in cores {
        let started = Instant::now();
        match run_core(core, &decoder, short) {
            Ok((row, errors)) => {
                failures.extend(errors);
                rows.push(row);
            }
            Err(e) => failures.push(format!("{}: {e}", core.name)),
        }
        println!(
            "{}: built and run in {:.0} s",
            core.name,
            started.elapsed().as_secs_f64()
        );
    }
    summary(&rows);
    println!("xtask qemu: {:.0} s", clock.elapsed().as_secs_f64());
    if failures.is_empty() {
        println!("xtask qemu: all checks passed");
        Ok(())
    } else {
        Err(failures.join("\n"))
    }
}

/// The images every core builds and runs besides the lockstep image.
const IMAGES: [&str; 2] = ["one-mechanism", "panic-free"];

/// The M4F's images that are only measured (`.text`), not run.
const SIZE_IMAGES: [&str; 4] = [
    "scene-text",
    "loop-text",
    "ragdoll-text",
    "ragdoll-impulse-text",
];

/// Builds, runs and reports one core: its row of the summary and its failed checks; `Err`
/// when the lockstep image could not be built. The M4F's images that are only measured (the
/// size images, the one-mechanism image with `libm-trig`, which builds the library once more
/// with another feature) are left out of the `short` form; its budget is checked in both.
fn run_core(core: &Core, decoder: &Path, short: bool) -> Result<(Row, Vec<String>), String> {
    let mut failures = Vec::new();
    let is_m4f = core.target == M4F.target;
    let measured = is_m4f && !short;
    // The libm-trig one-mechanism image first: the default build then overwrites its ELF.
    let libm_text = measured.then(|| {
        build(core, &["--bin", "one-mechanism", "--features", "libm-trig"])
            .and_then(|dir| text_size(&dir.join("one-mechanism")))
    });
    let mut bins = vec!["lockstep", "one-mechanism"];
    if measured {
        bins.extend(SIZE_IMAGES);
    }
    let args: Vec<&str> = bins.iter().flat_map(|bin| ["--bin", bin]).collect();
    // Off the M4F, the panic-free image links beside the others (two links at a time on two
    // cores); only if that fails are they built apart, so that the failure names its check.
    let together = !is_m4f
        && core.panic_free
        && build(core, &[args.as_slice(), &["--bin", "panic-free"]].concat()).is_ok();
    let dir = build(core, &args)?;
    let panic_free = if together {
        Ok(())
    } else if core.panic_free {
        build(core, &["--bin", "panic-free"]).map(|_| ())
    } else {
        Err(String::new())
    };
    match &panic_free {
        Ok(()) => println!(
            "{}: panic-free image linked: no panic path in the stepping code (the ragdoll's \
             impulse stepper included)",
            core.name
        ),
        Err(e) if core.panic_free => failures.push(format!(
            "{}: panic-free image: a panic path is left in the stepping code, or ({e})",
            core.name
        )),
        Err(_) => println!(
            "{}: no panic-free image (a core of `cargo xtask qemu` only, not of `cargo xtask \
             cross`: its link would cost CI a minute)",
            core.name
        ),
    }
    let mut row = match lockstep(core, &dir.join("lockstep"), decoder) {
        Ok((row, errors)) => {
            failures.extend(errors);
            row
        }
        Err(e) => {
            failures.push(format!("{}: {e}", core.name));
            Row::default()
        }
    };
    row.core = core.name;
    let images: &[&str] = if panic_free.is_ok() {
        &IMAGES
    } else {
        &IMAGES[..1]
    };
    for image in images {
        if let Err(e) = run_image(core, &dir.join(image)) {
            failures.push(e);
        }
    }
    row.text = text_size(&dir.join("lockstep")).ok();
    row.one_mechanism_text = text_size(&dir.join("one-mechanism")).ok();
    if is_m4f {
        match sizes(&dir, images, libm_text) {
            Ok(errors) => failures.extend(errors),
            Err(e) => failures.push(e),
        }
    }
    Ok((row, failures))
}

/// The final-state words the firmware reports under QEMU on the M4F for every lockstep case,
/// by case id (`None`: the case returned an error): the lockstep image built (a no-op when
/// `qemu` built it already), run and its log decoded. For `cargo xtask web --test`.
pub fn lockstep_states() -> Result<BTreeMap<usize, Option<Vec<u64>>>, String> {
    cross::ensure_target()?;
    M4F.emulator.ensure()?;
    let decoder = DEFMT_PRINT.ensure()?;
    let elf = build(&M4F, &["--bin", "lockstep"])?.join("lockstep");
    let log = decode(&M4F, &elf, &decoder)?;
    if !log.done {
        return Err("the firmware log ends before `done`".into());
    }
    Ok(log.states)
}

/// Runs the lockstep image under QEMU and decodes and parses its log.
fn decode(core: &Core, elf: &Path, decoder: &Path) -> Result<Log, String> {
    let raw = run_in_qemu(core, elf)?;
    let (status, decoded) = run_captured(
        Command::new(decoder)
            .arg("-e")
            .arg(elf)
            .args(["--log-format", "{s}", "stdin"]),
        raw,
    )?;
    if !status.success() {
        return Err(format!("{} failed ({status})", DEFMT_PRINT.name));
    }
    parse_log(&String::from_utf8_lossy(&decoded))
}

/// The firmware crate is outside the host workspace, so `cargo xtask ci`'s fmt and clippy do
/// not see it: format check, and clippy with `-D warnings` for a Cortex-M and a RISC-V target
/// (each compiles its own counter module), here.
fn lint() -> Result<(), String> {
    let dir = cmd::project_root().join(FIRMWARE_DIR);
    let mut result = cmd::run(
        cmd::cargo()
            .current_dir(&dir)
            .args(["fmt", "--", "--check"]),
    );
    for target in [M4F.target, "riscv32imac-unknown-none-elf"] {
        let clippy = cmd::run(
            cmd::cargo()
                .current_dir(&dir)
                .args(["clippy", "--quiet", "--release", "--target", target])
                .arg("--target-dir")
                .arg(dir.join("target"))
                .args(["--", "-D", "warnings"]),
        );
        result = result.and(clippy);
    }
    result
}

/// Builds the firmware's binaries in release with `extra` cargo arguments; the directory of
/// the ELFs.
///
/// As in `cargo xtask cross`, cargo runs from the crate's directory (so that its
/// `.cargo/config.toml` applies) and the target and target directory are explicit.
fn build(core: &Core, extra: &[&str]) -> Result<PathBuf, String> {
    let dir = cmd::project_root().join(FIRMWARE_DIR);
    let target_dir = dir.join("target");
    cmd::run(
        cmd::cargo()
            .current_dir(&dir)
            .args(["build", "--quiet", "--release", "--target", core.target])
            .arg("--target-dir")
            .arg(&target_dir)
            .args(extra),
    )?;
    Ok(target_dir.join(core.target).join("release"))
}

/// Runs `command` with `input` on its stdin (none when empty), collecting stdout, and kills it
/// after [`RUN_TIMEOUT`].
fn run_captured(command: &mut Command, input: Vec<u8>) -> Result<(ExitStatus, Vec<u8>), String> {
    let shown = cmd::shown(command);
    println!("$ {shown}");
    let mut child = command
        .stdin(if input.is_empty() {
            Stdio::null()
        } else {
            Stdio::piped()
        })
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| format!("could not start ({e}): {shown}"))?;
    let writer = child.stdin.take().map(|mut stdin| {
        std::thread::spawn(move || {
            // A decoder that exits early closes the pipe; its status tells.
            let _ = stdin.write_all(&input);
        })
    });
    let mut stdout = child
        .stdout
        .take()
        .ok_or_else(|| format!("no stdout: {shown}"))?;
    let reader = std::thread::spawn(move || {
        let mut out = Vec::new();
        let _ = stdout.read_to_end(&mut out);
        out
    });
    let started = Instant::now();
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) if !cmd::overdue(child.id(), started.elapsed(), RUN_TIMEOUT) => {
                std::thread::sleep(Duration::from_millis(20));
            }
            Ok(None) => {
                let _ = child.kill();
                let _ = child.wait();
                return Err(format!(
                    "used {} s of CPU time (or {} s of wall time) and was killed: {shown}",
                    RUN_TIMEOUT.as_secs(),
                    cmd::WALL_FACTOR * RUN_TIMEOUT.as_secs()
                ));
            }
            Err(e) => return Err(format!("lost ({e}): {shown}")),
        }
    };
    if let Some(writer) = writer {
        let _ = writer.join();
    }
    let out = reader
        .join()
        .map_err(|_| format!("stdout reader failed: {shown}"))?;
    Ok((status, out))
}

/// Runs `elf` under QEMU; its stdout (the semihosting output) when it exits with success.
fn run_in_qemu(core: &Core, elf: &Path) -> Result<Vec<u8>, String> {
    let (status, out) = run_captured(
        Command::new(core.emulator.program)
            .args(core.machine)
            .args(QEMU_ARGS)
            .arg("-kernel")
            .arg(elf),
        Vec::new(),
    )?;
    if status.success() {
        Ok(out)
    } else {
        Err(format!("{} failed under QEMU ({status})", elf.display()))
    }
}

/// Runs an image that only reports through its exit status.
fn run_image(core: &Core, elf: &Path) -> Result<(), String> {
    run_in_qemu(core, elf)
        .map(|_| println!("{}: ran to success on the {}", elf.display(), core.name))
}

/// What the lockstep firmware logged.
#[derive(Default)]
struct Log {
    /// `(cases, steps)` from the header line.
    header: Option<(usize, u32)>,
    /// Bytes the stack probe paints (from the header line): a mark of all of them means the
    /// probe was too shallow.
    paint: Option<u64>,
    /// Final-state words by case id (`None`: the case returned an error).
    states: BTreeMap<usize, Option<Vec<u64>>>,
    /// SysTick ticks of a run of no steps and of `STEPS` steps (`None`: it wrapped).
    costs: BTreeMap<usize, Option<(u64, u64)>>,
    /// Stack high-water mark by case id, bytes.
    stacks: BTreeMap<usize, u64>,
    /// SysTick ticks of the slowest step by case id, for the cases that time their steps
    /// (`None`: a step wrapped the counter).
    worst: BTreeMap<usize, Option<u64>>,
    /// `(digest, ticks)` by kernel id.
    kernels: BTreeMap<usize, (u64, u64)>,
    /// `(instructions, ticks)` of the calibration loop.
    calibration: Option<(u64, u64)>,
    /// The last line arrived.
    done: bool,
}

/// The number after `prefix=` in `word`.
fn field<T: std::str::FromStr>(word: Option<&str>, prefix: &str) -> Option<T> {
    word?.strip_prefix(prefix)?.parse().ok()
}

/// Parses the decoded log (see `embedded/firmware/src/bin/lockstep.rs` for its lines).
fn parse_log(text: &str) -> Result<Log, String> {
    let mut log = Log::default();
    for line in text.lines() {
        let bad = || format!("unexpected log line: {line:?}");
        let mut words = line.split_whitespace();
        let kind = words.next().unwrap_or_default();
        let number = |w: Option<&str>| -> Result<u64, String> {
            w.and_then(|w| {
                w.trim_matches(|c| c == '[' || c == ']' || c == ',')
                    .parse()
                    .ok()
            })
            .ok_or_else(bad)
        };
        match kind {
            "lockstep" => {
                let cases = field(words.next(), "cases=").ok_or_else(bad)?;
                let steps = field(words.next(), "steps=").ok_or_else(bad)?;
                log.header = Some((cases, steps));
                log.paint = Some(field(words.next(), "paint=").ok_or_else(bad)?);
            }
            "case" => {
                let id = usize::try_from(number(words.next())?).map_err(|_| bad())?;
                let rest: Vec<&str> = words.collect();
                let state = if rest == ["error"] {
                    None
                } else {
                    Some(
                        rest.iter()
                            .map(|w| number(Some(w)))
                            .collect::<Result<Vec<u64>, String>>()?,
                    )
                };
                log.states.insert(id, state);
            }
            "cost" => {
                let id = usize::try_from(number(words.next())?).map_err(|_| bad())?;
                let next = words.next();
                let cost = if next == Some("wrapped") {
                    None
                } else {
                    Some((number(next)?, number(words.next())?))
                };
                log.costs.insert(id, cost);
            }
            "stack" => {
                let id = usize::try_from(number(words.next())?).map_err(|_| bad())?;
                log.stacks.insert(id, number(words.next())?);
            }
            "worst" => {
                let id = usize::try_from(number(words.next())?).map_err(|_| bad())?;
                let next = words.next();
                let ticks = if next == Some("wrapped") {
                    None
                } else {
                    Some(number(next)?)
                };
                log.worst.insert(id, ticks);
            }
            "kernel" => {
                let id = usize::try_from(number(words.next())?).map_err(|_| bad())?;
                let digest = number(words.next())?;
                log.kernels.insert(id, (digest, number(words.next())?));
            }
            "calibrate" => {
                log.calibration = Some((number(words.next())?, number(words.next())?));
            }
            "done" => log.done = true,
            _ => return Err(bad()),
        }
    }
    Ok(log)
}

/// Instructions per counter tick from the calibration (SysTick counts at a fixed fraction of
/// QEMU's instruction clock: 40, 50 and 62.5 instructions a tick on the M4F, M33 and M0 boards;
/// `minstret` counts instructions), checked to be within 0.1% of a multiple of 1/8.
fn instructions_per_tick(calibration: Option<(u64, u64)>) -> Result<f64, String> {
    let (instructions, ticks) = calibration.ok_or("no calibration line in the log")?;
    if ticks == 0 {
        return Err("the calibration loop took no ticks".into());
    }
    let measured = instructions as f64 / ticks as f64;
    let per_tick = (measured * 8.0).round() / 8.0;
    if per_tick == 0.0 || (measured / per_tick - 1.0).abs() > 1e-3 {
        return Err(format!(
            "calibration: {instructions} instructions in {ticks} ticks is not a whole number \
             of eighths of an instruction per tick"
        ));
    }
    Ok(per_tick)
}

/// One core's figures for the summary table.
#[derive(Default)]
struct Row {
    /// The core's name.
    core: &'static str,
    /// Cases whose final state the firmware gave bit for bit as the host: `f32` ones, `f64`
    /// ones.
    identical: (usize, usize),
    /// Cases run.
    cases: usize,
    /// Mean instructions per step by case id.
    per_step: BTreeMap<usize, f64>,
    /// Instructions of the slowest step by case id (the cases that time their steps).
    worst: BTreeMap<usize, u64>,
    /// Stack high-water mark by case id, bytes.
    stacks: BTreeMap<usize, u64>,
    /// `.text` of the lockstep image (every case and kernel), bytes.
    text: Option<u32>,
    /// `.text` of the one-mechanism image (one f32 RK4 pendulum), bytes.
    one_mechanism_text: Option<u32>,
}

/// Runs the lockstep image, decodes its log, compares with the host and prints the core's
/// table; its summary row and the list of failed checks (the budgets are checked on the M4F
/// only).
fn lockstep(core: &Core, elf: &Path, decoder: &Path) -> Result<(Row, Vec<String>), String> {
    let name = core.name;
    let log = decode(core, elf, decoder)?;
    let mut failures = Vec::new();
    if log.header != Some((CASES.len(), STEPS)) {
        failures.push(format!(
            "{name}: firmware header {:?}, host has {} cases of {STEPS} steps",
            log.header,
            CASES.len()
        ));
    }
    if !log.done {
        failures.push(format!("{name}: the firmware log ends before `done`"));
    }
    let per_tick = instructions_per_tick(log.calibration)?;
    println!(
        "\nlockstep on the {name} ({}, -icount shift=0: {per_tick} instructions per tick), \
         {STEPS} steps (of 1 ms; the scenes' frames of 1/120 s, the ragdoll's steps of 1/240 s); \
         instructions per step, the mean and, where a case times its steps, the worst:",
        core.board
    );
    let same = format!("host = {name}");
    println!(
        "{:>3}  {:<28} {:<29} {:<5} {:<14} {:>12} {:>12} {:>8}",
        "id", "system", "integrator", "type", same, "instr/step", "worst step", "stack B"
    );
    let mut row = Row {
        cases: CASES.len(),
        ..Row::default()
    };
    let mut words = BTreeMap::new();
    for (id, case) in CASES.iter().enumerate() {
        let host = case.run(STEPS).ok().map(|o| o.words().to_vec());
        if let Some(h) = &host {
            words.insert(id, h.clone());
        }
        let firmware = log.states.get(&id);
        let verdict = match (firmware, &host) {
            (Some(Some(f)), Some(h)) if f == h => "identical",
            (Some(None), None) => "same error",
            (None, _) => "missing",
            _ => "DIFFERENT",
        };
        if verdict == "identical" {
            if case.precision == "f32" {
                row.identical.0 += 1;
            } else {
                row.identical.1 += 1;
            }
        } else {
            failures.push(format!(
                "{name}: case {id} ({} {} {}): {verdict}: firmware {firmware:?}, host {host:?}",
                case.system, case.method, case.precision
            ));
        }
        let cost = match log.costs.get(&id) {
            Some(Some((setup, run))) => {
                let instructions = run.saturating_sub(*setup) as f64 * per_tick;
                let step = instructions / f64::from(STEPS);
                row.per_step.insert(id, step);
                format!("{step:.1}")
            }
            _ => {
                failures.push(format!("{name}: case {id}: no cost measured"));
                "-".into()
            }
        };
        let worst = match log.worst.get(&id) {
            Some(Some(ticks)) => {
                let instructions = (*ticks as f64 * per_tick).round() as u64;
                row.worst.insert(id, instructions);
                instructions.to_string()
            }
            Some(None) => {
                failures.push(format!("{name}: case {id}: a step wrapped the counter"));
                "wrapped".into()
            }
            None if case.times_steps() => {
                failures.push(format!("{name}: case {id}: no worst step measured"));
                "missing".into()
            }
            None => "-".into(),
        };
        let stack = log
            .stacks
            .get(&id)
            .map_or_else(|| "-".into(), u64::to_string);
        if let (Some(&bytes), Some(paint)) = (log.stacks.get(&id), log.paint) {
            if bytes >= paint {
                failures.push(format!(
                    "{name}: case {id}: its stack reached the probe's whole depth ({paint} B): \
                     deeper than measured"
                ));
            }
        }
        println!(
            "{id:>3}  {:<28} {:<29} {:<5} {:<14} {cost:>12} {worst:>12} {stack:>8}",
            case.system, case.method, case.precision, verdict
        );
    }
    row.stacks = log.stacks.clone();
    let per_step = &row.per_step;
    let find = |system: &str, method: &str| {
        CASES
            .iter()
            .position(|c| c.system == system && c.method == method && c.precision == "f32")
            .and_then(|id| per_step.get(&id).copied())
    };
    let is_m4f = core.target == M4F.target;
    match (find("pendulum", "RK4"), find("pendulum (libm sinf)", "RK4")) {
        (Some(fast), Some(libm)) if is_m4f => {
            println!(
                "f32 RK4 pendulum: {fast:.1} instructions per step with fast_trig, {libm:.1} \
                 with libm::sinf ({:.1}x); budget {PENDULUM_RK4_F32_BUDGET}",
                libm / fast
            );
            if fast > PENDULUM_RK4_F32_BUDGET {
                failures.push(format!(
                    "f32 RK4 pendulum: {fast:.1} instructions per step, over the budget of \
                     {PENDULUM_RK4_F32_BUDGET}"
                ));
            }
        }
        (Some(fast), Some(libm)) => println!(
            "f32 RK4 pendulum: {fast:.1} instructions per step with fast_trig, {libm:.1} with \
             libm::sinf ({:.1}x)",
            libm / fast
        ),
        _ => failures.push(format!("{name}: no f32 RK4 pendulum cost")),
    }
    let asleep = asleep_cost(per_step);
    if is_m4f {
        failures.extend(asleep);
    }
    lane_cost(name, per_step);
    failures.extend(ragdoll_cost(per_step, &row.worst, &words, &log.stacks));
    failures.extend(kernels(name, &log, per_tick));
    Ok((row, failures))
}

/// What an asleep instance costs a frame: the difference between the scene cases with
/// [`SLEEPERS`] asleep beside one awake and with none, per sleeper; the failed check, if any.
fn asleep_cost(per_step: &BTreeMap<usize, f64>) -> Option<String> {
    let find = |system: &str| {
        CASES
            .iter()
            .position(|c| c.system == system)
            .and_then(|id| per_step.get(&id).copied())
    };
    let (Some(none), Some(many)) = (find("scene, 1 awake"), find("scene, 1 awake + 64 asleep"))
    else {
        return Some("no cost measured for the scene cases with and without sleepers".into());
    };
    let each = (many - none) / SLEEPERS as f64;
    println!(
        "scene frame: {none:.1} instructions with one pendulum awake, {many:.1} with {SLEEPERS} \
         more asleep: {each:.2} per sleeper per frame; budget on the M4F {ASLEEP_BUDGET}"
    );
    (each > ASLEEP_BUDGET).then(|| {
        format!("an asleep instance costs {each:.2} instructions per frame, over {ASLEEP_BUDGET}")
    })
}

/// Prints what 16 pendulums cost per instance and step one by one, in lanes of 4, and in a
/// scene's bank on the core.
fn lane_cost(core: &str, per_step: &BTreeMap<usize, f64>) {
    let find = |system: &str| {
        CASES
            .iter()
            .position(|c| c.system == system)
            .and_then(|id| per_step.get(&id).copied())
    };
    if let (Some(alone), Some(lanes), Some(bank)) = (
        find("16 pendulums, one by one"),
        find("16 pendulums, in lanes"),
        find("16 pendulums, a scene's bank"),
    ) {
        let n = LANE_INSTANCES as f64;
        println!(
            "f32 RK4 pendulums on the {core}: {:.1} instructions per instance and step one by one, \
             {:.1} in lanes of 4 ({:.2}x), {:.1} in a scene's bank, one by one here ({:.2}x)",
            alone / n,
            lanes / n,
            lanes / alone,
            bank / n,
            bank / alone
        );
    }
}

/// The ragdoll landing under the impulse stepper against its free step: mean and worst
/// instructions per step of each, their ratios, the worst step's work (the landing's peak
/// report, from its outcome words) beside the stepper's documented bound, and the stack; the
/// failed checks (a figure missing, the work past its cap).
fn ragdoll_cost(
    per_step: &BTreeMap<usize, f64>,
    worst_step: &BTreeMap<usize, u64>,
    words: &BTreeMap<usize, Vec<u64>>,
    stacks: &BTreeMap<usize, u64>,
) -> Vec<String> {
    let id = |system: &str| CASES.iter().position(|c| c.system == system);
    let (Some(landing), Some(free)) = (id(RAGDOLL_LANDING), id(RAGDOLL_FREE)) else {
        return vec!["no ragdoll cases in CASES".into()];
    };
    let figures = (
        per_step.get(&landing),
        worst_step.get(&landing),
        per_step.get(&free),
        worst_step.get(&free),
    );
    let (Some(&mean), Some(&worst), Some(&free_mean), Some(&free_worst)) = figures else {
        return vec!["no cost measured for the ragdoll cases".into()];
    };
    let worst = worst as f64;
    println!(
        "ragdoll landing (f32, impulse stepper, semi-implicit Euler inside, {RAGDOLL_ROWS} rows, \
         1/240 s): {mean:.0} instructions per step on average, {worst:.0} in the worst step; \
         a free RK4 step of the ragdoll {free_mean:.0} (worst {free_worst}): the landing's worst \
         step is {:.1} free steps, its mean {:.2}; stack {} B (free: {} B)",
        worst / free_mean,
        mean / free_mean,
        stacks.get(&landing).copied().unwrap_or_default(),
        stacks.get(&free).copied().unwrap_or_default(),
    );
    let Some(&[.., rows, speculative, frictional, rounds]) = words.get(&landing).map(Vec::as_slice)
    else {
        return vec!["no peak report in the ragdoll landing's outcome".into()];
    };
    let k = u64::from(RAGDOLL_ITERATIONS);
    println!(
        "  its worst work (peak report): R = {rows} rows ({speculative} speculative), F = \
         {frictional} with friction, {rounds} rounds (cap K + 3 = {}, C = {RAGDOLL_ROWS})",
        k + 3
    );
    println!(
        "  bound (ImpulseStepper's docs): the inner step + position_residual + jacobian + \
         tangent_jacobian + 2 velocity_jumps (R and F columns) + a velocity_jump per \
         speculative row + at most K + 3 rounds in all (an exact solve of the R rows: F D F^T \
         of at most R rows a pass, at most 4 C + 4 passes; one sweep of the F tangents, at \
         most K in a solve's last round) + at most 3 exact solves for the drift + 2 to 4 \
         evaluations of T and V"
    );
    let mut failures = Vec::new();
    if rows > RAGDOLL_ROWS as u64 || rounds > k + 3 {
        failures.push(format!(
            "ragdoll landing: {rows} rows and {rounds} rounds in a step, past the caps of \
             {RAGDOLL_ROWS} rows and {} rounds",
            k + 3
        ));
    }
    failures
}

/// Compares the kernels' digests with the host's and prints instructions per call (the
/// kernel's ticks less those of the identity loop above it); the list of failed checks.
fn kernels(core: &str, log: &Log, per_tick: f64) -> Vec<String> {
    let mut failures = Vec::new();
    println!(
        "\nmath kernels on the {core}, {KERNEL_CALLS} calls each (results compared as digests):"
    );
    let same = format!("host = {core}");
    println!(
        "{:>3}  {:<26} {:<14} {:<14} {:>13}",
        "id", "function", "inputs", same, "instr/call"
    );
    let mut identity = None;
    for (id, kernel) in KERNELS.iter().enumerate() {
        let Some(&(digest, ticks)) = log.kernels.get(&id) else {
            failures.push(format!("{core}: kernel {id} ({}): missing", kernel.name));
            continue;
        };
        let verdict = if digest == kernel.run(KERNEL_CALLS) {
            "identical"
        } else {
            failures.push(format!(
                "{core}: kernel {id} ({} on {}): results differ from the host's",
                kernel.name, kernel.inputs
            ));
            "DIFFERENT"
        };
        let cost = if kernel.name.starts_with("identity") {
            identity = Some(ticks);
            "(loop)".to_string()
        } else {
            identity.map_or_else(
                || "-".into(),
                |base| {
                    let instructions = ticks.saturating_sub(base) as f64 * per_tick;
                    format!("{:.1}", instructions / f64::from(KERNEL_CALLS))
                },
            )
        };
        println!(
            "{id:>3}  {:<26} {:<14} {verdict:<14} {cost:>13}",
            kernel.name, kernel.inputs
        );
    }
    failures
}

/// The `.text` size of an ELF, bytes.
fn text_size(elf: &Path) -> Result<u32, String> {
    cross::section_sizes(elf)?
        .iter()
        .find(|(name, _)| *name == ".text")
        .and_then(|(_, size)| *size)
        .ok_or_else(|| format!("{}: no .text", elf.display()))
}

/// Prints the `.text` sizes and checks the one-mechanism budget; the list of failed checks.
fn sizes(
    dir: &Path,
    images: &[&str],
    libm_one_mechanism: Option<Result<u32, String>>,
) -> Result<Vec<String>, String> {
    let mut failures = Vec::new();
    println!("\n.text of the M4F's firmware images (release, opt-level 3, fat LTO):");
    for image in std::iter::once(&"lockstep").chain(images) {
        let text = text_size(&dir.join(image))?;
        println!("  {image:<40} {text:>8} B");
        if *image == "one-mechanism" && text > ONE_MECHANISM_TEXT_BUDGET {
            failures.push(format!(
                "one-mechanism image: .text {text} B, over the budget of \
                 {ONE_MECHANISM_TEXT_BUDGET} B"
            ));
        }
    }
    println!("  budget of the one-mechanism image: {ONE_MECHANISM_TEXT_BUDGET} B");
    // The measured images (not in the short form).
    let Some(libm_one_mechanism) = libm_one_mechanism else {
        return Ok(failures);
    };
    let scene = text_size(&dir.join("scene-text"))?;
    let plain = text_size(&dir.join("loop-text"))?;
    println!(
        "  {:<40} {scene:>8} B\n  {:<40} {plain:>8} B\n  a scene without sleeping against the \
         loop it replaces: {:+} B ({:.2}x; goal: no bigger)",
        "scene-text (16 pendulums in a scene)",
        "loop-text (16 pendulums, a FixedTimestep each)",
        i64::from(scene) - i64::from(plain),
        f64::from(scene) / f64::from(plain)
    );
    let free = text_size(&dir.join("ragdoll-text"))?;
    let impulses = text_size(&dir.join("ragdoll-impulse-text"))?;
    println!(
        "  {:<40} {free:>8} B\n  {:<40} {impulses:>8} B\n  the impulse stepper with the \
         ragdoll's {RAGDOLL_ROWS} rows adds {:+} B ({:.2}x)",
        "ragdoll-text (f32, semi-implicit Euler)",
        "ragdoll-impulse-text (the same, impulses)",
        i64::from(impulses) - i64::from(free),
        f64::from(impulses) / f64::from(free)
    );
    match libm_one_mechanism {
        Ok(text) => println!("  {:<40} {text:>8} B", "one-mechanism with libm-trig"),
        Err(e) => failures.push(format!("one-mechanism with libm-trig: {e}")),
    }
    Ok(failures)
}

/// The id of the case of `system` by `method` in `precision`.
fn case_id(system: &str, method: &str, precision: &str) -> Option<usize> {
    CASES
        .iter()
        .position(|c| c.system == system && c.method == method && c.precision == precision)
}

/// The summary's columns of mean instructions per step: heading, system, method, precision.
const COLUMNS: [(&str, &str, &str, &str); 7] = [
    ("pendulum", "pendulum", "RK4", "f32"),
    ("double p.", "double pendulum", "RK4", "f32"),
    ("cart-pole", "cart-pole", "RK4", "f32"),
    ("c-p f64", "cart-pole", "RK4", "f64"),
    ("c-p S-V", "cart-pole", "Stormer-Verlet", "f32"),
    (
        "c-p var.",
        "cart-pole (automatic)",
        "variational midpoint",
        "f32",
    ),
    ("16 in scene", "16 pendulums, a scene's bank", "RK4", "f32"),
];

/// The cycles per instruction assumed for a Cortex-M0+ running soft-float code from
/// zero-wait-state memory: most of its instructions take one cycle, loads, stores and taken
/// branches two (an assumption: QEMU counts instructions, not cycles).
const M0_PLUS_CPI: f64 = 1.5;

/// The M0+ clock and loop rate the advice is for: cycles a step may take.
const M0_PLUS_CYCLES_PER_STEP: f64 = 48e6 / 1e3;

/// Prints the cores side by side (the lockstep verdicts, instructions per step of the chosen
/// cases, the ragdoll landing's worst step and stack, `.text`), and what the M0's counts mean
/// for an M0+ stepping at 1 kHz at 48 MHz.
fn summary(rows: &[Row]) {
    println!(
        "\ncores side by side: lockstep cases bit-identical to the host (f32, f64, of all); mean \
         instructions per step (f32 unless marked: RK4; the cart-pole also by Stormer-Verlet and \
         the variational midpoint rule; a frame of 16 pendulums in a scene's bank); the ragdoll \
         landing's worst step (impulse stepper, f32) and its stack; the deepest stack of any \
         case; .text of the lockstep image and of the one-mechanism image:"
    );
    let mut heading = format!("{:<10} {:>11}", "core", "f32,f64 =");
    for (title, ..) in COLUMNS {
        heading.push_str(&format!(" {title:>11}"));
    }
    heading.push_str(&format!(
        " {:>11} {:>9} {:>9} {:>9} {:>9}",
        "ragdoll wst", "rd. stack", "max stack", ".text", "1-mech"
    ));
    println!("{heading}");
    let landing = CASES.iter().position(|c| c.system == RAGDOLL_LANDING);
    for row in rows {
        let mut line = format!(
            "{:<10} {:>11}",
            row.core,
            format!("{},{} of {}", row.identical.0, row.identical.1, row.cases)
        );
        for (_, system, method, precision) in COLUMNS {
            let cost = case_id(system, method, precision).and_then(|id| row.per_step.get(&id));
            line.push_str(&cost.map_or_else(|| format!(" {:>11}", "-"), |c| format!(" {c:>11.0}")));
        }
        let shown = |v: Option<u64>| v.map_or_else(|| "-".to_string(), |v| v.to_string());
        line.push_str(&format!(
            " {:>11} {:>9} {:>9} {:>9} {:>9}",
            shown(landing.and_then(|id| row.worst.get(&id).copied())),
            shown(landing.and_then(|id| row.stacks.get(&id).copied())),
            shown(row.stacks.values().max().copied()),
            shown(row.text.map(u64::from)),
            shown(row.one_mechanism_text.map(u64::from)),
        ));
        println!("{line}");
    }
    if let Some(m0) = rows.iter().find(|r| r.core == "M0") {
        m0_plus_advice(m0);
    }
}

/// What the M0's instruction counts (the M0+'s: the same instruction set) mean for a 1 kHz loop
/// on an M0+ at 48 MHz, for the cart-pole by each method and scalar: an estimate at
/// [`M0_PLUS_CPI`] cycles per instruction.
fn m0_plus_advice(m0: &Row) {
    println!(
        "\nCortex-M0+ at 48 MHz, one cart-pole step per 1 ms (48000 cycles), estimated at \
         {M0_PLUS_CPI} cycles per instruction (an assumption; QEMU counts instructions):"
    );
    let mut fitting = Vec::new();
    for (method, title) in [
        ("RK4", "RK4"),
        ("Stormer-Verlet", "Stormer-Verlet"),
        ("variational midpoint", "variational midpoint"),
    ] {
        for precision in ["f32", "f64"] {
            let system = if method == "variational midpoint" {
                "cart-pole (automatic)"
            } else {
                "cart-pole"
            };
            let Some(&instructions) =
                case_id(system, method, precision).and_then(|id| m0.per_step.get(&id))
            else {
                continue;
            };
            let share = instructions * M0_PLUS_CPI / M0_PLUS_CYCLES_PER_STEP;
            println!(
                "  {title:<22} {precision}: {instructions:>8.0} instructions, ~{:>7.0} cycles, \
                 {:>4.0}% of the millisecond",
                instructions * M0_PLUS_CPI,
                100.0 * share
            );
            if share < 1.0 {
                fitting.push((share, format!("{title} in {precision}")));
            }
        }
    }
    fitting.sort_by(|a, b| a.0.total_cmp(&b.0));
    match fitting.first() {
        None => println!("  none fits in the millisecond"),
        Some((share, cheapest)) => println!(
            "  fitting in the millisecond: {}; the choice: {cheapest}, leaving {:.0}% of it for \
             the rest of the loop",
            fitting
                .iter()
                .map(|(_, name)| name.as_str())
                .collect::<Vec<_>>()
                .join(", "),
            100.0 * (1.0 - share)
        ),
    }
}

#[cfg(test)]
mod tests {
    /// Every core of the short form is one of [`super::CORES`] (a misspelt name would drop
    /// a core from CI without a word), the M4F among them (the page's bits are checked
    /// against its).
    #[test]
    fn the_short_form_names_cores_that_exist() {
        for name in super::SHORT {
            assert!(super::CORES.iter().any(|core| core.name == name), "{name}");
        }
        assert!(super::SHORT.contains(&super::M4F.name));
    }
}
