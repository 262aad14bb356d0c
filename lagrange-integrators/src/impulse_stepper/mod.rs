//! [`ImpulseStepper`]: contacts at a bounded cost per step, for games and firmware: any
//! integrator's free step, then one capped impulse solve over the rows in contact.

mod report;
mod rows;
mod settings;
mod solve;

pub use report::ImpulseReport;
pub use settings::ImpulseSettings;

use crate::integrator::{check_run_step, check_step, continues, step_loop};
use crate::{Cost, Failure, Integrator, Method, Work};
use lagrange_core::constraints::contact::{
    within_kinetic_energy, ContactModel, Contacts, Delassus, Row,
};
use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{Error, Mechanism, Real, State};
use rows::{finite_gaps, finite_rows, Direction};
use solve::{Impulses, Problem, Solved};

/// Any integrator, stepping a mechanism with contacts `g(q) >= 0` (and optional bilateral
/// rows) at a fixed step whose cost has a bound: time stepping at the velocity level, in the
/// mechanism's generalized coordinates (Moreau's scheme, with split impulses for the drift).
///
/// ```text
/// 1. free step      (q_f, q'_f) = the inner integrator's step of dt, contacts ignored
/// 2. rows           every bilateral row and every contact with g(q_f) <= 0, with its
///                   tangent where the model has friction; their mobilities M^-1 J^T through
///                   the mechanism's own mass solve (Mechanism::velocity_jumps)
/// 3. impulses       plastic first: the normal rows' complementarity problem solved exactly
///                   (w+ = J q'+ >= 0, impulse >= 0, one of the two zero; bilateral rows
///                   w+ = 0), alternated with a Coulomb sweep of the tangents
///                   (|friction| <= mu normal, sliding stopped where the cone allows)
/// 4. coordinates    q = q_f + POSITION_SHARE dt (q'_plastic - q'_f): the impulses as a
///                   constant force over the step (the inner method's share; semi-implicit
///                   Euler's 1 makes this Moreau's q = q0 + dt q'+), so that a body held at
///                   rest does not creep, on a floor or along it. A contact still open that
///                   this would close below the slop joins (speculative: its target the
///                   speed that closes it over the step), and 3 is solved again
/// 5. rebounds       where a contact approached at w_f with e |w_f| at least the model's rest
///                   speed, 3 again with the target w+ >= -e w_f on it: the rebound leaves
///                   from where the contact is (it neither lifts the body nor feeds a cycle
///                   of small bounces)
/// 6. drift          split impulses, exactly, on the rows' linearised gaps: contacts below
///                   -slop moved back to it, bilateral rows to zero (the velocities are left
///                   alone, so no body leaves the floor faster than it hit it); a contact the
///                   correction would push below the slop joins, and it is solved again
/// 7. energy         T + V after at most max(T + V before, T + V after the free step): where
///                   the drift's potential or rebounds of rows coupled in the mass metric
///                   would add energy, the velocities are scaled down to it
/// ```
///
/// **Work of a step** (a firmware budget; `R` normal rows, at most the contact set's `C`
/// (or the settings' `max_rows` in contact), `F <= R` of them with friction, `K` the
/// settings' `max_iterations`):
///
/// ```text
/// the inner method's step                      (Method::COST of the inner method)
/// 1 position_residual; with R > 0: 1 jacobian, 1 tangent_jacobian (with friction),
///   2 velocity_jumps of R and F columns (and one velocity_jump per speculative row)
/// at most 4 solves of the impulses (plastic, twice more with speculative rows, rebound),
///   each at most K rounds of: one exact solve of the R normal rows (the active-set method
///   of Delassus::complementary: a Cholesky factorisation of at most R rows per pass, at most
///   4 C + 4 passes, one or two from the last step's active rows), one sweep of F tangents
/// at most 3 exact solves of the R rows for the drift
/// 2 to 4 evaluations of T and V
/// ```
///
/// A step with no row in contact is the inner step and one `position_residual`. The report
/// of the last step ([`ImpulseStepper::last_report`]) gives `R`, `F`, the rounds taken and
/// whether the friction sweeps settled within the cap: where they did not, the step still
/// returns a state that does not gain energy (step 7), never an error.
///
/// **Which inner method.** Semi-implicit Euler (one acceleration a step, `POSITION_SHARE` 1:
/// the classic Moreau-Jean scheme, what games run at 60 to 240 Hz) or any second-order one
/// ([`VelocityVerlet`](crate::VelocityVerlet), [`StormerVerlet`](crate::StormerVerlet)),
/// whose free flight is second order; [`Rk4`](crate::Rk4) makes the free flight fourth order,
/// which pays where flights are long. Through contacts the scheme is first order whatever
/// the inner method (an impulse lands at the end of a step). Implicit methods work too, but
/// their Newton iterations buy stability the impulses do not need.
///
/// **Which contact stepper.** This one for real time: bounded work, no hitch when a ragdoll
/// lands, resting bodies quiet (they fall asleep in a scene), first order through contacts.
/// [`ContactStepper`](crate::ContactStepper) for accuracy: it locates every contact inside
/// the step and keeps the inner method's order between them, at a cost that grows with the
/// events (a thrown ragdoll: hundreds of times a free step).
///
/// The same rows and [`ContactModel`] as [`ContactStepper`](crate::ContactStepper): a
/// mechanism switches by changing one line. The model's time tolerance is not used.
///
/// ```
/// use lagrange_core::{nalgebra::SVector, Holonomic, HolonomicConstraints, Scalar, State};
/// use lagrange_integrators::{ContactModel, ImpulseSettings, ImpulseStepper, Integrator, SemiImplicitEuler};
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
/// let settings = ImpulseSettings::new(1e-3, 10)?;
/// let mut stepper = ImpulseStepper::new(SemiImplicitEuler, Holonomic::new(Ground), model, settings);
/// let end = stepper.integrate(&ball, &State::at_rest([1.0]), 1.0 / 120.0, 600)?;
/// // At rest after 5 s, on the ground (Moreau's scheme rests a body where its last step
/// // caught it: within dt^2 g above), and still.
/// assert!(end.q[0].abs() < 1e-3 && end.qd[0] == 0.0);
/// assert!(stepper.last_report().rows == 1);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy)]
pub struct ImpulseStepper<T: Real, const N: usize, const C: usize, I, K> {
    integrator: I,
    contacts: K,
    model: ContactModel<T>,
    settings: ImpulseSettings<T>,
    bilateral: [bool; C],
    memory: Memory<T, N, C>,
}

