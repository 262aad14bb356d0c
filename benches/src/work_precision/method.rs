//! The [`Method`] contract of the bench (a way of solving a problem over `[0, T]` at a step size
//! or a tolerance) and the methods table: the library's integrators, the hand-written RK4 loop
//! and `ode_solvers`' Dopri5 and Dop853 (on the problem's equations written by hand).

use super::ode_peer::Peer;
use super::outcome::{Observer, Outcome};
use super::problem::Problem;
use super::real::BenchReal;
use lagrange_core::{Error, Mechanism, Real, State};
use lagrange_integrators::{
    AdaptiveSettings, BackwardEuler, Clock, Dop853Pair, Dopri5Pair, EmbeddedPair,
    EmbeddedRungeKutta, ExplicitEuler, Failure, GaussLegendre2, ImplicitMidpoint, Integrator,
    Nystrom1210Pair, Nystrom64Pair, Nystrom86Pair, RadauIIA2, Rk4, SemiImplicitEuler,
    StormerVerlet, VariationalMidpoint, VelocityVerlet, Verner76Pair, Verner98Pair, Yoshida4,
};
use std::marker::PhantomData;

/// Whose code a method is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Origin {
    /// lagrange's own integrators.
    Library,
    /// A plain loop written by hand for one problem: the speed limit.
    HandWritten,
    /// The `ode_solvers` crate.
    OdeSolvers,
    /// SciPy (`--peers`), on the problem's equations written in Python.
    SciPy,
}

