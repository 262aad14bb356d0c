//! [`ContactStepper`]: any integrator stepping through contacts: found inside the step, impacts
//! at the contact time, resting contacts held as constraints (the laws of
//! [`lagrange_core::constraints::contact`]).

use lagrange_core::constraints::contact::{ActiveRows, ContactModel, Contacts, Impact, Impacts};

use crate::integrator::{check_run_step, check_step, continues, finish, step_loop};
use crate::{Cost, Failure, Integrator, Method, Work};
use lagrange_core::constraints::Projection;
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, Mechanism, Real, State};

/// Any integrator, stepping a mechanism with unilateral contacts `g(q) >= 0` (and optional
/// bilateral rows) at a fixed step:
///
/// ```text
/// 1. trial step over what is left of dt, with the bilateral rows and the resting contacts
///    held as constraints (multipliers; a resting contact that would pull lets go)
/// 2. no free contact crossed (g_i < 0 and deeper than at the start)?  accept, go to 5
/// 3. locate the crossing: bisection on the step length, re-stepping from the start of the
///    stretch, until the bracket is shorter than time_tolerance; advance to its early end
///    (the contact is then open by at most |w| time_tolerance: no penetration)
/// 4. impact there (velocity jump, see ContactModel and Impact), back to 1
/// 5. project onto the contacts' feasible positions (Projection::project_contacts: the
///    bilateral and resting rows onto zero, every other contact kept at or above zero) and
///    the velocities onto the rows held; release the resting contacts that would pull
/// ```
///
/// Between events the inner integrator's order holds; each event costs about
/// `log2(dt / time_tolerance)` re-steps. A contact that opens and closes again within one step
/// without being open at its end is not seen (choose `dt` so that a bounce lasts several
/// steps). Depth: no contact ends a step deeper than it started it and below the projection's
/// tolerance (`g >= min(g_start, -tolerance)` for every contact, every step); a resting one
/// ends within the tolerance of zero. At most `4 C + 8` events per step: beyond that the step
/// fails with [`Error::NoConvergence`] rather than loop, which with resting contacts (no Zeno)
/// does not happen in `f64`; in `f32` a ragdoll's many resting contacts can reach it as it
/// lands (single precision cannot tell their rounding from motion): use `f64` here, or the
/// time-stepping stepper.
///
/// The resting contacts' forces are their complementarity problem solved exactly: each
/// pushes and holds, or lets go as the motion lifts it and is held again if it would close.
/// Contacts that depend on the others in force (several rows for one contact, more resting
/// contacts than degrees of freedom) are left out of a solve while those hold the motion (the
/// force distribution among them is not determined), and rejoin when one lets go. Dependent
/// bilateral rows are an error ([`Error::RedundantConstraints`]). Impacts never add kinetic
/// energy (Poisson's law; see [`Impacts::impact`]).
///
/// A start state must satisfy the bilateral rows to within the projection's tolerance and
/// have every gap above `-tolerance`; the first step from any state other than this stepper's
/// last output checks it (and forgets the resting set).
///
/// ```
/// use lagrange_core::{nalgebra::SVector, Holonomic, HolonomicConstraints, Projection, Scalar, State};
/// use lagrange_integrators::{ContactModel, ContactStepper, Integrator, Rk4};
/// use lagrange_systems::FallingParticle;
///
/// /// The ground at y = 0.
/// struct Ground;
/// impl HolonomicConstraints<f64, 1, 1> for Ground {
///     fn phi<S: Scalar<Real = f64> + 'static>(&self, q: &SVector<S, 1>) -> SVector<S, 1> {
///         *q
///     }
/// }
///
/// let ball = FallingParticle::new(1.0, 9.81)?;
/// let model = ContactModel::new(0.5, 0.05, 1e-10)?;
/// let mut stepper = ContactStepper::new(Rk4, Holonomic::new(Ground), model, Projection::new(1e-12, 4)?);
/// let end = stepper.integrate(&ball, &State::at_rest([1.0]), 1e-3, 3000)?;
/// assert!(stepper.resting()[0] && end.q[0].abs() < 1e-12);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactStepper<T: Real, const N: usize, const C: usize, I, K> {
    integrator: I,
    contacts: K,
    model: ContactModel<T>,
    projection: Projection<T>,
    bilateral: [bool; C],
    resting: [bool; C],
    impacts: u64,
    last: Option<State<T, N>>,
}

