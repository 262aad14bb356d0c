//! [`ActiveRows`]: a mechanism under the rows of a contact set that are in force (bilateral
//! rows and resting contacts), which is what a contact stepper's integrator steps between
//! events; and [`drop_dependent_contacts`], which keeps the rows in force independent.

use super::lcp::{each_column, Delassus, Row};
use super::{ContactModel, Contacts};
use crate::constraints::{ConstrainedAcceleration, Schur};
use crate::mechanism::{finite, finite_jacobian};
use crate::nalgebra::{SMatrix, SVector};
use crate::{
    Borrowed, Error, GeneralizedForce, Input, Jacobian, Lagrangian, Mechanism, Real, Scalar, State,
};

/// A mechanism held by the rows of its contact set that are in force (bilateral rows and
/// resting contacts): the law that a contact stepper's integrator steps between events.
///
/// Every solve is the contacts' complementarity problem, solved exactly: a resting contact
/// either pushes and holds, or lets go as soon as the motion lifts it (it would pull), and
/// one that let go is held again when it would close. With friction, a resting contact slides against a Coulomb force
/// `-mu lambda_n sat(u / slip_speed)` along its tangent (`u` the sliding speed): the normal
/// force from the frictionless solve, then one more solve with the friction forces applied
/// (exact when tangent and normal are decoupled in the mass metric, as for a point on flat
/// ground; one fixed-point pass otherwise).
#[derive(Debug, Clone, Copy)]
pub struct ActiveRows<'a, T, const C: usize, M, K> {
    mechanism: &'a M,
    contacts: &'a K,
    active: [bool; C],
    unilateral: [bool; C],
    friction: T,
    slip_speed: T,
}

impl<'a, T: Real, const C: usize, M, K> ActiveRows<'a, T, C, M, K> {
    /// `mechanism` held by the rows of `contacts` in force: the `bilateral` ones and the
    /// `resting` contacts, with `model`'s friction (a resting contact sliding faster than
    /// the model's rest speed feels the full Coulomb force).
    pub fn new(
        mechanism: &'a M,
        contacts: &'a K,
        model: &ContactModel<T>,
        bilateral: &[bool; C],
        resting: &[bool; C],
    ) -> Self {
        Self {
            mechanism,
            contacts,
            active: core::array::from_fn(|i| bilateral[i] || resting[i]),
            unilateral: core::array::from_fn(|i| !bilateral[i]),
            friction: model.friction(),
            slip_speed: model.rest_speed(),
        }
    }

    /// The rows still in force at `state`: those in force less the contacts that would pull.
    ///
    /// # Errors
    /// As [`Mechanism::acceleration`] of this law.
    pub fn still_in_force<const N: usize>(&self, state: &State<T, N>) -> Result<[bool; C], Error>
    where
        M: Mechanism<T, N>,
        K: Contacts<T, N, C>,
    {
        Ok(self.solve(state, &crate::NoForce)?.1)
    }

    /// Accelerations and multipliers at `state` with `extra` force, and the rows still in
    /// force: the contacts' complementarity problem solved exactly ([`Delassus::complementary`]:
    /// every resting contact either pushes and holds, or lets go and opens; none pulls and
    /// none is left to close), then, with friction, solved once more with the Coulomb forces
    /// of the first solution's normal forces applied.
    fn solve<F: GeneralizedForce<T, N>, const N: usize>(
        &self,
        state: &State<T, N>,
        extra: &F,
    ) -> Result<(ConstrainedAcceleration<T, N, C>, [bool; C]), Error>
    where
        M: Mechanism<T, N>,
        K: Contacts<T, N, C>,
    {
        let mut rows = Delassus::new(
            &self.contacts.jacobian(&state.q),
            |jt| each_column(jt, |b| self.mechanism.solve_mass(state, b)),
            &self.active,
        )?;
        let kinds: [Row<T>; C] = core::array::from_fn(|i| {
            if self.unilateral[i] {
                Row::Unilateral
            } else {
                Row::Bilateral
            }
        });
        let velocity_product = self.contacts.velocity_product(&state.q, &state.qd);
        let mut held = |free: SVector<T, N>| -> Result<_, Error> {
            let b = rows.jacobian() * free + velocity_product;
            let solved = rows.complementary(&b, &kinds)?;
            let acceleration = free + rows.response(&solved.lambda);
            Ok((
                ConstrainedAcceleration {
                    acceleration: finite(acceleration)?,
                    multipliers: solved.lambda,
                },
                solved.active,
            ))
        };
        let (solved, active) = held(self.mechanism.law(state, extra)?)?;
        if self.friction > T::zero() {
            if let Some(tangents) = self.contacts.tangent_jacobian(&state.q) {
                let friction = Input {
                    value: self.sliding_friction(state, &tangents, &solved.multipliers, &active),
                };
                return held(self.mechanism.law(state, &(Borrowed(extra), friction))?);
            }
        }
        Ok((solved, active))
    }

