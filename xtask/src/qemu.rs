//! `cargo xtask qemu`: the firmware of `embedded/firmware` run on an emulated Cortex-M4F,
//! compared bit for bit with the host, with its costs, sizes and stack.
//!
//! 1. Installs what is missing: the `thumbv7em-none-eabihf` target (rustup), `qemu-system-arm`
//!    (Debian's package, by `apt-get`), `defmt-print` (crates.io, `cargo install --locked` at a
//!    pinned version).
//! 2. Builds the firmware in release (opt-level 3, fat LTO): the lockstep image, the
//!    one-mechanism image (also with `libm-trig`, for comparison), the panic-free image (whose
//!    link fails if any panic path is left in the stepping code).
//! 3. Runs each under `qemu-system-arm -machine mps2-an386` with `-icount shift=0` (one
//!    instruction, one nanosecond of virtual time), semihosting on, inside a timeout: a hang, a
//!    panic or a fault fails the run.
//! 4. Decodes the lockstep image's defmt log with `defmt-print`, runs the same
//!    `lagrange_cases::CASES` on the host, and compares every final state bit for bit.
//! 5. Reports instructions per step of every case (SysTick ticks of a run of `STEPS` steps less
//!    those of a run of none, times instructions per tick as the firmware's calibration loop
//!    measures it), the worst single step of the cases that time their steps (the ragdoll
//!    landing under the impulse stepper, beside its free RK4 step), stack high-water marks and
//!    `.text` sizes (the ragdoll stepped with and without the impulse stepper among them), and
//!    checks the budgets.

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
use crate::cross::{self, TARGET};

/// The firmware crate, relative to the project root.
const FIRMWARE_DIR: &str = "embedded/firmware";

/// The emulator, from Debian's package of the same name.
const QEMU: &str = "qemu-system-arm";

