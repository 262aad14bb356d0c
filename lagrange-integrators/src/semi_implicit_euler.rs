//! Semi-implicit (symplectic) Euler.

use crate::integrator::{check_run_step, check_step, finish, Cost};
use crate::{Integrator, Method};
use lagrange_core::{Error, Mechanism, Real, State};

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
}

impl<T: Real, const N: usize, M: Mechanism<T, N>> Integrator<T, N, M> for SemiImplicitEuler {
    fn step(&mut self, m: &M, s: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        kick_drift(m, s, check_step(s, dt)?)
    }

    fn run_step(&mut self, m: &M, s: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        kick_drift(m, s, check_run_step(s, dt)?)
    }
}

/// One step of `h` (checked) from `s`.
fn kick_drift<T: Real, const N: usize, M: Mechanism<T, N>>(
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
