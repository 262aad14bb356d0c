//! Impacts: the jump of the generalized velocities by mass-weighted impulses, and the
//! [`Impact`] record an observer receives.

use super::active_rows::independent;
use super::{ContactModel, Contacts};
use crate::constraints::Schur;
use crate::nalgebra::SVector;
use crate::{Error, Mechanism, Real, State};

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

/// The outcome of one impulse: new velocities, the impulses, the rows that took part.
struct Jump<T: Real, const N: usize, const C: usize> {
    velocity: SVector<T, N>,
    impulses: SVector<T, C>,
    kept: [bool; C],
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
    /// w = J q'-, S_A = J M^-1 J^T over the rows A = bilateral + resting + approaching struck
    /// e_event = e when some approaching struck row would rebound at e |w_i| >= rest_speed,
    ///           else 0 (a plastic impact: those contacts come to rest)
    /// w+ = -e_event w on the struck rows, 0 on the held ones;  p = S_A^-1 (w+ - w)
    /// q'+ = q'- + M^-1 J^T p              one contact: q'- - (1 + e) M^-1 J^T S^-1 J q'-
    /// ```
    ///
    /// A unilateral row whose impulse comes out negative (it would pull) leaves `A` (and the
    /// resting set) and the rest is solved again. A struck row that is not approaching (it
    /// crossed within the time tolerance by acceleration alone, so `w` is at most
    /// `|g''| time_tolerance`; or it creeps in at below `rest_speed / 1000`) comes to rest
    /// without an impulse, and an event of such
    /// rows alone changes no velocity and releases no resting contact (many contacts at
    /// rest, a ragdoll's, otherwise evict each other on the sign of rounding noise).
    ///
    /// One coefficient for every row of an event keeps the energy law exact: the held rows have
    /// `w = 0`, so the jump takes from the kinetic energy exactly `(1 - e_event^2)` times the
    /// energy `w^T S_A^-1 w / 2` of the removed part and never adds any (a per-row choice of
    /// plastic or elastic could, through rows coupled in the mass metric). A slow contact struck
    /// together with a fast one rebounds at most at `e rest_speed` and rests at its next,
    /// plastic, event. With friction, each struck contact then gets a Coulomb tangential
    /// impulse (at most `mu` times its normal impulse, never reversing the sliding) and the
    /// velocities are projected once more onto the bilateral and resting rows; both only
    /// remove energy.
    ///
    /// # Errors
    /// [`Error::RedundantConstraints`] for dependent bilateral rows; [`Error::NonFiniteState`];
    /// whatever [`Mechanism::solve_mass`] returns.
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
        let w = self.contacts.jacobian(&state.q) * state.qd;
        // Approach speeds a thousand times below the resting threshold (a contact reached by
        // acceleration alone, or by the creep of a body settling on many contacts) are no
        // approach: the contact comes to rest, and the projection at the end of the step
        // takes the creep out. Solving impulses for them only divides noise, whose sign would
        // evict resting contacts at random, event after event.
        let noise = self.model.rest_speed() * T::from_f64(1e-3);
        let approaching: [bool; C] = core::array::from_fn(|i| struck[i] && w[i] < -noise);
        let elastic = (0..C).any(|i| approaching[i] && -e * w[i] >= self.model.rest_speed());
        let e_event = if elastic { e } else { T::zero() };
        let active: [bool; C] =
            core::array::from_fn(|i| self.bilateral[i] || resting[i] || approaching[i]);
        let Jump {
            velocity: mut after,
            impulses,
            kept,
        } = if approaching.iter().any(|&a| a) {
            self.jump(mechanism, state, active, &approaching, e_event)?
        } else {
            // Only contacts that settle: no impulse, nothing released.
            Jump {
                velocity: state.qd,
                impulses: SVector::zeros(),
                kept: active,
            }
        };
        for i in 0..C {
            let settles = struck[i] && !approaching[i];
            let plastic = !elastic && approaching[i];
            resting[i] = (resting[i] && kept[i]) || settles || (plastic && kept[i]);
        }
        if self.model.friction() > T::zero() {
            after = self.friction(mechanism, state, after, &impulses, &approaching, resting)?;
        }
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

    /// The impulse over the rows `active` that sends `w = J q'` to `-e w` on the rows `bounce`
    /// and to zero on the others, dropping unilateral rows that would pull: the new
    /// velocities, the impulses and the rows that stayed.
    fn jump<M, const N: usize>(
        &self,
        mechanism: &M,
        state: &State<T, N>,
        mut active: [bool; C],
        bounce: &[bool; C],
        e: T,
    ) -> Result<Jump<T, N, C>, Error>
    where
        M: Mechanism<T, N>,
        K: Contacts<T, N, C>,
    {
        // Each pass either finishes or removes at least one row, so at most C + 1 passes.
        loop {
            let schur = independent(
                mechanism,
                self.contacts,
                state,
                &mut active,
                &self.bilateral,
            )?;
            let w = schur.jacobian() * state.qd;
            let change = SVector::<T, C>::from_fn(|i, _| {
                if bounce[i] {
                    -(T::one() + e) * w[i]
                } else {
                    -w[i]
                }
            });
            let impulses = schur.multipliers(&change);
            // The row that pulls hardest leaves, alone: dropping every pulling row at once
            // also drops rows that only pulled because of it (with many contacts, a
            // ragdoll's, that evicts most of the resting set at every event).
            let mut pulled: Option<(usize, T)> = None;
            for i in 0..C {
                let pulls = active[i] && !self.bilateral[i] && impulses[i] < T::zero();
                if pulls && pulled.is_none_or(|(_, p)| impulses[i] < p) {
                    pulled = Some((i, impulses[i]));
                }
            }
            if let Some((i, _)) = pulled {
                active[i] = false;
            } else {
                return Ok(Jump {
                    velocity: state.qd + schur.response(&impulses),
                    impulses,
                    kept: active,
                });
            }
        }
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
