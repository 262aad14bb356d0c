//! [`Awake`]: the awake instances of a bank during a step, stepped one by one or a group at
//! a time in lanes.

use super::slot::Slot;
use super::states::States;
use crate::Integrator;
use core::marker::PhantomData;
use lagrange_core::{divergences, Lanes, Mechanism, Real, State};

/// The awake places of a bank (its first `slots.len()`) with the states of all its places,
/// for one step.
pub struct Awake<'a, T: Real, const N: usize, const K: usize, M, I, S> {
    /// The awake instances' slots.
    pub slots: &'a mut [Slot<M, I>],
    /// Every place's state after the last step.
    pub current: &'a mut S,
    /// Every place's state before it.
    pub previous: &'a mut S,
    /// What `S` stores: states of `N` coordinates in `T`.
    pub states: PhantomData<State<T, N>>,
}

impl<T, const N: usize, const K: usize, M, I, S> Awake<'_, T, N, K, M, I, S>
where
    T: Real,
    M: Mechanism<T, N>,
    I: Integrator<T, N, M>,
    S: States<T, N, K>,
{
    /// How many are awake.
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    /// The mechanism at `place`, if awake.
    pub fn mechanism(&self, place: usize) -> Option<&M> {
        self.slots.get(place).map(|slot| &slot.mechanism)
    }

    /// Steps the `count` instances from `at` one by one by `dt`, landing at `t`; how many
    /// failed (each keeps its state and its error).
    #[inline(always)]
    pub fn step_each(&mut self, at: usize, count: usize, dt: T, t: T) -> u32 {
        let mut failed = 0;
        let end = at.saturating_add(count).min(self.slots.len());
        let slots = self.slots.get_mut(at..end).unwrap_or_default();
        S::step_each(
            self.current,
            self.previous,
            at,
            slots,
            |slot, state| match slot.integrator.run_step(&slot.mechanism, state, dt) {
                Ok(next) => Some(State { t, ..next }),
                Err(e) => {
                    slot.fail(e);
                    failed += 1;
                    None
                }
            },
        );
        failed
    }

    /// Steps the `count` instances from `at` (at most `L`) side by side by `dt`, landing at
    /// `t`, with `mechanism` their mechanisms gathered (lanes past `count` copies of the
    /// first, as [`States::window`] pads the states); each lane takes the bits of its
    /// instance stepped alone. `None`, with nothing changed, where the method does not step
    /// lanes, the step fails or the lanes diverged: then they are to be stepped one by one.
    #[inline(always)]
    pub fn step_group<const L: usize, G: Mechanism<Lanes<T, L>, N>>(
        &mut self,
        mechanism: &G,
        at: usize,
        count: usize,
        dt: T,
        t: T,
    ) -> Option<()> {
        let before = divergences()?;
        let state = self.current.window::<L>(at, count);
        let next = self
            .slots
            .get(at)?
            .integrator
            .step_lanes(mechanism, &state, dt)?
            .ok()?;
        if divergences()? != before {
            return None;
        }
        self.previous.set_window(at, count, &state);
        let next = State {
            t: Lanes::splat(t),
            ..next
        };
        self.current.set_window(at, count, &next);
        Some(())
    }
}