/// What an [`ImpulseStepper`] keeps between steps.
#[derive(Debug, Clone, Copy)]
struct Memory<T: Real, const N: usize, const C: usize> {
    /// The last step's impulses, its end state and that state's energy `T + V`.
    last: Option<(Impulses<T, C>, State<T, N>, T)>,
    /// The rows that pushed in the last step (or were bilateral): the contacts resting at its
    /// end, which a body the scheme brought to rest may touch from up to `dt^2 g` above.
    pushed: [bool; C],
    report: ImpulseReport,
    /// The largest counts of any step since the stepper was made or
    /// [`ImpulseStepper::clear_peak`].
    peak: ImpulseReport,
    /// The last step's size, for the sleep test's trial step.
    dt: Option<T>,
}

impl<T: Real, const N: usize, const C: usize> Memory<T, N, C> {
    /// Nothing yet.
    fn fresh() -> Self {
        Self {
            last: None,
            pushed: [false; C],
            report: ImpulseReport::default(),
            peak: ImpulseReport::default(),
            dt: None,
        }
    }
}

impl<T: Real, const N: usize, const C: usize, I, K> ImpulseStepper<T, N, C, I, K> {
    /// `integrator` stepping with the contacts `contacts` under `model` (its restitution,
    /// rest speed and friction), with `settings` (slop and caps).
    pub fn new(
        integrator: I,
        contacts: K,
        model: ContactModel<T>,
        settings: ImpulseSettings<T>,
    ) -> Self {
        Self {
            integrator,
            contacts,
            model,
            settings,
            bilateral: [false; C],
            memory: Memory::fresh(),
        }
    }

