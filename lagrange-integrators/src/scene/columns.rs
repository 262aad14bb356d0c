//! [`Columns`]: the states of a bank's instances as structure of arrays, one array per
//! component, so that a group of instances side by side is a window of each array.

use super::states::States;
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Lanes, Real, State};

/// The states of up to `K` instances, by place: the time of each, then each coordinate's and
/// each velocity's array. A group of `L` places is `L` consecutive values of each array, which
/// a step in [`Lanes`] loads and stores whole, where a state per instance would have to be
/// gathered and scattered component by component (on x86_64 that cost a bank of pendulums half
/// again their step in lanes).
#[derive(Debug, Clone)]
pub struct Columns<T, const N: usize, const K: usize> {
    t: Lanes<T, K>,
    q: [Lanes<T, K>; N],
    qd: [Lanes<T, K>; N],
}

impl<T: Real, const N: usize, const K: usize> States<T, N, K> for Columns<T, N, K> {
    fn new() -> Self {
        Self {
            t: Lanes::splat(T::zero()),
            q: [Lanes::splat(T::zero()); N],
            qd: [Lanes::splat(T::zero()); N],
        }
    }

    #[inline(always)]
    fn get(&self, place: usize) -> State<T, N> {
        let at = |column: &Lanes<T, K>| column.0.get(place).copied().unwrap_or_else(T::zero);
        State {
            t: at(&self.t),
            q: SVector::from_fn(|j, _| self.q.get(j).map_or_else(T::zero, at)),
            qd: SVector::from_fn(|j, _| self.qd.get(j).map_or_else(T::zero, at)),
        }
    }

    #[inline(always)]
    fn set(&mut self, place: usize, s: &State<T, N>) {
        self.t.set(place, s.t);
        for (column, &x) in self.q.iter_mut().zip(s.q.iter()) {
            column.set(place, x);
        }
        for (column, &x) in self.qd.iter_mut().zip(s.qd.iter()) {
            column.set(place, x);
        }
    }

    #[inline(always)]
    fn step_each<X>(
        current: &mut Self,
        previous: &mut Self,
        at: usize,
        slots: &mut [X],
        mut step: impl FnMut(&mut X, &State<T, N>) -> Option<State<T, N>>,
    ) {
        for (place, slot) in (at..).zip(slots) {
            let now = current.get(place);
            if let Some(next) = step(slot, &now) {
                previous.set(place, &now);
                current.set(place, &next);
            }
        }
    }

    fn set_time(&mut self, place: usize, t: T) {
        self.t.set(place, t);
    }

    fn swap(&mut self, a: usize, b: usize) {
        let (x, y) = (self.get(a), self.get(b));
        self.set(a, &y);
        self.set(b, &x);
    }

    #[inline(always)]
    fn window<const L: usize>(&self, at: usize, count: usize) -> State<Lanes<T, L>, N> {
        let lanes = |column: &Lanes<T, K>| {
            let mut lanes = column.window::<L>(at);
            if count < L {
                let first = lanes.0.first().copied().unwrap_or_else(T::zero);
                for x in lanes.0.iter_mut().skip(count) {
                    *x = first;
                }
            }
            lanes
        };
        State {
            t: lanes(&self.t),
            q: SVector::from_fn(|j, _| self.q.get(j).map_or_else(Lanes::default, lanes)),
            qd: SVector::from_fn(|j, _| self.qd.get(j).map_or_else(Lanes::default, lanes)),
        }
    }

    #[inline(always)]
    fn set_window<const L: usize>(&mut self, at: usize, count: usize, s: &State<Lanes<T, L>, N>) {
        let write = |column: &mut Lanes<T, K>, lanes: &Lanes<T, L>| {
            // A whole group is one store of `L` lanes; a short one goes value by value.
            let whole = column.0.get_mut(at..).and_then(|rest| rest.get_mut(..L));
            match whole.filter(|_| count == L) {
                Some(places) => places.copy_from_slice(&lanes.0),
                None => {
                    for (place, &x) in column.0.iter_mut().skip(at).zip(lanes.0.iter().take(count))
                    {
                        *place = x;
                    }
                }
            }
        };
        write(&mut self.t, &s.t);
        for (column, lanes) in self.q.iter_mut().zip(s.q.iter()) {
            write(column, lanes);
        }
        for (column, lanes) in self.qd.iter_mut().zip(s.qd.iter()) {
            write(column, lanes);
        }
    }
}
