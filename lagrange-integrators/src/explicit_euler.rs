//! Explicit (forward) Euler.

use crate::integrator::{check_run_step, check_step, finish, step_loop, Cost, Failure};
use crate::{Integrator, Method};
use lagrange_core::{Error, Lanes, Mechanism, Real, State};

/// Forward Euler: `q1 = q0 + h q'0`, `q'1 = q'0 + h q''0`.
///
/// Order 1, explicit, 1 acceleration evaluation per step. Not symplectic: an undamped
/// oscillator gains energy every step (by a factor `1 + (h w)^2` per step for a linear one), so
/// it is here as a baseline, not for long runs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ExplicitEuler;

impl Method for ExplicitEuler {
    const NAME: &'static str = "explicit Euler";
    const ORDER: u32 = 1;
    const COST: Cost = Cost::explicit(1);
    /// It moves by the old velocity alone.
    const POSITION_SHARE: f64 = 0.0;
}

impl<T: Real, const N: usize, M: Mechanism<T, N>> Integrator<T, N, M> for ExplicitEuler {
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
    let a = m.acceleration(s)?;
    finish(State {
        t: s.t + h,
        q: s.q + s.qd * h,
        qd: s.qd + a * h,
    })
}