impl Origin {
    /// For tables.
    pub fn label(self) -> &'static str {
        match self {
            Self::Library => "lagrange",
            Self::HandWritten => "hand-written",
            Self::OdeSolvers => "ode_solvers",
            Self::SciPy => "scipy",
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

/// The Butcher tableau a method steps with, where solvers of different origins share one:
/// the report compares such pairs like for like.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tableau {
    /// Dormand and Prince's 5(4) pair (the library's `Dopri5Pair`, `ode_solvers`' Dopri5,
    /// SciPy's RK45).
    DormandPrince54,
    /// Hairer's 8(5,3) pair of Dormand and Prince (the library's `Dop853Pair`, `ode_solvers`'
    /// Dop853, SciPy's DOP853).
    DormandPrince853,
}

impl Tableau {
    /// Every tableau, in the order of the report's rows.
    pub const ALL: [Self; 2] = [Self::DormandPrince54, Self::DormandPrince853];
}

/// A way of solving a problem: an integrator of the library, a hand-written loop, another
/// crate's solver.
pub trait Method {
    /// Name for tables and legends.
    fn name(&self) -> &'static str;
    /// Whose code it is.
    fn origin(&self) -> Origin;
    /// Fixed step or adaptive.
    fn kind(&self) -> Kind;
    /// Its Butcher tableau, where solvers of other origins use the same one.
    fn tableau(&self) -> Option<Tableau> {
        None
    }
    /// For an explicit fixed-step method, the largest `h w` for which it is stable on an
    /// undamped linear oscillator of frequency `w` (`0` when no step is: explicit Euler).
    fn linear_stability_limit(&self) -> Option<f64> {
        None
    }
    /// True for a fixed-step method whose step is explicit (for the mechanisms of the
    /// stability scan), so that it has a stability limit to find.
    fn explicit(&self) -> bool {
        false
    }
    /// Solves `problem` (whose mechanism in `T` is `mechanism`, possibly wrapped) from `start`
    /// to `t_end` at `param`, calling `observe` with every new state when given.
    ///
    /// `None` when the method does not apply to the problem (a fixed-step method at a
    /// tolerance); `Some(Err)` when the solve failed (a blow-up past the stability limit,
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
/// line in [`fixed_step!`]'s list below and one line here; an adaptive one, one line here.
pub fn for_each(v: &mut impl MethodVisitor) {
    v.visit(&Library(ExplicitEulerFamily));
    v.visit(&Library(SemiImplicitEulerFamily));
    v.visit(&Library(VelocityVerletFamily));
    v.visit(&Library(StormerVerletFamily));
    v.visit(&Library(Rk4Family));
    v.visit(&Library(Yoshida4Family));
    v.visit(&Library(ImplicitMidpointFamily));
    v.visit(&Library(GaussLegendre2Family));
    v.visit(&Library(BackwardEulerFamily));
    v.visit(&Library(RadauIIA2Family));
    v.visit(&Library(VariationalMidpointFamily));
    v.visit(&Library(Yoshida4VariationalFamily));
    v.visit(&Adaptive::<7, 1, Dopri5Pair>::new(Tableau::DormandPrince54));
    v.visit(&Adaptive::<16, 4, Dop853Pair>::new(
        Tableau::DormandPrince853,
    ));
    v.visit(&Adaptive::<11, 2, Verner76Pair>::unpaired());
    v.visit(&Adaptive::<17, 2, Verner98Pair>::unpaired());
    v.visit(&Adaptive::<16, 4, Dop853Pair>::holding_energy(
        "Dormand-Prince 8(5,3), energy held",
    ));
    v.visit(&Adaptive::<17, 2, Verner98Pair>::holding_energy(
        "Verner 9(8), energy held",
    ));
    v.visit(&Adaptive::<6, 2, Nystrom64Pair>::unpaired());
    v.visit(&Adaptive::<9, 2, Nystrom86Pair>::unpaired());
    v.visit(&Adaptive::<18, 2, Nystrom1210Pair>::unpaired());
    v.visit(&HandRk4);
    v.visit(&OdeSolvers(Peer::Dopri5));
    v.visit(&OdeSolvers(Peer::Dop853));
}

/// A fixed-step integrator of the library, for every scalar, dimension and mechanism at once
/// (which a bound `Integrator<T, N, M>` cannot say for all `T`, `N` and `M`): a family of
/// integrator types, each declared by one line of [`fixed_step!`].
pub trait FixedStep {
    /// The integrator in precision `T` for `N` degrees of freedom.
    type Of<T: Real, const N: usize>;
    /// Name for tables and legends: the integrator's own.
    const NAME: &'static str;
    /// The largest stable `h w` on an undamped linear oscillator (the imaginary-axis extent
    /// of the stability region), for the explicit methods whose value is classical.
    const LINEAR_STABILITY_LIMIT: Option<f64>;
    /// Explicit (no Newton iteration where `q''` does not depend on `q'`).
    const EXPLICIT: bool;
    /// A new integrator (default settings).
    fn make<T: Real, const N: usize>() -> Self::Of<T, N>;
    /// [`run`] with a new integrator of the family on `mechanism`.
    ///
    /// # Errors
    /// As [`run`].
    fn run<T: Real, M: Mechanism<T, N>, const N: usize>(
        mechanism: &M,
        start: &State<T, N>,
        dt: T,
        steps: u64,
        observe: Observer<'_, T, N>,
    ) -> Result<Outcome<T, N>, String>;
}

/// `steps` steps of `dt` from `start` by `integrator`: one call of `integrate` when not
/// observed; else the steps one by one as `integrate` takes them (on the same compensated
/// clock), calling `observe` with every new state and summing the work of each
/// (`last_step`), which the sweep checks ends at the same state to the bit.
///
/// # Errors
/// The failed step, with the time it started from.
pub fn run<T, M, I, const N: usize>(
    mut integrator: I,
    mechanism: &M,
    start: &State<T, N>,
    dt: T,
    steps: u64,
    observe: Observer<'_, T, N>,
) -> Result<Outcome<T, N>, String>
where
    T: Real,
    M: Mechanism<T, N>,
    I: Integrator<T, N, M>,
{
    let Some(observe) = observe else {
        return integrator
            .integrate(mechanism, start, dt, steps)
            .map(|end| Outcome {
                end,
                steps,
                evals: None,
                work: None,
            })
            .map_err(|f| f.to_string());
    };
    let mut s = *start;
    let mut clock = Clock::new(start.t);
    let (mut evals, mut jacobians) = (0, 0);
    for step in 0..steps {
        let mut next = integrator.step(mechanism, &s, dt).map_err(|error| {
            Failure {
                error,
                step,
                last: s,
            }
            .to_string()
        })?;
        clock.tick(dt);
        next.t = clock.time();
        s = next;
        let work = integrator.last_step();
        evals += u64::from(work.evaluations);
        jacobians += u64::from(work.jacobians);
        observe(&s);
    }
    Ok(Outcome {
        end: s,
        steps,
        evals: None,
        work: Some((evals, jacobians)),
    })
}

/// Declares a [`FixedStep`] family per line: its marker type, the integrator type (in terms of
/// `T` and `N`), how to make one, whether it is explicit, and its linear stability limit.
macro_rules! fixed_step {
    ($($family:ident: $ty:ty = $make:expr, $explicit:expr, $limit:expr;)*) => {
        $(
            #[doc = concat!("The family of `", stringify!($ty), "`.")]
            pub struct $family;
            impl FixedStep for $family {
                type Of<T: Real, const N: usize> = $ty;
                const NAME: &'static str =
                    <Self::Of<f64, 1> as lagrange_integrators::Method>::NAME;
                const LINEAR_STABILITY_LIMIT: Option<f64> = $limit;
                const EXPLICIT: bool = $explicit;
                fn make<T: Real, const N: usize>() -> Self::Of<T, N> {
                    $make
                }
                fn run<T: Real, M: Mechanism<T, N>, const N: usize>(
                    mechanism: &M,
                    start: &State<T, N>,
                    dt: T,
                    steps: u64,
                    observe: Observer<'_, T, N>,
                ) -> Result<Outcome<T, N>, String> {
                    run(Self::make::<T, N>(), mechanism, start, dt, steps, observe)
                }
            }
        )*
    };
}

// Stability on y' = i w y: explicit Euler |1 + i h w| > 1 for every h; semi-implicit Euler and
// Stormer-Verlet are stable for h w < 2; RK4 for h w < 2 sqrt 2. Yoshida's and the implicit
// methods' limits are left to the bench to measure.
fixed_step! {
    ExplicitEulerFamily: ExplicitEuler = ExplicitEuler, true, Some(0.0);
    SemiImplicitEulerFamily: SemiImplicitEuler = SemiImplicitEuler, true, Some(2.0);
    VelocityVerletFamily: VelocityVerlet = VelocityVerlet, true, Some(2.0);
    StormerVerletFamily: StormerVerlet<T, N> = StormerVerlet::default(), true, Some(2.0);
    Rk4Family: Rk4 = Rk4, true, Some(2.0 * std::f64::consts::SQRT_2);
    Yoshida4Family: Yoshida4<StormerVerlet<T, N>> = Yoshida4::new(StormerVerlet::default()), true, None;
    ImplicitMidpointFamily: ImplicitMidpoint<T> = ImplicitMidpoint::default(), false, None;
    GaussLegendre2Family: GaussLegendre2<T> = GaussLegendre2::default(), false, None;
    BackwardEulerFamily: BackwardEuler<T> = BackwardEuler::default(), false, None;
    RadauIIA2Family: RadauIIA2<T> = RadauIIA2::default(), false, None;
    VariationalMidpointFamily: VariationalMidpoint<T, N> =
        VariationalMidpoint::default(), false, None;
    Yoshida4VariationalFamily: Yoshida4<VariationalMidpoint<T, N>> =
        Yoshida4::new(VariationalMidpoint::default()), false, None;
}

/// A fixed-step integrator of the library.
pub struct Library<F>(pub F);

impl<F: FixedStep> Method for Library<F> {
    fn name(&self) -> &'static str {
        F::NAME
    }
    fn origin(&self) -> Origin {
        Origin::Library
    }
    fn kind(&self) -> Kind {
        Kind::FixedStep
    }
    fn linear_stability_limit(&self) -> Option<f64> {
        F::LINEAR_STABILITY_LIMIT
    }
    fn explicit(&self) -> bool {
        F::EXPLICIT
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
        Some(F::run(mechanism, start, T::real(dt), steps, observe))
    }
}

/// An adaptive embedded Runge-Kutta pair of the library (`S` stages, `R` dense-output rows),
/// with or without the energy projection.
pub struct Adaptive<const S: usize, const R: usize, P> {
    tableau: Option<Tableau>,
    /// Its own name where it holds the energy (`None`: the pair's).
    holding_energy: Option<&'static str>,
    pair: PhantomData<P>,
}

impl<const S: usize, const R: usize, P> Adaptive<S, R, P> {
    /// The pair `P`, whose coefficients are `tableau`'s.
    pub fn new(tableau: Tableau) -> Self {
        Self {
            tableau: Some(tableau),
            holding_energy: None,
            pair: PhantomData,
        }
    }