impl<T: Real, const N: usize, const C: usize, I, K> ContactStepper<T, N, C, I, K> {
    /// `integrator` stepping with the unilateral `contacts` under `model`, with `projection`
    /// for the rows held as constraints.
    pub fn new(
        integrator: I,
        contacts: K,
        model: ContactModel<T>,
        projection: Projection<T>,
    ) -> Self {
        Self {
            integrator,
            contacts,
            model,
            projection,
            bilateral: [false; C],
            resting: [false; C],
            impacts: 0,
            last: None,
        }
    }

    /// The same stepper with the rows marked `true` in `rows` bilateral (`phi_i = 0` always,
    /// e.g. a pendulum's rod) instead of unilateral.
    #[must_use]
    pub fn with_bilateral(self, rows: [bool; C]) -> Self {
        Self {
            bilateral: rows,
            last: None,
            ..self
        }
    }

    /// The contacts resting now (held as constraints).
    #[must_use]
    pub fn resting(&self) -> &[bool; C] {
        &self.resting
    }

    /// Impacts so far.
    #[must_use]
    pub fn impacts(&self) -> u64 {
        self.impacts
    }

    /// The contact model.
    #[must_use]
    pub fn model(&self) -> &ContactModel<T> {
        &self.model
    }

    /// The contact set.
    #[must_use]
    pub fn contacts(&self) -> &K {
        &self.contacts
    }

    /// The rows held as constraints now: bilateral rows and resting contacts.
    fn held(&self) -> [bool; C] {
        held(&self.bilateral, &self.resting)
    }
}

/// Bilateral rows and resting contacts.
fn held<const C: usize>(bilateral: &[bool; C], resting: &[bool; C]) -> [bool; C] {
    core::array::from_fn(|i| bilateral[i] || resting[i])
}

/// The law the inner integrator steps between events: `mechanism` held by the bilateral and
/// resting rows of `contacts`, with `model`'s friction.
fn active<'a, M, K, T: Real, const C: usize>(
    mechanism: &'a M,
    contacts: &'a K,
    model: &ContactModel<T>,
    bilateral: &[bool; C],
    resting: &[bool; C],
) -> ActiveRows<'a, T, C, M, K> {
    ActiveRows::new(mechanism, contacts, model, bilateral, resting)
}

