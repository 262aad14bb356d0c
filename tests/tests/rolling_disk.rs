//! The vertical rolling disk, two nonholonomic (Pfaffian) constraints: steady turning traces
//! the exact circle, energy is constant, and the velocity residual stays at rounding.

use lagrange_core::{Constrained, Constraints, Error, Lagrangian, Projection, Real};
use lagrange_integrators::{Integrator, Projected, Rk4};
use lagrange_systems::RollingDisk;
use lagrange_tests::{for_f32_and_f64, pick};

/// Radius 0.5 m, rolling at 4 rad/s (2 m/s) and turning at 1 rad/s: the contact point runs on
/// a circle of radius `R phi' / psi' = 2 m`, once round in 2 pi s.
const RADIUS: f64 = 0.5;
const ROLL: f64 = 4.0;
const TURN: f64 = 1.0;
const PSI0: f64 = 0.3;

/// RK4 + projection (velocity level: these rows have no position residual) at dt = 1e-3 for
/// 10 s against the exact motion
///
/// ```text
/// psi = psi0 + psi' t,  phi = phi' t,
/// x = rho (sin psi - sin psi0),  y = -rho (cos psi - cos psi0),  rho = R phi' / psi'
/// ```
///
/// f64: measured position error 3.3e-12 m (RK4's truncation), energy drift 1.8e-14 J (of 3 J),
/// velocity residual 2.2e-16 m/s (half an ulp of 2 m/s); bounds 1e-11 m, 5e-14 J, 2e-15 m/s
/// (~4 ulps). f32: adding `psi' dt = 1e-3` to a heading near 10 rad, whose ulp is 1e-6, rounds
/// with a bias that accumulates over 10^4 steps (as in the time `t` itself): measured 1.3e-3 m
/// (6e-4 rad of heading at 2 m), 1.6e-5 J, 1.2e-7 m/s (~1 ulp of 2 m/s); bounds 4e-3 m, 5e-5 J,
/// 5e-7 m/s.
fn steady_turn_is_the_exact_circle<T: Real>() -> Result<(), Error> {
    let disk = Constrained::new(RollingDisk::new(T::one(), T::from_f64(RADIUS))?);
    let start = disk.parts().rolling(
        T::zero(),
        [T::zero(), T::zero(), T::from_f64(PSI0), T::zero()],
        T::from_f64(TURN),
        T::from_f64(ROLL),
    )?;
    let e0 = disk.energy(&start);
    let rho = RADIUS * ROLL / TURN;
    let (mut d_pos, mut d_e, mut residual) = (0.0f64, 0.0f64, 0.0f64);
    let tol = T::from_f64(pick::<T>(1e-6, 1e-14));
    Projected::new(Rk4, Projection::new(tol, 2)?).integrate_with(
        &disk,
        &start,
        T::from_f64(1e-3),
        10_000,
        |s| {
            let t = s.t.to_f64();
            let psi = PSI0 + TURN * t;
            let (x, y) = (
                rho * (psi.sin() - PSI0.sin()),
                -rho * (psi.cos() - PSI0.cos()),
            );
            d_pos = d_pos
                .max((s.q[0].to_f64() - x).abs())
                .max((s.q[1].to_f64() - y).abs())
                .max((s.q[2].to_f64() - psi).abs() * rho);
            d_e = d_e.max((disk.energy(s) - e0).abs().to_f64());
            residual = residual.max(disk.residual(s).velocity.to_f64());
        },
    )?;
    println!(
        "rolling disk, 10 s: position error {d_pos:.2e} m, energy drift {d_e:.2e} J of {e0}, \
         velocity residual {residual:.2e} m/s"
    );
    assert!(d_pos < pick::<T>(4e-3, 1e-11), "{d_pos:e}");
    assert!(d_e < pick::<T>(5e-5, 5e-14), "{d_e:e}");
    assert!(residual < pick::<T>(5e-7, 2e-15), "{residual:e}");
    Ok(())
}

for_f32_and_f64!(steady_turn_is_the_exact_circle);
