//! The impulses of one step: the normal rows' complementarity problem solved exactly
//! ([`Delassus::complementary`]), alternated with Coulomb friction sweeps, at most a capped
//! number of times.

use super::rows::{within, Direction};
use lagrange_core::constraints::contact::{Delassus, Row};
use lagrange_core::nalgebra::SVector;
use lagrange_core::{split_dot, Error, Real};

/// The impulses of one step per row of the contact set: along each row's normal and its
/// tangent (zero where a row took no part).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Impulses<T, const C: usize> {
    pub(super) normal: SVector<T, C>,
    pub(super) tangent: [T; C],
}

impl<T: Real, const C: usize> Impulses<T, C> {
    /// None.
    pub(super) fn zero() -> Self {
        Self {
            normal: SVector::zeros(),
            tangent: [T::zero(); C],
        }
    }
}

/// Sweeps of projected Gauss-Seidel where the exact solve of the normal rows cycles: 4 C, the
/// exact method's own cap on its passes (each sweep costs about what one of its passes does
/// on a few rows).
const fn relaxed_sweeps<const C: usize>() -> u32 {
    let sweeps = 4 * C;
    if sweeps > u32::MAX as usize {
        u32::MAX
    } else {
        sweeps as u32
    }
}

/// How a solve went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Solved<T: Real, const N: usize, const C: usize> {
    pub(super) impulses: Impulses<T, C>,
    /// The velocities after the impulses.
    pub(super) velocity: SVector<T, N>,
    /// Normal solves taken (each followed by a friction sweep where there is friction).
    pub(super) rounds: u32,
    /// Whether the last friction sweep changed no tangent's speed by more than the tolerance
    /// (always, without friction).
    pub(super) settled: bool,
    /// The normal rows the last round solved for: the first guess of a solve after it.
    pub(super) active: [bool; C],
}

/// The rows of one step's solve.
pub(super) struct Problem<'a, T: Real, const N: usize, const C: usize> {
    /// The normal rows (the candidates: in contact, or speculative).
    pub(super) normal: &'a mut Delassus<T, N, C>,
    /// How each normal row holds.
    pub(super) kinds: &'a [Row<T>; C],
    /// The tangents of the contacts with friction.
    pub(super) tangent: &'a [Option<Direction<T, N>>; C],
    /// The Coulomb coefficient.
    pub(super) friction: T,
    /// The first guess of the normal solve's active rows: the rows that pushed last (in the
    /// last step; for a solve after a step's plastic one, the rows that solve ended with).
    pub(super) pushed: &'a [bool; C],
}

