//! The lockstep firmware: runs every case of `lagrange_cases::CASES` on the core it is built
//! for (Cortex-M4F, M0+, M33, RISC-V) and logs, with defmt over semihosting, each final state
//! as exact bit patterns, the counter's ticks (SysTick on Cortex-M, `minstret` on RISC-V) of a
//! run of 0 and of `STEPS` steps, and the stack high-water mark; for a case that takes its
//! steps one by one (`Case::times_steps`: the ragdoll's), a run more with each step timed, and
//! the ticks of the worst; then every math kernel of `lagrange_cases::KERNELS` (digest and
//! ticks); then a calibration of ticks against instructions. `cargo xtask qemu` decodes the
//! log with `defmt-print` and compares every state bit for bit with the same cases run on the
//! host.
//!
//! Log lines (the host parses them):
//!
//! ```text
//! lockstep cases=<n> steps=<STEPS> paint=<bytes the stack probe paints>
//! case <id> <words as [a, b, ...]>       or   case <id> error
//! cost <id> <ticks for 0 steps> <ticks for STEPS steps>
//! stack <id> <bytes>
//! worst <id> <ticks of the slowest step>   (stepwise cases only)
//! kernel <id> <digest of the results' bits> <ticks for KERNEL_CALLS calls>
//! calibrate <instructions> <ticks>
//! done
//! ```
//!
//! Any panic logs and exits with failure; a fault exits with failure.

#![no_std]
#![no_main]

use defmt_semihosting as _;
use lagrange_cases::{Stopwatch, CASES, KERNELS, KERNEL_CALLS, STEPS};
use lagrange_core::Error;
use lagrange_firmware::{calibrate, entry, exit, stack_high_water, Counter, PAINT_DEPTH};

#[entry]
fn main() -> ! {
    let Some(mut counter) = Counter::take() else {
        defmt::println!("error: counter taken");
        exit(false)
    };
    defmt::println!(
        "lockstep cases={=usize} steps={=u32} paint={=u32}",
        CASES.len(),
        STEPS,
        PAINT_DEPTH
    );
    for (id, case) in CASES.iter().enumerate() {
        let (_, setup) = counter.measure(|| case.run(0));
        let ((outcome, run), stack) = stack_high_water(|| counter.measure(|| case.run(STEPS)));
        match outcome {
            Ok(outcome) => defmt::println!("case {=usize} {=[?]}", id, outcome.words()),
            Err(_) => defmt::println!("case {=usize} error", id),
        }
        defmt::println!("cost {=usize} {=u64} {=u64}", id, setup, run);
        defmt::println!("stack {=usize} {=u32}", id, stack);
        if case.times_steps() {
            let mut watch = WorstStep {
                counter: &mut counter,
                worst: 0,
            };
            // The outcome is the one logged above (the host checks that timing changes no bit).
            let _ = case.run_timed(STEPS, &mut watch);
            defmt::println!("worst {=usize} {=u64}", id, watch.worst);
        }
    }
    for (id, kernel) in KERNELS.iter().enumerate() {
        let (digest, ticks) = counter.measure(|| kernel.run(KERNEL_CALLS));
        defmt::println!("kernel {=usize} {=u64} {=u64}", id, digest, ticks);
    }
    let (instructions, ticks) = calibrate(&mut counter);
    defmt::println!("calibrate {=u64} {=u64}", instructions, ticks);
    defmt::println!("done");
    exit(true)
}

/// The counter's ticks of the slowest step timed. Each step's ticks include the stopwatch's
/// own reads of the counter and the call of the step, a few instructions.
struct WorstStep<'a> {
    counter: &'a mut Counter,
    worst: u64,
}

impl Stopwatch for WorstStep<'_> {
    fn time(&mut self, step: &mut dyn FnMut() -> Result<(), Error>) -> Result<(), Error> {
        let (result, ticks) = self.counter.measure(step);
        self.worst = self.worst.max(ticks);
        result
    }
}

#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    defmt::println!("panic");
    exit(false)
}
