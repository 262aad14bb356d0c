//! [`BodyLists`]: each body's contacts as a linked list through the contacts' array, in
//! the keys' order (what the sweeps' order and the twins' test of a body's supports walk).

use super::rows::Contact;
use lagrange_core::Real;

/// No contact.
pub(crate) const NONE: u32 = u32::MAX;

/// Each body's contacts as a list, in the keys' order: `front[body]` its first, then
/// `after[side][c]` the one after contact `c` on its side `side`'s body ([`NONE`]: no more).
pub(crate) struct BodyLists<const B: usize, const K: usize> {
    pub(crate) front: [u32; B],
    pub(crate) after: [[u32; K]; 2],
}

impl<const B: usize, const K: usize> BodyLists<B, K> {
    /// The lists of `contacts` (built from the last back).
    pub(crate) fn of<T: Real, const N: usize>(contacts: &[Contact<T, N>]) -> Self {
        let mut front = [NONE; B];
        let mut after = [[NONE; K]; 2];
        for (c, contact) in contacts.iter().enumerate().rev() {
            for (side, body) in contact.bodies.iter().enumerate() {
                let (Some(head), Some(next)) = (
                    body.and_then(|b| front.get_mut(b)),
                    after.get_mut(side).and_then(|a| a.get_mut(c)),
                ) else {
                    continue;
                };
                *next = *head;
                *head = u32::try_from(c).unwrap_or(NONE);
            }
        }
        Self { front, after }
    }

    /// The contacts of `body` (at most `K`: a contact of a body with itself is on its
    /// first side's list once, and twice on the second's, which this does not walk).
    pub(crate) fn contacts_of<'a, T: Real, const N: usize>(
        &'a self,
        contacts: &'a [Contact<T, N>],
        body: usize,
    ) -> impl Iterator<Item = &'a Contact<T, N>> + 'a {
        let mut at = self.front.get(body).copied().unwrap_or(NONE);
        core::iter::from_fn(move || {
            let c = contacts.get(at as usize)?;
            let side = usize::from(c.bodies[0] != Some(body));
            at = self
                .after
                .get(side)
                .and_then(|a| a.get(at as usize))
                .copied()
                .unwrap_or(NONE);
            Some(c)
        })
        .take(K)
    }
}
