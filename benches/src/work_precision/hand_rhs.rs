//! [`HandRhs`]: a problem's equations of motion as another solver's user writes them.

/// A problem's equations of motion written by hand on plain arrays, as a user of another
/// solver writes them: the accelerations `q''` at `(t, q, q')`, with no `Result`, no trait
/// of the library and no checks. `ode_solvers` runs on it, so that a comparison with the
/// library measures the solvers alone, and the generic hand-written RK4 loop steps it.
pub trait HandRhs<T, const N: usize> {
    /// Writes `q''` at `(t, q, q')` into `qdd`.
    fn accelerations(&self, t: T, q: &[T; N], qd: &[T; N], qdd: &mut [T; N]);
}