/// The emulator's arguments before the ELF: the MPS2 board with the AN386 image (a Cortex-M4
/// with FPU), no display, monitor or serial (the log goes through semihosting to stdout), and
/// deterministic instruction counting: each instruction advances the virtual clock by 2^0 ns,
/// with no alignment to real time and no sleeping.
const QEMU_ARGS: [&str; 14] = [
    "-machine",
    "mps2-an386",
    "-cpu",
    "cortex-m4",
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

/// The decoder, installed from crates.io when missing.
const DEFMT_PRINT: &str = "defmt-print";

/// The decoder's pinned version (it decodes defmt 1.x's wire format).
const DEFMT_PRINT_VERSION: &str = "1.2.0";

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

/// Builds, runs, compares and reports; every step runs and every failure is reported at the
/// end.
pub fn run() -> Result<(), String> {
    let clock = Instant::now();
    let mut failures = Vec::new();
    let tools = [cross::ensure_target(), ensure_qemu(), ensure_defmt_print()];
    let tools: Result<Vec<()>, String> = tools.into_iter().collect();
    let decoder = match tools.and_then(|_| defmt_print()) {
        Ok(decoder) => decoder,
        Err(e) => return Err(format!("xtask qemu: missing tools: {e}")),
    };
    failures.extend(lint().err());
    // The libm-trig one-mechanism image first: the default build then overwrites its ELF.
    let libm_text = build(&["--bin", "one-mechanism", "--features", "libm-trig"])
        .and_then(|dir| text_size(&dir.join("one-mechanism")));
    let dir = match build(&[
        "--bin",
        "lockstep",
        "--bin",
        "one-mechanism",
        "--bin",
        "scene-text",
        "--bin",
        "loop-text",
        "--bin",
        "ragdoll-text",
        "--bin",
        "ragdoll-impulse-text",
    ]) {
        Ok(dir) => dir,
        Err(e) => return Err(format!("xtask qemu: {e}")),
    };
    // Its own build, so that a failure to link names the check that failed.
    let panic_free = build(&["--bin", "panic-free"]).map_err(|e| {
        format!("panic-free image: a panic path is left in the stepping code, or ({e})")
    });
    match &panic_free {
        Ok(_) => println!(
            "panic-free image linked: no panic path in the stepping code (the ragdoll's \
             impulse stepper included)"
        ),
        Err(e) => failures.push(e.clone()),
    }

    match lockstep(&dir.join("lockstep"), &decoder) {
        Ok(errors) => failures.extend(errors),
        Err(e) => failures.push(e),
    }
    let images: &[&str] = if panic_free.is_ok() {
        &["one-mechanism", "panic-free"]
    } else {
        &["one-mechanism"]
    };
    for image in images {
        if let Err(e) = run_image(&dir.join(image)) {
            failures.push(e);
        }
    }
    match sizes(&dir, images, libm_text) {
        Ok(errors) => failures.extend(errors),
        Err(e) => failures.push(e),
    }
    println!("xtask qemu: {:.0} s", clock.elapsed().as_secs_f64());
    if failures.is_empty() {
        println!("xtask qemu: all checks passed");
        Ok(())
    } else {
        Err(failures.join("\n"))
    }
}

/// The final-state words the firmware reports under QEMU for every lockstep case, by case
/// id (`None`: the case returned an error): the lockstep image built (a no-op when `qemu`
/// built it already), run and its log decoded. For `cargo xtask web --test`.
pub fn lockstep_states() -> Result<BTreeMap<usize, Option<Vec<u64>>>, String> {
    let tools = [cross::ensure_target(), ensure_qemu(), ensure_defmt_print()];
    tools.into_iter().collect::<Result<Vec<()>, String>>()?;
    let decoder = defmt_print()?;
    let elf = build(&["--bin", "lockstep"])?.join("lockstep");
    let log = decode(&elf, &decoder)?;
    if !log.done {
        return Err("the firmware log ends before `done`".into());
    }
    Ok(log.states)
}

/// Runs the lockstep image under QEMU and decodes and parses its log.
fn decode(elf: &Path, decoder: &Path) -> Result<Log, String> {
    let raw = run_in_qemu(elf)?;
    let (status, decoded) = run_captured(
        Command::new(decoder)
            .arg("-e")
            .arg(elf)
            .args(["--log-format", "{s}", "stdin"]),
        raw,
    )?;
    if !status.success() {
        return Err(format!("{DEFMT_PRINT} failed ({status})"));
    }
    parse_log(&String::from_utf8_lossy(&decoded))
}

/// Runs `program --version`-like `args` quietly; `true` when it starts and succeeds.
pub(crate) fn works(program: &Path, args: &[&str]) -> bool {
    Command::new(program)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Installs `qemu-system-arm` with `apt-get` when it is not on `PATH`.
fn ensure_qemu() -> Result<(), String> {
    if works(Path::new(QEMU), &["--version"]) {
        return Ok(());
    }
    println!("{QEMU} is missing: installing Debian's package");
    let clock = Instant::now();
    cmd::run(Command::new("apt-get").args(["update", "-qq"]))?;
    cmd::run(
        Command::new("apt-get")
            .env("DEBIAN_FRONTEND", "noninteractive")
            .args(["install", "-y", "-qq", "--no-install-recommends", QEMU]),
    )?;
    if works(Path::new(QEMU), &["--version"]) {
        println!("{QEMU} installed in {:.0} s", clock.elapsed().as_secs_f64());
        Ok(())
    } else {
        Err(format!("{QEMU} still does not run after apt-get install"))
    }
}

/// The directory `cargo install` puts binaries in.
fn cargo_bin_dir() -> Option<PathBuf> {
    std::env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|home| Path::new(&home).join(".cargo")))
        .map(|home| home.join("bin"))
}

/// `defmt-print`: on `PATH`, else in cargo's bin directory, else `None`.
fn find_defmt_print() -> Option<PathBuf> {
    let on_path = PathBuf::from(DEFMT_PRINT);
    if works(&on_path, &["--version"]) {
        return Some(on_path);
    }
    cargo_bin_dir()
        .map(|dir| dir.join(DEFMT_PRINT))
        .filter(|path| works(path, &["--version"]))
}

/// Installs `defmt-print` at [`DEFMT_PRINT_VERSION`] with its lock file when it is missing.
///
/// Unoptimised (`--debug`): that halves the build (measured here: 1.5 against 2.7 CPU
/// minutes), and decoding a log of a few kilobytes takes no time either way.
fn ensure_defmt_print() -> Result<(), String> {
    if find_defmt_print().is_some() {
        return Ok(());
    }
    println!("{DEFMT_PRINT} is missing: installing it from crates.io");
    let clock = Instant::now();
    cmd::run(cmd::cargo().args([
        "install",
        "--locked",
        "--debug",
        "--version",
        DEFMT_PRINT_VERSION,
        DEFMT_PRINT,
    ]))?;
    println!(
        "{DEFMT_PRINT} installed in {:.0} s",
        clock.elapsed().as_secs_f64()
    );
    Ok(())
}

/// The `defmt-print` to run.
fn defmt_print() -> Result<PathBuf, String> {
    find_defmt_print().ok_or_else(|| format!("{DEFMT_PRINT} is not installed"))
}