    /// The same stepper with the rows marked `true` in `rows` bilateral (`phi_i = 0` always,
    /// held by impulses of either sign) instead of contacts.
    #[must_use]
    pub fn with_bilateral(self, rows: [bool; C]) -> Self {
        Self {
            bilateral: rows,
            memory: Memory::fresh(),
            ..self
        }
    }

    /// What the last step did: rows in contact, rounds, whether the solve settled, whether
    /// the energy guard acted.
    #[must_use]
    pub fn last_report(&self) -> ImpulseReport {
        self.memory.report
    }

    /// The worst of the steps since the stepper was made or [`ImpulseStepper::clear_peak`]:
    /// the largest counts of any step, and the flags of any (`settled` when every step
    /// settled). What a firmware budget is checked against.
    #[must_use]
    pub fn peak_report(&self) -> ImpulseReport {
        self.memory.peak
    }

    /// Starts [`ImpulseStepper::peak_report`] afresh.
    pub fn clear_peak(&mut self) {
        self.memory.peak = ImpulseReport::default();
    }

    /// The impulses of the last step along each row's normal and its tangent (zero where a
    /// row took no part): `|tangent_i| <= mu normal_i` for every contact.
    #[must_use]
    pub fn impulses(&self) -> ([T; C], [T; C]) {
        self.memory
            .last
            .map_or(([T::zero(); C], [T::zero(); C]), |(p, _, _)| {
                (p.normal.into(), p.tangent)
            })
    }

    /// The contact model.
    #[must_use]
    pub fn model(&self) -> &ContactModel<T> {
        &self.model
    }

    /// The settings.
    #[must_use]
    pub fn settings(&self) -> &ImpulseSettings<T> {
        &self.settings
    }

    /// The contact set.
    #[must_use]
    pub fn contacts(&self) -> &K {
        &self.contacts
    }

    /// `f`, and the stepper as it was (warm start, report) when `f` fails.
    fn transaction<V, E>(&mut self, f: impl FnOnce(&mut Self) -> Result<V, E>) -> Result<V, E> {
        let saved = self.memory;
        let result = f(self);
        if result.is_err() {
            self.memory = saved;
        }
        result
    }
}

