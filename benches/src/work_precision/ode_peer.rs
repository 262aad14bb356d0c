//! The `ode_solvers` crate's Dopri5 and Dop853 driving a mechanism: its `acceleration` behind
//! `ode_solvers`' `System` trait, on a static vector of the whole state. The bench's method
//! for them is [`OdeSolvers`](super::method::OdeSolvers).

use super::outcome::{Observer, Outcome};
use lagrange_core::nalgebra as na;
use lagrange_core::{Error, Mechanism, Real, Scalar, State};
use ode_solvers::dop_shared::FloatNumber;
use ode_solvers::{Dop853, Dopri5, OutputType, System};
use std::cell::Cell;

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

/// A mechanism as an `ode_solvers` system.
struct Sys<'a, 'o, T: OdeReal, M, const N: usize> {
    mechanism: &'a M,
    /// The first error `acceleration` returned. The derivative is then NaN, which makes
    /// `ode_solvers`' controller reject the step and retry a smaller one (as a trial stage of
    /// a too-large step may leave the coordinates' domain, `r <= 0` for Kepler).
    failure: &'a Cell<Option<Error>>,
    observe: Observer<'o, T, N>,
}

/// The state at `t` from the whole-state vector `y`.
fn state<T: OdeReal, const N: usize, const N2: usize>(t: T, y: &Y<T, N2>) -> State<T, N> {
    State {
        t,
        q: na::SVector::from_fn(|i, _| y[i]),
        qd: na::SVector::from_fn(|i, _| y[N + i]),
    }
}

impl<T: OdeReal, M: Mechanism<T, N>, const N: usize, const N2: usize> System<T, Y<T, N2>>
    for Sys<'_, '_, T, M, N>
{
    fn system(&self, t: T, y: &Y<T, N2>, dy: &mut Y<T, N2>) {
        match self.mechanism.acceleration(&state(t, y)) {
            Ok(a) => {
                for i in 0..N {
                    dy[i] = y[N + i];
                    dy[N + i] = a[i];
                }
            }
            Err(e) => {
                if self.failure.get().is_none() {
                    self.failure.set(Some(e));
                }
                dy.fill(<T as Scalar>::from_f64(f64::NAN));
            }
        }
    }

    fn solout(&mut self, t: T, y: &Y<T, N2>, _dy: &Y<T, N2>) -> bool {
        if let Some(observe) = self.observe.as_mut() {
            observe(&state(t, y));
        }
        false
    }
}

/// Solves with `peer` from `start` to `t_end` at relative and absolute tolerance `tol`.
///
/// # Errors
/// `ode_solvers`' own (too many steps, step size underflow, stiffness detected), or the
/// mechanism's first error.
pub fn solve<T, M, const N: usize, const N2: usize>(
    peer: Peer,
    mechanism: &M,
    start: &State<T, N>,
    t_end: T,
    tol: T,
    observe: Observer<'_, T, N>,
) -> Result<Outcome<T, N>, String>
where
    T: OdeReal,
    f64: From<T>,
    M: Mechanism<T, N>,
{
    const { assert!(N2 == 2 * N, "N2 must be 2 N") };
    let y0 = Y::<T, N2>::from_fn(|i, _| if i < N { start.q[i] } else { start.qd[i - N] });
    let failure = Cell::new(None);
    let sys = Sys {
        mechanism,
        failure: &failure,
        observe,
    };
    let f = <T as Scalar>::from_f64;
    let (t0, span, zero) = (start.t, t_end - start.t, f(0.0));
    // Each method's defaults (safety, beta, fac_min, fac_max) as its `new` sets them, with
    // sparse output (every accepted step stored, no dense interpolation) and MAX_STEPS.
    let solved = match peer {
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
    };
    // A failed evaluation only rejected a trial step, unless the solve failed too.
    let (stats, t, y) = solved.map_err(|e| match failure.get() {
        Some(first) => format!("{e} (first failed evaluation: {first})"),
        None => e,
    })?;
    let end = state(t, &y);
    if end.is_finite() {
        Ok(Outcome {
            end,
            steps: u64::from(stats.accepted_steps + stats.rejected_steps),
            evals: None,
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
