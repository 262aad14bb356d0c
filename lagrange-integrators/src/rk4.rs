//! The classical fourth-order Runge-Kutta method.

use crate::integrator::{check_run_step, check_step, finish, step_loop, Cost, Failure};
use crate::{Integrator, Method};
use lagrange_core::{Error, Lanes, Mechanism, Real, State};

/// Classical Runge-Kutta on `y = (q, q')`, `y' = (q', q'')`:
///
/// ```text
///  0  |
/// 1/2 | 1/2
/// 1/2 |  0   1/2
///  1  |  0    0    1
/// ----+--------------------
///     | 1/6  1/3  1/3  1/6
/// ```
///
/// Order 4, explicit, 4 acceleration evaluations per step. Not symplectic: for a conservative
/// system the energy error is tiny per step (`O(h^5)`) but drifts, usually downwards, linearly
/// in time. The best accuracy per evaluation of the fixed-step explicit methods here for short
/// and medium runs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Rk4;

impl Method for Rk4 {
    const NAME: &'static str = "RK4";
    const ORDER: u32 = 4;
    const COST: Cost = Cost::explicit(4);
}

impl<T: Real, const N: usize, M: Mechanism<T, N>> Integrator<T, N, M> for Rk4 {
    /// The same step over lanes: it keeps nothing between steps.
    fn step_lanes<const L: usize, G: Mechanism<Lanes<T, L>, N>>(
        &self,
        mechanism: &G,
        state: &State<Lanes<T, L>, N>,
        dt: T,
    ) -> Option<Result<State<Lanes<T, L>, N>, Error>> {
        Some(Integrator::<Lanes<T, L>, N, G>::run_step(
            &mut Rk4,
            mechanism,
            state,
            Lanes::splat(dt),
        ))
    }

    fn step(&mut self, m: &M, s: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        let h = check_step(s, dt)?;
        finish(stages(m, s, h)?)
    }

    fn run_step(&mut self, m: &M, s: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        let h = check_run_step(s, dt)?;
        finish(stages(m, s, h)?)
    }

    /// As the default, with `dt` and the start checked once (each step's end is checked, so
    /// the next step's start is known finite) and the stages inlined into the loop: a call per
    /// step cost a quarter of a pendulum's RK4 step.
    fn integrate_with<F: FnMut(&State<T, N>)>(
        &mut self,
        m: &M,
        state: &State<T, N>,
        dt: T,
        steps: u64,
        observe: F,
    ) -> Result<State<T, N>, Failure<T, N>> {
        step_loop(state, dt, steps, |s| finish(stages(m, s, dt)?), observe)
    }
}

/// One step of `h` from `s`, unchecked.
#[inline(always)]
fn stages<T: Real, const N: usize, M: Mechanism<T, N>>(
    m: &M,
    s: &State<T, N>,
    h: T,
) -> Result<State<T, N>, Error> {
    let half = h * T::HALF;
    let sixth = h / T::from_f64(6.0);
    let t_mid = s.t + half;
    let t_end = s.t + h;

    // k_i = (dq_i, dv_i): the derivatives of q and q' at stage i.
    let (dq1, dv1) = (s.qd, m.acceleration(s)?);
    let s2 = State {
        t: t_mid,
        q: s.q + dq1 * half,
        qd: s.qd + dv1 * half,
    };
    let (dq2, dv2) = (s2.qd, m.acceleration(&s2)?);
    let s3 = State {
        t: t_mid,
        q: s.q + dq2 * half,
        qd: s.qd + dv2 * half,
    };
    let (dq3, dv3) = (s3.qd, m.acceleration(&s3)?);
    let s4 = State {
        t: t_end,
        q: s.q + dq3 * h,
        qd: s.qd + dv3 * h,
    };
    let (dq4, dv4) = (s4.qd, m.acceleration(&s4)?);

    Ok(State {
        t: t_end,
        q: s.q + (dq1 + (dq2 + dq3) * T::TWO + dq4) * sixth,
        qd: s.qd + (dv1 + (dv2 + dv3) * T::TWO + dv4) * sixth,
    })
}
