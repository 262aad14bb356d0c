//! The [`Method`] contract of the bench (a way of solving a problem over `[0, T]` at a step size
//! or a tolerance) and the methods table.

use super::ode_peer::{OdeSolvers, Peer};
use super::problem::Problem;
use super::real::BenchReal;
use lagrange_core::{Error, Mechanism, Real, State};
use lagrange_integrators::{ExplicitEuler, Integrator, Rk4, SemiImplicitEuler, VelocityVerlet};

/// Whose code a method is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Origin {
    /// lagrange's own integrators.
    Library,
    /// A plain loop written by hand for one problem: the speed limit.
    HandWritten,
    /// The `ode_solvers` crate.
    OdeSolvers,
}

impl Origin {
    /// For tables.
    pub fn label(self) -> &'static str {
        match self {
            Self::Library => "lagrange",
            Self::HandWritten => "hand-written",
            Self::OdeSolvers => "ode_solvers",
        }
    }
}

/// What a method's sweep varies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A fixed step `dt`, swept from the problem's coarsest step down by halves.
    FixedStep,
    /// An error tolerance (relative = absolute), swept down by decades.
    Adaptive,
}

/// One point of a sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Param {
    /// `steps` steps of `dt`, with `dt * steps` the final time.
    Step {
        /// Step size, s.
        dt: f64,
        /// Number of steps.
        steps: u64,
    },
    /// Relative and absolute tolerance.
    Tolerance(f64),
}

impl Param {
    /// `dt` or the tolerance.
    pub fn value(self) -> f64 {
        match self {
            Self::Step { dt, .. } => dt,
            Self::Tolerance(tol) => tol,
        }
    }
}

/// What a solve returns.
pub struct Outcome<T: Real, const N: usize> {
    /// The state at the final time.
    pub end: State<T, N>,
    /// Steps taken (accepted and rejected, for adaptive methods).
    pub steps: u64,
    /// Acceleration evaluations, when the method counts them itself (otherwise the runner
    /// counts calls to `Mechanism::acceleration`).
    pub evals: Option<u64>,
}

/// An observer of every state a solve passes through (`None` in timed runs).
pub type Observer<'a, T, const N: usize> = Option<&'a mut dyn FnMut(&State<T, N>)>;

/// A way of solving a problem: an integrator of the library, a hand-written loop, another
/// crate's solver.
pub trait Method {
    /// Name for tables and legends.
    fn name(&self) -> &'static str;
    /// Whose code it is.
    fn origin(&self) -> Origin;
    /// Fixed step or adaptive.
    fn kind(&self) -> Kind;
    /// For an explicit fixed-step method, the largest `h w` for which it is stable on an
    /// undamped linear oscillator of frequency `w` (`0` when no step is: explicit Euler).
    fn linear_stability_limit(&self) -> Option<f64> {
        None
    }
    /// Solves `problem` (whose mechanism in `T` is `mechanism`, possibly wrapped) from `start`
    /// to `t_end` at `param`, calling `observe` with every new state when given.
    ///
    /// `None` when the method does not apply to the problem (a hand-written loop exists for
    /// P1 and P2 only); `Some(Err)` when the solve failed (a blow-up past the stability limit,
    /// a step size underflow), with the reason.
    #[allow(clippy::too_many_arguments)]
    fn solve<T, P, M, const N: usize, const N2: usize>(
        &self,
        problem: &P,
        mechanism: &M,
        start: &State<T, N>,
        t_end: T,
        param: Param,
        observe: Observer<'_, T, N>,
    ) -> Option<Result<Outcome<T, N>, String>>
    where
        T: BenchReal,
        P: Problem<N, N2>,
        M: Mechanism<T, N>;
}

/// Something done once per method of the table.
pub trait MethodVisitor {
    /// Called with each method.
    fn visit<X: Method>(&mut self, method: &X);
}

/// The methods table: one line per method. A new fixed-step integrator of the library is one
/// line here and its type in [`fixed_step!`]'s list below.
pub fn for_each(v: &mut impl MethodVisitor) {
    v.visit(&Library(ExplicitEuler));
    v.visit(&Library(SemiImplicitEuler));
    v.visit(&Library(VelocityVerlet));
    v.visit(&Library(Rk4));
    v.visit(&HandRk4);
    v.visit(&OdeSolvers(Peer::Dopri5));
    v.visit(&OdeSolvers(Peer::Dop853));
}

