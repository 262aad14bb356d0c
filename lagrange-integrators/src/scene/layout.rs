//! How a bank keeps and steps its instances, chosen per bank as a type parameter:
//! [`OneByOne`] (any mechanism) or [`InLanes`] (a mechanism that [`Gather`]s).

use super::awake::Awake;
use super::columns::Columns;
use super::states::{Rows, States};
use crate::Integrator;
use core::fmt::Debug;
use lagrange_core::{Gather, Mechanism, Real, VECTOR_UNIT};

/// Instances a bank in lanes steps side by side: 16 where lanes map onto a vector unit
/// ([`VECTOR_UNIT`]: x86_64, aarch64, wasm32 with `simd128`: four 128-bit vector registers of
/// `f32`), 1 elsewhere, where a bank in lanes steps one by one.
///
/// Why 16 rather than the 8 of one or two registers: a group's step is one chain of dependent
/// operations (each stage's law waits for the one before), and the core overlaps little of one
/// group's chain with the next group's, so the width is what gives it independent work. With
/// RK4 on x86_64 (SSE2), a bank of 1,024 `f32` pendulums costs 3.6 times fewer ns per
/// instance-step in lanes of 16 than one by one, and 2.0 times in lanes of 8 (by hand,
/// without a bank: 4.5 and 2.5 times; interleaved timings, one machine).
///
/// On the Cortex-M4F, which has no vector unit, lanes of 4 of the pendulum's RK4 step cost
/// 0.86 times the instructions of one by one when gathered once, but a bank that gathered and
/// scattered its instances every step took 1.09 times (16 `f32` pendulums under `cargo xtask
/// qemu`), in a third more code: lanes are not worth their code there.
pub const LANES: usize = if VECTOR_UNIT { 16 } else { 1 };

/// Instances side by side in the groups that step what is left of a bank's awake instances
/// when it is less than half of [`LANES`] (one 128-bit vector register of `f32`).
const TAIL: usize = if VECTOR_UNIT { 4 } else { 1 };

/// How a [`Bank`](super::Bank) keeps and steps its instances: [`OneByOne`] (the default) or
/// [`InLanes`]. Sealed: the two are the library's.
pub trait Layout<T: Real, const N: usize, const K: usize, M>: sealed::Layout<T, N, K, M> {}

/// Every instance stepped alone, for any mechanism: the bank keeps each instance's mechanism
/// and nothing else of it.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct OneByOne;

/// The awake instances stepped [`LANES`] at a time, side by side in lanes, for a mechanism that
/// [`Gather`]s and a method that steps lanes ([`Integrator::step_lanes`]: RK4, explicit and
/// semi-implicit Euler, velocity Verlet); each instance's trajectory is, bit for bit, the one
/// it has stepped alone.
///
/// The bank keeps all its instances' mechanisms gathered, as one [`Gather::Gathered`] of `K`
/// lanes, beside each instance's own: a group's mechanism is then a window of it, and an
/// instance is written into it when it changes (added, its input or parameters changed, moved
/// as others fall asleep or wake). Its states are kept as structure of arrays (an array per
/// component), so that a group's states are a window of each.
///
/// The awake instances are stepped [`LANES`] at a time; what is left at the end, fewer, in one
/// group of [`LANES`] when it is at least half of one, else in groups of 4, the lanes past
/// the awake ones repeating the first. Where the lanes diverged on a branch
/// ([`divergences`](lagrange_core::divergences)), or the step of any lane failed, or the
/// method does not step lanes, the group is stepped one by one instead, with the same bits.
/// Where there is no vector unit ([`LANES`] is 1) the bank is a bank [`OneByOne`]: it steps
/// one by one, keeps its states as one `State` per instance and nothing gathered.
///
/// Lanes pay where many instances are awake: a group's step is one chain of dependent
/// operations, and a group of 4 takes about as long as a group of 16. With 1 to 6 pendulums
/// awake, a bank in lanes took 1.3 to 3.3 times as long as one by one (x86_64, RK4).
///
/// ```
/// use lagrange_integrators::prelude::*;
/// use lagrange_integrators::scene::{Bank, InLanes, NeverSleeps, Scene};
/// use lagrange_systems::SimplePendulum;
///
/// let mut bank: Bank<f32, 1, 64, SimplePendulum<f32>, Rk4, NeverSleeps, InLanes> =
///     Bank::new(Rk4, NeverSleeps)?;
/// let mut alone = Vec::new();
/// for k in 0..64 {
///     let p = SimplePendulum::new(1.0, 0.5 + 0.01 * k as f32, 9.81, 0.0)?;
///     let start = State::at_rest([0.2 + 0.01 * k as f32]);
///     alone.push((bank.add(p, start)?, p, start));
/// }
/// let mut scene = Scene::new(bank, 1.0 / 120.0, 1)?;
/// for _ in 0..120 {
///     scene.advance(1.0 / 120.0)?;
/// }
/// for (id, p, start) in alone {
///     let end = Rk4.integrate(&p, &start, 1.0 / 120.0, 120)?;
///     let got = scene.banks().state(id)?;
///     assert_eq!((got.q, got.qd), (end.q, end.qd)); // bit for bit
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct InLanes;

