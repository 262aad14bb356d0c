//! Velocity Verlet (Stormer-Verlet, kick-drift-kick).

use crate::integrator::{check_run_step, check_step, finish, step_loop, Cost, Failure};
use crate::{Integrator, Method};
use lagrange_core::{Error, Lanes, Mechanism, Real, State};

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
    /// The same step over lanes: it keeps nothing between steps. Inlined whole into the
    /// caller (see [`Integrator::step_lanes`]).
    #[inline(always)]
    fn step_lanes<const L: usize, G: Mechanism<Lanes<T, L>, N>>(
        &self,
        mechanism: &G,
        state: &State<Lanes<T, L>, N>,
        dt: T,
    ) -> Option<Result<State<Lanes<T, L>, N>, Error>> {
        Some(match check_run_step(state, Lanes::splat(dt)) {
            Ok(h) => advance(mechanism, state, h),
            Err(e) => Err(e),
        })
    }

    fn step(&mut self, m: &M, s: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        let h = check_step(s, dt)?;
        advance(m, s, h)
    }

    fn run_step(&mut self, m: &M, s: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        advance(m, s, check_run_step(s, dt)?)
    }

    /// As the default, with `dt` and the start checked once rather than at every step (each
    /// step's end is checked, so the next step's start is known finite), as [`Rk4`](crate::Rk4)
    /// does.
    fn integrate_with<F: FnMut(&State<T, N>)>(
        &mut self,
        m: &M,
        state: &State<T, N>,
        dt: T,
        steps: u64,
        observe: F,
    ) -> Result<State<T, N>, Failure<T, N>> {
        step_loop(state, dt, steps, |s| advance(m, s, dt), observe)
    }
}

/// One step of `h` from `s`, unchecked but for the result.
#[inline(always)]
fn advance<T: Real, const N: usize, M: Mechanism<T, N>>(
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
