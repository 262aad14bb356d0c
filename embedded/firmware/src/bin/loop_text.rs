//! The loop a scene replaces: 16 `f32` pendulums, each with its own parameters and its own
//! `FixedTimestep` stepping RK4 at 1/120 s from 60 Hz frames. `cargo xtask qemu` compares its `.text` with that of
//! `scene-text`, the same work done by a scene.

#![no_std]
#![no_main]

use core::hint::black_box;

use lagrange_core::{Error, State};
use lagrange_firmware::{entry, exit};
use lagrange_integrators::{FixedTimestep, Rk4};
use lagrange_systems::SimplePendulum;

/// Pendulums in the loop.
const K: usize = 16;

/// One 60 Hz frame of every pendulum: the loop a scene replaces (out of line, measured by
/// `cargo xtask qemu` as the symbol `loop_text::frame`).
#[inline(never)]
fn frame(pendulums: &mut [Pendulum; K]) -> Result<(), Error> {
    for (p, c) in pendulums {
        c.advance(p, black_box(1.0 / 60.0))?;
    }
    Ok(())
}

/// A pendulum and its clock.
type Pendulum = (SimplePendulum<f32>, FixedTimestep<f32, 1, Rk4>);

/// Builds the clocks and advances them 1000 frames; the first pendulum's angle at the end.
fn run() -> Result<f32, Error> {
    let p = SimplePendulum::new(black_box(1.0f32), 1.0, 9.81, 0.0)?;
    let clock = FixedTimestep::new(Rk4, 1.0 / 120.0, 4, State::at_rest([0.0]))?;
    let mut pendulums = [(p, clock); K];
    for (k, (_, c)) in pendulums.iter_mut().enumerate().skip(1) {
        c.reset(State::at_rest([0.05 * k as f32]))?;
    }
    for _ in 0..black_box(1000) {
        frame(&mut pendulums)?;
    }
    Ok(pendulums[0].1.current().q[0])
}

#[entry]
fn main() -> ! {
    exit(black_box(run()).is_ok())
}

#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    exit(false)
}