impl<T, I, K, const N: usize, const C: usize> ImpulseStepper<T, N, C, I, K>
where
    T: Real,
    I: Method,
    K: Contacts<T, N, C>,
{
    /// One step of `dt`, already checked: the scheme of the type's docs.
    fn advance<M>(&mut self, mechanism: &M, s: &State<T, N>, dt: T) -> Result<State<T, N>, Error>
    where
        M: Mechanism<T, N>,
        I: Integrator<T, N, M>,
    {
        let free = self.integrator.run_step(mechanism, s, dt)?;
        let (end, memory) = self.contacts_of(mechanism, s, free, dt, &self.memory)?;
        self.memory = memory;
        Ok(end)
    }

    /// The contacts' part of a step from `s` whose free step reached `free`, with `memory` of
    /// the steps before: the end state, and the memory after.
    fn contacts_of<M>(
        &self,
        mechanism: &M,
        s: &State<T, N>,
        free: State<T, N>,
        dt: T,
        memory: &Memory<T, N, C>,
    ) -> Result<(State<T, N>, Memory<T, N, C>), Error>
    where
        M: Mechanism<T, N>,
    {
        let (warm, start_energy) = match memory.last {
            Some((p, last, e)) if continues(&last, s) => (p.tangent, Some(e)),
            _ => ([T::zero(); C], None),
        };
        let mut next = *memory;
        next.dt = Some(dt);
        let gaps = finite_gaps(self.contacts.position_residual(&free.q))?;
        let touching: [bool; C] =
            core::array::from_fn(|i| self.bilateral[i] || gaps[i] <= T::zero());
        let in_contact = touching.iter().filter(|&&t| t).count();
        if in_contact == 0 {
            next.report = ImpulseReport::default();
            // The energy of a state no row touches is not needed: marked unknown.
            next.last = Some((Impulses::zero(), free, T::INFINITY));
            next.pushed = [false; C];
            next.peak = next.peak.worst(&next.report);
            return Ok((free, next));
        }
        if self
            .settings
            .max_rows()
            .is_some_and(|cap| in_contact > cap as usize)
        {
            return Err(Error::InvalidParameter {
                name: "max_rows",
                reason: "more rows are in contact than max_rows allows",
            });
        }
        let (jacobian, tangent_rows) = self.contacts.jacobians(&free.q);
        let jacobian = finite_rows(jacobian, &[true; C])?;
        let (mut normal, tangent) =
            self.mobilities(mechanism, &free, &jacobian, tangent_rows, &touching)?;
        let kinds = Row::kinds(&self.bilateral);
        // The rows that pushed in the last step: the first guess of each solve's active rows.
        let guess = if start_energy.is_some() {
            memory.pushed
        } else {
            touching
        };
        let settings = self.settings;
        let (rounds, tolerance, slop) = (
            settings.max_iterations(),
            settings.tolerance(),
            settings.slop(),
        );
        let friction = self.model.friction();
        let w = jacobian * free.qd;
        let share = T::from_f64(I::POSITION_SHARE) * dt;
        let jump = |b: &SVector<T, N>| mechanism.velocity_jump(&free, b);
        let mut target = SVector::<T, C>::zeros();
        let solve = |work: &mut Delassus<T, N, C>, target: &SVector<T, C>, warm: &[T; C]| {
            Problem {
                normal: work,
                kinds: &kinds,
                tangent: &tangent,
                friction,
                pushed: &guess,
            }
            .solve(&free.qd, target, warm, rounds, tolerance)
        };
        let mut plastic = solve(&mut normal, &target, &warm)?;
        let (mut taken, mut speculative) = (plastic.rounds, 0u32);
        for _ in 0..SPECULATIVE_ROUNDS {
            let reach = jacobian * ((plastic.velocity - free.qd) * share) + gaps;
            let joining: [bool; C] =
                core::array::from_fn(|i| !normal.candidates()[i] && reach[i] < -slop);
            if share <= T::zero() || !joining.iter().any(|&j| j) {
                break;
            }
            normal.extend(&jacobian, jump, &joining)?;
            for i in (0..C).filter(|&i| joining[i]) {
                target[i] = w[i] - gaps[i] / share;
                speculative += 1;
            }
            plastic = solve(&mut normal, &target, &plastic.impulses.tangent)?;
            taken += plastic.rounds;
        }
        let rebound = self.rebounds(&gaps, &w);
        let solved = if rebound.iter().any(|&r| r > T::zero()) {
            let bounce = target.zip_map(&rebound, |t, r| t.max(r));
            let bounced = solve(&mut normal, &bounce, &plastic.impulses.tangent)?;
            taken += bounced.rounds;
            Solved {
                settled: plastic.settled && bounced.settled,
                ..bounced
            }
        } else {
            plastic
        };
        let shift = (plastic.velocity - free.qd) * share;
        let (dq, corrected) = self.drift(
            &mut normal,
            &jacobian,
            jacobian * shift + gaps,
            &kinds,
            jump,
        )?;
        let end = State {
            t: free.t,
            q: free.q + shift + dq,
            qd: solved.velocity,
        };
        let (end, energy, guarded) = guard(mechanism, s, start_energy, &free, end)?;
        let count = |rows: &[bool; C]| {
            u32::try_from(rows.iter().filter(|&&r| r).count()).unwrap_or(u32::MAX)
        };
        next.report = ImpulseReport {
            rows: count(normal.candidates()),
            speculative,
            frictional: count(&core::array::from_fn(|i| tangent[i].is_some())),
            rounds: taken,
            settled: solved.settled,
            corrected,
            energy_guard: guarded,
        };
        next.pushed =
            core::array::from_fn(|i| self.bilateral[i] || solved.impulses.normal[i] > T::zero());
        next.last = Some((solved.impulses, end, energy));
        next.peak = next.peak.worst(&next.report);
        Ok((end, next))
    }

    /// The rows of a step at `state`: the normal rows in `touching` (their [`Delassus`]), and
    /// the tangents of those contacts (where the model has friction and
    /// the set gives them), their mobilities from one call of
    /// [`Mechanism::velocity_jumps`] where the tangents fit in the columns the normal rows
    /// leave free (two calls where they do not).
    #[allow(clippy::type_complexity)]
    fn mobilities<M: Mechanism<T, N>>(
        &self,
        mechanism: &M,
        state: &State<T, N>,
        jacobian: &SMatrix<T, C, N>,
        tangent_rows: Option<SMatrix<T, C, N>>,
        touching: &[bool; C],
    ) -> Result<(Delassus<T, N, C>, [Option<Direction<T, N>>; C]), Error> {
        let frictional: [bool; C] = core::array::from_fn(|i| touching[i] && !self.bilateral[i]);
        let tangent_rows = match tangent_rows {
            Some(t) if self.model.friction() > T::zero() => Some(finite_rows(t, &frictional)?),
            _ => None,
        };
        // Normal rows in their own columns; each tangent in a column no normal row uses.
        let mut columns = SMatrix::<T, N, C>::zeros();
        let mut slot = [None::<usize>; C];
        let mut free = (0..C).filter(|&k| !touching[k]);
        let mut overflow = false;
        for i in (0..C).filter(|&i| touching[i]) {
            columns.set_column(i, &jacobian.row(i).transpose());
        }
        if let Some(t) = &tangent_rows {
            // Row by row through iterators, and `k < C` clamped (a no-op), here and where the
            // slots are read: no bounds check (no panic path) is left to the optimiser.
            let tangents = t.row_iter().zip(&frictional).zip(&mut slot);
            for ((row, _), slot) in tangents.filter(|((_, &on), _)| on) {
                match free.next() {
                    Some(k) => {
                        let k = k.min(C - 1);
                        columns.set_column(k, &row.transpose());
                        *slot = Some(k);
                    }
                    None => overflow = true,
                }
            }
        }
        let jumps = mechanism.velocity_jumps(state, &columns)?;
        let mut normal = jumps;
        for k in (0..C).filter(|&k| !touching[k]) {
            normal.column_mut(k).fill(T::zero());
        }
        let rows = Delassus::new(*jacobian, |_| Ok(normal), touching)?;
        let mut out = [None; C];
        let Some(t) = tangent_rows else {
            return Ok((rows, out));
        };
        let rest = if overflow {
            let mut columns = SMatrix::<T, N, C>::zeros();
            let tangents = columns.column_iter_mut().zip(t.row_iter());
            for ((mut column, row), _) in tangents
                .zip(frictional.iter().zip(&slot))
                .filter(|(_, (&on, slot))| on && slot.is_none())
            {
                column.copy_from(&row.transpose());
            }
            Some(mechanism.velocity_jumps(state, &columns)?)
        } else {
            None
        };
        for i in (0..C).filter(|&i| frictional[i]) {
            // Copied rather than `into_owned` (whose length assertion stays in the optimised
            // code, a panic path).
            let mut b = SVector::<T, N>::zeros();
            match (slot[i], &rest) {
                (Some(k), _) => b.copy_from(&jumps.column(k.min(C - 1))),
                (None, Some(r)) => b.copy_from(&r.column(i)),
                (None, None) => continue,
            }
            out[i] = Direction::new(t.row(i).transpose(), b);
        }
        Ok((rows, out))
    }

    /// The drift correction of coordinates whose rows' gaps would be `reach`: split impulses
    /// over the normal rows, solved exactly on the linearised gaps, contacts back to `-slop`
    /// and bilateral rows to zero; a contact that the correction itself would take below the
    /// slop joins and it is solved again (at most [`SPECULATIVE_ROUNDS`] times). The
    /// displacement, and whether there was one.
    fn drift<F>(
        &self,
        normal: &mut Delassus<T, N, C>,
        jacobian: &SMatrix<T, C, N>,
        reach: SVector<T, C>,
        kinds: &[Row; C],
        jump: F,
    ) -> Result<(SVector<T, N>, bool), Error>
    where
        F: FnMut(&SVector<T, N>) -> Result<SVector<T, N>, Error>,
    {
        let slop = self.settings.slop();
        let mut jump = jump;
        let mut dq = SVector::<T, N>::zeros();
        let mut corrected = false;
        let off = SVector::<T, C>::from_fn(|i, _| {
            if self.bilateral[i] {
                reach[i]
            } else {
                reach[i] + slop
            }
        });
        for _ in 0..=SPECULATIVE_ROUNDS {
            let after = jacobian * dq + off;
            let joining: [bool; C] = core::array::from_fn(|i| {
                !normal.candidates()[i] && !self.bilateral[i] && after[i] < T::zero()
            });
            let deep = (0..C).any(|i| {
                (normal.candidates()[i] || joining[i])
                    && (after[i] < T::zero() || (self.bilateral[i] && after[i] != T::zero()))
            });
            if !deep {
                break;
            }
            normal.extend(jacobian, &mut jump, &joining)?;
            let push = normal.complementary(&off, kinds)?.lambda;
            dq = normal.response(&push);
            corrected = true;
        }
        Ok((dq, corrected))
    }

    /// Each row's rebound: `-e w` for a contact touching and approaching at `w` fast enough
    /// that it would leave at the model's rest speed or more, else zero (it rests).
    fn rebounds(&self, gaps: &SVector<T, C>, w: &SVector<T, C>) -> SVector<T, C> {
        let e = self.model.restitution();
        SVector::from_fn(|i, _| {
            let rebound = -e * w[i];
            if !self.bilateral[i] && gaps[i] <= T::zero() && rebound >= self.model.rest_speed() {
                rebound
            } else {
                T::zero()
            }
        })
    }
}

