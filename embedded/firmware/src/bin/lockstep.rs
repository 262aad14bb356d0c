//! The lockstep firmware: runs every case of `lagrange_cases::CASES` on the Cortex-M4F and
//! logs, with defmt over semihosting, each final state as exact bit patterns, the SysTick
//! ticks of a run of 0 and of `STEPS` steps, and the stack high-water mark; for a case that
//! takes its steps one by one (`Case::times_steps`: the ragdoll's), a run more with each
//! step timed, and the ticks of the worst; then every math
//! kernel of `lagrange_cases::KERNELS` (digest and ticks); then a calibration
//! of ticks against instructions. `cargo xtask qemu` decodes the log with `defmt-print` and
//! compares every state bit for bit with the same cases run on the host.
//!
//! Log lines (the host parses them):
//!
//! ```text
//! lockstep cases=<n> steps=<STEPS> paint=<bytes the stack probe paints>
//! case <id> <words as [a, b, ...]>       or   case <id> error
//! cost <id> <ticks for 0 steps> <ticks for STEPS steps>
//! stack <id> <bytes>
//! worst <id> <ticks of the slowest step>   or   worst <id> wrapped   (stepwise cases only)
//! kernel <id> <digest of the results' bits> <ticks for KERNEL_CALLS calls>
//! calibrate <instructions> <ticks>
//! done
//! ```
//!
//! Any panic logs and exits with failure; a HardFault exits with failure.

#![no_std]
#![no_main]

use cortex_m_rt::{entry, exception, ExceptionFrame};
use defmt_semihosting as _;
use lagrange_cases::{Stopwatch, CASES, KERNELS, KERNEL_CALLS, STEPS};
use lagrange_core::Error;
use lagrange_firmware::{exit, stack_high_water, Counter, PAINT_DEPTH};

/// The calibration loop's argument: `cortex_m::asm::delay(n)` (cortex-m 0.7.10) runs `n + 1`
/// iterations of `subs; bne`, so `delay(n)` takes `2 n` instructions more than `delay(0)`.
const CALIBRATION_CYCLES: u32 = 4_000_000;

#[entry]
fn main() -> ! {
    let Some(peripherals) = cortex_m::Peripherals::take() else {
        defmt::println!("error: peripherals taken");
        exit(false)
    };
    let mut counter = Counter::start(peripherals.SYST);
    defmt::println!(
        "lockstep cases={=usize} steps={=u32} paint={=u32}",
        CASES.len(),
        STEPS,
        PAINT_DEPTH
    );
    let mut ok = true;
    for (id, case) in CASES.iter().enumerate() {
        let (_, setup_ticks) = counter.measure(|| case.run(0));
        let ((outcome, run_ticks), stack) =
            stack_high_water(|| counter.measure(|| case.run(STEPS)));
        match outcome {
            Ok(outcome) => defmt::println!("case {=usize} {=[?]}", id, outcome.words()),
            Err(_) => defmt::println!("case {=usize} error", id),
        }
        match (setup_ticks, run_ticks) {
            (Some(setup), Some(run)) => {
                defmt::println!("cost {=usize} {=u32} {=u32}", id, setup, run)
            }
            _ => {
                defmt::println!("cost {=usize} wrapped", id);
                ok = false;
            }
        }
        defmt::println!("stack {=usize} {=u32}", id, stack);
        if case.times_steps() {
            let mut watch = WorstStep {
                counter: &mut counter,
                worst: Some(0),
            };
            // The outcome is the one logged above (the host checks that timing changes no bit).
            let _ = case.run_timed(STEPS, &mut watch);
            match watch.worst {
                Some(ticks) => defmt::println!("worst {=usize} {=u32}", id, ticks),
                None => {
                    defmt::println!("worst {=usize} wrapped", id);
                    ok = false;
                }
            }
        }
    }
    for (id, kernel) in KERNELS.iter().enumerate() {
        match counter.measure(|| kernel.run(KERNEL_CALLS)) {
            (digest, Some(ticks)) => {
                defmt::println!("kernel {=usize} {=u64} {=u32}", id, digest, ticks)
            }
            (_, None) => ok = false,
        }
    }
    let (_, empty) = counter.measure(|| cortex_m::asm::delay(0));
    let (_, full) = counter.measure(|| cortex_m::asm::delay(CALIBRATION_CYCLES));
    match (empty, full) {
        (Some(empty), Some(full)) => defmt::println!(
            "calibrate {=u32} {=u32}",
            2 * CALIBRATION_CYCLES,
            full - empty
        ),
        _ => ok = false,
    }
    defmt::println!("done");
    exit(ok)
}

/// The SysTick ticks of the slowest step timed (`None` once a step wrapped the counter). Each
/// step's ticks include the stopwatch's own reads of SysTick and the call of the step, a few
/// instructions, within a tick.
struct WorstStep<'a> {
    counter: &'a mut Counter,
    worst: Option<u32>,
}

impl Stopwatch for WorstStep<'_> {
    fn time(&mut self, step: &mut dyn FnMut() -> Result<(), Error>) -> Result<(), Error> {
        let (result, ticks) = self.counter.measure(step);
        self.worst = self.worst.zip(ticks).map(|(w, t)| w.max(t));
        result
    }
}

#[exception]
unsafe fn HardFault(_frame: &ExceptionFrame) -> ! {
    exit(false)
}

#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    defmt::println!("panic");
    exit(false)
}
