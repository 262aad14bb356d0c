//! The contacts' part of an [`ImpulseStepper`](super::ImpulseStepper)'s step, after the free
//! step: rows, impulses, the coordinates' shift, rebounds, drift, energy (steps 2 to 7 of
//! the type's docs).

use super::energy::guard;
use super::report::ImpulseReport;
use super::rows::{within, Columns, Filled, Measured, Reuse, Workspace};
use super::settings::ImpulseSettings;
use super::solve::{Impulses, Problem, Solved};
use crate::integrator::continues;
use lagrange_core::constraints::contact::{ContactModel, Contacts, Delassus, Row};
use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{Error, Mechanism, Real, State};

/// How many times a step's plastic solve (or its drift correction) may be done again with
/// contacts joining that its coordinates' shift would close (speculative rows).
const SPECULATIVE_ROUNDS: u32 = 2;

/// How many times the drift correction may be done again on the gaps the last one left: the
/// correction is exact on the gaps linearised where the free step ended, and a link that
/// turns in the step leaves a second-order remainder (a hand 0.7 m from its joint turned
/// 0.08 rad: 2 mm); each round shrinks it by about the share of a radian turned.
const DRIFT_ROUNDS: u32 = 3;

/// What a stepper is given: its contacts, their model, the settings, the bilateral rows.
#[derive(Debug, Clone, Copy)]
pub(super) struct Setup<T: Real, const C: usize, K> {
    pub(super) contacts: K,
    pub(super) model: ContactModel<T>,
    pub(super) settings: ImpulseSettings<T>,
    pub(super) bilateral: [bool; C],
}

/// What an [`ImpulseStepper`](super::ImpulseStepper) keeps between steps.
#[derive(Debug, Clone, Copy)]
pub(super) struct Memory<T: Real, const N: usize, const C: usize> {
    /// The last step's impulses, its end state and that state's energy `T + V` (infinite
    /// where it was not needed: a step no row touched).
    pub(super) last: Option<(Impulses<T, C>, State<T, N>, T)>,
    /// The rows that pushed in the last step (or were bilateral): the contacts resting at its
    /// end, the first guess of the next step's active rows.
    pub(super) pushed: [bool; C],
    pub(super) report: ImpulseReport,
    /// The largest counts of any step since the stepper was made or the peak cleared.
    pub(super) peak: ImpulseReport,
    /// The last step's size, for the sleep test's trial step.
    pub(super) dt: Option<T>,
}

/// What a step found touching at its free step's end ([`Setup::touch`]).
struct Touch<T: Real, const C: usize> {
    /// Where the rows are filled anew, the scratch columns of their mobilities.
    columns: Option<Columns<C>>,
    /// The gaps there.
    gaps: SVector<T, C>,
    /// The rows in contact (gap at most zero) and the bilateral ones.
    touching: [bool; C],
    /// The rows in contact that friction acts on (not bilateral).
    frictional: [bool; C],
    /// Whether the tangents count.
    tangents: bool,
}

impl<T: Real, const N: usize, const C: usize> Memory<T, N, C> {
    /// Nothing yet.
    pub(super) fn fresh() -> Self {
        Self {
            last: None,
            pushed: [false; C],
            report: ImpulseReport::default(),
            peak: ImpulseReport::default(),
            dt: None,
        }
    }

    /// The step just taken ended at `end` (energy `energy`) with `impulses`, and did what
    /// `report` says.
    fn record(
        &mut self,
        impulses: Impulses<T, C>,
        end: State<T, N>,
        energy: T,
        pushed: [bool; C],
        report: ImpulseReport,
    ) {
        self.last = Some((impulses, end, energy));
        self.pushed = pushed;
        self.report = report;
        self.peak = self.peak.worst(&report);
    }
}