/// How many times a step's plastic solve (or its drift correction) may be done again with
/// contacts joining that its coordinates' shift would close (speculative rows).
const SPECULATIVE_ROUNDS: u32 = 2;

/// The energy guard of a step from `start` (whose energy `T + V` is `known`, when the step
/// continues the last one) whose free step reached `free` and whose impulses and drift
/// correction reached `end`: the end state, its energy, and whether the guard acted.
/// Allowed: the larger of the start's energy and the free step's, plus the free step's own
/// energy error, to rounding. Above it, the velocities
/// are scaled down to the kinetic energy the allowance leaves; where the contacts' move of
/// the coordinates alone takes the potential energy above it (a body lifted out of the floor
/// with no kinetic energy to pay for it), the velocities are zeroed and the move shortened
/// to what the allowance pays (the free step's coordinates, at rest, are within it): a
/// contact stays deeper for a step rather than gain energy.
///
/// # Errors
/// As [`within_kinetic_energy`].
fn guard<T: Real, M: Mechanism<T, N>, const N: usize>(
    mechanism: &M,
    start: &State<T, N>,
    known: Option<T>,
    free: &State<T, N>,
    mut end: State<T, N>,
) -> Result<(State<T, N>, T, bool), Error> {
    let before = match known {
        Some(e) if e.is_finite() => e,
        _ => mechanism.energy(start),
    };
    let after_free = mechanism.energy(free);
    // Allowed: the larger of the start's energy and the free step's, plus the free step's
    // own energy error (the motion the contacts allow is integrated no better than the free
    // motion: a sliding or rotating contact gains or loses as the free step does), plus the
    // rounding of the energies compared (16 ulps of the sizes of their terms: T + V may be
    // near zero while T and V are not).
    let allowed = before.max(after_free) + (after_free - before).abs();
    let energy = mechanism.energy(&end);
    let potential = mechanism.potential_energy(&end);
    let rounding =
        T::from_f64(16.0) * T::EPSILON * (allowed.abs() + energy.abs() + T::TWO * potential.abs());
    if energy <= allowed + rounding {
        return Ok((end, energy, false));
    }
    let kinetic = allowed - potential;
    if kinetic > T::zero() {
        end.qd = within_kinetic_energy(mechanism, &end, kinetic)?;
    } else {
        let rest = State {
            qd: SVector::zeros(),
            ..end
        };
        let moved = end.q - free.q;
        let at = |share: T| State {
            q: free.q + moved * share,
            ..rest
        };
        let low = mechanism.potential_energy(&at(T::zero()));
        let high = mechanism.potential_energy(&rest);
        let share = if low < allowed && high > low {
            ((allowed - low) / (high - low)).min(T::one())
                * (T::one() - T::from_f64(16.0) * T::EPSILON)
        } else {
            T::zero()
        };
        end = at(share);
        if mechanism.potential_energy(&end) > allowed {
            end = at(T::zero());
        }
    }
    Ok((end, mechanism.energy(&end), true))
}

