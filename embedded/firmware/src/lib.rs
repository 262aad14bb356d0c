//! What the firmware binaries share: an instruction counter (SysTick under QEMU's `-icount`),
//! a stack high-water probe (stack painting) and the exit through semihosting.
//!
//! Under `qemu-system-arm -icount shift=0` every guest instruction advances the virtual clock
//! by 1 ns, and SysTick, clocked from the CPU clock, counts that virtual time: a count of
//! SysTick ticks is a count of instructions, at a fixed number of instructions per tick that
//! the lockstep binary calibrates against a loop of known length (`cortex_m::asm::delay`).

#![no_std]

use core::ptr;

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;

/// SysTick as a 24-bit down-counter of instruction-clock ticks.
pub struct Counter {
    syst: SYST,
}

/// SysTick's reload value: the full 24 bits.
const RELOAD: u32 = 0x00ff_ffff;

impl Counter {
    /// Starts SysTick free-running from the processor clock, without its interrupt.
    #[must_use]
    pub fn start(mut syst: SYST) -> Self {
        syst.set_clock_source(SystClkSource::Core);
        syst.set_reload(RELOAD);
        syst.clear_current();
        syst.disable_interrupt();
        syst.enable_counter();
        Self { syst }
    }

    /// Runs `f` and returns its result with the ticks it took, or `None` for the ticks when
    /// the counter wrapped (2^24 ticks or more, which no measured run comes near).
    ///
    /// The counter restarts from the top first: COUNTFLAG is set whenever it passes zero, so
    /// a free-running counter would flag a run of any length that happened to cross zero.
    pub fn measure<R>(&mut self, f: impl FnOnce() -> R) -> (R, Option<u32>) {
        // Writing the current value clears it and COUNTFLAG; it reloads at the next tick.
        self.syst.clear_current();
        while SYST::get_current() == 0 {}
        // Reading the control register clears COUNTFLAG (in case the reload set it).
        let _ = self.syst.has_wrapped();
        let before = SYST::get_current();
        let result = f();
        let after = SYST::get_current();
        let wrapped = self.syst.has_wrapped();
        let ticks = before.wrapping_sub(after) & RELOAD;
        (result, if wrapped { None } else { Some(ticks) })
    }
}

/// The word painted below the stack pointer before a run.
const PAINT: u32 = 0xdead_beef;

/// How far below the stack pointer the probe paints, bytes: far more than any case uses (the
/// ragdoll landing, the deepest, uses over 32 KiB), far less than the 4 MiB of RAM. A mark of
/// the whole depth means the probe was too shallow.
pub const PAINT_DEPTH: u32 = 256 * 1024;

/// Runs `f` and returns its result with its stack high-water mark: the bytes below this
/// function's stack pointer that `f` (and all it calls) wrote.
///
/// Paints [`PAINT_DEPTH`] bytes below the stack pointer, calls `f`, then finds the lowest word
/// no longer holding the paint. A word that `f` wrote with the paint value itself would be
/// missed, so the figure is a lower bound in principle; in practice stack frames do not hold
/// `0xdeadbeef`.
#[inline(never)]
pub fn stack_high_water<R>(f: impl FnOnce() -> R) -> (R, u32) {
    let top = cortex_m::register::msp::read();
    let bottom = top - PAINT_DEPTH;
    // SAFETY: the words from `bottom` up to `top` are below the stack pointer of this frame:
    // no live data is there (interrupts are not enabled, and this loop calls nothing), and the
    // 4 MiB of RAM under the stack top leave room for `PAINT_DEPTH`.
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
