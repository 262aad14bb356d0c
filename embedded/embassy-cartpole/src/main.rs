//! A cart-pole model run as firmware is usually written: an embassy application for an
//! nRF52840 (a Cortex-M4F) that, every millisecond of a [`Ticker`], reads the pole's angle
//! from a sensor, corrects the model's state by it, and steps the model by RK4 in `f32`; it
//! logs with defmt (over RTT) ten times a second.
//!
//! The model is an observer: the sensor gives the angle only, and the model, kept on the
//! measurement by a fixed-gain correction, gives what the sensor does not (the pole's rate,
//! the cart's motion under the force it is driven with). The force is the one the firmware
//! commands (zero here; a controller would set it the same way, with
//! [`CartPole::set_force`], before the step).
//!
//! The sensor is a potentiometer on the hinge, read by the SAADC on AIN0 (P0.02): 12 bits
//! over 0 to 3.6 V (the SAADC's internal reference with gain 1/6), the middle of its travel
//! upright, [`RADIANS_PER_COUNT`] apart. A magnetic encoder over I2C would replace
//! [`read_angle`] alone.
//!
//! Why embassy rather than RTIC: one task that awaits the ticker and the sensor reads like
//! the loop it is, and the HAL's drivers are async; RTIC would fit as well, with the step in
//! a timer's interrupt handler.
//!
//! Timing: embassy-nrf's time driver counts the RTC at 32768 Hz, so the ticker's period of
//! 1 ms is 33 ticks, 1.0071 ms; the model is stepped by that period, not by 1 ms, so that its
//! time keeps up with the clock's. The RK4 step of the cart-pole in `f32` takes about 520
//! instructions on a Cortex-M4F (the lockstep case of `cargo xtask qemu`), under 1% of the
//! 64 MHz core's millisecond; the sample (about 10 us of acquisition and conversion) is
//! awaited, not computed. Each log line reports the slowest step of the last 100 (sample,
//! correction and step) and how many overran the period.
//!
//! Built by `cargo xtask cross`; QEMU has no nRF52 board, so it is not run there.

#![no_std]
#![no_main]

use defmt::{info, warn};
use embassy_executor::Spawner;
use embassy_nrf::saadc::{self, ChannelConfig, Saadc};
use embassy_nrf::{bind_interrupts, Peri};
use embassy_time::{Duration, Instant, Ticker, TICK_HZ};
use lagrange_core::{Error, State};
use lagrange_integrators::{Integrator, Rk4};
use lagrange_systems::CartPole;
use {defmt_rtt as _, panic_probe as _};

bind_interrupts!(struct Irqs {
    SAADC => saadc::InterruptHandler;
});

/// The loop's rate, Hz.
const RATE_HZ: u64 = 1000;

/// Steps between two log lines (ten lines a second).
const LOG_EVERY: u32 = 100;

/// The SAADC's count with the pole upright (the middle of 12 bits).
const UPRIGHT_COUNT: i16 = 2048;

/// The angle one count of the SAADC stands for: a potentiometer of 300 degrees of travel over
/// the full 4096 counts.
const RADIANS_PER_COUNT: f32 = 300.0 / 4096.0 * core::f32::consts::PI / 180.0;

/// The correction's bandwidth, rad/s: the model's angle and rate follow a measurement within
/// about `2 / BANDWIDTH` s, far faster than the pole falls (its time constant at the top is
/// `sqrt(4 l / 3 g)`, 0.26 s for the pole below).
const BANDWIDTH: f32 = 30.0;

/// The cart-pole's parameters: cart mass kg, pole mass kg, pole half-length m, gravity m/s^2.
const CART_POLE: (f32, f32, f32, f32) = (1.0, 0.1, 0.5, 9.81);

#[embassy_executor::main]
async fn main(_spawner: Spawner) {
    let p = embassy_nrf::init(Default::default());
    let mut adc = angle_sensor(p.SAADC, p.P0_02);
    adc.calibrate().await;

    let period = Duration::from_hz(RATE_HZ);
    // The period the ticker really keeps (a whole number of the time driver's ticks), s.
    let dt = period.as_ticks() as f32 / TICK_HZ as f32;
    info!("cart-pole observer: a step every {=f32} ms", dt * 1e3);

    let (cart_mass, pole_mass, half_length, gravity) = CART_POLE;
    let mut cart_pole = match CartPole::new(cart_mass, pole_mass, half_length, gravity) {
        Ok(cart_pole) => cart_pole,
        Err(e) => {
            warn!("bad cart-pole parameters: {}", e);
            return;
        }
    };
    let mut state = State::at_rest([0.0, read_angle(&mut adc).await]);
    let mut rk4 = Rk4;
    let mut ticker = Ticker::every(period);
    let mut steps: u32 = 0;
    let mut slowest = Duration::from_ticks(0);
    let mut late: u32 = 0;
    loop {
        ticker.next().await;
        let started = Instant::now();
        let measured = read_angle(&mut adc).await;
        // The force the cart is driven with during the coming step: none here.
        let force = 0.0;
        match observe(&mut rk4, &mut cart_pole, &state, measured, force, dt) {
            Ok(next) => state = next,
            Err(e) => {
                // A state the model cannot step from (not finite): start again from the
                // measurement, at rest.
                warn!("step failed ({}): restarting from the measured angle", e);
                state = State::at_rest([0.0, measured]);
            }
        }
        let took = Instant::now() - started;
        slowest = slowest.max(took);
        if took > period {
            late += 1;
        }
        steps = steps.wrapping_add(1);
        if steps % LOG_EVERY == 0 {
            info!(
                "t={=f32} s angle: measured {=f32} model {=f32} rad, rate {=f32} rad/s; cart \
                 {=f32} m {=f32} m/s; slowest step {=u64} us, {=u32} late",
                state.t,
                measured,
                state.q[1],
                state.qd[1],
                state.q[0],
                state.qd[0],
                slowest.as_micros(),
                late
            );
            slowest = Duration::from_ticks(0);
        }
    }
}

/// The SAADC reading the hinge's potentiometer on AIN0.
fn angle_sensor<'d>(
    saadc: Peri<'d, embassy_nrf::peripherals::SAADC>,
    ain0: Peri<'d, embassy_nrf::peripherals::P0_02>,
) -> Saadc<'d, 1> {
    Saadc::new(
        saadc,
        Irqs,
        saadc::Config::default(),
        [ChannelConfig::single_ended(ain0)],
    )
}

/// The pole's angle from the upward vertical, rad, as the potentiometer gives it.
async fn read_angle(adc: &mut Saadc<'_, 1>) -> f32 {
    let mut sample = [0i16; 1];
    adc.sample(&mut sample).await;
    f32::from(sample[0] - UPRIGHT_COUNT) * RADIANS_PER_COUNT
}

/// One step of the observer: the model's angle and rate pulled towards the measured angle
/// (gains `2 BANDWIDTH dt` and `BANDWIDTH^2 dt`: the error decays like a critically damped
/// oscillator of that bandwidth), the force set, and an RK4 step of `dt`.
fn observe(
    rk4: &mut Rk4,
    cart_pole: &mut CartPole<f32>,
    state: &State<f32, 2>,
    measured: f32,
    force: f32,
    dt: f32,
) -> Result<State<f32, 2>, Error> {
    let error = measured - state.q[1];
    let mut corrected = *state;
    corrected.q[1] += 2.0 * BANDWIDTH * dt * error;
    corrected.qd[1] += BANDWIDTH * BANDWIDTH * dt * error;
    cart_pole.set_force(force)?;
    rk4.step(cart_pole, &corrected, dt)
}
