//! Semi-implicit (symplectic) Euler.

use crate::integrator::{check_run_step, check_step, finish, step_loop, Cost, Failure};
use crate::{Integrator, Method};
use lagrange_core::{Error, Lanes, Mechanism, Real, State};

/// Semi-implicit Euler: `q'1 = q'0 + h q''(q0, q'0)`, then `q1 = q0 + h q'1`.
///
/// Order 1, explicit, 1 acceleration evaluation per step. Symplectic when the mass matrix is
/// constant and forces depend on `q` only (a separable Hamiltonian): then the energy error
/// stays bounded, `O(h)`, with no drift. With a configuration-dependent mass matrix (pendulum
/// chains) it updates `q'` rather than the momentum `p = M q'` and is not symplectic in
/// `(q, p)`, though it still behaves far better than explicit Euler.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SemiImplicitEuler;

impl Method for SemiImplicitEuler {
    const NAME: &'static str = "semi-implicit Euler";
    const ORDER: u32 = 1;
    const COST: Cost = Cost::explicit(1);
    /// It moves by the new velocity, `h (q'0 + h a)`.
    const POSITION_SHARE: f64 = 1.0;
}

impl<T: Real, const N: usize, M: Mechanism<T, N>> Integrator<T, N, M> for SemiImplicitEuler {
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
    let qd = s.qd + m.acceleration(s)? * h;
    finish(State {
        t: s.t + h,
        q: s.q + qd * h,
        qd,
    })
}
