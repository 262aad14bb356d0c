//! The broad phase: [`BroadPhase`], the pairs of shapes whose bounding boxes overlap and that
//! may collide, by sweep and prune along x, without a heap.

use crate::vec2::Vec2;
use heapless::Vec;
use lagrange_core::{Error, Real};

/// A shape as the broad phase sees it: its bounding box, whose it is and what it may touch.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Proxy<T> {
    /// The bounding box, lower and upper corners ([`Shape::bounds`](crate::Shape::bounds),
    /// grown by a margin for speculative contacts).
    pub bounds: (Vec2<T>, Vec2<T>),
    /// The body (a mechanism instance) it belongs to, and a key unique among the proxies:
    /// pairs come out ordered by keys, so the order proxies were added in does not matter.
    pub body: u32,
    /// Unique among the proxies; see `body`.
    pub key: u32,
    /// The collision groups it belongs to, one bit each.
    pub group: u32,
    /// The groups it collides with: a pair is kept only where each one's group meets the
    /// other's mask.
    pub mask: u32,
    /// Static geometry: never paired with other static geometry.
    pub fixed: bool,
    /// Asleep: never paired with another asleep or static proxy.
    pub asleep: bool,
}

/// The pairs of proxies whose boxes overlap and that may touch: not both static, not both
/// asleep (or asleep and static), not of the same body (a mechanism's own links are its own
/// business: its rows, its limits), and each one's group in the other's mask.
///
/// `P` proxies at most. Sweep and prune: the proxies sorted by the lower x of their boxes
/// (by key among equals), each compared with those after it until one starts beyond its end;
/// `O(P log P + pairs + overlaps along x)`.
///
/// ```
/// use lagrange_world::{BroadPhase, Proxy};
/// let proxy = |key: u32, x: f64, fixed: bool| Proxy {
///     bounds: ([x, 0.0], [x + 1.0, 1.0]),
///     body: key,
///     key,
///     group: 1,
///     mask: u32::MAX,
///     fixed,
///     asleep: false,
/// };
/// let mut broad = BroadPhase::<f64, 8>::new();
/// for p in [proxy(0, 0.0, true), proxy(1, 0.5, false), proxy(2, 3.0, false)] {
///     broad.add(p)?;
/// }
/// let mut pairs = heapless::Vec::<(u32, u32), 8>::new();
/// broad.pairs(&mut pairs)?;
/// assert_eq!(pairs.as_slice(), &[(0, 1)]);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct BroadPhase<T, const P: usize> {
    proxies: Vec<Proxy<T>, P>,
}

impl<T: Real, const P: usize> Default for BroadPhase<T, P> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Real, const P: usize> BroadPhase<T, P> {
    /// No proxies.
    #[must_use]
    pub fn new() -> Self {
        Self {
            proxies: Vec::new(),
        }
    }

    /// Adds `proxy`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `proxy` when its box is not finite or upside down, or its
    /// key is taken; `capacity` when `P` proxies are there already.
    pub fn add(&mut self, proxy: Proxy<T>) -> Result<(), Error> {
        check_box(&proxy)?;
        if self.proxies.iter().any(|p| p.key == proxy.key) {
            return Err(Error::InvalidParameter {
                name: "proxy",
                reason: "its key is taken",
            });
        }
        self.push(proxy)
    }

    /// As [`BroadPhase::add`], for a caller whose keys are unique already (a world, whose
    /// shapes' keys are): the box checked, the key not looked for among the others, so that
    /// refilling `n` proxies each step costs `n` checks rather than `n^2 / 2` (a world of
    /// 1,000 balls spent 0.36 ms of its 3 ms step on that scan).
    pub(crate) fn add_unique(&mut self, proxy: Proxy<T>) -> Result<(), Error> {
        check_box(&proxy)?;
        self.push(proxy)
    }

    /// `proxy` appended, or the broad phase is full.
    fn push(&mut self, proxy: Proxy<T>) -> Result<(), Error> {
        self.proxies
            .push(proxy)
            .map_err(|_| Error::InvalidParameter {
                name: "capacity",
                reason: "the broad phase is full",
            })
    }

    /// Forgets every proxy (a broad phase is refilled each step from where the shapes are).
    pub fn clear(&mut self) {
        self.proxies.clear();
    }

    /// The proxies, in the order they were added.
    #[must_use]
    pub fn proxies(&self) -> &[Proxy<T>] {
        &self.proxies
    }

    /// Fills `out` with the keys of the pairs that may touch, each pair `(lower key, higher
    /// key)`, ordered by keys.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `capacity` when `out` cannot hold them all (it holds as
    /// many as it could, in order).
    pub fn pairs<const Q: usize>(&mut self, out: &mut Vec<(u32, u32), Q>) -> Result<(), Error> {
        out.clear();
        self.proxies.sort_unstable_by(|a, b| {
            a.bounds.0[0]
                .partial_cmp(&b.bounds.0[0])
                .unwrap_or(core::cmp::Ordering::Equal)
                .then(a.key.cmp(&b.key))
        });
        let mut full = false;
        for (i, a) in self.proxies.iter().enumerate() {
            for b in self.proxies.iter().skip(i + 1) {
                if b.bounds.0[0] > a.bounds.1[0] {
                    break;
                }
                if may_touch(a, b) {
                    let pair = (a.key.min(b.key), a.key.max(b.key));
                    full |= out.push(pair).is_err();
                }
            }
        }
        out.sort_unstable();
        if full {
            return Err(Error::InvalidParameter {
                name: "capacity",
                reason: "more pairs than the output holds",
            });
        }
        Ok(())
    }
}

/// `Ok` where `proxy`'s box is finite and its lower corner below its upper.
fn check_box<T: Real>(proxy: &Proxy<T>) -> Result<(), Error> {
    let (lo, hi) = proxy.bounds;
    let finite = lo.iter().chain(&hi).all(|x| x.is_finite());
    if !finite || lo[0] > hi[0] || lo[1] > hi[1] {
        return Err(Error::InvalidParameter {
            name: "proxy",
            reason: "its box must be finite, its lower corner below its upper",
        });
    }
    Ok(())
}

/// Whether `a` and `b`, overlapping along x, overlap along y and may touch.
pub(crate) fn may_touch<T: Real>(a: &Proxy<T>, b: &Proxy<T>) -> bool {
    let overlap = a.bounds.0[1] <= b.bounds.1[1] && b.bounds.0[1] <= a.bounds.1[1];
    let resting = (a.fixed || a.asleep) && (b.fixed || b.asleep);
    let groups = a.group & b.mask != 0 && b.group & a.mask != 0;
    overlap && !resting && a.body != b.body && groups
}
