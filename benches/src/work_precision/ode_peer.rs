//! The `ode_solvers` crate's Dopri5 and Dop853 on a problem's equations of motion written by
//! hand ([`HandRhs`]), behind `ode_solvers`' `System` trait, on a static vector of the whole
//! state: the right-hand side a user of `ode_solvers` writes, so that a comparison with the
//! library measures the solvers alone. The bench's method for them is
//! [`OdeSolvers`](super::method::OdeSolvers).

use super::hand_rhs::HandRhs;
use super::outcome::{Observer, Outcome};
use lagrange_core::nalgebra as na;
use lagrange_core::{Error, Real, Scalar, State};
use ode_solvers::dop_shared::FloatNumber;
use ode_solvers::{Dop853, Dopri5, OutputType, System};

/// The whole state `(q, q')` as `ode_solvers` wants it (its own nalgebra version).
type Y<T, const N2: usize> = ode_solvers::SVector<T, N2>;

/// Most steps one solve may take before `ode_solvers` gives up (its default is 10^5, too few
/// for P4 at tight tolerances).
const MAX_STEPS: u32 = 10_000_000;

/// Which `ode_solvers` method.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Peer {
    /// Dormand-Prince 5(4).
    Dopri5,
    /// Dormand-Prince 8(5,3).
    Dop853,
}

impl Peer {
    /// Name for tables and legends.
    pub fn name(self) -> &'static str {
        match self {
            Self::Dopri5 => "ode_solvers Dopri5",
            Self::Dop853 => "ode_solvers Dop853",
        }
    }
}

/// A precision both the library and `ode_solvers` accept.
pub trait OdeReal: Real + FloatNumber {}

impl<T: Real + FloatNumber> OdeReal for T {}

/// Equations written by hand as an `ode_solvers` system.
pub struct Sys<'a, 'o, T: OdeReal, R, const N: usize> {
    rhs: &'a R,
    observe: Observer<'o, T, N>,
}

impl<'a, T: OdeReal, R, const N: usize> Sys<'a, '_, T, R, N> {
    /// The system of `rhs`, observing nothing.
    pub fn new(rhs: &'a R) -> Self {
        Self { rhs, observe: None }
    }
}

/// The state at `t` from the whole-state vector `y`.
fn state<T: OdeReal, const N: usize, const N2: usize>(t: T, y: &Y<T, N2>) -> State<T, N> {
    State {
        t,
        q: na::SVector::from_fn(|i, _| y[i]),
        qd: na::SVector::from_fn(|i, _| y[N + i]),
    }
}

impl<T: OdeReal, R: HandRhs<T, N>, const N: usize, const N2: usize> System<T, Y<T, N2>>
    for Sys<'_, '_, T, R, N>
{
    /// `y' = (q', q'')`: the rates copied, the accelerations from the hand-written equations.
    #[inline]
    fn system(&self, t: T, y: &Y<T, N2>, dy: &mut Y<T, N2>) {
        let (y, dy) = (y.as_slice(), dy.as_mut_slice());
        let (Some(q), Some(qd)) = (
            y.first_chunk::<N>(),
            y.get(N..).and_then(<[T]>::first_chunk::<N>),
        ) else {
            // N2 = 2 N (asserted where a solve starts): never taken.
            return dy.fill(<T as Scalar>::from_f64(f64::NAN));
        };
        let (rates, accelerations) = dy.split_at_mut(N);
        let mut a = [T::zero(); N];
        self.rhs.accelerations(t, q, qd, &mut a);
        rates.copy_from_slice(qd);
        accelerations.copy_from_slice(&a);
    }

    fn solout(&mut self, t: T, y: &Y<T, N2>, _dy: &Y<T, N2>) -> bool {
        if let Some(observe) = self.observe.as_mut() {
            observe(&state(t, y));
        }
        false
    }
}

/// Solves the equations `rhs` with `peer` from `start` to `t_end` at relative and absolute
/// tolerance `tol`.
///
/// # Errors
/// `ode_solvers`' own (too many steps, step size underflow, stiffness detected), or a final
/// state that is not finite.
pub fn solve<T, R, const N: usize, const N2: usize>(
    peer: Peer,
    rhs: &R,
    start: &State<T, N>,
    t_end: T,
    tol: T,
    observe: Observer<'_, T, N>,
) -> Result<Outcome<T, N>, String>
where
    T: OdeReal,
    f64: From<T>,
    R: HandRhs<T, N>,
{
    const { assert!(N2 == 2 * N, "N2 must be 2 N") };
    let y0 = Y::<T, N2>::from_fn(|i, _| if i < N { start.q[i] } else { start.qd[i - N] });
    let sys = Sys { rhs, observe };
    let f = <T as Scalar>::from_f64;
    let (t0, span, zero) = (start.t, t_end - start.t, f(0.0));
    // Each method's defaults (safety, beta, fac_min, fac_max) as its `new` sets them, with
    // sparse output (every accepted step stored, no dense interpolation) and MAX_STEPS.
    let (stats, t, y) = match peer {
        Peer::Dopri5 => {
            let mut s = Dopri5::from_param(
                sys,
                t0,
                t_end,
                span,
                y0,
                tol,
                tol,
                f(0.9),
                f(0.04),
                f(0.2),
                f(10.0),
                span,
                zero,
                MAX_STEPS,
                1000,
                OutputType::Sparse,
            );
            finish(s.integrate(), s.x_out(), s.y_out())
        }
        Peer::Dop853 => {
            let mut s = Dop853::from_param(
                sys,
                t0,
                t_end,
                span,
                y0,
                tol,
                tol,
                f(0.9),
                f(0.0),
                f(0.333),
                f(6.0),
                span,
                zero,
                MAX_STEPS,
                1000,
                OutputType::Sparse,
            );
            finish(s.integrate(), s.x_out(), s.y_out())
        }
    }?;
    let end = state(t, &y);
    if end.is_finite() {
        Ok(Outcome {
            end,
            steps: u64::from(stats.accepted_steps + stats.rejected_steps),
            evals: Some(u64::from(stats.num_eval)),
            work: None,
        })
    } else {
        Err(Error::NonFiniteState.to_string())
    }
}

/// The statistics and last stored point of a finished solve.
fn finish<T: OdeReal, const N2: usize>(
    result: Result<ode_solvers::dop_shared::Stats, ode_solvers::dop_shared::IntegrationError>,
    x: &[T],
    y: &[Y<T, N2>],
) -> Result<(ode_solvers::dop_shared::Stats, T, Y<T, N2>), String> {
    let stats = result.map_err(|e| format!("ode_solvers: {e}"))?;
    match (x.last(), y.last()) {
        (Some(&t), Some(&y)) => Ok((stats, t, y)),
        _ => Err("ode_solvers returned no output".into()),
    }
}
