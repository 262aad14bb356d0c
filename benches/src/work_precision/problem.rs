//! The [`Problem`] contract of the bench: a mechanism, a start, a span, a reference final state
//! and the energy convention of `shared/BENCH_PROBLEMS.md`.

pub use super::hand_rhs::HandRhs;
use super::real::BenchReal;
use lagrange_core::{Error, Mechanism, State};

/// The final state a run is measured against, with where it came from.
pub struct Reference<const N: usize> {
    /// The state at the final time (angles unwrapped).
    pub state: State<f64, N>,
    /// Where it comes from: an exact solution, a published high-precision solve, or the
    /// tightest run of a named method.
    pub source: String,
    /// Its own error (max norm over coordinates and rates), as published or as estimated.
    pub error: f64,
}

/// A standard problem of `N` degrees of freedom (`N2 = 2 N` state components, spelled out
/// because `ode_solvers` wants a static vector of the whole state and stable Rust cannot write
/// `2 * N` in a type).
pub trait Problem<const N: usize, const N2: usize> {
    /// The mechanism simulated, in precision `T` (a [`Lagrangian`](lagrange_core::Lagrangian)
    /// too, as every mechanism is: the variational integrator steps its `L`).
    type Mech<T: BenchReal>: Mechanism<T, N>;

    /// Its equations of motion written by hand ([`HandRhs`]), in precision `T`.
    type Hand<T: BenchReal>: HandRhs<T, N>;

    /// Short key used in file names, the CSV and `--only`: `P1`, `P3-N20`, ...
    fn id(&self) -> &'static str;
    /// One line saying what it is, with its parameters.
    fn title(&self) -> &'static str;
    /// Which mechanism type is simulated, and any caveat about its timings.
    fn mechanism_note(&self) -> &'static str;
    /// The mechanism in precision `T`.
    ///
    /// # Errors
    /// When a parameter is refused (never, for the fixed parameters used here).
    fn mechanism<T: BenchReal>(&self) -> Result<Self::Mech<T>, Error>;
    /// The equations of motion written by hand, in precision `T`: what `ode_solvers` runs
    /// on, and what the generic hand-written RK4 loop steps where the problem has no loop of
    /// its own.
    fn hand<T: BenchReal>(&self) -> Self::Hand<T>;
    /// The start state, in `f64`.
    fn start(&self) -> State<f64, N>;
    /// The final time, s.
    fn t_end(&self) -> f64;
    /// The state of zero potential energy (the hanging rest state), when the energy convention
    /// of `BENCH_PROBLEMS.md` measures energy from one; `None` to use the mechanism's own.
    fn energy_datum(&self) -> Option<State<f64, N>>;
    /// The reference final state.
    ///
    /// # Errors
    /// When an exact solution or a reference solve fails.
    fn reference(&self) -> Result<Reference<N>, String>;
    /// The coarsest step of the fixed-step sweeps, s.
    fn coarsest_dt(&self) -> f64;
    /// The fastest natural frequency of the problem, rad/s, to report a stability limit as
    /// `h w` (the number that stability regions are drawn in).
    fn fastest_frequency(&self) -> f64;

    /// The equations of motion in Python, for SciPy (`--peers`): source defining
    /// `rhs(t, y)` for `y = (q, q')`, with `math` imported; `None` where not written.
    fn python_rhs(&self) -> Option<&'static str> {
        None
    }

    /// The hand-written RK4 loop for this problem in precision `T`: by default the generic
    /// loop over arrays ([`hand_rk4::rk4`](super::hand_rk4::rk4)) on [`Problem::hand`]; P1 and
    /// P2 keep their state in scalar locals instead.
    fn hand_rk4<T: BenchReal>(
        &self,
        start: &State<T, N>,
        dt: T,
        steps: u64,
    ) -> Option<State<T, N>> {
        Some(super::hand_rk4::rk4(&self.hand::<T>(), start, dt, steps))
    }
}

/// Something done once per problem of the registry.
pub trait ProblemVisitor {
    /// Called with each problem.
    fn visit<P: Problem<N, N2>, const N: usize, const N2: usize>(&mut self, problem: &P);
}

/// The energy of `s` under the problem's convention, in `f64`.
pub fn energy<M: Mechanism<f64, N>, const N: usize>(
    mechanism: &M,
    datum: Option<&State<f64, N>>,
    s: &State<f64, N>,
) -> f64 {
    mechanism.energy(s) - datum.map_or(0.0, |d| mechanism.energy(d))
}

/// `max_i |y_i - y_ref_i|` over coordinates and rates, in `f64`.
pub fn state_error<const N: usize>(s: &State<f64, N>, reference: &State<f64, N>) -> f64 {
    let mut worst: f64 = 0.0;
    let pairs = s.q.iter().zip(reference.q.iter());
    for (a, b) in pairs.chain(s.qd.iter().zip(reference.qd.iter())) {
        let e = (a - b).abs();
        if e.is_nan() {
            return f64::NAN;
        }
        worst = worst.max(e);
    }
    worst
}
