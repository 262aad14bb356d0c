//! The free ragdoll image: the `f32` adult ragdoll thrown and stepped by semi-implicit Euler,
//! no contacts. `cargo xtask qemu` compares its `.text` with that of `ragdoll-impulse-text`,
//! the same run with the impulse stepper around the same integrator: the difference is the
//! code the stepper and the ragdoll's 31 rows add.

#![no_std]
#![no_main]

use core::hint::black_box;

use lagrange_cases::ragdoll_thrown;
use lagrange_core::Error;
use lagrange_firmware::{entry, exit};
use lagrange_integrators::{Integrator, SemiImplicitEuler};
use lagrange_systems::{Ragdoll, RagdollBody};

/// Steps 1000 times at 1/240 s; the torso's height at the end.
fn run() -> Result<f32, Error> {
    let doll = Ragdoll::new(black_box(RagdollBody::adult()))?;
    let mut s = black_box(ragdoll_thrown());
    for _ in 0..black_box(1000) {
        s = SemiImplicitEuler.step(&doll, &s, black_box(1.0 / 240.0))?;
    }
    Ok(s.q[1])
}

#[entry]
fn main() -> ! {
    exit(black_box(run()).is_ok())
}

#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    exit(false)
}