impl<T: Real, const C: usize, K> Setup<T, C, K> {
    /// Each row's rebound: `-e w` for a contact `touching` (not a bilateral row) and
    /// approaching at `w` fast enough that it would leave at the model's rest speed or more,
    /// else zero (it rests); `w` the slower of its approaches at the free step's velocities
    /// `w_free` and at the step's start `w_start` (see [`Setup::contacts_of`]).
    fn rebounds(
        &self,
        touching: &[bool; C],
        w_free: &SVector<T, C>,
        w_start: impl Fn() -> SVector<T, C>,
    ) -> SVector<T, C> {
        let e = self.model.restitution();
        // No row that could rebound: the start's speeds are not needed.
        if !(0..C).any(|i| touching[i] && -e * w_free[i] >= self.model.rest_speed()) {
            return SVector::zeros();
        }
        let w_start = w_start();
        SVector::from_fn(|i, _| {
            let rebound = -e * w_free[i].max(w_start[i]);
            if touching[i] && rebound >= self.model.rest_speed() {
                rebound
            } else {
                T::zero()
            }
        })
    }

    /// The rows of `joining` that the settings' `max_rows` leaves room for beside the
    /// `candidates` (all of them without the cap): the deepest first by `depth`, the first
    /// of equal ones; the others marked in `left_out`. The rows of a solve never exceed the
    /// cap: a row left out is open at the step's start, and is a row in contact (counted
    /// against the cap) at the next.
    fn within_cap(
        &self,
        joining: [bool; C],
        candidates: &[bool; C],
        depth: &SVector<T, C>,
        left_out: &mut [bool; C],
    ) -> [bool; C] {
        let Some(cap) = self.settings.max_rows() else {
            return joining;
        };
        let count = |rows: &[bool; C]| rows.iter().filter(|&&r| r).count();
        let room = usize::try_from(cap)
            .unwrap_or(usize::MAX)
            .saturating_sub(count(candidates));
        if count(&joining) <= room {
            return joining;
        }
        // The rows still to place, the deepest taken from them into `kept` while room lasts.
        let (mut left, mut kept) = (joining, [false; C]);
        for _ in 0..room {
            let mut deepest: Option<usize> = None;
            for i in (0..C).filter(|&i| left[i]) {
                if deepest.is_none_or(|d| depth[i] < depth[within::<C>(d)]) {
                    deepest = Some(i);
                }
            }
            if let Some(d) = deepest.map(within::<C>) {
                (kept[d], left[d]) = (true, false);
            }
        }
        for (out, &l) in left_out.iter_mut().zip(&left) {
            *out |= l;
        }
        kept
    }

