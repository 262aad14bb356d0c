//! A scene: 100 damped lamps on one 120 Hz clock, driven by 60 Hz frames. One swings and the
//! others hang still, asleep, costing nothing per frame; a push wakes one, it swings and falls
//! asleep again; the frame's cost follows the number awake.
//!
//! `cargo run --release --example scene`

use lagrange_integrators::prelude::*;
use lagrange_systems::SimplePendulum;
use std::time::Instant;

/// Capacity of the bank.
const LAMPS: usize = 100;

type Lamps = Bank<f32, 1, LAMPS, SimplePendulum<f32>, StormerVerlet<f32, 1>, Sleeps<f32>>;

fn main() -> Result<(), Error> {
    // Asleep once the kinetic energy is below 1e-6 J and the acceleration at rest below 1e-3
    // for 60 steps (half a second).
    let rule = Sleeps::new(1e-6_f32, 1e-3, 60)?;
    let mut lamps: Lamps = Bank::new(StormerVerlet::default(), rule)?;
    let lamp = SimplePendulum::new(1.0, 1.0, 9.81, 4.0)?;
    let swinging = lamps.add(lamp, State::at_rest([0.5]))?;
    let mut ids = vec![swinging];
    for _ in 1..LAMPS {
        ids.push(lamps.add_asleep(lamp, [0.0])?);
    }
    let mut scene = Scene::new(lamps, 1.0 / 120.0, 8)?;

    let frame = 1.0 / 60.0;
    for second in 0..12 {
        if second == 6 {
            // A push on lamp 50 wakes it.
            scene
                .banks_mut()
                .apply_impulse(ids[50], &SVector::from([2.0]))?;
            println!("t = 6 s: lamp 50 pushed");
        }
        let clock = Instant::now();
        for _ in 0..60 {
            scene.advance(frame)?;
        }
        let per_frame = clock.elapsed().as_secs_f64() / 60.0;
        let drawn = scene.banks().interpolated(swinging, scene.alpha())?;
        println!(
            "t = {} s: {:>3} of {LAMPS} awake, lamp 0 at {:+.4} rad, {:.2} us per frame",
            second + 1,
            scene.banks().awake(),
            drawn.q[0],
            per_frame * 1e6
        );
    }
    Ok(())
}