impl<T: Real, const N: usize, const C: usize> Problem<'_, T, N, C> {
    /// The impulses that give every normal row at least its `target` speed from the
    /// velocities `v0` (exactly its target where it pushes; a bilateral row exactly), with
    /// Coulomb friction `|tangent| <= mu normal` stopping the sliding where it can: the
    /// normal rows solved exactly with the tangents' impulses held, then a projected
    /// Gauss-Seidel sweep of the tangents with the normals held (in the last round `rounds`
    /// allows, sweeps until they settle, at most `sweeps`), from the tangents' impulses
    /// `warm`, at most `rounds` times, ending early once a round's first sweep changes no
    /// tangent's speed by more than `tolerance` (plus the rounding of its speed). The cone
    /// holds exactly at the end. The velocities returned are `v0` plus the response of the
    /// final impulses.
    ///
    /// Where the exact solve has no answer (targets no impulses reach: a joint's two limits
    /// asked for rebounds that would cross its range in the step) or does not end in its
    /// passes (a degenerate set that cycles), that round's normal impulses are projected
    /// Gauss-Seidel's ([`Delassus::relaxed`]) and the solve is not settled.
    ///
    /// # Errors
    /// As [`Delassus::complementary`], but for [`Error::NoConvergence`].
    pub(super) fn solve(
        self,
        v0: &SVector<T, N>,
        target: &SVector<T, C>,
        warm: &Impulses<T, C>,
        rounds: u32,
        sweeps: u32,
        tolerance: T,
    ) -> Result<Solved<T, N, C>, Error> {
        let mut p = Impulses::zero();
        for (i, t) in self.tangent.iter().enumerate() {
            if t.is_some() {
                p.tangent[i] = warm.tangent[i];
            }
        }
        // The rows with a tangent, listed: the sweeps run over them alone.
        let mut with_tangent = [0_usize; C];
        let mut count = 0;
        for (slot, i) in with_tangent
            .iter_mut()
            .zip((0..C).filter(|&i| self.tangent[i].is_some()))
        {
            *slot = within::<C>(i);
            count += 1;
        }
        let frictional = self.friction > T::zero() && count > 0;
        let rounding = T::from_f64(16.0) * T::EPSILON;
        let (mut taken, mut settled, mut exact) = (0, false, true);
        let mut guess = *self.pushed;
        while taken < rounds.max(1) && !settled {
            taken += 1;
            let sliding = self.tangent_response(v0, &p.tangent, &with_tangent[..count.min(C)]);
            let b = self.normal.speeds(&sliding) - target;
            let solved = match self.normal.complementary_from(&b, self.kinds, &guess) {
                Ok(solved) => solved,
                // Targets no impulses reach, or a degenerate set the exact method cycles on
                // (many contacts struck at once, more than the motion has freedoms):
                // projected Gauss-Seidel, whose impulses never add energy, for this round;
                // the solve has not settled.
                Err(Error::NoConvergence { .. }) => {
                    exact = false;
                    self.normal.relaxed(&b, self.kinds, relaxed_sweeps::<C>())
                }
                Err(e) => return Err(e),
            };
            (p.normal, guess) = (solved.lambda, solved.active);
            if !frictional {
                settled = true;
                break;
            }
            // One sweep of the tangents, and the next round solves the normals again: the
            // rounds are Gauss-Seidel over the normals (exactly) and the tangents. Sweeping
            // the tangents until they settle against normals that the next round moves was
            // work lost (a landing ragdoll's rounds moved its normals by 5% each, and took
            // four sweeps a round). The last round the cap allows sweeps until they settle,
            // at most `sweeps` sweeps: the tangents that end the solve are the best for its
            // normals. A round settles when its first sweep changed nothing.
            let last = taken >= rounds.max(1);
            let mut v = sliding + self.normal.response(&p.normal);
            for sweep in 0..if last { sweeps.max(1) } else { 1 } {
                let (mut change, mut allowed) = (T::zero(), tolerance);
                for &i in with_tangent.iter().take(count) {
                    // Clamped (a no-op): the optimiser does not follow a row number
                    // through an array, and a bounds check is a panic path.
                    let i = within::<C>(i);
                    let Some(t) = &self.tangent[i] else { continue };
                    // In partial sums: the next tangent's speed waits on this one.
                    let u = split_dot(t.j.as_slice(), v.as_slice());
                    let bound = self.friction * p.normal[i];
                    let tangent = &mut p.tangent[i];
                    let next = (*tangent - u * t.inverse).max(-bound).min(bound);
                    let dp = next - *tangent;
                    v += t.b * dp;
                    *tangent = next;
                    change = change.max((dp / t.inverse).abs());
                    allowed = allowed.max(tolerance + rounding * u.abs());
                }
                let quiet = change <= allowed;
                if sweep == 0 {
                    settled = quiet;
                }
                if quiet {
                    break;
                }
            }
        }
        if !frictional {
            p.tangent = [T::zero(); C];
        }
        let velocity = self.tangent_response(v0, &p.tangent, &with_tangent[..count.min(C)])
            + self.normal.response(&p.normal);
        Ok(Solved {
            impulses: p,
            velocity,
            rounds: taken,
            settled: settled && exact,
            active: guess,
        })
    }

    /// `v` plus the velocity change of the tangents' impulses, over the rows `listed` (those
    /// with a tangent: the rest are none of the set's kilobytes of directions).
    fn tangent_response(
        &self,
        v: &SVector<T, N>,
        tangent: &[T; C],
        listed: &[usize],
    ) -> SVector<T, N> {
        let mut out = *v;
        for &i in listed {
            let i = within::<C>(i);
            if let Some(t) = &self.tangent[i] {
                out += t.b * tangent[i];
            }
        }
        out
    }
}