impl<T: Real, const N: usize, const K: usize, M> Layout<T, N, K, M> for OneByOne {}

impl<T: Real, const N: usize, const K: usize, M: Gather<T, N>> Layout<T, N, K, M> for InLanes {}

/// What a layout does, out of sight: its methods name the bank's private parts.
pub(super) mod sealed {
    use super::Awake;
    use super::{Debug, Integrator, Mechanism, Real, States};

    /// What a bank keeps and how it steps, by layout.
    pub trait Layout<T: Real, const N: usize, const K: usize, M> {
        /// What the bank keeps of its instances' mechanisms besides each one's own.
        type Kept: Clone + Debug;

        /// How the bank stores its states.
        type States: States<T, N, K>;

        /// Kept of no instance.
        fn kept() -> Self::Kept;

        /// The instance at `place` is now `mechanism` (added, changed or moved there).
        fn put(kept: &mut Self::Kept, place: usize, mechanism: &M);

        /// Steps every awake instance by `dt`, landing at `t`; how many failed.
        fn step<I>(
            kept: &Self::Kept,
            awake: Awake<'_, T, N, K, M, I, Self::States>,
            dt: T,
            t: T,
        ) -> u32
        where
            M: Mechanism<T, N>,
            I: Integrator<T, N, M>;
    }
}

impl<T: Real, const N: usize, const K: usize, M> sealed::Layout<T, N, K, M> for OneByOne {
    type Kept = ();
    type States = Rows<T, N, K>;

    fn kept() {}

    #[inline(always)]
    fn put((): &mut (), _place: usize, _mechanism: &M) {}

