//! Cortex-M (M0+, M4F, M33): SysTick as the counter, the main stack pointer, a delay loop of
//! known length, and the HardFault handler.

use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;
use cortex_m_rt::{exception, ExceptionFrame};

pub use cortex_m_rt::entry;

use crate::exit;

/// SysTick counting ticks of the core clock, extended to 64 bits by its interrupt, which
/// counts the times it passes zero (the M0+'s soft-float runs take more than the 2^24 ticks of
/// the bare counter).
pub struct Counter(());

/// SysTick's reload value: the full 24 bits. The counter passes zero every `RELOAD + 1` ticks
/// (671 million instructions on the M4F), so the handler below runs rarely: a measured run
/// that crosses zero also counts its few instructions, and may find an exception frame on its
/// stack (up to 104 B with the FPU's state).
const RELOAD: u32 = 0x00ff_ffff;

/// Times SysTick has passed zero since [`Counter::take`].
static WRAPS: AtomicU32 = AtomicU32::new(0);

#[exception]
fn SysTick() {
    // A load and a store: ARMv6-M has no atomic read-modify-write, and only this handler
    // writes the count.
    WRAPS.store(
        WRAPS.load(Ordering::Relaxed).wrapping_add(1),
        Ordering::Relaxed,
    );
}

impl Counter {
    /// Takes SysTick (`None` when the core peripherals were taken already) and starts it
    /// free-running from the processor clock, with its interrupt.
    #[must_use]
    pub fn take() -> Option<Self> {
        let mut syst = cortex_m::Peripherals::take()?.SYST;
        syst.set_clock_source(SystClkSource::Core);
        syst.set_reload(RELOAD);
        syst.clear_current();
        syst.enable_interrupt();
        syst.enable_counter();
        Some(Self(()))
    }

    /// Ticks since the counter's first reload.
    ///
    /// The count of zeros and the counter are read until the count is the same on both sides
    /// of the counter's read and the counter is not at zero: at zero the interrupt has already
    /// counted the period that is still ending. Within a period the counter runs down from
    /// `RELOAD`, so the ticks are `RELOAD + 1` per zero passed plus `RELOAD - current`.
    fn now() -> u64 {
        loop {
            let wraps = WRAPS.load(Ordering::Relaxed);
            let current = SYST::get_current();
            if current != 0 && WRAPS.load(Ordering::Relaxed) == wraps {
                return u64::from(wraps) * (u64::from(RELOAD) + 1) + u64::from(RELOAD - current);
            }
        }
    }

    /// Runs `f` and returns its result with the ticks it took.
    pub fn measure<R>(&mut self, f: impl FnOnce() -> R) -> (R, u64) {
        let before = Self::now();
        let result = f();
        let after = Self::now();
        (result, after - before)
    }
}

/// The main stack pointer.
pub fn stack_pointer() -> u32 {
    cortex_m::register::msp::read()
}

/// `iterations` more iterations of `subs; bne` than `spin(0)`: `cortex_m::asm::delay(n)`
/// (cortex-m 0.7.10) runs `n + 1`.
pub fn spin(iterations: u32) {
    cortex_m::asm::delay(iterations);
}

#[exception]
unsafe fn HardFault(_frame: &ExceptionFrame) -> ! {
    exit(false)
}