    /// The pair `P`, which no peer has.
    pub fn unpaired() -> Self {
        Self {
            tableau: None,
            holding_energy: None,
            pair: PhantomData,
        }
    }

    /// The pair `P` with the energy projection
    /// ([`AdaptiveSettings::with_energy_projection`]), named `name`: another method than the
    /// pair alone, which no peer has.
    pub fn holding_energy(name: &'static str) -> Self {
        Self {
            tableau: None,
            holding_energy: Some(name),
            pair: PhantomData,
        }
    }
}

/// Most steps one adaptive solve may take.
const MAX_ADAPTIVE_STEPS: u64 = 10_000_000;

impl<const S: usize, const R: usize, Pair: EmbeddedPair<S, R>> Method for Adaptive<S, R, Pair> {
    fn name(&self) -> &'static str {
        self.holding_energy.unwrap_or(Pair::NAME)
    }
    fn origin(&self) -> Origin {
        Origin::Library
    }
    fn kind(&self) -> Kind {
        Kind::Adaptive
    }
    fn tableau(&self) -> Option<Tableau> {
        self.tableau
    }
    fn solve<T, P, M, const N: usize, const N2: usize>(
        &self,
        _problem: &P,
        mechanism: &M,
        start: &State<T, N>,
        t_end: T,
        param: Param,
        observe: Observer<'_, T, N>,
    ) -> Option<Result<Outcome<T, N>, String>>
    where
        T: BenchReal,
        P: Problem<N, N2>,
        M: Mechanism<T, N>,
    {
        let Param::Tolerance(tol) = param else {
            return None;
        };
        // A Nyström pair does not apply to a law that reads the velocities.
        if Pair::NYSTROM.is_some() && mechanism.reads_velocities() {
            return None;
        }
        let solve = || -> Result<Outcome<T, N>, String> {
            let tol = T::real(tol);
            let mut settings = AdaptiveSettings::new(tol, tol)
                .and_then(|s| s.with_max_steps(MAX_ADAPTIVE_STEPS))
                .map_err(|e| e.to_string())?;
            if self.holding_energy.is_some() {
                settings = settings.with_energy_projection();
            }
            let mut rk = EmbeddedRungeKutta::<T, N, S, R, Pair>::new(settings);
            let end = match observe {
                None => rk.integrate_to(mechanism, start, t_end),
                // The steps of `integrate_to` (each told where the end is, so that the last
                // lands on it), with the observer riding on a guard that never changes sign:
                // the observed run and the timed runs are the same computation.
                Some(o) => rk
                    .integrate_until_event(mechanism, start, t_end, |s| {
                        o(s);
                        T::one()
                    })
                    .map(|stop| *stop.state()),
            }
            .map_err(|f| f.to_string())?;
            let stats = rk.statistics();
            Ok(Outcome {
                end,
                steps: stats.accepted + stats.rejected,
                evals: None,
                work: None,
            })
        };
        Some(solve())
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
                work: None,
            })
        } else {
            Err(Error::NonFiniteState.to_string())
        })
    }
}

