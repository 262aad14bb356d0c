//! [`Slot`]: what a bank keeps of one instance besides its state.

use lagrange_core::Error;

/// One instance: its mechanism (parameters and input), its integrator (and what that keeps
/// between steps), and the bank's bookkeeping. Its state is kept apart, with every other
/// instance's ([`States`](super::states::States)).
#[derive(Debug, Clone)]
pub struct Slot<M, I> {
    /// Its parameters and input.
    pub mechanism: M,
    /// Its copy of the bank's integrator.
    pub integrator: I,
    /// Its [`Id::index`](super::Id::index).
    pub id: u32,
    /// 0 while not found at rest; else 1 + the steps spanned by its consecutive checks at
    /// rest.
    pub quiet: u32,
    /// Why its last step failed, while it is set aside.
    pub failure: Option<Error>,
}

impl<M, I> Slot<M, I> {
    /// Keeps the error of a failed step (out of line: rare, and the error is large).
    #[cold]
    #[inline(never)]
    pub fn fail(&mut self, e: Error) {
        self.failure = Some(e);
    }
}
