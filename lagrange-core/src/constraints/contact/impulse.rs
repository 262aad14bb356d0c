//! Impacts: the jump of the generalized velocities by mass-weighted impulses, and the
//! [`Impact`] record an observer receives.

use super::lcp::{each_column, Delassus, Row};
use super::{ContactModel, Contacts};
use crate::constraints::Schur;
use crate::nalgebra::SVector;
use crate::{Error, Lagrangian, Mechanism, Real, State};

/// One impact: the state just before and just after the velocity jump.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Impact<T: Real, const N: usize, const C: usize> {
    /// Time of the impact, s.
    pub t: T,
    /// Coordinates at the impact (they do not jump).
    pub q: SVector<T, N>,
    /// Generalized velocities just before.
    pub before: SVector<T, N>,
    /// Generalized velocities just after.
    pub after: SVector<T, N>,
    /// The normal impulse of each row (zero for rows that took no part): the generalized
    /// impulse is `J^T impulses`.
    pub impulses: SVector<T, C>,
    /// The contacts that struck.
    pub struck: [bool; C],
    /// The resting contacts after the impact.
    pub resting: [bool; C],
}

impl<T: Real, const N: usize, const C: usize> Impact<T, N, C> {
    /// The state just before.
    #[must_use]
    pub fn state_before(&self) -> State<T, N> {
        State {
            t: self.t,
            q: self.q,
            qd: self.before,
        }
    }

    /// The state just after.
    #[must_use]
    pub fn state_after(&self) -> State<T, N> {
        State {
            t: self.t,
            q: self.q,
            qd: self.after,
        }
    }
}

/// The impact law of a contact set: what an impact acts on, the rows' roles and the model.
#[derive(Debug, Clone, Copy)]
pub struct Impacts<'a, T, const C: usize, K> {
    contacts: &'a K,
    model: &'a ContactModel<T>,
    /// Bilateral rows: their velocity residual stays zero through the impact.
    bilateral: [bool; C],
}

impl<'a, T: Real, const C: usize, K> Impacts<'a, T, C, K> {
    /// Impacts on `contacts` under `model`, the rows marked `bilateral` held throughout.
    pub fn new(contacts: &'a K, model: &'a ContactModel<T>, bilateral: [bool; C]) -> Self {
        Self {
            contacts,
            model,
            bilateral,
        }
    }

