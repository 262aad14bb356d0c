//! [`States`]: how a bank stores its instances' states, by place: as rows ([`Rows`], one
//! `State` per instance, what stepping one by one reads) or as columns
//! ([`Columns`](super::columns::Columns), one array per component, what stepping in lanes
//! reads). Which of the two a bank in lanes uses is its layout's choice
//! ([`LaneStates`](super::layout::LaneStates)).

use lagrange_core::nalgebra::SVector;
use lagrange_core::{Lanes, Real, State};

/// The states of up to `K` instances by place, read and written by value. Places at or past
/// `K` read as zero and take no write: the bank never asks for them.
pub trait States<T: Real, const N: usize, const K: usize>: Clone + core::fmt::Debug {
    /// Every state zero.
    fn new() -> Self;

    /// The state at `place`.
    fn get(&self, place: usize) -> State<T, N>;

    /// Writes the state at `place`.
    fn set(&mut self, place: usize, s: &State<T, N>);

    /// Sets the time at `place`.
    fn set_time(&mut self, place: usize, t: T);

    /// Swaps the states at two places.
    fn swap(&mut self, a: usize, b: usize);

    /// Steps the places from `at` on, one for each of `slots` (what the bank keeps of the
    /// instance there): `step` is given the slot and the place's state in `current`, and where
    /// it gives a new state, that state becomes the place's previous one (in `previous`) and
    /// the new one its state.
    fn step_each<X>(
        current: &mut Self,
        previous: &mut Self,
        at: usize,
        slots: &mut [X],
        step: impl FnMut(&mut X, &State<T, N>) -> Option<State<T, N>>,
    );

    /// The states of places `at..at + count` side by side (`count` at most `L`), the lanes
    /// past `count` copies of the first, so that they take the branches it takes and fail
    /// where it fails.
    fn window<const L: usize>(&self, at: usize, count: usize) -> State<Lanes<T, L>, N>;

    /// Writes the first `count` lanes of `s` into places `at..at + count`.
    fn set_window<const L: usize>(&mut self, at: usize, count: usize, s: &State<Lanes<T, L>, N>);
}

/// One `State` per place, side by side: an instance stepped alone reads and writes its state
/// whole. The storage of a bank one by one, and of a bank in lanes where there is no vector
/// unit: on the Cortex-M4F (16 `f32` pendulums by RK4 under `cargo xtask qemu`), 223
/// instructions per instance-step from rows read in place, 297 from columns (whose loop the
/// compiler also no longer inlined the step into).
#[derive(Debug, Clone)]
pub struct Rows<T: Real, const N: usize, const K: usize>([State<T, N>; K]);

impl<T: Real, const N: usize, const K: usize> States<T, N, K> for Rows<T, N, K> {
    fn new() -> Self {
        Self([State::at_rest([T::zero(); N]); K])
    }

    #[inline(always)]
    fn get(&self, place: usize) -> State<T, N> {
        self.0
            .get(place)
            .copied()
            .unwrap_or_else(|| State::at_rest([T::zero(); N]))
    }

    #[inline(always)]
    fn set(&mut self, place: usize, s: &State<T, N>) {
        if let Some(row) = self.0.get_mut(place) {
            *row = *s;
        }
    }

    fn set_time(&mut self, place: usize, t: T) {
        if let Some(row) = self.0.get_mut(place) {
            row.t = t;
        }
    }

    fn swap(&mut self, a: usize, b: usize) {
        let (x, y) = (self.get(a), self.get(b));
        self.set(a, &y);
        self.set(b, &x);
    }

    /// Each state read where it is and written there, in one pass over the slots and both
    /// rows (indexed by place, with their bounds checks and copies, the Cortex-M4F's bank of
    /// 16 pendulums took 241 instructions per instance-step rather than 223).
    #[inline(always)]
    fn step_each<X>(
        current: &mut Self,
        previous: &mut Self,
        at: usize,
        slots: &mut [X],
        mut step: impl FnMut(&mut X, &State<T, N>) -> Option<State<T, N>>,
    ) {
        let (Some(current), Some(previous)) = (current.0.get_mut(at..), previous.0.get_mut(at..))
        else {
            return;
        };
        for ((slot, now), before) in slots.iter_mut().zip(current).zip(previous) {
            if let Some(next) = step(slot, now) {
                *before = *now;
                *now = next;
            }
        }
    }

    /// Lane by lane (a bank steps in lanes from rows nowhere: [`LaneStates`](super::layout::LaneStates) are columns
    /// where it does).
    fn window<const L: usize>(&self, at: usize, count: usize) -> State<Lanes<T, L>, N> {
        let rows: [State<T, N>; L] =
            core::array::from_fn(|i| self.get(at.saturating_add(if i < count { i } else { 0 })));
        State {
            t: Lanes::from_fn(|i| rows[i].t),
            q: SVector::from_fn(|j, _| Lanes::from_fn(|i| rows[i].q[j])),
            qd: SVector::from_fn(|j, _| Lanes::from_fn(|i| rows[i].qd[j])),
        }
    }

    fn set_window<const L: usize>(&mut self, at: usize, count: usize, s: &State<Lanes<T, L>, N>) {
        for i in 0..count.min(L) {
            let lane = |x: &Lanes<T, L>| x.0.get(i).copied().unwrap_or_else(T::zero);
            let row = State {
                t: lane(&s.t),
                q: s.q.map(|x| lane(&x)),
                qd: s.qd.map(|x| lane(&x)),
            };
            self.set(at.saturating_add(i), &row);
        }
    }
}
