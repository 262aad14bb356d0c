//! Velocity Verlet (Stormer-Verlet, kick-drift-kick).

use crate::integrator::{check_run_step, check_step, finish, Cost};
use crate::{Integrator, Method};
use lagrange_core::{Error, Mechanism, Real, State};

/// Velocity Verlet in kick-drift-kick form:
///
/// ```text
/// a0    = q''(t0, q0, q'0)
/// v     = q'0 + h/2 a0                 half kick
/// q1    = q0 + h v                     drift
/// a1    = q''(t0 + h, q1, q'0 + h a0)  velocity predicted by Euler
/// q'1   = v + h/2 a1                   half kick
/// ```
///
/// Order 2, explicit, 2 acceleration evaluations per step. Where the acceleration depends on
/// `q` only (constant mass matrix, conservative forces) `a1` does not see the predicted
/// velocity and this is exactly Stormer-Verlet: symplectic and time-reversible, with a bounded,
/// non-drifting `O(h^2)` energy error. Where it depends on `q'` (damping, the velocity-product
/// terms of a pendulum chain), evaluating `a1` at the Euler-predicted velocity keeps the method
/// second order (at the half-kick velocity it would fall to first order), but it is then
/// neither symplectic nor reversible.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct VelocityVerlet;

impl Method for VelocityVerlet {
    const NAME: &'static str = "velocity Verlet";
    const ORDER: u32 = 2;
    const COST: Cost = Cost::explicit(2);
}

impl<T: Real, const N: usize, M: Mechanism<T, N>> Integrator<T, N, M> for VelocityVerlet {
    fn step(&mut self, m: &M, s: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        kick_drift_kick(m, s, check_step(s, dt)?)
    }

    fn run_step(&mut self, m: &M, s: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        kick_drift_kick(m, s, check_run_step(s, dt)?)
    }
}

/// One step of `h` (checked) from `s`.
fn kick_drift_kick<T: Real, const N: usize, M: Mechanism<T, N>>(
    m: &M,
    s: &State<T, N>,
    h: T,
) -> Result<State<T, N>, Error> {
    let half = h * T::HALF;
    let a0 = m.acceleration(s)?;
    let v = s.qd + a0 * half;
    let t = s.t + h;
    let q = s.q + v * h;
    let a1 = m.acceleration(&State {
        t,
        q,
        qd: s.qd + a0 * h,
    })?;
    finish(State {
        t,
        q,
        qd: v + a1 * half,
    })
}
