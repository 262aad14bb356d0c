//! The landing ragdoll image: the `f32` adult ragdoll thrown onto the floor and stepped by
//! `ImpulseStepper` with semi-implicit Euler inside and the ragdoll's 31 rows (13 floor
//! points, 18 joint limits), as the lockstep case does. `cargo xtask qemu` compares its
//! `.text` with that of `ragdoll-text`, the same run without the stepper.

#![no_std]
#![no_main]

use core::hint::black_box;

use lagrange_cases::ragdoll_thrown;
use lagrange_core::Error;
use lagrange_firmware::{entry, exit};
use lagrange_integrators::{
    ContactModel, ImpulseSettings, ImpulseStepper, Integrator, SemiImplicitEuler,
};
use lagrange_systems::{Ragdoll, RagdollBody, RagdollContacts};

/// Steps 1000 times at 1/240 s; the torso's height at the end.
fn run() -> Result<f32, Error> {
    let doll = Ragdoll::new(black_box(RagdollBody::adult()))?;
    let contacts = RagdollContacts::adult(&doll, black_box(0.0))?;
    let model = ContactModel::new(black_box(0.3), 0.3, 1.0)?.with_friction(black_box(0.8))?;
    let settings = ImpulseSettings::new(black_box(2e-3), black_box(4))?;
    let mut stepper = ImpulseStepper::new(SemiImplicitEuler, contacts, model, settings);
    let mut s = black_box(ragdoll_thrown());
    for _ in 0..black_box(1000) {
        s = stepper.step(&doll, &s, black_box(1.0 / 240.0))?;
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
