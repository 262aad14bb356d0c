//! [`Gather`]: mechanisms whose instances can be laid side by side in [`Lanes`], with a type
//! that names them so laid ([`Gather::Gathered`]), for a scene's bank to keep between steps.

use crate::{Lanes, Mechanism, Real};
use core::fmt::Debug;

/// A mechanism whose instances can be laid side by side: `L` of them as one mechanism over
/// [`Lanes`] ([`Gather::Gathered`], lane `i` instance `i`), so that any method that steps lanes
/// ([`Integrator::step_lanes`] in `lagrange-integrators`) steps them together, each lane bit for
/// bit its instance stepped alone.
///
/// Opt-in, apart from [`Mechanism`]: a mechanism of your own needs nothing of it to be stepped,
/// in a bank or alone. The standard mechanisms of `lagrange-systems` that are plain structs of
/// scalars implement it (the pendulum, double pendulum, cart-pole, acrobot, spring, falling
/// particle, rigid body), and a scene's bank in lanes (`InLanes` in `lagrange-integrators`) keeps its
/// instances gathered, all `K` of them as one `Gathered<K>`, from which it takes each group's
/// [`Gather::window`] at every step and into which it [`Gather::put`]s an instance that changed.
///
/// The three methods must agree: lane `i` of `gather(instances)` is `instances[i]`; lane `i` of
/// `window(wide, at)` is lane `at + i` of `wide`; after `put(m, lanes, i)`, lane `i` is `m` and
/// the others are as they were. And the gathered law must pass its errors on, not replace a
/// failed result by another: the tests of results ([`check_finite`](crate::check_finite)) fail
/// for all lanes when one lane fails and count no divergence, because the error sends the
/// step's lanes one by one.
///
/// [`Integrator::step_lanes`]: https://docs.rs/lagrange-integrators
///
/// A spring of stiffness `k` (unit mass):
///
/// ```
/// use lagrange_core::prelude::*;
/// use lagrange_core::{Gather, Lanes};
/// use lagrange_core::nalgebra::SMatrix;
///
/// #[derive(Debug, Clone, Copy)]
/// struct Spring<T: Real> {
///     k: T,
/// }
/// impl<T: Real> Lagrangian<T, 1> for Spring<T> {
///     fn kinetic<S: Scalar<Real = T>>(&self, _: S, _: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
///         qd[0] * qd[0] * T::HALF
///     }
///     fn potential<S: Scalar<Real = T>>(&self, _: S, q: &SVector<S, 1>) -> S {
///         q[0] * q[0] * (self.k * T::HALF)
///     }
/// }
/// impl<T: Real> Mechanism<T, 1> for Spring<T> {
///     fn mass_matrix(&self, _: &State<T, 1>) -> SMatrix<T, 1, 1> {
///         SMatrix::identity()
///     }
///     fn rhs(&self, s: &State<T, 1>) -> SVector<T, 1> {
///         SVector::from([-self.k * s.q[0]])
///     }
/// }
/// impl<T: Real> Gather<T, 1> for Spring<T> {
///     type Gathered<const L: usize> = Spring<Lanes<T, L>>;
///     fn gather<const L: usize>(instances: [&Self; L]) -> Spring<Lanes<T, L>> {
///         Spring { k: Lanes::gather(&instances, |m| m.k) }
///     }
///     #[inline(always)]
///     fn window<const W: usize, const L: usize>(
///         wide: &Spring<Lanes<T, W>>,
///         at: usize,
///     ) -> Spring<Lanes<T, L>> {
///         Spring { k: wide.k.window(at) }
///     }
///     fn put<const L: usize>(&self, lanes: &mut Spring<Lanes<T, L>>, lane: usize) {
///         lanes.k.set(lane, self.k);
///     }
/// }
///
/// let springs = [Spring { k: 1.0 }, Spring { k: 4.0 }];
/// let both = Spring::gather([&springs[0], &springs[1]]);
/// let s = State::new(Lanes([0.0; 2]), [Lanes([1.0, 1.0])], [Lanes([0.0; 2])]);
/// let a = both.acceleration(&s)?;
/// assert_eq!(a[0].0, [-1.0, -4.0]);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
pub trait Gather<T: Real, const N: usize>: Mechanism<T, N> + Sized {
    /// `L` instances side by side: this type over [`Lanes<T, L>`](Lanes), each parameter the
    /// lanes of the instances' values.
    type Gathered<const L: usize>: Mechanism<Lanes<T, L>, N> + Clone + Debug;

    /// These instances side by side, lane `i` being `instances[i]`.
    fn gather<const L: usize>(instances: [&Self; L]) -> Self::Gathered<L>;

    /// `L` lanes of a wider gathered mechanism from lane `at` on ([`Lanes::window`]: lanes
    /// past its end repeat its last).
    ///
    /// A bank in lanes calls it for every group at every step: mark it `#[inline(always)]`,
    /// as the standard mechanisms do. Inlined, the step reads the parameters its law uses
    /// straight from the bank and leaves the others; called, it copies them all (left to the
    /// compiler, it was not inlined in a bank that sleeps).
    fn window<const W: usize, const L: usize>(
        wide: &Self::Gathered<W>,
        at: usize,
    ) -> Self::Gathered<L>;

    /// Writes this instance into lane `lane` of `lanes` ([`Lanes::set`]: nothing when `lane`
    /// is not below `L`).
    fn put<const L: usize>(&self, lanes: &mut Self::Gathered<L>, lane: usize);
}
