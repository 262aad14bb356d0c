//! How a bank keeps and steps its instances, chosen per bank as a type parameter:
//! [`OneByOne`] (any mechanism) or [`InLanes`] (a mechanism that [`Gather`]s).

use super::awake::Awake;
use crate::Integrator;
use core::fmt::Debug;
use lagrange_core::{Gather, Mechanism, Real, VECTOR_UNIT};

/// Instances a bank in lanes steps side by side: 8 where lanes map onto a vector unit
/// ([`VECTOR_UNIT`]: x86_64, aarch64, wasm32 with `simd128`: one or two vector registers of
/// `f32`), 1 elsewhere, where a bank in lanes steps one by one.
///
/// On the Cortex-M4F, which has no vector unit, lanes of 4 of the pendulum's RK4 step cost
/// 0.86 times the instructions of one by one when gathered once, but a bank that gathered and
/// scattered its instances every step took 1.09 times (16 `f32` pendulums under `cargo xtask
/// qemu`), in a third more code: lanes are not worth their code there.
pub const LANES: usize = if VECTOR_UNIT { 8 } else { 1 };

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
/// as others fall asleep or wake). Its states are kept as structure of arrays in either layout.
///
/// A group steps in lanes when at least half of it is awake (the last group of the awake ones
/// may be short: the lanes past the awake ones repeat the first); where the lanes diverged on
/// a branch ([`divergences`](lagrange_core::divergences)), or the step of any lane failed, or
/// the method does not step lanes, the group is stepped one by one instead, with the same bits.
/// Where there is no vector unit ([`LANES`] is 1) the bank steps one by one and keeps nothing
/// gathered.
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
    use super::{Debug, Integrator, Mechanism, Real};

    /// What a bank keeps and how it steps, by layout.
    pub trait Layout<T: Real, const N: usize, const K: usize, M> {
        /// What the bank keeps of its instances' mechanisms besides each one's own.
        type Kept: Clone + Debug;

        /// Kept of no instance.
        fn kept() -> Self::Kept;

        /// The instance at `place` is now `mechanism` (added, changed or moved there).
        fn put(kept: &mut Self::Kept, place: usize, mechanism: &M);

        /// Steps every awake instance by `dt`, landing at `t`; how many failed.
        fn step<I>(kept: &Self::Kept, awake: Awake<'_, T, N, K, M, I>, dt: T, t: T) -> u32
        where
            M: Mechanism<T, N>,
            I: Integrator<T, N, M>;
    }
}

impl<T: Real, const N: usize, const K: usize, M> sealed::Layout<T, N, K, M> for OneByOne {
    type Kept = ();

    fn kept() {}

    #[inline(always)]
    fn put((): &mut (), _place: usize, _mechanism: &M) {}

    #[inline(always)]
    fn step<I>((): &(), mut awake: Awake<'_, T, N, K, M, I>, dt: T, t: T) -> u32
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
    fn step<I>(kept: &Self::Kept, mut awake: Awake<'_, T, N, K, M, I>, dt: T, t: T) -> u32
    where
        I: Integrator<T, N, M>,
    {
        let len = awake.len();
        let Some(all) = kept.as_ref().filter(|_| LANES > 1) else {
            return awake.step_each(0, len, dt, t);
        };
        let mut failed = 0;
        let mut at = 0;
        while at < len {
            let count = (len - at).min(LANES);
            if 2 * count < LANES {
                return failed + awake.step_each(at, count, dt, t);
            }
            let mut group = M::window::<K, LANES>(all, at);
            if let Some(first) = awake.mechanism(at).filter(|_| count < LANES) {
                for lane in count..LANES {
                    first.put(&mut group, lane);
                }
            }
            if awake.step_group(&group, at, count, dt, t).is_none() {
                failed += awake.step_each(at, count, dt, t);
            }
            at += count;
        }
        failed
    }
}