/// An `ode_solvers` method, with its own default step-size controller settings.
pub struct OdeSolvers(pub Peer);

impl Method for OdeSolvers {
    fn name(&self) -> &'static str {
        self.0.name()
    }
    fn origin(&self) -> Origin {
        Origin::OdeSolvers
    }
    fn kind(&self) -> Kind {
        Kind::Adaptive
    }
    fn tableau(&self) -> Option<Tableau> {
        Some(match self.0 {
            Peer::Dopri5 => Tableau::DormandPrince54,
            Peer::Dop853 => Tableau::DormandPrince853,
        })
    }
    /// On the problem's equations written by hand ([`Problem::hand`]), not on `mechanism`.
    fn solve<T, P, M, const N: usize, const N2: usize>(
        &self,
        problem: &P,
        _mechanism: &M,
        start: &State<T, N>,
        t_end: T,
        param: Param,
        observe: Observer<'_, T, N>,
    ) -> Option<Result<Outcome<T, N>, String>>
    where
        T: BenchReal,
        P: Problem<N, N2>,
        M: Mechanism<T, N>,
    {
        let Param::Tolerance(tol) = param else {
            return None;
        };
        Some(T::ode_solve::<_, N, N2>(
            self.0,
            &problem.hand::<T>(),
            start,
            t_end,
            T::real(tol),
            observe,
        ))
    }
}