impl<T, I, K, const N: usize, const C: usize> ContactStepper<T, N, C, I, K>
where
    T: Real,
    K: Contacts<T, N, C>,
{
    /// As [`Integrator::step`], calling `observe` with every impact inside the step.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `dt` unless positive and finite; [`Error::NonFiniteState`];
    /// [`Error::ConstraintViolated`] for a start state that violates a bilateral row or
    /// penetrates a contact beyond the projection's tolerance; [`Error::NoConvergence`] after
    /// `4 C + 8` events in one step; the inner integrator's and the projection's errors. A
    /// step that fails leaves the stepper as it found it (resting set, impact count, the
    /// state it continues from); `observe` has seen the impacts before the failure.
    pub fn step_observed<M, F>(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        dt: T,
        observe: F,
    ) -> Result<State<T, N>, Error>
    where
        M: Mechanism<T, N>,
        I: for<'a> Integrator<T, N, ActiveRows<'a, T, C, M, K>>,
        F: FnMut(&Impact<T, N, C>),
    {
        self.transaction(|c| c.step_events(mechanism, state, dt, observe, false))
    }

    /// `f`, and the stepper as it was (resting set, impact count, the state it continues
    /// from) when `f` fails.
    fn transaction<V, E>(&mut self, f: impl FnOnce(&mut Self) -> Result<V, E>) -> Result<V, E> {
        let saved = (self.resting, self.impacts, self.last);
        let result = f(self);
        if result.is_err() {
            (self.resting, self.impacts, self.last) = saved;
        }
        result
    }

    /// The step of [`ContactStepper::step_observed`], or of a run (`run`: a `dt` below the
    /// resolution of the time is taken). The inner integrator's steps are steps of a run
    /// either way: what is left of `dt` after an impact and the bisection's trial lengths may
    /// be far below the resolution of the time.
    fn step_events<M, F>(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        dt: T,
        mut observe: F,
        run: bool,
    ) -> Result<State<T, N>, Error>
    where
        M: Mechanism<T, N>,
        I: for<'a> Integrator<T, N, ActiveRows<'a, T, C, M, K>>,
        F: FnMut(&Impact<T, N, C>),
    {
        let dt = if run {
            check_run_step(state, dt)?
        } else {
            check_step(state, dt)?
        };
        if !self.last.is_some_and(|last| continues(&last, state)) {
            self.start(state)?;
        }
        let max_events = 4 * C + 8;
        let mut s = *state;
        let mut remaining = dt;
        let mut events = 0;
        loop {
            let trial = self.integrator.run_step(
                &active(
                    mechanism,
                    &self.contacts,
                    &self.model,
                    &self.bilateral,
                    &self.resting,
                ),
                &s,
                remaining,
            )?;
            let start_gaps = self.contacts.position_residual(&s.q);
            let crossed = self.crossed(&start_gaps, &trial);
            if !crossed.iter().any(|&c| c) {
                s = trial;
                break;
            }
            let (lo, at, struck) = self.locate(mechanism, &s, &start_gaps, remaining, crossed)?;
            let impacts = Impacts::new(&self.contacts, &self.model, self.bilateral);
            let (after, impact) = impacts.impact(mechanism, &at, struck, &mut self.resting)?;
            observe(&impact);
            self.impacts += 1;
            events += 1;
            if events > max_events {
                return Err(Error::NoConvergence {
                    iterations: u32::try_from(events).unwrap_or(u32::MAX),
                });
            }
            s = after;
            remaining -= lo;
        }
        // Every step ends on the contacts' feasible positions: the held rows drift with the
        // integrator's error, and a contact the last event released may have drifted below
        // zero while it was held.
        let held = self.held();
        s = self.projection.project_contacts(
            mechanism,
            &self.contacts,
            &s,
            &self.bilateral,
            &held,
        )?;
        if held.iter().any(|&h| h) {
            let rows = active(
                mechanism,
                &self.contacts,
                &self.model,
                &self.bilateral,
                &self.resting,
            );
            let still = rows.still_in_force(&s)?;
            for (r, kept) in self.resting.iter_mut().zip(still) {
                *r = *r && kept;
            }
        }
        let s = finish(s)?;
        self.last = Some(s);
        Ok(s)
    }

    /// Checks a new start state and forgets the resting set.
    fn start(&mut self, s: &State<T, N>) -> Result<(), Error> {
        let tol = self.projection.tolerance();
        let phi = self.contacts.position_residual(&s.q);
        let w = self.contacts.jacobian(&s.q) * s.qd;
        for i in 0..C {
            let ok = if self.bilateral[i] {
                phi[i].abs() <= tol && w[i].abs() <= tol
            } else {
                phi[i] >= -tol
            };
            if !ok {
                return Err(Error::ConstraintViolated { row: i });
            }
        }
        self.resting = [false; C];
        Ok(())
    }

    /// The free contacts that are below zero at `end` and deeper than at the start.
    fn crossed(&self, start_gaps: &SVector<T, C>, end: &State<T, N>) -> [bool; C] {
        let gaps = self.contacts.position_residual(&end.q);
        let held = self.held();
        core::array::from_fn(|i| !held[i] && gaps[i] < T::zero() && gaps[i] < start_gaps[i])
    }

    /// Bisection on the step length from `s` for the first crossing: the length `lo` at the
    /// early end of the final bracket, the state there, and the contacts crossed at its late
    /// end.
    fn locate<M>(
        &mut self,
        mechanism: &M,
        s: &State<T, N>,
        start_gaps: &SVector<T, C>,
        remaining: T,
        crossed: [bool; C],
    ) -> Result<(T, State<T, N>, [bool; C]), Error>
    where
        M: Mechanism<T, N>,
        I: for<'a> Integrator<T, N, ActiveRows<'a, T, C, M, K>>,
    {
        let (mut lo, mut hi, mut at, mut struck) = (T::zero(), remaining, *s, crossed);
        while hi - lo > self.model.time_tolerance() {
            let mid = lo + (hi - lo) * T::HALF;
            if mid <= lo || mid >= hi {
                break; // the bracket is at the resolution of T
            }
            let trial = self.integrator.run_step(
                &active(
                    mechanism,
                    &self.contacts,
                    &self.model,
                    &self.bilateral,
                    &self.resting,
                ),
                s,
                mid,
            )?;
            let c = self.crossed(start_gaps, &trial);
            if c.iter().any(|&x| x) {
                hi = mid;
                struck = c;
            } else {
                lo = mid;
                at = trial;
            }
        }
        Ok((lo, at, struck))
    }
}

