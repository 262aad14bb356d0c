//! The pairs of shapes that touch, kept sorted from step to step by a merge in place (see
//! `World::record_events`).

use heapless::Vec;

/// `pairs` (sorted, none of them in `into`) merged into `into` (sorted): `into` sorted. From
/// the back, in place, each pair moved once; past the capacity, the smallest of `pairs` are
/// the ones left out.
pub(super) fn merge_pairs<const K: usize, I>(into: &mut Vec<(u32, u32), K>, pairs: I)
where
    I: DoubleEndedIterator<Item = (u32, u32)> + ExactSizeIterator,
{
    let mut read = into.len();
    let mut write = (read + pairs.len()).min(K);
    let _ = into.resize(write, (0, 0));
    for pair in pairs.rev() {
        if write == read {
            break;
        }
        // The pairs of `into` above this one move up past it.
        while let Some(&p) = read.checked_sub(1).and_then(|r| into.get(r)) {
            if p < pair {
                break;
            }
            (read, write) = (read - 1, write - 1);
            if let Some(slot) = into.get_mut(write) {
                *slot = p;
            }
        }
        write -= 1;
        if let Some(slot) = into.get_mut(write) {
            *slot = pair;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::merge_pairs;
    use heapless::Vec;

    type Pairs = Vec<(u32, u32), 64>;

    /// Sorted disjoint pairs, drawn from the first `count`.
    fn split(seed: u64, count: u32) -> (Pairs, Pairs) {
        let mut x = seed;
        let (mut a, mut b) = (Pairs::new(), Pairs::new());
        for k in 0..count {
            x = x
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let pair = (k / 3, k);
            let _ = match x >> 62 {
                0 => a.push(pair),
                1 => b.push(pair),
                _ => Ok(()),
            };
        }
        (a, b)
    }

    /// The merge is the sorted union, for lists of every size up to the capacity; past it,
    /// `into` is kept with the largest of the others that fit, sorted, and nothing panics.
    #[test]
    fn merged_pairs_are_the_sorted_union() {
        for seed in 0..200 {
            let (a, b) = split(seed, u32::try_from(seed % 64).unwrap_or(0));
            let mut into = a.clone();
            merge_pairs(&mut into, b.iter().copied());
            let mut union = a.clone();
            for &p in &b {
                let _ = union.push(p);
            }
            union.sort_unstable();
            assert_eq!(into, union, "seed {seed}");
            let mut small: Vec<(u32, u32), 8> = a.iter().take(8).copied().collect();
            let mut expected: Vec<(u32, u32), 8> = small.clone();
            for &p in b.iter().rev().take(8 - small.len()) {
                let _ = expected.push(p);
            }
            expected.sort_unstable();
            merge_pairs(&mut small, b.iter().copied());
            assert_eq!(small, expected, "seed {seed}");
        }
    }
}
