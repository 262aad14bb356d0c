//! [`Case`]: one mechanism x integrator x scalar run, its [`Outcome`] as bit patterns, and
//! the [`Stopwatch`] that times each step of a case that lets it.

use core::hint::black_box;

use lagrange_core::{Error, Real, State};
use lagrange_integrators::{Integrator, VariationalMidpoint};

use crate::Setup;

/// The most words an [`Outcome`] holds: `t`, then up to 4 coordinates and 4 velocities.
pub const MAX_WORDS: usize = 9;

/// The name of a scalar type in logs and tables.
pub trait Precision: Real {
    /// `"f32"` or `"f64"`.
    const NAME: &'static str;
    /// The bit pattern, widened to `u64` (an `f32`'s 32 bits in the low half).
    fn bits(self) -> u64;
}

impl Precision for f32 {
    const NAME: &'static str = "f32";
    fn bits(self) -> u64 {
        u64::from(self.to_bits())
    }
}

impl Precision for f64 {
    const NAME: &'static str = "f64";
    fn bits(self) -> u64 {
        self.to_bits()
    }
}

/// The final state of a run as exact bit patterns: `t`, `q[0..N]`, `q'[0..N]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Outcome {
    words: [u64; MAX_WORDS],
    len: usize,
}

impl Outcome {
    /// The bits of `state`: `t`, the coordinates, the velocities (at most [`MAX_WORDS`]).
    #[must_use]
    pub fn of<T: Precision, const N: usize>(state: &State<T, N>) -> Self {
        let mut words = [0; MAX_WORDS];
        let values = core::iter::once(state.t)
            .chain(state.q.iter().copied())
            .chain(state.qd.iter().copied());
        let mut len = 0;
        for (word, value) in words.iter_mut().zip(values) {
            *word = value.bits();
            len += 1;
        }
        Self { words, len }
    }

    /// An outcome of up to [`MAX_WORDS`] words of its own (a scene's digest and counts);
    /// words beyond that are dropped.
    #[must_use]
    pub fn from_words(given: &[u64]) -> Self {
        let mut words = [0; MAX_WORDS];
        let len = given.len().min(MAX_WORDS);
        words[..len].copy_from_slice(&given[..len]);
        Self { words, len }
    }

    /// The words: `t`, `q`, `q'`, each an `f32`'s or `f64`'s bits.
    #[must_use]
    pub fn words(&self) -> &[u64] {
        self.words.get(..self.len).unwrap_or(&self.words)
    }
}

/// What times each step of a run, one at a time: the firmware's SysTick, for the worst step
/// of a case whose cost varies from step to step (contacts); [`Untimed`] elsewhere.
pub trait Stopwatch {
    /// Runs `step` once (timing it) and returns its result.
    ///
    /// # Errors
    /// `step`'s.
    fn time(&mut self, step: &mut dyn FnMut() -> Result<(), Error>) -> Result<(), Error>;
}

/// The [`Stopwatch`] that times nothing: it only runs the step.
#[derive(Debug, Clone, Copy, Default)]
pub struct Untimed;

impl Stopwatch for Untimed {
    fn time(&mut self, step: &mut dyn FnMut() -> Result<(), Error>) -> Result<(), Error> {
        step()
    }
}

/// How a [`Case`] runs.
#[derive(Debug, Clone, Copy)]
enum Runner {
    /// A run of `steps` steps, as a whole.
    Whole(fn(u32) -> Result<Outcome, Error>),
    /// A run of `steps` steps, each through a [`Stopwatch`].
    Stepwise(fn(u32, &mut dyn Stopwatch) -> Result<Outcome, Error>),
}

/// One lockstep case: a [`Setup`] stepped by an integrator in a scalar type.
#[derive(Debug, Clone, Copy)]
pub struct Case {
    /// The setup's name, e.g. `"pendulum"`.
    pub system: &'static str,
    /// The integrator's name, e.g. `"RK4"`.
    pub method: &'static str,
    /// `"f32"` or `"f64"`.
    pub precision: &'static str,
    /// Words in its outcome: `1 + 2 N` for a mechanism's final state (`t`, `q`, `q'`), its
    /// own count for a scripted case.
    pub words: usize,
    runner: Runner,
}