    /// The drift correction of coordinates whose rows' gaps would be `reach`: split impulses
    /// over the normal rows, solved exactly on the linearised gaps, contacts back to `-slop`
    /// and bilateral rows to zero; a contact that the correction itself would take below the
    /// slop joins (within the settings' `max_rows`: see [`Setup::within_cap`], which marks
    /// the rows it leaves out in `left_out`) and it is solved again (at most
    /// [`SPECULATIVE_ROUNDS`] times). The displacement, and whether there was one.
    fn drift<const N: usize, F>(
        &self,
        normal: &mut Delassus<T, N, C>,
        jacobian: &SMatrix<T, C, N>,
        reach: SVector<T, C>,
        kinds: &[Row<T>; C],
        mut jump: F,
        left_out: &mut [bool; C],
    ) -> Result<(SVector<T, N>, bool), Error>
    where
        F: FnMut(&SVector<T, N>) -> Result<SVector<T, N>, Error>,
    {
        let slop = self.settings.slop();
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
            // No product for the first look (no displacement yet).
            let after = if corrected { jacobian * dq + off } else { off };
            let joining: [bool; C] = core::array::from_fn(|i| {
                !normal.candidates()[i] && !self.bilateral[i] && after[i] < T::zero()
            });
            let joining = self.within_cap(joining, normal.candidates(), &after, left_out);
            let deep = (0..C).any(|i| {
                (normal.candidates()[i] || joining[i])
                    && (after[i] < T::zero() || (self.bilateral[i] && after[i] != T::zero()))
            });
            if !deep {
                break;
            }
            normal.extend(jacobian, &mut jump, &joining)?;
            // The rows below the slop push first (the others rarely need to: starting from
            // every row, each that did not was one more pass and factorisation).
            let below: [bool; C] = core::array::from_fn(|i| off[i] < T::zero());
            let push = normal.complementary_from(&off, kinds, &below)?.lambda;
            dq = normal.response(&push);
            corrected = true;
        }
        Ok((dq, corrected))
    }

    /// The coordinates `q` that the drift correction reached, corrected again on their own
    /// gaps (measured through `ended`; the same rows and Jacobian: a chord iteration) until
    /// no contact is deeper than the slop, at most [`DRIFT_ROUNDS`] times; where one still
    /// is, and deeper than at the start `start`, the start's coordinates (a contact is never
    /// left deeper than the slop by a step that took it there). The coordinates, the rounds
    /// taken, and whether they are the start's.
    #[allow(clippy::too_many_arguments)]
    fn settle<const N: usize, F>(
        &self,
        normal: &mut Delassus<T, N, C>,
        jacobian: &SMatrix<T, C, N>,
        kinds: &[Row<T>; C],
        mut jump: F,
        ended: &mut Measured<T, N, C>,
        start: &SVector<T, N>,
        mut q: SVector<T, N>,
        left_out: &mut [bool; C],
    ) -> Result<(SVector<T, N>, u32, bool), Error>
    where
        K: Contacts<T, N, C>,
        F: FnMut(&SVector<T, N>) -> Result<SVector<T, N>, Error>,
    {
        let slop = self.settings.slop();
        // Deeper than the slop by more than 2^-10 of it and the rounding of a gap of
        // coordinates as large as these (64 ulps: a gap sums a few terms of that size).
        let deep = |gaps: &SVector<T, C>, q: &SVector<T, N>, i: usize| {
            let rounding = T::from_f64(64.0)
                * T::EPSILON
                * (T::one() + q.iter().fold(T::zero(), |m, x| m.max(x.abs())));
            !self.bilateral[i] && gaps[i] < -(slop + slop * T::from_f64(1.0 / 1024.0) + rounding)
        };
        let mut rounds = 0;
        loop {
            // A move that overflowed is the state's fault, not a row's.
            if !q.iter().all(|x| x.is_finite()) {
                return Err(Error::NonFiniteState);
            }
            let gaps = ended.gaps(&self.contacts, &q)?;
            if !(0..C).any(|i| deep(&gaps, &q, i)) {
                return Ok((q, rounds, false));
            }
            if rounds == DRIFT_ROUNDS {
                let before = self.contacts.position_residual(start);
                let deeper = (0..C).any(|i| deep(&gaps, &q, i) && gaps[i] < before[i]);
                return Ok(if deeper {
                    (*start, rounds, true)
                } else {
                    (q, rounds, false)
                });
            }
            let (dq, _) = self.drift(normal, jacobian, gaps, kinds, &mut jump, left_out)?;
            q += dq;
            rounds += 1;
        }
    }
}

