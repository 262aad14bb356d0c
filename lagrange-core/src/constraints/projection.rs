//! [`Projection`]: a state moved back onto `phi = 0` and `J q' = 0`, mass-weighted.

use super::contact::{each_column, Delassus, Row};
use super::{max_abs, Constraints, Schur};
use crate::{validate, Error, Mechanism, Real, State};
use nalgebra::SVector;

/// Most Newton iterations a projection may be allowed.
const MAX_ITERATIONS_CAP: u32 = 1000;

/// Projection of a state onto its constraints after a step: positions by bounded Newton
/// iterations, then velocities exactly, both in the metric of the mass matrix:
///
/// ```text
/// repeat while max |phi_i(q)| > tolerance (at most max_iterations times):
///     q  <- q  - M^-1 J^T (J M^-1 J^T)^-1 phi(q)        J, M at the current q
/// then
///     q' <- q' - M^-1 J^T (J M^-1 J^T)^-1 J q'          J, M at the final q
/// ```
///
/// Each correction is the smallest in kinetic-energy norm that removes the residual to first
/// order, so projection changes the motion as little as possible; the velocity step is an
/// `M`-orthogonal projection, so it never adds kinetic energy. Newton converges
/// quadratically: after one integrator step the residual is the step's truncation error and
/// one iteration (often none) brings it below the tolerance. Pfaffian rows (zero `phi`) take
/// part in the velocity step and keep their linearised `A dq = 0` in the position step.
///
/// `tolerance` is in the units of `phi`; choose it above the rounding level of `phi` (about
/// `EPSILON` times its largest term), or Newton cannot reach it.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Projection<T> {
    tolerance: T,
    max_iterations: u32,
}

impl<T: Real> Projection<T> {
    /// Newton on positions until `max_i |phi_i| <= tolerance` (> 0), in at most
    /// `max_iterations` (1 to 1000) iterations: Newton converges quadratically, so a
    /// projection that has not converged in a thousand never will (its tolerance is below the
    /// rounding of `phi`), and the limit bounds the cost of a projection whatever is asked.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `tolerance` when not positive and finite,
    /// `max_iterations` when zero or above 1000.
    pub fn new(tolerance: T, max_iterations: u32) -> Result<Self, Error> {
        if !(1..=MAX_ITERATIONS_CAP).contains(&max_iterations) {
            return Err(Error::InvalidParameter {
                name: "max_iterations",
                reason: "must be from 1 to 1000",
            });
        }
        Ok(Self {
            tolerance: validate::positive("tolerance", tolerance)?,
            max_iterations,
        })
    }

    /// The position tolerance.
    #[must_use]
    pub fn tolerance(&self) -> T {
        self.tolerance
    }

    /// The most Newton iterations per projection.
    #[must_use]
    pub fn max_iterations(&self) -> u32 {
        self.max_iterations
    }

    /// `state` projected onto every row of `constraints`, mass-weighted by `mechanism`.
    ///
    /// # Errors
    /// As [`Projection::project_rows`].
    pub fn project<M, K, const N: usize, const C: usize>(
        &self,
        mechanism: &M,
        constraints: &K,
        state: &State<T, N>,
    ) -> Result<State<T, N>, Error>
    where
        M: Mechanism<T, N>,
        K: Constraints<T, N, C>,
    {
        self.project_rows(mechanism, constraints, state, &[true; C])
    }

    /// `state` projected onto the rows of `constraints` marked `active` (the others are left
    /// free), mass-weighted by `mechanism`.
    ///
    /// # Errors
    /// [`Error::NoConvergence`] when the position residual is still above the tolerance after
    /// `max_iterations`; [`Error::RedundantConstraints`] at dependent or singular rows;
    /// [`Error::NonFiniteState`]; whatever [`Mechanism::solve_mass`] returns.
    pub fn project_rows<M, K, const N: usize, const C: usize>(
        &self,
        mechanism: &M,
        constraints: &K,
        state: &State<T, N>,
        active: &[bool; C],
    ) -> Result<State<T, N>, Error>
    where
        M: Mechanism<T, N>,
        K: Constraints<T, N, C>,
    {
        let mut s = *state;
        let mut iterations = 0;
        loop {
            let phi = masked(constraints.position_residual(&s.q), active);
            let worst = max_abs(&phi);
            if !worst.is_finite() {
                return Err(Error::NonFiniteState);
            }
            let schur = Schur::new(mechanism, constraints, &s, active)?;
            if worst <= self.tolerance {
                let w = schur.jacobian() * s.qd;
                s.qd -= schur.correction(&w);
                return s.check_finite().map(|()| s);
            }
            if iterations == self.max_iterations {
                return Err(Error::NoConvergence { iterations });
            }
            s.q -= schur.correction(&phi);
            iterations += 1;
        }
    }
}