impl Case {
    /// The case of setup `S` stepped by integrator `I` in `T`.
    #[must_use]
    pub const fn new<T, const N: usize, S, I>() -> Self
    where
        T: Precision,
        S: Setup<T, N>,
        I: Integrator<T, N, S::Mechanism> + Default,
    {
        Self {
            system: S::NAME,
            method: I::NAME,
            precision: T::NAME,
            words: 1 + 2 * N,
            runner: Runner::Whole(run::<T, N, S, I>),
        }
    }

    /// The case of setup `S` stepped by the variational midpoint integrator in
    /// position-momentum form throughout (its `integrate`), in `T`.
    #[must_use]
    pub const fn variational<T, const N: usize, S>() -> Self
    where
        T: Precision,
        S: Setup<T, N>,
    {
        Self {
            system: S::NAME,
            method: "variational midpoint",
            precision: T::NAME,
            words: 1 + 2 * N,
            runner: Runner::Whole(run_variational::<T, N, S>),
        }
    }

    /// A case run by `runner` of its own (a scripted scene: `steps` counts its frames), whose
    /// outcome holds `words` words.
    #[must_use]
    pub const fn scripted(
        system: &'static str,
        method: &'static str,
        precision: &'static str,
        words: usize,
        runner: fn(u32) -> Result<Outcome, Error>,
    ) -> Self {
        Self {
            system,
            method,
            precision,
            words,
            runner: Runner::Whole(runner),
        }
    }

    /// A case run by `runner` of its own, which takes each of its `steps` steps through the
    /// [`Stopwatch`] it is given (so that the firmware can time the worst), and whose outcome
    /// holds `words` words.
    #[must_use]
    pub const fn stepwise(
        system: &'static str,
        method: &'static str,
        precision: &'static str,
        words: usize,
        runner: fn(u32, &mut dyn Stopwatch) -> Result<Outcome, Error>,
    ) -> Self {
        Self {
            system,
            method,
            precision,
            words,
            runner: Runner::Stepwise(runner),
        }
    }

    /// Builds the setup and takes `steps` steps; the final state's bits.
    ///
    /// # Errors
    /// Whatever the setup's constructor or a step returns.
    pub fn run(&self, steps: u32) -> Result<Outcome, Error> {
        self.run_timed(steps, &mut Untimed)
    }

    /// Whether the case takes its steps one by one through a [`Stopwatch`]
    /// ([`Case::run_timed`] times them).
    #[must_use]
    pub fn times_steps(&self) -> bool {
        matches!(self.runner, Runner::Stepwise(_))
    }

    /// As [`Case::run`], each step through `watch` where the case [times its
    /// steps](Case::times_steps) (elsewhere `watch` is not called).
    ///
    /// # Errors
    /// As [`Case::run`].
    pub fn run_timed(&self, steps: u32, watch: &mut dyn Stopwatch) -> Result<Outcome, Error> {
        match self.runner {
            Runner::Whole(run) => run(steps),
            Runner::Stepwise(run) => run(steps, watch),
        }
    }
}

/// Builds `S` and steps it `steps` times with `I`. Parameters, step size and count pass
/// through [`black_box`], so that the firmware's cost is that of a mechanism whose parameters
/// arrive at run time, not one the optimiser specialised for these constants.
fn run<T, const N: usize, S, I>(steps: u32) -> Result<Outcome, Error>
where
    T: Precision,
    S: Setup<T, N>,
    I: Integrator<T, N, S::Mechanism> + Default,
{
    let (mechanism, start) = S::build()?;
    let mechanism = black_box(mechanism);
    let dt = black_box(T::from_f64(S::DT));
    let mut state = black_box(start);
    let mut integrator = I::default();
    for _ in 0..black_box(steps) {
        state = integrator.step(&mechanism, &state, dt)?;
    }
    Ok(Outcome::of(&state))
}

/// As [`run`], with [`VariationalMidpoint`] in position-momentum form throughout.
fn run_variational<T, const N: usize, S>(steps: u32) -> Result<Outcome, Error>
where
    T: Precision,
    S: Setup<T, N>,
{
    let (mechanism, start) = S::build()?;
    let mechanism = black_box(mechanism);
    let dt = black_box(T::from_f64(S::DT));
    let state = VariationalMidpoint::default().integrate(
        &mechanism,
        &black_box(start),
        dt,
        u64::from(black_box(steps)),
    )?;
    Ok(Outcome::of(&state))
}