/// The firmware crate is outside the host workspace, so `cargo xtask ci`'s fmt and clippy do
/// not see it: format check and clippy with `-D warnings` for the target, here.
fn lint() -> Result<(), String> {
    let dir = cmd::project_root().join(FIRMWARE_DIR);
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
            .arg(dir.join("target"))
            .args(["--", "-D", "warnings"]),
    );
    fmt.and(clippy)
}

/// Builds the firmware's binaries in release with `extra` cargo arguments; the directory of
/// the ELFs.
///
/// As in `cargo xtask cross`, cargo runs from the crate's directory (so that its
/// `.cargo/config.toml` applies) and the target and target directory are explicit.
fn build(extra: &[&str]) -> Result<PathBuf, String> {
    let dir = cmd::project_root().join(FIRMWARE_DIR);
    let target_dir = dir.join("target");
    cmd::run(
        cmd::cargo()
            .current_dir(&dir)
            .args(["build", "--quiet", "--release", "--target", TARGET])
            .arg("--target-dir")
            .arg(&target_dir)
            .args(extra),
    )?;
    Ok(target_dir.join(TARGET).join("release"))
}

/// Runs `command` with `input` on its stdin (none when empty), collecting stdout, and kills it
/// after [`RUN_TIMEOUT`].
fn run_captured(command: &mut Command, input: Vec<u8>) -> Result<(ExitStatus, Vec<u8>), String> {
    let shown = cross::shown(command);
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
fn run_in_qemu(elf: &Path) -> Result<Vec<u8>, String> {
    let (status, out) = run_captured(
        Command::new(QEMU).args(QEMU_ARGS).arg("-kernel").arg(elf),
        Vec::new(),
    )?;
    if status.success() {
        Ok(out)
    } else {
        Err(format!("{} failed under QEMU ({status})", elf.display()))
    }
}

/// Runs an image that only reports through its exit status.
fn run_image(elf: &Path) -> Result<(), String> {
    run_in_qemu(elf).map(|_| println!("{}: ran to success on the M4F", elf.display()))
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

/// Instructions per SysTick tick from the calibration: the nearest integer, checked to explain
/// the count to within one tick.
fn instructions_per_tick(calibration: Option<(u64, u64)>) -> Result<u64, String> {
    let (instructions, ticks) = calibration.ok_or("no calibration line in the log")?;
    if ticks == 0 {
        return Err("the calibration loop took no ticks".into());
    }
    let per_tick = (instructions + ticks / 2) / ticks;
    if instructions.abs_diff(per_tick * ticks) > per_tick {
        return Err(format!(
            "calibration: {instructions} instructions in {ticks} ticks is not a whole number \
             of instructions per tick"
        ));
    }
    Ok(per_tick)
}

/// Runs the lockstep image, decodes its log, compares with the host and prints the table;
/// the list of failed checks.
fn lockstep(elf: &Path, decoder: &Path) -> Result<Vec<String>, String> {
    let log = decode(elf, decoder)?;
    let mut failures = Vec::new();
    if log.header != Some((CASES.len(), STEPS)) {
        failures.push(format!(
            "firmware header {:?}, host has {} cases of {STEPS} steps",
            log.header,
            CASES.len()
        ));
    }
    if !log.done {
        failures.push("the firmware log ends before `done`".into());
    }
    let per_tick = instructions_per_tick(log.calibration)?;
    println!(
        "\nlockstep on the M4F (QEMU mps2-an386, -icount shift=0: {per_tick} instructions per \
         SysTick tick), {STEPS} steps (of 1 ms; the scenes' frames of 1/120 s, the ragdoll's \
         steps of 1/240 s); instructions per step, the mean and, where a case times its steps, \
         the worst:"
    );
    println!(
        "{:>3}  {:<28} {:<29} {:<5} {:<12} {:>12} {:>12} {:>8}",
        "id", "system", "integrator", "type", "host = M4F", "instr/step", "worst step", "stack B"
    );
    let mut per_step = BTreeMap::new();
    let mut worst_step = BTreeMap::new();
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
        if verdict != "identical" {
            failures.push(format!(
                "case {id} ({} {} {}): {verdict}: M4F {firmware:?}, host {host:?}",
                case.system, case.method, case.precision
            ));
        }
        let cost = match log.costs.get(&id) {
            Some(Some((setup, run))) => {
                let instructions = run.saturating_sub(*setup) * per_tick;
                let step = instructions as f64 / f64::from(STEPS);
                per_step.insert(id, step);
                format!("{step:.1}")
            }
            _ => {
                failures.push(format!("case {id}: no cost measured"));
                "-".into()
            }
        };
        let worst = match log.worst.get(&id) {
            Some(Some(ticks)) => {
                let instructions = ticks * per_tick;
                worst_step.insert(id, instructions);
                instructions.to_string()
            }
            Some(None) => {
                failures.push(format!("case {id}: a step wrapped the counter"));
                "wrapped".into()
            }
            None if case.times_steps() => {
                failures.push(format!("case {id}: no worst step measured"));
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
                    "case {id}: its stack reached the probe's whole depth ({paint} B): deeper \
                     than measured"
                ));
            }
        }
        println!(
            "{id:>3}  {:<28} {:<29} {:<5} {:<12} {cost:>12} {worst:>12} {stack:>8}",
            case.system, case.method, case.precision, verdict
        );
    }
    let find = |system: &str, method: &str| {
        CASES
            .iter()
            .position(|c| c.system == system && c.method == method && c.precision == "f32")
            .and_then(|id| per_step.get(&id).copied())
    };
    match (find("pendulum", "RK4"), find("pendulum (libm sinf)", "RK4")) {
        (Some(fast), Some(libm)) => {
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
        _ => failures.push("no f32 RK4 pendulum cost to check against its budget".into()),
    }
    failures.extend(asleep_cost(&per_step));
    lane_cost(&per_step);
    failures.extend(ragdoll_cost(&per_step, &worst_step, &words, &log.stacks));
    failures.extend(kernels(&log, per_tick));
    Ok(failures)
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
         more asleep: {each:.2} per sleeper per frame; budget {ASLEEP_BUDGET}"
    );
    (each > ASLEEP_BUDGET).then(|| {
        format!("an asleep instance costs {each:.2} instructions per frame, over {ASLEEP_BUDGET}")
    })
}

