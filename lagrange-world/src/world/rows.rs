//! The rows of a [`World`](super::World)'s contacts: a contact point between two bodies (or a
//! body and static geometry) as a normal row and a tangent row in the two bodies' generalized
//! coordinates, each with its mobilities (`M^-1 j^T`, from each body's own mass solve) and
//! the impulse it has taken; and which of a contact's impulses a sweep solves for
//! ([`Phase`], [`Part`]).

use super::block::LOCKS;
use crate::vec2::Vec2;
use lagrange_core::nalgebra::SVector;
use lagrange_core::Real;

/// What identifies a contact point from step to step: the two shapes' keys (the first the
/// shape the normal points away from) and the features that meet (the manifold's id). Its
/// last impulses are matched by it (warm starting), and contacts are solved in its order.
pub(crate) type ContactKey = (u32, u32, u32);

/// The partial sums of a row's speed.
const LANES: usize = 4;

/// One row of a contact: `a = sum_s j[s] . v[body s]`, and the velocity change a unit impulse
/// on it makes, `b[s] = M_s^-1 j[s]^T`, on each side (zero on a static side).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Row<T: Real, const N: usize> {
    pub(crate) j: [SVector<T, N>; 2],
    pub(crate) b: [SVector<T, N>; 2],
    /// `1 / W`, `W = sum_s j[s] . b[s]`; zero for a row no impulse moves.
    pub(crate) inverse: T,
    /// The impulse taken this step (warm-started from the last step's).
    pub(crate) lambda: T,
    /// On each side, the impulses per unit of this row's that the rows locked on its body
    /// take (see `locks`; zero where none are).
    pub(crate) locks: [[T; LOCKS]; 2],
    /// Whether rows are locked in it on a side.
    pub(crate) held: bool,
}

impl<T: Real, const N: usize> Row<T, N> {
    /// A row of Jacobians `j` and mobilities `b`, no impulse yet.
    pub(crate) fn new(j: [SVector<T, N>; 2], b: [SVector<T, N>; 2]) -> Self {
        let mut row = Self::unsolved(j);
        row.b = b;
        row.refresh();
        row
    }

    /// A row of Jacobians `j` whose mobilities are still to come (zero, as its `1 / W`):
    /// set with its body's others, then [`Row::refresh`].
    pub(crate) fn unsolved(j: [SVector<T, N>; 2]) -> Self {
        Self {
            j,
            b: [SVector::zeros(); 2],
            inverse: T::zero(),
            lambda: T::zero(),
            locks: [[T::zero(); LOCKS]; 2],
            held: false,
        }
    }

    /// Its `1 / W` from its mobilities as they are now.
    pub(crate) fn refresh(&mut self) {
        self.inverse = self.inverse_now();
    }

    /// `1 / W` from its mobilities as they are now (zero for a row no impulse moves).
    pub(crate) fn inverse_now(&self) -> T {
        let w = self.j[0].dot(&self.b[0]) + self.j[1].dot(&self.b[1]);
        // A row no impulse moves (both sides static, or a point that no coordinate moves
        // along it) takes none.
        if w > T::EPSILON && (T::one() / w).is_finite() {
            T::one() / w
        } else {
            T::zero()
        }
    }

    /// The row's velocity `a` at the bodies' velocities `v` (a side of no body: `None`).
    pub(crate) fn speed(&self, v: [Option<&SVector<T, N>>; 2]) -> T {
        // Summed in four lanes, not one running sum: the solve's sweeps wait on each row's
        // speed before the next (its impulse moves the bodies the next row reads), and a
        // sum of 24 terms one after another was most of a ragdoll pile's step.
        let mut lanes = [T::zero(); LANES];
        for (j, v) in self.j.iter().zip(v) {
            if let Some(v) = v {
                for (k, (a, b)) in j.as_slice().iter().zip(v.as_slice()).enumerate() {
                    lanes[k % LANES] += *a * *b;
                }
            }
        }
        (lanes[0] + lanes[1]) + (lanes[2] + lanes[3])
    }
}

/// A contact point of a step.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Contact<T: Real, const N: usize> {
    pub(crate) key: ContactKey,
    /// The bodies (indices into the world's) on each side; `None` for static geometry.
    pub(crate) bodies: [Option<usize>; 2],
    pub(crate) normal: Row<T, N>,
    pub(crate) tangent: Row<T, N>,
    /// The gap at the step's start (negative: overlapping).
    pub(crate) gap: T,
    /// The normal row's lowest velocity after the solve: `-gap / dt` for a contact still
    /// open (it may close this step, no more), zero for one touching, `-e a0` for one that
    /// rebounds.
    pub(crate) lower: T,
    /// The normal row's speed at the free step's velocities (negative: closing).
    pub(crate) approach: T,
    /// The drift correction's impulse (on pseudo-velocities; see `solve::drift`).
    pub(crate) drift: T,
    /// The drift correction's lowest pseudo-speed (see `solve::drift`).
    pub(crate) reach: T,
    /// Where it is (met later in the step: where they meet) and the normal, world
    /// coordinates (for events and queries).
    pub(crate) point: Vec2<T>,
    pub(crate) direction: Vec2<T>,
    /// On the first of twins (the two points of one manifold: see `twins`), `W` of their
    /// normal rows, `[W11, W12, W22]`; else `None`.
    pub(crate) twin: Option<[T; 3]>,
}

/// What a contact's impulses were at the end of a step, kept for the next one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Kept<T> {
    pub(crate) key: ContactKey,
    pub(crate) normal: T,
    pub(crate) tangent: T,
}

/// Which impulses a sweep solves for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Phase {
    /// The velocities': each tangent within the cone, each normal row to its `lower` speed.
    Velocity,
    /// The drift's, on pseudo-velocities: each normal row to its `reach`.
    Drift,
}

/// One of a contact's two rows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Part {
    /// Along the contact's normal.
    Normal,
    /// Across it (friction).
    Tangent,
}

impl Phase {
    /// The impulse of row `part` of `c` that this phase solves for.
    pub(crate) fn impulse<T: Real, const N: usize>(
        self,
        c: &mut Contact<T, N>,
        part: Part,
    ) -> &mut T {
        match (self, part) {
            (Phase::Drift, _) => &mut c.drift,
            (Phase::Velocity, Part::Normal) => &mut c.normal.lambda,
            (Phase::Velocity, Part::Tangent) => &mut c.tangent.lambda,
        }
    }

    /// [`Phase::impulse`], read.
    pub(crate) fn impulse_of<T: Real, const N: usize>(self, c: &Contact<T, N>, part: Part) -> T {
        match (self, part) {
            (Phase::Drift, _) => c.drift,
            (Phase::Velocity, Part::Normal) => c.normal.lambda,
            (Phase::Velocity, Part::Tangent) => c.tangent.lambda,
        }
    }

    /// The speed row `part` of `c` is solved to.
    pub(crate) fn target<T: Real, const N: usize>(self, c: &Contact<T, N>, part: Part) -> T {
        match (self, part) {
            (Phase::Drift, _) => c.reach,
            (Phase::Velocity, Part::Normal) => c.lower,
            (Phase::Velocity, Part::Tangent) => T::zero(),
        }
    }
}

impl Part {
    /// Row `self` of `c`.
    pub(crate) fn of<T: Real, const N: usize>(self, c: &Contact<T, N>) -> &Row<T, N> {
        match self {
            Part::Normal => &c.normal,
            Part::Tangent => &c.tangent,
        }
    }
}
