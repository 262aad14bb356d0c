//! The mobilities of a [`World`](super::World)'s contact rows, `b = M^-1 j^T` on each side:
//! every contact of a body on a side solved together, [`BATCH`] to a call of
//! [`Mechanism::velocity_jumps`], so that a mechanism whose mass solve shares its work (a
//! ragdoll factors its mass matrix once, then solves the columns side by side) does it once
//! for them, not twice a contact point.

use super::limits::Limits;
use super::World;
use lagrange_core::links::Links;
use lagrange_core::nalgebra::SMatrix;
use lagrange_core::{Error, Mechanism, Real};

/// Contacts whose mobilities are solved by one call: a normal and a tangent column each.
const BATCH: usize = 8;

/// The end of a list.
const END: u32 = u32::MAX;

impl<T, M, L, const N: usize, const B: usize, const S: usize, const K: usize>
    World<T, M, N, B, S, K, L>
where
    T: Real,
    M: Mechanism<T, N> + Links<T, N> + Clone,
    L: Limits<T, N>,
{
    /// Every contact's mobilities on each of its sides with a body, then its rows' inverse
    /// masses. A body's contacts on a side are solved in their order, [`BATCH`] at a time.
    pub(super) fn mobilities(&mut self) -> Result<(), Error> {
        for side in 0..2 {
            // Each body's contacts on this side as a list: `first[body]`, then `next[c]`
            // after contact `c` (built from the last contact back, so in their order).
            let mut first = [END; B];
            let mut next = [END; K];
            for (c, contact) in self.contacts.iter().enumerate().rev() {
                let Some(body) = contact.bodies.get(side).copied().flatten() else {
                    continue;
                };
                if let (Some(head), Some(after)) = (first.get_mut(body), next.get_mut(c)) {
                    *after = *head;
                    *head = u32::try_from(c).unwrap_or(END);
                }
            }
            for (body, &head) in first.iter().enumerate().take(self.bodies.len()) {
                let mut at = head;
                while at != END {
                    at = self.batch(body, side, at, &next)?;
                }
            }
        }
        for c in self.contacts.iter_mut() {
            c.normal.refresh();
            c.tangent.refresh();
        }
        Ok(())
    }

    /// The mobilities on side `side` of body `body`'s contacts from `at` on along `next`, up
    /// to [`BATCH`] of them from one mass solve: where the list goes on after them.
    fn batch(&mut self, body: usize, side: usize, at: u32, next: &[u32; K]) -> Result<u32, Error> {
        let mut taken = [END; BATCH];
        let mut columns = SMatrix::<T, N, { 2 * BATCH }>::zeros();
        let mut at = at;
        for (k, slot) in taken.iter_mut().enumerate() {
            let Some(c) = self.contacts.get(at as usize) else {
                break;
            };
            let (normal, tangent) = (&c.normal.j[side & 1], &c.tangent.j[side & 1]);
            let storage = columns.as_mut_slice();
            if let Some(x) = storage.get_mut(2 * k * N..(2 * k + 1) * N) {
                x.copy_from_slice(normal.as_slice());
            }
            if let Some(x) = storage.get_mut((2 * k + 1) * N..(2 * k + 2) * N) {
                x.copy_from_slice(tangent.as_slice());
            }
            *slot = at;
            at = next.get(at as usize).copied().unwrap_or(END);
        }
        if let Some(b) = self.bodies.get(body) {
            b.mechanism.velocity_jumps(&b.state, &mut columns)?;
        }
        let storage = columns.as_slice();
        for (k, &c) in taken.iter().enumerate().take_while(|(_, &c)| c != END) {
            let Some(contact) = self.contacts.get_mut(c as usize) else {
                continue;
            };
            if let Some(x) = storage.get(2 * k * N..(2 * k + 1) * N) {
                contact.normal.b[side & 1].copy_from_slice(x);
            }
            if let Some(x) = storage.get((2 * k + 1) * N..(2 * k + 2) * N) {
                contact.tangent.b[side & 1].copy_from_slice(x);
            }
        }
        Ok(at)
    }
}
