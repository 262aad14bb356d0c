//! What the firmware binaries share, on every core they are built for: an instruction counter,
//! a stack high-water probe, the exit through semihosting, and a fault handler that turns any
//! fault into a failed exit.
//!
//! The counter is each core's own: on Cortex-M, SysTick clocked from the core (under
//! `qemu-system-arm -icount shift=0` every guest instruction advances the virtual clock by
//! 1 ns, so a tick is a fixed number of instructions); on RISC-V, `minstret`, the count of
//! instructions retired. [`calibrate`] measures instructions per tick against a loop of known
//! length, so that the host need not trust either.
//!
//! The memory map of each board is in `memory/`, picked by `build.rs` from the target.

#![no_std]

#[cfg(target_arch = "arm")]
mod arm;
#[cfg(target_arch = "riscv32")]
mod rv32;

use core::ptr;

#[cfg(target_arch = "arm")]
use arm as core_specific;
#[cfg(target_arch = "riscv32")]
use rv32 as core_specific;

pub use core_specific::{entry, Counter};

/// The calibration loop's length: [`calibrate`] times this many more iterations of a loop of
/// two instructions than a run of none.
const CALIBRATION_ITERATIONS: u32 = 4_000_000;

/// Times the calibration loop: `(instructions, ticks)` of [`CALIBRATION_ITERATIONS`] more
/// iterations of a two-instruction loop than none.
pub fn calibrate(counter: &mut Counter) -> (u64, u64) {
    let (_, empty) = counter.measure(|| core_specific::spin(0));
    let (_, full) = counter.measure(|| core_specific::spin(CALIBRATION_ITERATIONS));
    (
        2 * u64::from(CALIBRATION_ITERATIONS),
        full.saturating_sub(empty),
    )
}

/// The word painted below the stack pointer before a run.
const PAINT: u32 = 0xdead_beef;

/// How far below the stack pointer the probe paints, bytes: far more than any case uses (the
/// ragdoll landing, the deepest, uses 47 to 48 kB on every core), and at most half the RAM of
/// every board in `memory/` (the smallest has 256 KiB). A mark of the whole depth means the
/// probe was too shallow.
pub const PAINT_DEPTH: u32 = 128 * 1024;

/// Runs `f` and returns its result with its stack high-water mark: the bytes below this
/// function's stack pointer that `f` (and all it calls) wrote.
///
/// Paints [`PAINT_DEPTH`] bytes below the stack pointer, calls `f`, then finds the lowest word
/// no longer holding the paint. A word that `f` wrote with the paint value itself would be
/// missed, so the figure is a lower bound in principle; in practice stack frames do not hold
/// `0xdeadbeef`.
#[inline(never)]
pub fn stack_high_water<R>(f: impl FnOnce() -> R) -> (R, u32) {
    let top = core_specific::stack_pointer();
    let bottom = top - PAINT_DEPTH;
    // SAFETY: the words from `bottom` up to `top` are below the stack pointer of this frame:
    // no live data is there (this loop calls nothing; an exception taken meanwhile stacks its
    // frame below the stack pointer and unstacks it before the loop goes on), and every
    // board's RAM under the stack top leaves room for `PAINT_DEPTH` (see its docs).
    unsafe {
        let mut at = bottom;
        while at < top {
            ptr::write_volatile(at as *mut u32, PAINT);
            at += 4;
        }
    }
    let result = f();
    let mut at = bottom;
    // SAFETY: reads of the same words, all inside RAM; values only compared.
    while at < top && unsafe { ptr::read_volatile(at as *const u32) } == PAINT {
        at += 4;
    }
    (result, top - at)
}

/// Ends the QEMU run with exit status 0 (`success`) or 1.
pub fn exit(success: bool) -> ! {
    semihosting::process::exit(if success { 0 } else { 1 })
}
