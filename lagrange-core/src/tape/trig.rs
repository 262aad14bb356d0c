//! The sine and cosine nodes already on a tape, by the value they were taken of, so that an
//! angle taken again (in `T`, or in `V` recorded after it) reuses them: no new node, no new
//! `sin_cos`.
//!
//! A chain's `V` takes the cosine of every angle whose sine and cosine `T` has taken; with
//! both on one tape, `V` adds only its sums and products.

use super::NONE;
use crate::Scalar;
use core::cell::Cell;

/// How many angles are kept, in slots by the index of the node the angle is a multiple of
/// (its first nodes are a mechanism's inputs, so the coordinates of up to 32 have a slot each).
/// A further angle in an occupied slot takes it over.
const SLOTS: usize = 32;

/// One angle `x = scale node + shift` and what was taken of it.
#[derive(Clone, Copy)]
struct Entry<S> {
    /// The node `x` is a multiple of ([`NONE`]: a free slot).
    at: u16,
    scale: S,
    x: S,
    sin: S,
    cos: S,
    /// The nodes of the sine and the cosine, [`NONE`] where not yet recorded.
    nodes: (u16, u16),
}

/// The sine and cosine of an angle, and their nodes where recorded ([`NONE`] where not).
#[derive(Clone, Copy)]
pub(crate) struct Found<S> {
    /// `(sin x, cos x)`.
    pub(crate) values: (S, S),
    /// The nodes of the sine and the cosine.
    pub(crate) nodes: (u16, u16),
}

/// The angles taken so far on one tape. Only for plain numbers (`on` false otherwise): there
/// two non-zero values that compare equal are the same bits, so a hit gives the bits a new
/// computation would (zero, whose sine keeps its sign, is never kept; NaN equals nothing).
/// Over dual numbers equal values may differ in their derivatives.
pub(crate) struct TrigNodes<S> {
    slots: [Cell<Entry<S>>; SLOTS],
    on: bool,
}

impl<S: Scalar> TrigNodes<S> {
    /// No angle kept yet; `on` false keeps none ever.
    pub(crate) fn new(on: bool) -> Self {
        let z = S::zero();
        let free = Entry {
            at: NONE,
            scale: z,
            x: z,
            sin: z,
            cos: z,
            nodes: (NONE, NONE),
        };
        Self {
            slots: core::array::from_fn(|_| Cell::new(free)),
            on,
        }
    }

    /// `(sin x, cos x)` and their nodes ([`NONE`] where not recorded yet) for the angle
    /// `x = scale node(at) + shift`: remembered, or computed here.
    #[inline]
    pub(crate) fn find(&self, at: u16, scale: S, x: S) -> Found<S> {
        if let Some(e) = self.slot(at, scale, x).map(Cell::get) {
            if e.at == at && e.scale == scale && e.x == x {
                return Found {
                    values: (e.sin, e.cos),
                    nodes: e.nodes,
                };
            }
        }
        Found {
            values: x.sin_cos(),
            nodes: (NONE, NONE),
        }
    }

    /// Keeps what was `found` for the angle, with its nodes as they are now.
    #[inline]
    pub(crate) fn keep(&self, at: u16, scale: S, x: S, found: Found<S>) {
        if let Some(slot) = self.slot(at, scale, x) {
            slot.set(Entry {
                at,
                scale,
                x,
                sin: found.values.0,
                cos: found.values.1,
                nodes: found.nodes,
            });
        }
    }

    /// The slot of an angle that may be kept (by its node's index modulo [`SLOTS`]): none
    /// where memoing is off, or for a zero value or scale.
    fn slot(&self, at: u16, scale: S, x: S) -> Option<&Cell<Entry<S>>> {
        if !self.on || at == NONE || x.is_zero() || scale.is_zero() {
            return None;
        }
        self.slots.get(usize::from(at) % SLOTS)
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Node, Tape};
    use crate::Scalar;

    /// An angle taken again, in either function or both, is the node recorded first, with the
    /// functions' own bits; a shifted or scaled multiple of the same node, or a zero, is a new
    /// angle. With memoing off every call is a new node.
    #[test]
    fn an_angle_taken_again_is_the_node_recorded_first() {
        for remember in [true, false] {
            let mut storage = heapless::Vec::<Node<f64>, 64>::new();
            let tape = Tape::new(&mut storage, remember);
            let x = tape.input(0.7);
            let c = x.cos();
            let (s2, c2) = x.sin_cos();
            let s3 = x.sin();
            assert_eq!((c2.at == c.at, s3.at == s2.at), (remember, remember));
            let (s0, c0) = libm::sincos(0.7);
            for (v, want) in [(c, c0), (c2, c0), (s2, s0), (s3, s0)] {
                assert_eq!(v.v.to_bits(), want.to_bits());
            }
            let shifted = (x + 1.0).cos();
            let scaled = (x * 2.0).cos();
            assert!(shifted.at != c.at && scaled.at != c.at && shifted.at != scaled.at);
            assert_eq!(shifted.v.to_bits(), libm::cos(1.7).to_bits());
            assert_eq!(scaled.v.to_bits(), libm::cos(1.4).to_bits());
            // Zeros keep their sign through the sine, so they are never looked up.
            let zero = tape.input(-0.0);
            let (a, b) = (zero.sin(), zero.sin());
            assert!(a.at != b.at && a.v.to_bits() == (-0.0f64).to_bits());
            // Two inputs, the sine and cosine of x (each twice where not remembered), the
            // shifted and scaled angles' cosines, the zero's two sines.
            let of_x = if remember { 2 } else { 4 };
            assert_eq!(tape.nodes().map(|n| n.len()), Some(2 + of_x + 2 + 2));
        }
    }

    /// Angles of different nodes are kept side by side: a chain's angles are its first
    /// nodes, and each stays remembered while the others are taken.
    #[test]
    fn angles_of_different_nodes_are_all_kept() {
        let mut storage = heapless::Vec::<Node<f64>, 64>::new();
        let tape = Tape::new(&mut storage, true);
        let xs: [_; 8] = core::array::from_fn(|k| tape.input(0.1 + 0.2 * k as f64));
        let first: [_; 8] = core::array::from_fn(|k| xs[k].sin_cos());
        for (x, (s, c)) in xs.iter().zip(&first) {
            let (s2, c2) = x.sin_cos();
            assert!(s2.at == s.at && c2.at == c.at);
        }
        assert_eq!(tape.nodes().map(|n| n.len()), Some(8 + 16));
    }

    /// A hit is a look-up: a wrong value planted in the slot is what comes back.
    #[test]
    fn a_hit_is_a_look_up() {
        let mut storage = heapless::Vec::<Node<f64>, 16>::new();
        let tape = Tape::new(&mut storage, true);
        let x = tape.input(0.3);
        let c = x.cos();
        let slot = tape.trig.slot(x.at, x.scale, x.v).map(|s| {
            let mut e = s.get();
            e.cos = 42.0;
            s.set(e);
        });
        assert!(slot.is_some());
        let again = x.cos();
        assert_eq!((again.at, again.v), (c.at, 42.0));
    }
}