/// A fixed-step integrator of the library, for every scalar and dimension at once (which a
/// bound `Integrator<T, N>` cannot say for all `T` and `N`).
pub trait FixedStep: Copy {
    /// The integrator's name.
    const NAME: &'static str;
    /// The largest stable `h w` on an undamped linear oscillator (the imaginary-axis extent
    /// of the stability region), when the method is explicit.
    const LINEAR_STABILITY_LIMIT: Option<f64>;
    /// Runs `steps` steps of `dt`, observing each new state when asked.
    ///
    /// # Errors
    /// The integrator's.
    fn run<T: Real, const N: usize, M: Mechanism<T, N>>(
        self,
        mechanism: &M,
        start: &State<T, N>,
        dt: T,
        steps: u64,
        observe: Observer<'_, T, N>,
    ) -> Result<State<T, N>, Error>;
}

/// Implements [`FixedStep`] for integrators that implement `Integrator<T, N>` for every `T`
/// and `N`, each with its linear stability limit (`None` for implicit methods).
macro_rules! fixed_step {
    ($($ty:ident: $limit:expr),* $(,)?) => {
        $(
            impl FixedStep for $ty {
                const NAME: &'static str = <$ty as Integrator<f64, 1>>::NAME;
                const LINEAR_STABILITY_LIMIT: Option<f64> = $limit;
                fn run<T: Real, const N: usize, M: Mechanism<T, N>>(
                    mut self,
                    mechanism: &M,
                    start: &State<T, N>,
                    dt: T,
                    steps: u64,
                    observe: Observer<'_, T, N>,
                ) -> Result<State<T, N>, Error> {
                    match observe {
                        Some(o) => Integrator::<T, N>::integrate_with(
                            &mut self, mechanism, start, dt, steps, o,
                        ),
                        None => Integrator::<T, N>::integrate(&mut self, mechanism, start, dt, steps),
                    }
                }
            }
        )*
    };
}

// Stability on y' = i w y: explicit Euler |1 + i h w| > 1 for every h; semi-implicit Euler and
// Stormer-Verlet are stable for h w < 2; RK4 for h w < 2 sqrt 2.
fixed_step!(
    ExplicitEuler: Some(0.0),
    SemiImplicitEuler: Some(2.0),
    VelocityVerlet: Some(2.0),
    Rk4: Some(2.0 * std::f64::consts::SQRT_2),
);

/// A fixed-step integrator of the library.
pub struct Library<I>(pub I);

impl<I: FixedStep> Method for Library<I> {
    fn name(&self) -> &'static str {
        I::NAME
    }
    fn origin(&self) -> Origin {
        Origin::Library
    }
    fn kind(&self) -> Kind {
        Kind::FixedStep
    }
    fn linear_stability_limit(&self) -> Option<f64> {
        I::LINEAR_STABILITY_LIMIT
    }
    fn solve<T, P, M, const N: usize, const N2: usize>(
        &self,
        _problem: &P,
        mechanism: &M,
        start: &State<T, N>,
        _t_end: T,
        param: Param,
        observe: Observer<'_, T, N>,
    ) -> Option<Result<Outcome<T, N>, String>>
    where
        T: BenchReal,
        P: Problem<N, N2>,
        M: Mechanism<T, N>,
    {
        let Param::Step { dt, steps } = param else {
            return None;
        };
        Some(
            self.0
                .run(mechanism, start, T::real(dt), steps, observe)
                .map(|end| Outcome {
                    end,
                    steps,
                    evals: None,
                })
                .map_err(|e| e.to_string()),
        )
    }
}

/// The hand-written RK4 loop of a problem, where it has one.
pub struct HandRk4;

impl Method for HandRk4 {
    fn name(&self) -> &'static str {
        "hand-written RK4"
    }
    fn origin(&self) -> Origin {
        Origin::HandWritten
    }
    fn kind(&self) -> Kind {
        Kind::FixedStep
    }
    fn solve<T, P, M, const N: usize, const N2: usize>(
        &self,
        problem: &P,
        _mechanism: &M,
        start: &State<T, N>,
        _t_end: T,
        param: Param,
        observe: Observer<'_, T, N>,
    ) -> Option<Result<Outcome<T, N>, String>>
    where
        T: BenchReal,
        P: Problem<N, N2>,
        M: Mechanism<T, N>,
    {
        let Param::Step { dt, steps } = param else {
            return None;
        };
        let dt = T::real(dt);
        let end = match observe {
            // The loop carries only the state, so one call per step does the same arithmetic
            // as one call for all steps.
            Some(o) => {
                let mut s = *start;
                for _ in 0..steps {
                    s = problem.hand_rk4(&s, dt, 1)?;
                    o(&s);
                }
                s
            }
            None => problem.hand_rk4(start, dt, steps)?,
        };
        Some(if end.is_finite() {
            Ok(Outcome {
                end,
                steps,
                evals: Some(4 * steps),
            })
        } else {
            Err(Error::NonFiniteState.to_string())
        })
    }
}
