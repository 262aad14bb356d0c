//! The lockstep firmware: runs every case of `lagrange_cases::CASES` on the Cortex-M4F and
//! logs, with defmt over semihosting, each final state as exact bit patterns, the SysTick
//! ticks of a run of 0 and of `STEPS` steps, and the stack high-water mark; then every math
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
use lagrange_cases::{CASES, KERNELS, KERNEL_CALLS, STEPS};
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

#[exception]
unsafe fn HardFault(_frame: &ExceptionFrame) -> ! {
    exit(false)
}

#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    defmt::println!("panic");
    exit(false)
}
