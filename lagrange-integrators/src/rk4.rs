//! The classical fourth-order Runge-Kutta method.

use crate::integrator::{
    check_run_step, check_step, finish, step_loop, unobserved_loop, Cost, Failure,
};
use crate::{Integrator, Method};
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, Lanes, Mechanism, NoForce, Real, State};

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
///
/// A run that nothing observes ([`Integrator::integrate`]) of 5 coordinates or more tests one
/// state in 8 for finiteness rather than every state (a component once NaN or infinite stays
/// so through `y1 = y0 + ...`), and takes the steps since the last tested state again, each
/// tested, when a test or a step fails: its outcome, error, failed step and last good state
/// are those of a run tested at every step, bit for bit. A step that fails on a finite state
/// fails at once (every state before it was finite); only a run whose state turns NaN or
/// infinite evaluates the law again, up to 8 steps' worth, which a law that is not a pure
/// function of the state (one that counts its calls) would see.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Rk4;

impl Method for Rk4 {
    const NAME: &'static str = "RK4";
    const ORDER: u32 = 4;
    const COST: Cost = Cost::explicit(4);
}

impl<T: Real, const N: usize, M: Mechanism<T, N>> Integrator<T, N, M> for Rk4 {
    /// The same step over lanes: it keeps nothing between steps. Inlined whole into the
    /// caller (see [`Integrator::step_lanes`]).
    #[inline(always)]
    fn step_lanes<const L: usize, G: Mechanism<Lanes<T, L>, N>>(
        &self,
        mechanism: &G,
        state: &State<Lanes<T, L>, N>,
        dt: T,
    ) -> Option<Result<State<Lanes<T, L>, N>, Error>> {
        Some(run_step(mechanism, state, Lanes::splat(dt)))
    }

    fn step(&mut self, m: &M, s: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        let h = check_step(s, dt)?;
        finish(stages(m, s, h)?)
    }

    fn run_step(&mut self, m: &M, s: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        run_step(m, s, dt)
    }

    /// As the default, with `dt` and the start checked once; from 5 coordinates the states
    /// are tested one in 8 (see the type's docs).
    fn integrate(
        &mut self,
        m: &M,
        state: &State<T, N>,
        dt: T,
        steps: u64,
    ) -> Result<State<T, N>, Failure<T, N>> {
        // A test of a few coordinates costs less than the chunked loop (a pendulum's run
        // measured 4% slower chunked); from 5 the test is what costs.
        if N > 4 {
            unobserved_loop(state, dt, steps, |s| stages(m, s, dt))
        } else {
            self.integrate_with(m, state, dt, steps, |_| {})
        }
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

/// [`Integrator::run_step`], over plain numbers or lanes.
#[inline(always)]
fn run_step<T: Real, const N: usize, M: Mechanism<T, N>>(
    m: &M,
    s: &State<T, N>,
    dt: T,
) -> Result<State<T, N>, Error> {
    finish(stages(m, s, check_run_step(s, dt)?)?)
}

/// One step of `h` from `s`, unchecked.
///
/// Each stage's state and the new state are formed component by component in one loop (each a
/// straight loop over plain slices, which vectorises), not by whole-vector operations, each of
/// which went through memory on its own: at 14 and more coordinates those passes cost as much
/// as a cheap right-hand side. The arithmetic is that of the formulas, in their order.
#[inline(always)]
#[allow(clippy::needless_range_loop)] // the formulas over six slices at once
fn stages<T: Real, const N: usize, M: Mechanism<T, N>>(
    m: &M,
    s: &State<T, N>,
    h: T,
) -> Result<State<T, N>, Error> {
    let half = h * T::HALF;
    let sixth = h / T::from_f64(6.0);
    let t_mid = s.t + half;
    let t_end = s.t + h;

    // k_i = (dq_i, dv_i): the derivatives of q and q' at stage i; dq_i is the stage's q'.
    let dv1 = stage_law(m, s)?;
    let s2 = shifted(s, t_mid, &s.qd, &dv1, half);
    let dv2 = stage_law(m, &s2)?;
    let s3 = shifted(s, t_mid, &s2.qd, &dv2, half);
    let dv3 = stage_law(m, &s3)?;
    let s4 = shifted(s, t_end, &s3.qd, &dv3, h);
    let dv4 = stage_law(m, &s4)?;

    let mut end = State { t: t_end, ..*s };
    let (q, qd) = (end.q.as_mut_slice(), end.qd.as_mut_slice());
    let (q0, v0) = (s.q.as_slice(), s.qd.as_slice());
    let (dq2, dq3, dq4) = (s2.qd.as_slice(), s3.qd.as_slice(), s4.qd.as_slice());
    let (dv1, dv2, dv3, dv4) = (
        dv1.as_slice(),
        dv2.as_slice(),
        dv3.as_slice(),
        dv4.as_slice(),
    );
    for i in 0..N {
        q[i] = q0[i] + (v0[i] + (dq2[i] + dq3[i]) * T::TWO + dq4[i]) * sixth;
        qd[i] = v0[i] + (dv1[i] + (dv2[i] + dv3[i]) * T::TWO + dv4[i]) * sixth;
    }
    Ok(end)
}

/// A stage's accelerations. Above four coordinates, the law itself ([`Mechanism::law`]), not
/// [`Mechanism::acceleration`], which would test them for finiteness: a stage that is not
/// finite makes the new state not finite, which every caller refuses ([`finish`], or the
/// chunk's test of an unobserved run), so the
/// four tests per step are redundant, and they cost a tenth of a step of a 28-coordinate
/// N-body (f32 RK4 against the hand-written loop: 1.25 to 1.09 times). At four and fewer they
/// cost nothing measurable, and leaving them out made the f64 pendulum's loop compile 13%
/// slower (44 to 50 ns a step: the same arithmetic, scheduled differently), so they stay. A
/// law's own errors come back as before.
#[inline(always)]
fn stage_law<T: Real, const N: usize, M: Mechanism<T, N>>(
    m: &M,
    s: &State<T, N>,
) -> Result<SVector<T, N>, Error> {
    if N > 4 {
        m.law(s, &NoForce)
    } else {
        m.acceleration(s)
    }
}

/// The stage state `(t, s.q + dq h, s.q' + dv h)`, in one loop over the components.
#[inline(always)]
#[allow(clippy::needless_range_loop)] // the formulas over four slices at once
fn shifted<T: Real, const N: usize>(
    s: &State<T, N>,
    t: T,
    dq: &SVector<T, N>,
    dv: &SVector<T, N>,
    h: T,
) -> State<T, N> {
    let mut out = State { t, ..*s };
    let (q, qd) = (out.q.as_mut_slice(), out.qd.as_mut_slice());
    let (q0, v0, dq, dv) = (
        s.q.as_slice(),
        s.qd.as_slice(),
        dq.as_slice(),
        dv.as_slice(),
    );
    for i in 0..N {
        q[i] = q0[i] + dq[i] * h;
        qd[i] = v0[i] + dv[i] * h;
    }
    out
}