    /// The generalized Coulomb force of the active, pushing contacts.
    fn sliding_friction<const N: usize>(
        &self,
        state: &State<T, N>,
        tangents: &SMatrix<T, C, N>,
        normal: &SVector<T, C>,
        active: &[bool; C],
    ) -> SVector<T, N> {
        let u = tangents * state.qd;
        let mut force = SVector::<T, N>::zeros();
        for i in 0..C {
            if active[i] && self.unilateral[i] && normal[i] > T::zero() {
                let sat = (u[i] / self.slip_speed).max(-T::one()).min(T::one());
                force -= tangents.row(i).transpose() * (self.friction * normal[i] * sat);
            }
        }
        force
    }
}

/// True when `row` is an active unilateral row: a contact that depends on the other rows
/// carries no force of its own (they already hold the motion), so it can be left out, where
/// a dependent bilateral row is the user's error.
fn redundant_contact<const C: usize>(
    row: usize,
    active: &[bool; C],
    unilateral: &[bool; C],
) -> bool {
    active.get(row).copied().unwrap_or(false) && unilateral.get(row).copied().unwrap_or(false)
}

/// Leaves out of `active` every contact (row not in `bilateral`) that depends on the rows
/// before it: several contacts holding the same freedom, or more resting contacts than degrees
/// of freedom (the others already hold the motion, and how the force divides among them is
/// not determined).
///
/// # Errors
/// [`Error::RedundantConstraints`] when bilateral rows depend on each other;
/// [`Error::NonFiniteState`]; whatever [`Mechanism::solve_mass`] returns.
pub fn drop_dependent_contacts<T, M, K, const N: usize, const C: usize>(
    mechanism: &M,
    contacts: &K,
    state: &State<T, N>,
    active: &mut [bool; C],
    bilateral: &[bool; C],
) -> Result<(), Error>
where
    T: Real,
    M: Mechanism<T, N>,
    K: Contacts<T, N, C>,
{
    independent(mechanism, contacts, state, active, bilateral).map(drop)
}

/// The Schur complement of the `active` rows after [`drop_dependent_contacts`].
pub(crate) fn independent<T, M, K, const N: usize, const C: usize>(
    mechanism: &M,
    contacts: &K,
    state: &State<T, N>,
    active: &mut [bool; C],
    bilateral: &[bool; C],
) -> Result<Schur<T, N, C>, Error>
where
    T: Real,
    M: Mechanism<T, N>,
    K: Contacts<T, N, C>,
{
    let unilateral: [bool; C] = core::array::from_fn(|i| !bilateral[i]);
    // Each failed pass leaves out one more row, so at most C + 1 passes.
    loop {
        match Schur::new(mechanism, contacts, state, active) {
            Err(Error::RedundantConstraints { row })
                if redundant_contact(row, active, &unilateral) =>
            {
                active[row] = false;
            }
            other => return other,
        }
    }
}

impl<T, M, K, const N: usize, const C: usize> Lagrangian<T, N> for ActiveRows<'_, T, C, M, K>
where
    T: Real,
    M: Lagrangian<T, N>,
{
    const EXPLICIT_TIME: bool = M::EXPLICIT_TIME;
    const CONSTANT_MASS: bool = M::CONSTANT_MASS;
    const DRIVEN: bool = M::DRIVEN;
    const READS_TIME: bool = M::READS_TIME;
    fn kinetic<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>, qd: &SVector<S, N>) -> S {
        self.mechanism.kinetic(t, q, qd)
    }
    fn potential<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>) -> S {
        self.mechanism.potential(t, q)
    }
    fn non_conservative_force(&self, state: &State<T, N>) -> SVector<T, N> {
        self.mechanism.non_conservative_force(state)
    }
}

impl<T, M, K, const N: usize, const C: usize> Mechanism<T, N> for ActiveRows<'_, T, C, M, K>
where
    T: Real,
    M: Mechanism<T, N>,
    K: Contacts<T, N, C>,
{
    fn mass_matrix(&self, state: &State<T, N>) -> SMatrix<T, N, N> {
        self.mechanism.mass_matrix(state)
    }
    fn rhs(&self, state: &State<T, N>) -> SVector<T, N> {
        self.mechanism.rhs(state)
    }
    fn solve_mass(&self, state: &State<T, N>, b: &SVector<T, N>) -> Result<SVector<T, N>, Error> {
        finite(self.mechanism.solve_mass(state, b)?)
    }
    /// The rows in force as constraints; in free flight (no row in force) the mechanism's own,
    /// possibly closed-form, law.
    fn law<F: GeneralizedForce<T, N>>(
        &self,
        state: &State<T, N>,
        extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        if self.active.iter().any(|&on| on) {
            Ok(self.solve(state, extra)?.0.acceleration)
        } else {
            finite(self.mechanism.law(state, extra)?)
        }
    }
    /// In free flight the mechanism's own Jacobian (exact where it has one); with rows in
    /// force, central differences of the constrained law.
    fn law_jacobian<F: GeneralizedForce<T, N>>(
        &self,
        state: &State<T, N>,
        extra: &F,
    ) -> Result<(SVector<T, N>, Jacobian<T, N>), Error> {
        if self.active.iter().any(|&on| on) {
            crate::jacobian_by_differences(self, state, extra)
        } else {
            finite_jacobian(self.mechanism.law_jacobian(state, extra)?)
        }
    }
}
