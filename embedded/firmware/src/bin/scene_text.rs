//! The scene image: 16 `f32` pendulums in a bank that never sleeps, stepped by RK4 at
//! 1/120 s from 60 Hz frames by a `Scene`. Its `.text` is compared by `cargo xtask qemu` with
//! that of `loop-text`, the loop it replaces (a `FixedTimestep` per pendulum): a scene without
//! sleeping must be no bigger.

#![no_std]
#![no_main]

use core::hint::black_box;

use lagrange_core::{Error, State};
use lagrange_firmware::{entry, exit};
use lagrange_integrators::scene::{Bank, NeverSleeps, Scene};
use lagrange_integrators::Rk4;
use lagrange_systems::SimplePendulum;

/// Pendulums in the bank.
const K: usize = 16;

/// The scene of this image.
type Pendulums<'a> = Scene<f32, &'a mut Bank<f32, 1, K, SimplePendulum<f32>, Rk4>>;

/// One 60 Hz frame: the code that replaces the loop of `loop-text` (kept out of line, so
/// that `cargo xtask qemu` can measure it: the symbol `scene_text::frame`).
#[inline(never)]
fn frame(scene: &mut Pendulums<'_>) -> Result<(), Error> {
    scene.advance(black_box(1.0 / 60.0)).map(|_| ())
}

/// Builds the scene and advances it 1000 frames; the first pendulum's angle at the end.
fn run() -> Result<f32, Error> {
    let p = SimplePendulum::new(black_box(1.0f32), 1.0, 9.81, 0.0)?;
    let mut bank: Bank<f32, 1, K, SimplePendulum<f32>, Rk4> = Bank::new(Rk4, NeverSleeps)?;
    let first = bank.add(p, State::at_rest([0.0]))?;
    for k in 1..K {
        bank.add(p, State::at_rest([0.05 * k as f32]))?;
    }
    // The scene borrows the bank rather than taking it: no copy of its slots.
    let mut scene = Scene::new(&mut bank, 1.0 / 120.0, 4)?;
    for _ in 0..black_box(1000) {
        frame(&mut scene)?;
    }
    Ok(scene.banks().state(first)?.q[0])
}

#[entry]
fn main() -> ! {
    exit(black_box(run()).is_ok())
}

#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    exit(false)
}