    #[inline(always)]
    fn step<I>((): &(), mut awake: Awake<'_, T, N, K, M, I, Self::States>, dt: T, t: T) -> u32
    where
        M: Mechanism<T, N>,
        I: Integrator<T, N, M>,
    {
        let len = awake.len();
        awake.step_each(0, len, dt, t)
    }
}

impl<T: Real, const N: usize, const K: usize, M: Gather<T, N>> sealed::Layout<T, N, K, M>
    for InLanes
{
    /// Every instance's mechanism, by place, once there is one and lanes are used.
    type Kept = Option<M::Gathered<K>>;
    type States = LaneStates<T, N, K>;

    fn kept() -> Self::Kept {
        None
    }

    fn put(kept: &mut Self::Kept, place: usize, mechanism: &M) {
        if LANES == 1 {
            return;
        }
        match kept {
            Some(all) => mechanism.put(all, place),
            None => *kept = Some(M::gather([mechanism; K])),
        }
    }

    #[inline(always)]
    fn step<I>(
        kept: &Self::Kept,
        mut awake: Awake<'_, T, N, K, M, I, Self::States>,
        dt: T,
        t: T,
    ) -> u32
    where
        I: Integrator<T, N, M>,
    {
        let len = awake.len();
        let Some(all) = kept.as_ref().filter(|_| LANES > 1) else {
            return awake.step_each(0, len, dt, t);
        };
        let mut failed = 0;
        let mut at = 0;
        // Whole groups, inlined with nothing to pad, so that the compiler keeps in registers
        // the parameters the law reads and drops the others (with the last group's padding
        // in this loop, every group's parameters and states were copied whole: 1,024
        // pendulums cost 4.8 rather than 3.6 ns per instance-step).
        while at + LANES <= len {
            failed +=
                padded::<T, N, K, M, I, Self::States, LANES>(all, &mut awake, at, LANES, dt, t);
            at += LANES;
        }
        if at < len {
            failed += rest(all, &mut awake, at, dt, t);
        }
        failed
    }
}

/// Steps the awake instances from `at` to the end, fewer than [`LANES`]: in one group of
/// [`LANES`] when they are at least half of one, else in groups of [`TAIL`], the lanes past
/// them copies of the first; how many failed. Out of line: once a step, and its padding would
/// keep the whole groups' parameters in memory.
///
/// Why groups of [`TAIL`] rather than one by one: a bank of 1,000 sleeping `f32` pendulums
/// with 100 awake (six groups of 16 and 4 more) stepped by RK4 cost 7.4 times less than all
/// awake with the 4 one by one, 9.1 times with them in a group of 4 (8.4 in a group of 8).
#[inline(never)]
fn rest<T, const N: usize, const K: usize, M, I, S>(
    all: &M::Gathered<K>,
    awake: &mut Awake<'_, T, N, K, M, I, S>,
    mut at: usize,
    dt: T,
    t: T,
) -> u32
where
    T: Real,
    M: Gather<T, N>,
    I: Integrator<T, N, M>,
    S: States<T, N, K>,
{
    let len = awake.len();
    if 2 * len.saturating_sub(at) >= LANES {
        return padded::<T, N, K, M, I, S, LANES>(all, awake, at, len - at, dt, t);
    }
    let mut failed = 0;
    while at < len {
        let count = (len - at).min(TAIL);
        failed += padded::<T, N, K, M, I, S, TAIL>(all, awake, at, count, dt, t);
        at += count;
    }
    failed
}

/// Steps the `count` awake instances from `at` (at most `L`) in lanes of `L`, the lanes past
/// them copies of the first (so that they take its branches and fail where it fails); one by
/// one where that fails or diverges. How many failed.
#[inline(always)]
fn padded<T, const N: usize, const K: usize, M, I, S, const L: usize>(
    all: &M::Gathered<K>,
    awake: &mut Awake<'_, T, N, K, M, I, S>,
    at: usize,
    count: usize,
    dt: T,
    t: T,
) -> u32
where
    T: Real,
    M: Gather<T, N>,
    I: Integrator<T, N, M>,
    S: States<T, N, K>,
{
    let Some(first) = awake.mechanism(at) else {
        return 0;
    };
    let mut group = M::window::<K, L>(all, at);
    for lane in count..L {
        first.put(&mut group, lane);
    }
    match awake.step_group(&group, at, count, dt, t) {
        Some(()) => 0,
        None => awake.step_each(at, count, dt, t),
    }
}

/// The storage of a bank in lanes on the target built for: [`Columns`] where it steps
/// [`LANES`] instances side by side, [`Rows`] where it steps them one by one.
pub type LaneStates<T, const N: usize, const K: usize> =
    <Pick<{ LANES > 1 }> as Storage<T, N, K>>::States;

/// Chooses [`LaneStates`] by whether lanes are used.
pub struct Pick<const COLUMNS: bool>;

/// The storage [`Pick`] chooses.
pub trait Storage<T: Real, const N: usize, const K: usize> {
    /// Columns or rows.
    type States: States<T, N, K>;
}

impl<T: Real, const N: usize, const K: usize> Storage<T, N, K> for Pick<true> {
    type States = Columns<T, N, K>;
}

impl<T: Real, const N: usize, const K: usize> Storage<T, N, K> for Pick<false> {
    type States = Rows<T, N, K>;
}
