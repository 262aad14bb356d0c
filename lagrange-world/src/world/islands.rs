//! Islands: the bodies joined by contacts, found each step by union-find, each named by the
//! least key of its bodies (so that the names do not depend on the order bodies were added).

/// Union-find over `B` bodies.
pub(crate) struct Islands<const B: usize> {
    parent: [usize; B],
}

impl<const B: usize> Islands<B> {
    /// Every body its own island.
    pub(crate) fn new() -> Self {
        Self {
            parent: core::array::from_fn(|i| i),
        }
    }

    /// The island of body `i` (its root), paths halved on the way.
    pub(crate) fn root(&mut self, mut i: usize) -> usize {
        while let Some(&p) = self.parent.get(i) {
            if p == i {
                break;
            }
            let grand = self.parent.get(p).copied().unwrap_or(p);
            if let Some(slot) = self.parent.get_mut(i) {
                *slot = grand;
            }
            i = grand;
        }
        i
    }

    /// Joins the islands of bodies `a` and `b`: the root of the lesser key becomes the root
    /// of both (`key` of a body), so that the root is the body of least key.
    pub(crate) fn join(&mut self, a: usize, b: usize, key: impl Fn(usize) -> u32) {
        let (ra, rb) = (self.root(a), self.root(b));
        if ra == rb {
            return;
        }
        let (keep, under) = if key(ra) <= key(rb) {
            (ra, rb)
        } else {
            (rb, ra)
        };
        if let Some(slot) = self.parent.get_mut(under) {
            *slot = keep;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Islands;

    /// Chains joined in any order end with the body of least key at the root.
    #[test]
    fn the_least_key_names_the_island() {
        let keys = [40, 10, 30, 20, 50];
        for order in [[(0, 1), (2, 3), (1, 2)], [(2, 3), (1, 2), (0, 1)]] {
            let mut islands = Islands::<5>::new();
            for (a, b) in order {
                islands.join(a, b, |i| keys[i]);
            }
            for i in 0..4 {
                assert_eq!(islands.root(i), 1, "{order:?}");
            }
            assert_eq!(islands.root(4), 4);
        }
    }
}
