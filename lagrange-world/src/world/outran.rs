//! Whether a [`World`](super::World)'s impulses sent a body where its contacts were not looked
//! for: the shapes' reach is taken at the velocities before the impulses, and a limb whipped
//! by a landing can move several times as far. In a pile of ten ragdolls a shin went 92 mm
//! into another doll's thigh in one step where no pair of the two had been looked at; over
//! 24 throws (900 steps each), the deepest overlap of any step was 25-144 mm (f32) and
//! 35-220 mm (f64), and 17-135 and 20-99 mm once the step looked again where this says so.
//!
//! Looking again costs a second detection and solve, so it is asked for only where it
//! matters: a shape whose move at the solved velocities outruns its reach by more than half
//! the margin (the shapes of two bodies may both do so) and that, where the step ends,
//! crosses a half-plane or meets a shape it has no contact with (that one where it is, grown
//! by its own reach and half the margin). In the pile, a shape outran its reach in one step
//! of six to nine; asking for the second look there alone doubled the pile's step in those,
//! and nearly all of them found contacts that never pushed. With the test, 3 to 16 steps of
//! 900 look again.

use super::limits::Limits;
use super::places::Posed;
use super::World;
use crate::broad::{may_touch, Proxy};
use crate::collide::{collide, half_plane_points};
use crate::shape::Shape;
use lagrange_core::links::Links;
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Mechanism, Real};

impl<T, M, L, const N: usize, const B: usize, const S: usize, const K: usize>
    World<T, M, N, B, S, K, L>
where
    T: Real,
    M: Mechanism<T, N> + Links<T, N> + Clone,
    L: Limits<T, N>,
{
    /// Whether the bodies' velocities now (after the impulses; `free` before them, by body)
    /// take a shape of an awake body, outrunning its reach, into a half-plane or a shape it
    /// has no contact with.
    pub(super) fn outran(&self, free: &[SVector<T, N>; B], dt: T) -> bool {
        let slack = self.settings.margin * T::HALF;
        self.by_body.chunk_by(|x, y| x.0 == y.0).any(|group| {
            let Some((b, body, free)) = group.first().and_then(|&(b, _)| {
                let b = b as usize;
                Some((b, self.bodies.get(b)?, free.get(b)?))
            }) else {
                return false;
            };
            // A body the impulses did not touch moves as its reach was taken.
            if body.asleep || body.state.qd == *free {
                return false;
            }
            let then = Posed::ahead(body, &body.state.qd, dt);
            group.iter().any(|&(_, index)| {
                let index = index as usize;
                let (Some(s), Some(place)) = (self.shapes.get(index), self.places.get(index))
                else {
                    return false;
                };
                let link = s.on.map_or(0, |(_, link)| link);
                if then.reach(body, s.extent, link, &place.pose) <= place.reach + slack {
                    return false;
                }
                let end = s.shape.placed(&then.link(body, link));
                self.meets_new(index, b, &end, slack)
            })
        })
    }

    /// Whether shape `index` (on body `body`), placed at `end`, crosses a half-plane or
    /// meets a shape (where it is, grown by its reach and `slack`) it has no contact with.
    fn meets_new(&self, index: usize, body: usize, end: &Shape<T>, slack: T) -> bool {
        let Some(s) = self.shapes.get(index) else {
            return false;
        };
        let plane = self.planes.iter().any(|(key, plane)| {
            !half_plane_points(plane, end, T::zero()).is_empty() && !self.in_contact(*key, s.key)
        });
        if plane {
            return true;
        }
        let (lo, hi) = end.bounds();
        let this = Proxy {
            bounds: (lo, hi),
            body: u32::try_from(body).unwrap_or(u32::MAX),
            key: u32::try_from(index).unwrap_or(u32::MAX),
            group: s.group,
            mask: s.mask,
            fixed: false,
            asleep: false,
        };
        // The proxies are sorted by their boxes' lower x (the step's broad phase sorted them).
        self.broad
            .proxies()
            .iter()
            .take_while(|p| p.bounds.0[0] <= hi[0])
            .filter(|p| p.bounds.1[0] >= lo[0] && may_touch(&this, p))
            .any(|p| {
                let other = p.key as usize;
                let (Some(o), Some(place)) = (self.shapes.get(other), self.places.get(other))
                else {
                    return false;
                };
                let (a, b) = (s.key.min(o.key), s.key.max(o.key));
                !self.in_contact(a, b)
                    && !collide(end, &place.shape, place.reach + slack)
                        .points()
                        .is_empty()
            })
    }

    /// Whether the step's contacts (sorted by key) hold one keyed `(a, b, _)`.
    fn in_contact(&self, a: u32, b: u32) -> bool {
        let at = self
            .contacts
            .partition_point(|c| (c.key.0, c.key.1) < (a, b));
        self.contacts
            .get(at)
            .is_some_and(|c| (c.key.0, c.key.1) == (a, b))
    }
}
