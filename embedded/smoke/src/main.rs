//! Smoke firmware: links the lagrange crates into a `no_std`, `no_main` binary for
//! `thumbv7em-none-eabihf` with no global allocator, so that any use of `alloc` anywhere in the
//! library crates fails to link. `cargo xtask cross` builds it and reports its size.

#![no_std]
#![no_main]

use core::hint::black_box;
use core::panic::PanicInfo;

use cortex_m_rt::entry;
use lagrange_core::{Error, State};
use lagrange_integrators::{Integrator, Rk4, VelocityVerlet};
use lagrange_systems::{DoublePendulum, SimplePendulum};

/// Steps taken by each integrator.
const STEPS: u32 = 1000;

/// A damped simple pendulum in `f32`, stepped with RK4 from 0.5 rad at rest.
fn simple_pendulum() -> Result<State<f32, 1>, Error> {
    let pendulum = SimplePendulum::new(1.0_f32, 1.0, 9.81, 0.05)?;
    let mut state = State::new(0.0, [black_box(0.5)], [0.0]);
    let mut rk4 = Rk4;
    for _ in 0..STEPS {
        state = rk4.step(&pendulum, &state, black_box(1e-3))?;
    }
    Ok(state)
}

/// A double pendulum in `f64`, stepped with velocity Verlet from (0.5, -0.5) rad at rest.
fn double_pendulum() -> Result<State<f64, 2>, Error> {
    let pendulum = DoublePendulum::new(1.0_f64, 1.0, 1.0, 1.0, 9.81)?;
    let mut state = State::new(0.0, [black_box(0.5), black_box(-0.5)], [0.0, 0.0]);
    let mut verlet = VelocityVerlet;
    for _ in 0..STEPS {
        state = verlet.step(&pendulum, &state, black_box(1e-3))?;
    }
    Ok(state)
}

/// Runs both mechanisms once, keeps their results alive, then idles.
#[entry]
fn main() -> ! {
    match simple_pendulum() {
        Ok(state) => {
            black_box(state);
        }
        Err(e) => {
            black_box(e);
        }
    }
    match double_pendulum() {
        Ok(state) => {
            black_box(state);
        }
        Err(e) => {
            black_box(e);
        }
    }
    loop {
        core::hint::spin_loop();
    }
}

/// Any panic parks the core.
#[panic_handler]
fn panic(_info: &PanicInfo) -> ! {
    loop {
        core::hint::spin_loop();
    }
}
