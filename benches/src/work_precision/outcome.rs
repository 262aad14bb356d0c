//! What one solve returns ([`Outcome`]) and the observer it may call at every state
//! ([`Observer`]): the types every solver of the bench shares, the library's and the peers'.

use lagrange_core::{Real, State};

/// What a solve returns.
pub struct Outcome<T: Real, const N: usize> {
    /// The state at the final time.
    pub end: State<T, N>,
    /// Steps taken (accepted and rejected, for adaptive methods).
    pub steps: u64,
    /// Acceleration evaluations, when the method counts them itself (otherwise the runner
    /// counts calls to `Mechanism::acceleration`).
    pub evals: Option<u64>,
    /// The method's own count of its work, `(evaluations, Jacobians)` summed over its steps
    /// (the library's fixed-step integrators, from `Integrator::last_step`), where the runner
    /// keeps it: it sees work that calls to the law do not show.
    pub work: Option<(u64, u64)>,
}

/// An observer of every state a solve passes through (`None` in timed runs).
pub type Observer<'a, T, const N: usize> = Option<&'a mut dyn FnMut(&State<T, N>)>;