impl<T: Real, const C: usize, K> Setup<T, C, K> {
    /// The gaps at the free step's end `free` (the rows' taken again, or worked out with
    /// their Jacobians where `rows_too`), which rows touch, the Jacobians and tangents
    /// checked and, where the rows are filled anew, their mobilities: what a step finds
    /// before it fills its rows (it writes the workspace's Jacobians, tangents and scratch
    /// columns, nothing else); `None` where no row touches.
    ///
    /// # Errors
    /// [`Error::NonFiniteRow`] for a gap, Jacobian or tangent that is not finite,
    /// [`Error::InvalidParameter`] `max_rows` where more rows touch than it allows; the
    /// mass solve's.
    fn touch<M, const N: usize>(
        &self,
        work: &mut Workspace<T, N, C>,
        mechanism: &M,
        reuse: &Reuse<T, N, C>,
        free: &State<T, N>,
        rows_too: bool,
    ) -> Result<Option<Touch<T, C>>, Error>
    where
        M: Mechanism<T, N>,
        K: Contacts<T, N, C>,
    {
        let q = &free.q;
        let (gaps, given) = match reuse.rows {
            Some((gaps, _)) => (gaps, None),
            None => work.gaps(&self.contacts, q, rows_too)?,
        };
        let touching: [bool; C] =
            core::array::from_fn(|i| self.bilateral[i] || gaps[i] <= T::zero());
        let in_contact = touching.iter().filter(|&&t| t).count();
        if in_contact == 0 {
            return Ok(None);
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
        let frictional: [bool; C] = core::array::from_fn(|i| touching[i] && !self.bilateral[i]);
        let friction = self.model.friction() > T::zero();
        let tangents = match (reuse.rows, given) {
            (Some((_, tangents)), _) => tangents,
            (None, Some(tangents)) => work.checked(tangents && friction, &frictional)?,
            (None, None) => work.jacobians(&self.contacts, q, friction, &frictional)?,
        };
        let columns = match reuse.rows {
            Some(_) => None,
            None => Some(work.mobilities(mechanism, free, tangents, &touching, &frictional)?),
        };
        Ok(Some(Touch {
            columns,
            gaps,
            touching,
            frictional,
            tangents,
        }))
    }

    /// The contacts' part of a step from `s` whose free step reached `free`, the coordinates
    /// moved by `share` (the inner method's position share times the step) of the plastic
    /// impulses' velocity change: the end state, `memory` updated (the caller restores it
    /// when this fails), `work` filled and used.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn contacts_of<M, const N: usize>(
        &self,
        work: &mut Workspace<T, N, C>,
        memory: &mut Memory<T, N, C>,
        mechanism: &M,
        s: &State<T, N>,
        free: State<T, N>,
        dt: T,
        share: T,
    ) -> Result<State<T, N>, Error>
    where
        M: Mechanism<T, N>,
        K: Contacts<T, N, C>,
    {
        let (warm, start_energy) = match memory.last {
            Some((p, last, e)) if continues(&last, s) => (p, Some(e)),
            _ => (Impulses::zero(), None),
        };
        memory.dt = Some(dt);
        // After a step with rows in contact, the gaps and the rows at once (one pose of a
        // ragdoll); in flight, the gaps alone. Where the free step ended where the last
        // one's did, the rows it filled (a mechanism at rest).
        let rows_too = memory.report.rows > 0;
        // The record of the rows the last step left, put back if this one fails before it
        // fills its own over them.
        let prior = work.filled;
        let reuse = work.reuse(mechanism, &free, rows_too);
        let touch = match self.touch(work, mechanism, &reuse, &free, rows_too) {
            Ok(touch) => touch,
            Err(e) => {
                work.put_back(prior, &reuse, &self.contacts);
                return Err(e);
            }
        };
        let Some(Touch {
            columns,
            gaps,
            touching,
            frictional,
            tangents,
        }) = touch
        else {
            // The energy of a state no row touches is not needed: marked unknown.
            let none = ImpulseReport::default();
            memory.record(Impulses::zero(), free, T::INFINITY, [false; C], none);
            return Ok(free);
        };
        if let Some(columns) = columns {
            work.fill(mechanism, &free, tangents, &touching, &frictional, columns)?;
        }
        let Workspace {
            normal,
            tangent,
            jacobian,
            ended,
            ..
        } = work;
        let jacobian = &*jacobian;
        let tangent = &*tangent;
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
        // The solves after the plastic one (speculative rows, rebounds) start from its
        // impulses and the rows it ended with (from the last step's, a rebound's solve took
        // ten passes where the plastic one had found its rows) and share the rounds it
        // left, at least one each: a step takes at most `max_iterations + 3` rounds
        // (ImpulseSettings::max_rounds), where each solve capped on its own took four
        // times as many in the landing steps whose friction does not settle (the rounds
        // shrink its change by a third each).
        let left = |taken: u32| rounds.saturating_sub(taken).max(1);
        let friction = self.model.friction();
        let w = jacobian * free.qd;
        let jump = |b: &SVector<T, N>| mechanism.velocity_jump(&free, b);
        let mut target = SVector::<T, C>::zeros();
        let solve = |normal: &mut Delassus<T, N, C>,
                     target: &SVector<T, C>,
                     warm: &Impulses<T, C>,
                     guess: &[bool; C],
                     cap: u32| {
            Problem {
                normal,
                kinds: &kinds,
                tangent,
                friction,
                pushed: guess,
            }
            .solve(&free.qd, target, warm, cap, rounds, tolerance)
        };
        let mut plastic = solve(normal, &target, &warm, &guess, rounds)?;
        let (mut taken, mut speculative) = (plastic.rounds, 0u32);
        // The gaps where the plastic impulses' shift of the coordinates takes the rows.
        let reach_of =
            |plastic: &Solved<T, N, C>| jacobian * ((plastic.velocity - free.qd) * share) + gaps;
        let mut reach = reach_of(&plastic);
        // The rows that `max_rows` kept from joining.
        let mut left_out = [false; C];
        for _ in 0..SPECULATIVE_ROUNDS {
            let joining: [bool; C] =
                core::array::from_fn(|i| !normal.candidates()[i] && reach[i] < -slop);
            if share <= T::zero() || !joining.iter().any(|&j| j) {
                break;
            }
            let joining = self.within_cap(joining, normal.candidates(), &reach, &mut left_out);
            if !joining.iter().any(|&j| j) {
                break;
            }
            normal.extend(jacobian, jump, &joining)?;
            for i in (0..C).filter(|&i| joining[i]) {
                target[i] = w[i] - gaps[i] / share;
                speculative += 1;
            }
            plastic = solve(
                normal,
                &target,
                &plastic.impulses,
                &plastic.active,
                left(taken),
            )?;
            taken += plastic.rounds;
            reach = reach_of(&plastic);
        }
        // Newton's law on the slower approach, at the free step's velocities or the start's:
        // the free step's include the step's own forces (gravity's dt g), and a ball whose
        // rebound took them left each slow impact at e |v0| + e g dt, more than it struck
        // at for e close to 1 (the energy guard then kept it bouncing for ever at the
        // height where the two meet: 8 cm at e = 0.95, 120 Hz).
        let rebound = self.rebounds(&frictional, &w, || jacobian * s.qd);
        let solved = if rebound.iter().any(|&r| r > T::zero()) {
            let bounce = target.zip_map(&rebound, |t, r| t.max(r));
            let bounced = solve(
                normal,
                &bounce,
                &plastic.impulses,
                &plastic.active,
                left(taken),
            )?;
            taken += bounced.rounds;
            Solved {
                settled: plastic.settled && bounced.settled,
                ..bounced
            }
        } else {
            plastic
        };
        let shift = (plastic.velocity - free.qd) * share;
        let (dq, corrected) = self.drift(normal, jacobian, reach, &kinds, jump, &mut left_out)?;
        let (q, drift_rounds, held_back) = self.settle(
            normal,
            jacobian,
            &kinds,
            jump,
            ended,
            &s.q,
            free.q + shift + dq,
            &mut left_out,
        )?;
        let end = State {
            t: free.t,
            q,
            qd: solved.velocity,
        };
        let (end, energy, guarded) = guard(mechanism, s, start_energy, &free, end, dt)?;
        let count = |rows: &[bool; C]| {
            u32::try_from(rows.iter().filter(|&&r| r).count()).unwrap_or(u32::MAX)
        };
        let report = ImpulseReport {
            rows: count(normal.candidates()),
            speculative,
            left_out: count(&left_out),
            frictional: count(&core::array::from_fn(|i| tangent[i].is_some())),
            rounds: taken,
            settled: solved.settled,
            corrected: corrected || drift_rounds > 0,
            drift_rounds,
            held_back,
            energy_guard: guarded,
        };
        let pushed =
            core::array::from_fn(|i| self.bilateral[i] || solved.impulses.normal[i] > T::zero());
        memory.record(solved.impulses, end, energy, pushed, report);
        let filled = Filled {
            q: reuse.at,
            mass_known: reuse.mass_known,
            rows_too,
            gaps,
            tangents,
        };
        work.keep(filled, &touching);
        Ok(end)
    }
}