impl<T: Real> Projection<T> {
    /// `state` projected onto a contact set's feasible positions, mass-weighted: the `held`
    /// rows (bilateral rows and resting contacts) onto `phi = 0`, every other contact onto
    /// `g >= 0`, each Newton iteration a complementarity problem (a free contact that is
    /// open stays free unless the correction would close it; one that is closed or pushed
    /// shut is held at zero), until the held rows are within the tolerance of zero and no
    /// contact is below `-tolerance`; then the velocities onto `J q' = 0` over the held rows.
    /// Resting contacts that depend on the others (more of them than degrees of freedom) are
    /// left out of both solves: held with the others, they follow.
    ///
    /// Unlike [`Projection::project_rows`] over the rows held, this never moves a free
    /// contact below zero: the correction of the held rows is found with every contact's
    /// inequality in force.
    ///
    /// # Errors
    /// As [`Projection::project_rows`].
    pub fn project_contacts<M, K, const N: usize, const C: usize>(
        &self,
        mechanism: &M,
        contacts: &K,
        state: &State<T, N>,
        bilateral: &[bool; C],
        held: &[bool; C],
    ) -> Result<State<T, N>, Error>
    where
        M: Mechanism<T, N>,
        K: Constraints<T, N, C>,
    {
        let mut s = *state;
        let mut iterations = 0;
        // Resting contacts are pulled back to zero from above too, unless they conflict:
        // more of them than the motion has freedoms, one left out as dependent on the others
        // and below zero. From then on each contact is only kept above zero.
        let mut two_sided = true;
        let mut dependent = [false; C];
        loop {
            let g = contacts.position_residual(&s.q);
            two_sided &= !(0..C).any(|i| dependent[i] && g[i] < -self.tolerance);
            let mut worst = T::zero();
            for i in 0..C {
                let off = if bilateral[i] || (held[i] && two_sided && !dependent[i]) {
                    g[i].abs()
                } else {
                    -g[i]
                };
                if !off.is_finite() {
                    return Err(Error::NonFiniteState);
                }
                worst = worst.max(off);
            }
            if worst <= self.tolerance {
                break;
            }
            if iterations == self.max_iterations {
                return Err(Error::NoConvergence { iterations });
            }
            let mut rows = Delassus::new(
                &contacts.jacobian(&s.q),
                |jt| each_column(jt, |b| mechanism.solve_mass(&s, b)),
                &[true; C],
            )?;
            let kinds: [Row<T>; C] = core::array::from_fn(|i| match (bilateral[i], held[i]) {
                (true, _) => Row::Bilateral,
                (false, true) if two_sided => Row::Held,
                _ => Row::Unilateral,
            });
            let solved = rows.complementary(&g, &kinds)?;
            dependent = core::array::from_fn(|i| kinds[i] == Row::Held && !solved.active[i]);
            s.q += rows.response(&solved.lambda);
            iterations += 1;
        }
        if !held.iter().any(|&h| h) {
            return s.check_finite().map(|()| s);
        }
        let mut independent = *held;
        let unilateral: [bool; C] = core::array::from_fn(|i| !bilateral[i]);
        let schur = loop {
            match Schur::new(mechanism, contacts, &s, &independent) {
                Err(Error::RedundantConstraints { row })
                    if unilateral.get(row).copied().unwrap_or(false) && independent[row] =>
                {
                    independent[row] = false;
                }
                other => break other?,
            }
        };
        let w = schur.jacobian() * s.qd;
        s.qd -= schur.correction(&w);
        s.check_finite().map(|()| s)
    }
}

/// `v` with the entries of inactive rows set to zero.
fn masked<T: Real, const C: usize>(mut v: SVector<T, C>, active: &[bool; C]) -> SVector<T, C> {
    for (x, &on) in v.iter_mut().zip(active) {
        if !on {
            *x = T::zero();
        }
    }
    v
}