/// Prints what 16 pendulums cost per instance and step one by one, in lanes of 4, and in a
/// scene's bank on the M4F.
fn lane_cost(per_step: &BTreeMap<usize, f64>) {
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
            "f32 RK4 pendulums on the M4F: {:.1} instructions per instance and step one by one, \
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
         {frictional} with friction, {rounds} rounds (cap 4 K = {}, C = {RAGDOLL_ROWS})",
        4 * k
    );
    println!(
        "  bound (ImpulseStepper's docs): the inner step + position_residual + jacobian + \
         tangent_jacobian + 2 velocity_jumps (R and F columns) + a velocity_jump per \
         speculative row + at most 4 solves x K rounds (an exact solve of the R rows: Cholesky \
         of at most R rows a pass, at most 4 C + 4 passes; a sweep of the F tangents) + at \
         most 3 exact solves for the drift + 2 to 4 evaluations of T and V"
    );
    let mut failures = Vec::new();
    if rows > RAGDOLL_ROWS as u64 || rounds > 4 * k {
        failures.push(format!(
            "ragdoll landing: {rows} rows and {rounds} rounds in a step, past the caps of \
             {RAGDOLL_ROWS} rows and {} rounds",
            4 * k
        ));
    }
    failures
}

/// Compares the kernels' digests with the host's and prints instructions per call (the
/// kernel's ticks less those of the identity loop above it); the list of failed checks.
fn kernels(log: &Log, per_tick: u64) -> Vec<String> {
    let mut failures = Vec::new();
    println!("\nmath kernels on the M4F, {KERNEL_CALLS} calls each (results compared as digests):");
    println!(
        "{:>3}  {:<26} {:<14} {:<12} {:>13}",
        "id", "function", "inputs", "host = M4F", "instr/call"
    );
    let mut identity = None;
    for (id, kernel) in KERNELS.iter().enumerate() {
        let Some(&(digest, ticks)) = log.kernels.get(&id) else {
            failures.push(format!("kernel {id} ({}): missing", kernel.name));
            continue;
        };
        let verdict = if digest == kernel.run(KERNEL_CALLS) {
            "identical"
        } else {
            failures.push(format!(
                "kernel {id} ({} on {}): results differ from the host's",
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
                    let instructions = ticks.saturating_sub(base) * per_tick;
                    format!("{:.1}", instructions as f64 / f64::from(KERNEL_CALLS))
                },
            )
        };
        println!(
            "{id:>3}  {:<26} {:<14} {verdict:<12} {cost:>13}",
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
    libm_one_mechanism: Result<u32, String>,
) -> Result<Vec<String>, String> {
    let mut failures = Vec::new();
    println!("\n.text of the firmware images (release, opt-level 3, fat LTO):");
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
    println!("  budget of the one-mechanism image: {ONE_MECHANISM_TEXT_BUDGET} B");
    Ok(failures)
}