impl<T: Real, I: Method, K, const N: usize, const C: usize> Method
    for ContactStepper<T, N, C, I, K>
{
    const NAME: &'static str = I::NAME;
    const ORDER: u32 = I::ORDER;
    const POSITION_SHARE: f64 = I::POSITION_SHARE;
    /// The inner integrator's per step between events; each event adds about
    /// `log2(dt / time_tolerance)` steps of it.
    const COST: Cost = I::COST;

    fn last_step(&self) -> Work {
        self.integrator.last_step()
    }
}

impl<T, M, I, K, const N: usize, const C: usize> Integrator<T, N, M>
    for ContactStepper<T, N, C, I, K>
where
    T: Real,
    M: Mechanism<T, N>,
    I: for<'a> Integrator<T, N, ActiveRows<'a, T, C, M, K>>,
    K: Contacts<T, N, C>,
{
    /// One step with contacts; see [`ContactStepper::step_observed`].
    ///
    /// # Errors
    /// As [`ContactStepper::step_observed`].
    fn step(&mut self, mechanism: &M, state: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        self.step_observed(mechanism, state, dt, |_| {})
    }

    /// The inner integrator's, with the bilateral rows and the contacts resting now held.
    fn law_acceleration(&self, mechanism: &M, state: &State<T, N>) -> Result<SVector<T, N>, Error> {
        let rows = active(
            mechanism,
            &self.contacts,
            &self.model,
            &self.bilateral,
            &self.resting,
        );
        self.integrator.law_acceleration(&rows, state)
    }

    /// A step of a run; see [`ContactStepper::step_observed`].
    fn run_step(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        dt: T,
    ) -> Result<State<T, N>, Error> {
        self.transaction(|c| c.step_events(mechanism, state, dt, |_| {}, true))
    }

    /// As the default, and a run that fails leaves the stepper as it found it (resting set,
    /// impact count, the state it continues from), like a step that fails.
    fn integrate_with<F: FnMut(&State<T, N>)>(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        dt: T,
        steps: u64,
        observe: F,
    ) -> Result<State<T, N>, Failure<T, N>> {
        self.transaction(|c| {
            step_loop(
                state,
                dt,
                steps,
                |s| c.step_events(mechanism, s, dt, |_| {}, true),
                observe,
            )
        })
    }
}
