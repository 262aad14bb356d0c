//! The panic-free check: steps every shipped mechanism with every shipped integrator, in `f32`
//! and `f64`, plus the automatic Euler-Lagrange path with a damping force, from inputs the
//! optimiser cannot see (`black_box`), with `panic-never` as the panic handler. That handler
//! references an undefined symbol, so the image links only if the optimised stepping code holds
//! no panic path at all (no bounds check, unwrap or overflow check left). `cargo xtask qemu`
//! builds it in release (opt-level 3) and runs it.

#![no_std]
#![no_main]

use core::hint::black_box;

use cortex_m_rt::{entry, exception, ExceptionFrame};
use lagrange_core::{Error, EulerLagrange, Mechanism, Real, State, ViscousDamping};
use lagrange_firmware::exit;
use lagrange_integrators::{ExplicitEuler, Integrator, Rk4, SemiImplicitEuler, VelocityVerlet};
use lagrange_systems::{BeadOnRotatingHoop, DoublePendulum, FallingParticle, SimplePendulum};
use panic_never as _;

/// Steps per run: the count is opaque to the optimiser anyway.
const STEPS: u32 = 10;

/// `STEPS` steps of `m` from `start` with every shipped integrator; `true` when all succeed.
fn every_integrator<T: Real, const N: usize, M: Mechanism<T, N>>(
    m: &M,
    start: State<T, N>,
) -> bool {
    fn run<T: Real, const N: usize, M: Mechanism<T, N>, I: Integrator<T, N>>(
        mut integrator: I,
        m: &M,
        start: State<T, N>,
    ) -> Result<State<T, N>, Error> {
        let dt = black_box(T::from_f64(1e-3));
        let mut s = black_box(start);
        for _ in 0..black_box(STEPS) {
            s = integrator.step(black_box(m), &s, dt)?;
        }
        Ok(black_box(s))
    }
    run(ExplicitEuler, m, start).is_ok()
        & run(SemiImplicitEuler, m, start).is_ok()
        & run(VelocityVerlet, m, start).is_ok()
        & run(Rk4, m, start).is_ok()
}

/// Every shipped mechanism, and the automatic path, in `T`; `true` when every run succeeds.
fn every_mechanism<T: Real>() -> Result<bool, Error> {
    let v = |x: f64| black_box(T::from_f64(x));
    let pendulum = SimplePendulum::new(v(1.0), v(1.0), v(9.81), v(0.1))?;
    let automatic = EulerLagrange::new(SimplePendulum::new(v(1.0), v(1.0), v(9.81), v(0.0))?)
        .with_force(ViscousDamping::uniform(v(0.1))?);
    Ok(every_integrator(
        &FallingParticle::new(v(1.0), v(9.81))?,
        State::at_rest([v(1.0)]),
    ) & every_integrator(&pendulum, State::at_rest([v(0.5)]))
        & every_integrator(
            &BeadOnRotatingHoop::new(v(1.0), v(1.0), v(5.0), v(9.81))?,
            State::at_rest([v(0.5)]),
        )
        & every_integrator(
            &DoublePendulum::new(v(1.0), v(1.0), v(1.0), v(1.0), v(9.81))?,
            State::at_rest([v(1.5), v(-1.5)]),
        )
        & every_integrator(&automatic, State::at_rest([v(0.5)])))
}

#[entry]
fn main() -> ! {
    let f32_ok = matches!(every_mechanism::<f32>(), Ok(true));
    let f64_ok = matches!(every_mechanism::<f64>(), Ok(true));
    exit(f32_ok && f64_ok)
}

#[exception]
unsafe fn HardFault(_frame: &ExceptionFrame) -> ! {
    exit(false)
}
