//! Explicit (forward) Euler.

use crate::integrator::{check_run_step, check_step, finish, Cost};
use crate::{Integrator, Method};
use lagrange_core::{Error, Mechanism, Real, State};

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
}

impl<T: Real, const N: usize, M: Mechanism<T, N>> Integrator<T, N, M> for ExplicitEuler {
    fn step(&mut self, m: &M, s: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        euler(m, s, check_step(s, dt)?)
    }

    fn run_step(&mut self, m: &M, s: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        euler(m, s, check_run_step(s, dt)?)
    }
}

/// One step of `h` (checked) from `s`.
fn euler<T: Real, const N: usize, M: Mechanism<T, N>>(
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