    /// The velocity jump at `state` where the contacts `struck` hit, with the contacts in
    /// `resting` (updated: contacts that come to rest join, contacts the impact lifts leave).
    ///
    /// ```text
    /// w = J q'-, W = J M^-1 J^T over the rows A0 = bilateral + resting + approaching struck
    /// compression: the plastic impulses p_c >= 0 with w_c = w + W p_c >= 0, p_c w_c = 0
    ///              (zero on the bilateral rows: exact complementarity, Delassus::complementary)
    /// e_event = e when some approaching struck row would rebound at e |w_i| >= rest_speed,
    ///           else 0 (a plastic impact: those contacts come to rest)
    /// expansion:   p = (1 + e_event) p_c    (Poisson's law)
    /// q'+ = q'- + M^-1 J^T p                one contact: q'- - (1 + e) M^-1 J^T S^-1 J q'-
    /// ```
    ///
    /// The compression is the impulse of a perfectly plastic impact: every row of `A0` ends
    /// pushing and held (`w_c = 0`) or free and opening, none pulling. Restitution scales it,
    /// so a row held at the end of the compression rebounds at `-e_event w`: Newton's law for
    /// a single contact, and for a row struck beside resting ones. Poisson's law never adds
    /// energy, whatever the rows and their coupling in the mass metric: the jump takes
    /// `(1 - e_event^2)/2 |M^-1 J^T p_c|_M^2` from the kinetic energy. (Newton's law row by row
    /// can add energy when several rows act at once, as they do when events pile up at one
    /// instant: a ragdoll struck at extreme joint speeds gained four times its kinetic energy
    /// that way.) A struck row that is not approaching (it crossed within the time tolerance
    /// by acceleration alone, so `w` is at most `|g''| time_tolerance`; or it creeps in at
    /// below `rest_speed / 1000`) comes to rest without an impulse, and an event of such rows
    /// alone changes no velocity and releases no resting contact (many contacts at rest, a
    /// ragdoll's, otherwise evict each other on the sign of rounding noise).
    ///
    /// A slow contact struck together with a fast one rebounds at most at `e rest_speed` and
    /// rests at its next, plastic, event. With friction, each struck contact then gets a
    /// Coulomb tangential impulse (at most `mu` times its normal impulse, never reversing the
    /// sliding) and the velocities are projected once more onto the bilateral and resting
    /// rows; both only remove energy. Last, the kinetic energy `q'^T M q' / 2` after is
    /// compared with the energy before in floating point, and where rounding (or rows so
    /// ill-conditioned at extreme speeds that the solve is inexact) leaves it larger, the
    /// velocities are scaled down to it: the jump never adds energy, not even a rounding.
    ///
    /// # Errors
    /// [`Error::RedundantConstraints`] for dependent bilateral rows; [`Error::NonFiniteState`];
    /// [`Error::NoConvergence`] where the complementarity problem cycles; whatever
    /// [`Mechanism::solve_mass`] returns.
    pub fn impact<M, const N: usize>(
        &self,
        mechanism: &M,
        state: &State<T, N>,
        struck: [bool; C],
        resting: &mut [bool; C],
    ) -> Result<(State<T, N>, Impact<T, N, C>), Error>
    where
        M: Mechanism<T, N>,
        K: Contacts<T, N, C>,
    {
        let e = self.model.restitution();
        let jacobian = self.contacts.jacobian(&state.q);
        let w = jacobian * state.qd;
        // Approach speeds a thousand times below the resting threshold (a contact reached by
        // acceleration alone, or by the creep of a body settling on many contacts) are no
        // approach: the contact comes to rest, and the projection at the end of the step
        // takes the creep out. Solving impulses for them only divides noise, whose sign would
        // evict resting contacts at random, event after event.
        let noise = self.model.rest_speed() * T::from_f64(1e-3);
        let approaching: [bool; C] = core::array::from_fn(|i| struck[i] && w[i] < -noise);
        let elastic = (0..C).any(|i| approaching[i] && -e * w[i] >= self.model.rest_speed());
        let e_event = if elastic { e } else { T::zero() };
        let candidate: [bool; C] =
            core::array::from_fn(|i| self.bilateral[i] || resting[i] || approaching[i]);
        let (mut after, impulses, kept) = if approaching.iter().any(|&a| a) {
            let mut rows = Delassus::new(
                &jacobian,
                |jt| each_column(jt, |b| mechanism.solve_mass(state, b)),
                &candidate,
            )?;
            let compression = rows.complementary(&w, &Row::kinds(&self.bilateral))?;
            let impulses = compression.lambda * (T::one() + e_event);
            (
                state.qd + rows.response(&impulses),
                impulses,
                compression.active,
            )
        } else {
            // Only contacts that settle: no impulse, nothing released.
            (state.qd, SVector::zeros(), candidate)
        };
        for i in 0..C {
            let settles = struck[i] && !approaching[i];
            let plastic = !elastic && approaching[i];
            resting[i] = (resting[i] && kept[i]) || settles || (plastic && kept[i]);
        }
        if self.model.friction() > T::zero() {
            after = self.friction(mechanism, state, after, &impulses, &approaching, resting)?;
        }
        let after = no_energy_gain(mechanism, state, after)?;
        let next = State {
            t: state.t,
            q: state.q,
            qd: after,
        };
        next.check_finite()?;
        let record = Impact {
            t: state.t,
            q: state.q,
            before: state.qd,
            after,
            impulses,
            struck,
            resting: *resting,
        };
        Ok((next, record))
    }

