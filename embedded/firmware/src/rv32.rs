//! RISC-V (RV32IMAC, RV32IMAFC): `minstret` as the counter, the stack pointer, a delay loop of
//! known length, and `abort`, which riscv-rt calls for every exception and interrupt without
//! a handler of its own.

pub use riscv_rt::entry;

use crate::exit;

/// `minstret`, the count of instructions retired (64 bits: it does not wrap).
pub struct Counter(());

impl Counter {
    /// The counter (on RISC-V there is nothing to take: `minstret` always runs in M mode).
    #[must_use]
    pub fn take() -> Option<Self> {
        Some(Self(()))
    }

    /// Runs `f` and returns its result with the instructions it retired.
    pub fn measure<R>(&mut self, f: impl FnOnce() -> R) -> (R, u64) {
        let before = riscv::register::minstret::read64();
        let result = f();
        let after = riscv::register::minstret::read64();
        (result, after.wrapping_sub(before))
    }
}

/// The stack pointer.
pub fn stack_pointer() -> u32 {
    let sp: u32;
    // SAFETY: copies `sp` into a register; reads no memory, writes nothing else.
    unsafe {
        core::arch::asm!("mv {0}, sp", out(reg) sp, options(nomem, nostack, preserves_flags))
    };
    sp
}

/// `iterations` more iterations of `addi; bne` than `spin(0)`: `riscv::asm::delay(n)`
/// (riscv 0.16) runs `1 + n / 2`.
pub fn spin(iterations: u32) {
    riscv::asm::delay(2 * iterations);
}

/// Ends the run with failure: riscv-rt's default target for exceptions and interrupts without
/// a handler (an illegal instruction, a load fault, ...).
#[no_mangle]
pub extern "C" fn abort() -> ! {
    exit(false)
}
