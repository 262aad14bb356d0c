//! The one-mechanism image: the origin's pendulum in `f32` stepped by RK4 for
//! `lagrange_cases::STEPS` steps, exiting through semihosting with success when the run
//! succeeded. Its `.text` is the code size a firmware pays for one mechanism and one
//! integrator (`cargo xtask qemu` reports it, and runs it).

#![no_std]
#![no_main]

use lagrange_cases::{Case, PendulumSetup, STEPS};
use lagrange_firmware::{entry, exit};
use lagrange_integrators::Rk4;

/// The one case this image runs.
const CASE: Case = Case::new::<f32, 1, PendulumSetup, Rk4>();

#[entry]
fn main() -> ! {
    exit(CASE.run(STEPS).is_ok())
}

#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    exit(false)
}