    /// Coulomb tangential impulses at the struck contacts, then a projection back onto the
    /// bilateral and resting rows.
    fn friction<M, const N: usize>(
        &self,
        mechanism: &M,
        state: &State<T, N>,
        velocity: SVector<T, N>,
        normal: &SVector<T, C>,
        struck: &[bool; C],
        resting: &[bool; C],
    ) -> Result<SVector<T, N>, Error>
    where
        M: Mechanism<T, N>,
        K: Contacts<T, N, C>,
    {
        let Some(tangents) = self.contacts.tangent_jacobian(&state.q) else {
            return Ok(velocity);
        };
        let mut v = velocity;
        for i in 0..C {
            if !struck[i] {
                continue;
            }
            let t = tangents.row(i).transpose();
            let mobility = mechanism.solve_mass(state, &t)?;
            let inverse_mass = t.dot(&mobility);
            if inverse_mass <= T::zero() {
                continue;
            }
            let cap = self.model.friction() * normal[i];
            let stop = -t.dot(&v) / inverse_mass;
            v += mobility * stop.max(-cap).min(cap);
        }
        let held: [bool; C] = core::array::from_fn(|i| self.bilateral[i] || resting[i]);
        if held.iter().any(|&h| h) {
            let schur = Schur::new(mechanism, self.contacts, state, &held)?;
            v -= schur.correction(&(schur.jacobian() * v));
        }
        Ok(v)
    }
}

/// `after` at `state` (which holds the velocities before), scaled down where its kinetic
/// energy is above the energy before in floating point, so that it is not: the last guard of
/// every velocity jump (a jump that cannot add energy in real arithmetic can still gain a
/// rounding).
fn no_energy_gain<T, M, const N: usize>(
    mechanism: &M,
    state: &State<T, N>,
    after: SVector<T, N>,
) -> Result<SVector<T, N>, Error>
where
    T: Real,
    M: Lagrangian<T, N>,
{
    let limit = mechanism.kinetic_energy(state);
    within_kinetic_energy(
        mechanism,
        &State {
            qd: after,
            ..*state
        },
        limit,
    )
}

/// The velocities of `state`, scaled down where their kinetic energy (the mechanism's own
/// [`Lagrangian::kinetic_energy`], what an observer compares) is above `limit` in floating
/// point, so that it is not; all zero for a limit that is not positive. Scaling keeps the
/// direction of the motion and every row held at zero velocity. The square root of the
/// ratio, then a few ulps more each time: it settles in one or two.
///
/// # Errors
/// [`Error::NoConvergence`] where scaling cannot bring the energy down in eight tries (a
/// kinetic energy that is not a quadratic form of the velocities, or not finite).
pub fn within_kinetic_energy<T, M, const N: usize>(
    mechanism: &M,
    state: &State<T, N>,
    limit: T,
) -> Result<SVector<T, N>, Error>
where
    T: Real,
    M: Lagrangian<T, N>,
{
    let energy = |qd: SVector<T, N>| mechanism.kinetic_energy(&State { qd, ..*state });
    let mut v = state.qd;
    for _ in 0..8 {
        let e = energy(v);
        if e <= limit {
            return Ok(v);
        }
        let scale = if limit > T::zero() && e.is_finite() {
            (limit / e).sqrt() * (T::one() - T::from_f64(4.0) * T::EPSILON)
        } else {
            T::zero()
        };
        v *= scale;
    }
    Err(Error::NoConvergence { iterations: 8 })
}

#[cfg(feature = "defmt")]
impl<T: Real, const N: usize, const C: usize> defmt::Format for Impact<T, N, C> {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(
            f,
            "Impact {{ t: {}, struck: {}, resting: {} }}",
            self.t.to_f64(),
            self.struck,
            self.resting
        );
    }
}
