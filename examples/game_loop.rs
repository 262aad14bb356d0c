//! A game loop: a fixed-timestep clock steps a double pendulum at 1/120 s from frame times that
//! vary (a steady 60 Hz, a hitch, a long pause in a debugger), and the state to draw is
//! interpolated between the last two steps. The same loop drives an adaptive pair, which lands
//! on each step's time through its dense output.
//!
//! `cargo run --example game_loop`

use lagrange_integrators::prelude::*;
use lagrange_systems::DoublePendulum;

/// The frame times of the loop: mostly 60 Hz, with a 0.1 s hitch and a 5 s pause.
fn frame_times() -> impl Iterator<Item = f64> {
    (0..600).map(|i| match i {
        200 => 0.1,
        400 => 5.0,
        _ => 1.0 / 60.0,
    })
}

fn main() -> Result<(), Error> {
    let pendulum = DoublePendulum::new(1.0, 1.0, 1.0, 1.0, 9.81)?;
    let start = State::at_rest([1.0, 0.5]);
    let e0 = pendulum.energy(&start);

    // Stormer-Verlet at 120 Hz, at most 8 steps per frame: beyond that, time is dropped rather
    // than the frame rate spiralling down.
    let mut clock = FixedTimestep::new(StormerVerlet::default(), 1.0 / 120.0, 8, start)?;
    let (mut steps, mut dropped) = (0, 0.0);
    for (i, frame) in frame_times().enumerate() {
        let f = clock.advance(&pendulum, frame)?;
        steps += f.steps;
        dropped += f.dropped;
        let drawn = clock.interpolated();
        if i % 100 == 0 || f.dropped > 0.0 {
            println!(
                "frame {i:>3}: {} steps, draw at t = {:.4} s (alpha {:.2}), th1 = {:+.4}{}",
                f.steps,
                drawn.t,
                clock.alpha(),
                drawn.q[0],
                if f.dropped > 0.0 {
                    format!(", dropped {:.3} s", f.dropped)
                } else {
                    String::new()
                }
            );
        }
    }
    let end = clock.current();
    println!(
        "Stormer-Verlet: {steps} steps, {dropped:.3} s dropped, t = {:.6} s, energy error {:.2e}",
        end.t,
        (pendulum.energy(end) - e0) / e0.abs()
    );

    // The same loop with an adaptive pair: its own steps as long as the tolerance allows, each
    // fixed step's state from its continuous extension.
    let adaptive = DormandPrince853::new(AdaptiveSettings::new(1e-9, 1e-12)?);
    let mut clock = FixedTimestep::new(adaptive, 1.0 / 120.0, 8, start)?;
    for frame in frame_times() {
        clock.advance(&pendulum, frame)?;
    }
    let end = clock.current();
    println!(
        "DOP853 at rtol 1e-9: t = {:.6} s, energy error {:.2e}",
        end.t,
        (pendulum.energy(end) - e0) / e0.abs()
    );
    Ok(())
}