impl<T: Real, I: Method, K, const N: usize, const C: usize> Method
    for ImpulseStepper<T, N, C, I, K>
{
    const NAME: &'static str = I::NAME;
    /// The inner method's in free flight; through contacts the scheme is first order.
    const ORDER: u32 = I::ORDER;
    /// The inner method's per step; the contacts' work is in the type's docs.
    const COST: Cost = I::COST;
    const POSITION_SHARE: f64 = I::POSITION_SHARE;

    fn last_step(&self) -> Work {
        self.integrator.last_step()
    }
}

impl<T, M, I, K, const N: usize, const C: usize> Integrator<T, N, M>
    for ImpulseStepper<T, N, C, I, K>
where
    T: Real,
    M: Mechanism<T, N>,
    I: Integrator<T, N, M> + Clone,
    K: Contacts<T, N, C>,
{
    /// One step with contacts; see [`ImpulseStepper`].
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `dt` unless positive and finite, `max_rows` when more rows
    /// are in contact than it allows; [`Error::NonFiniteState`]; [`Error::NonFiniteRow`] for a
    /// row whose gap, Jacobian or tangent is not finite; the inner integrator's errors and the
    /// mechanism's mass solve's. A step that fails leaves the stepper as it found it.
    fn step(&mut self, mechanism: &M, state: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        let dt = check_step(state, dt)?;
        self.transaction(|c| c.advance(mechanism, state, dt))
    }

    /// What one step of the stepper does to `state` from rest: the velocity change of a step
    /// of the last step's size from `state` with its velocities zeroed (the integrator's own
    /// step and the contacts' impulses, static friction included), divided by the step; the
    /// mechanism's own acceleration before any step. What a scene's sleep test reads: a body
    /// resting on the floor, or held on a slope by friction, does not accelerate.
    fn law_acceleration(&self, mechanism: &M, state: &State<T, N>) -> Result<SVector<T, N>, Error> {
        let Some(dt) = self.memory.dt else {
            return mechanism.acceleration(state);
        };
        let rest = State {
            qd: SVector::zeros(),
            ..*state
        };
        // Warm-started from the last step's impulses, as the next step would be.
        let mut memory = self.memory;
        memory.last = memory
            .last
            .map(|(p, _, _)| (p, rest, mechanism.energy(&rest)));
        let free = self.integrator.clone().run_step(mechanism, &rest, dt)?;
        let (next, _) = self.contacts_of(mechanism, &rest, free, dt, &memory)?;
        Ok(next.qd / dt)
    }

    /// A step of a run; see [`ImpulseStepper`].
    fn run_step(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        dt: T,
    ) -> Result<State<T, N>, Error> {
        let dt = check_run_step(state, dt)?;
        self.transaction(|c| c.advance(mechanism, state, dt))
    }

    /// As the default, and a run that fails leaves the stepper as it found it.
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
                |s| {
                    let dt = check_run_step(s, dt)?;
                    c.advance(mechanism, s, dt)
                },
                observe,
            )
        })
    }
}
