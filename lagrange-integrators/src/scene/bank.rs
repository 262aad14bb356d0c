//! [`Bank`]: up to `K` instances of one mechanism type, stepped by one kind of integrator,
//! with the awake instances packed in front.

use super::awake::Awake;
use super::slot::Slot;
use super::states::States;
use super::{Layout, NeverSleeps, OneByOne, Sleep, Sleeps};
use crate::Integrator;
use heapless::Vec;
use lagrange_core::nalgebra::SVector;
use lagrange_core::{all_finite, Controlled, Error, Mechanism, Real, State};

/// A handle to an instance of a [`Bank`], given by [`Bank::add`]. It stays valid until the
/// instance is removed; after that it names nothing ([`Error::NoSuchInstance`]), even when
/// its index has been given to a new instance. Nor does it name anything in another bank
/// (each bank made by [`Bank::new`] has a key of its own, where the target has 32-bit
/// atomics; a clone of a bank keeps the key, and its handles name the clone's copies).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Id {
    index: u32,
    generation: u32,
    bank: u32,
}

/// The key of the next bank made.
#[cfg(target_has_atomic = "32")]
static NEXT_BANK: core::sync::atomic::AtomicU32 = core::sync::atomic::AtomicU32::new(0);

/// A key for a new bank: distinct from those of the last 2^32 banks made (0 for all of them
/// on a target without 32-bit atomics, where handles then carry no bank).
fn bank_key() -> u32 {
    #[cfg(target_has_atomic = "32")]
    {
        NEXT_BANK.fetch_add(1, core::sync::atomic::Ordering::Relaxed)
    }
    #[cfg(not(target_has_atomic = "32"))]
    {
        0
    }
}

impl Id {
    /// Its index, below the bank's capacity: unique among the instances in the bank at one
    /// time, for tables of your own kept beside the bank (meshes, sounds).
    #[must_use]
    pub fn index(&self) -> usize {
        self.index as usize
    }
}

/// Where an instance of a [`Bank`] stands.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Status {
    /// Stepped every step.
    Awake,
    /// At rest and not stepped ([`Sleeps`](super::Sleeps)) until something wakes it.
    Asleep,
    /// Its last step failed with this error (a step past the stability limit, a singular
    /// configuration): it keeps its last good state and is not stepped until something
    /// wakes it (a state written, an impulse, a new input or parameters, an explicit wake),
    /// which retries.
    Failed(Error),
}

/// Energies of an instance, computed when asked ([`Bank::energies`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Energies<T> {
    /// Kinetic energy `T`, J.
    pub kinetic: T,
    /// Potential energy `V`, J.
    pub potential: T,
}

impl<T: Real> Energies<T> {
    /// `T + V`, J.
    #[must_use]
    pub fn total(&self) -> T {
        self.kinetic + self.potential
    }
}

/// What a bank knows of one id index: where its instance is and which generation of the
/// index is live. All zeros for an index never given out, so that a bank's table starts
/// cleared.
#[derive(Debug, Clone, Copy, Default)]
struct Entry {
    /// The instance's place in the bank's slots plus one, or 0 when the index is free.
    place: u32,
    /// The generation of the id now (or next) given out for this index.
    generation: u32,
}

/// Up to `K` instances of the mechanism type `M`, each with its own parameters and input
/// (its own value of `M`), its own state and its own copy of the integrator `I` (made from
/// the bank's, so that what a method keeps between steps is per instance), stepped
/// together by a [`Scene`](super::Scene). `Z` chooses sleeping: [`NeverSleeps`] (the
/// default) or [`Sleeps`]. `Y` chooses the layout: [`OneByOne`] (the default, any mechanism)
/// or [`InLanes`](super::InLanes) (a mechanism that gathers, stepped [`LANES`](super::LANES)
/// instances at a time where the target has a vector unit, each with the bits it has alone).
///
/// ```text
/// slots:  [ awake ........ | asleep or failed ...... | free ]
///           stepped every step, in slot order         nothing touches them
/// ```
///
/// The awake instances are packed at the front, so that a step is one tight loop over them
/// and an asleep instance costs nothing but its memory. The states are kept apart from the
/// rest (in a bank in lanes as structure of arrays: an array of times, one per coordinate, one
/// per velocity, so that a group of instances is one window of each); they are therefore read
/// and written by value ([`Bank::state`], [`Bank::set_state`]). Falling asleep and
/// waking swap an instance across the boundary (its [`Id`] follows it); the order of the
/// instances within the array therefore depends on their history, but no instance's bits
/// depend on it: instances do not interact, and each has its own integrator.
///
/// Per instance: read its state ([`Bank::state`]) or the state to draw
/// ([`Bank::interpolated`]); write its state ([`Bank::set_state`]); apply an impulse
/// ([`Bank::apply_impulse`]); set its input ([`Bank::set_input`]) or change its parameters
/// ([`Bank::modify`]); wake it ([`Bank::wake`], [`Bank::contact`]); read its energies
/// ([`Bank::energies`]) and status ([`Bank::status`]).
///
/// What wakes a sleeper: a state written, an impulse, an input that differs from the one it
/// slept with, a change of parameters, an explicit wake, a contact event. Every one of them
/// also restarts its integrator from the bank's, so that from then on its trajectory is,
/// bit for bit, that of a fresh run from the state it woke with.
///
/// Time: the instances share the bank's clock. A step lands every awake instance at the
/// scene's time; a state written or an instance added takes the bank's time; a sleeper
/// keeps the time it fell asleep at, and takes the bank's time when it wakes.
///
/// ```
/// use lagrange_integrators::prelude::*;
/// use lagrange_integrators::scene::{Bank, Scene, Sleeps, Status};
/// use lagrange_systems::SimplePendulum;
///
/// // Two damped pendulums at 120 Hz; they sleep once at rest for half a second.
/// let rule = Sleeps::new(1e-6_f32, 1e-3, 60)?;
/// let mut bank: Bank<f32, 1, 2, SimplePendulum<f32>, StormerVerlet<f32, 1>, Sleeps<f32>> =
///     Bank::new(StormerVerlet::default(), rule)?;
/// let damped = SimplePendulum::new(1.0, 1.0, 9.81, 1.0)?;
/// let swinging = bank.add(damped, State::at_rest([0.5]))?;
/// let resting = bank.add(damped, State::at_rest([0.0]))?;
/// let mut scene = Scene::new(bank, 1.0 / 120.0, 4)?;
/// for _ in 0..120 {
///     scene.advance(1.0 / 120.0)?; // one second of frames, one step each
/// }
/// let bank = scene.banks();
/// assert_eq!(bank.status(resting)?, Status::Asleep);
/// assert_eq!(bank.status(swinging)?, Status::Awake);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Bank<
    T: Real,
    const N: usize,
    const K: usize,
    M,
    I,
    Z = NeverSleeps,
    Y: Layout<T, N, K, M> = OneByOne,
> {
    integrator: I,
    sleep: Z,
    /// By place.
    slots: Vec<Slot<M, I>, K>,
    /// Each place's state after the last step.
    current: Y::States,
    /// Each place's state before the last step (what [`Bank::interpolated`] draws from).
    previous: Y::States,
    /// What the layout keeps of the mechanisms.
    kept: Y::Kept,
    awake: usize,
    /// By id index.
    entries: [Entry; K],
    /// Id indices given back by removed instances, to give out again.
    free: Vec<u32, K>,
    /// Id indices never given out yet: `fresh..K`.
    fresh: u32,
    time: T,
    steps: u64,
    /// The key its handles carry.
    key: u32,
}

impl<T, const N: usize, const K: usize, M, I, Z, Y> Bank<T, N, K, M, I, Z, Y>
where
    T: Real,
    M: Mechanism<T, N>,
    I: Integrator<T, N, M> + Clone,
    Z: Sleep<T>,
    Y: Layout<T, N, K, M>,
{
    /// An empty bank of capacity `K` (at least 1) whose instances are stepped by copies of
    /// `integrator`, and fall asleep by `sleep`, at time 0.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `K` when zero or above `u32::MAX - 1`.
    #[inline(always)] // built in place in the caller: a bank is large, and moving it costs a copy
    pub fn new(integrator: I, sleep: Z) -> Result<Self, Error> {
        if K == 0 || K >= u32::MAX as usize {
            return Err(Error::InvalidParameter {
                name: "K",
                reason: "a bank holds at least 1 and fewer than u32::MAX instances",
            });
        }
        Ok(Self {
            integrator,
            sleep,
            slots: Vec::new(),
            current: States::new(),
            previous: States::new(),
            kept: Y::kept(),
            awake: 0,
            entries: [Entry::default(); K],
            free: Vec::new(),
            fresh: 0,
            time: T::zero(),
            steps: 0,
            key: bank_key(),
        })
    }

    /// Adds an instance of `mechanism` starting from `state` (finite; its time becomes the
    /// bank's), awake.
    ///
    /// # Errors
    /// [`Error::NonFiniteState`] for a non-finite `state`; [`Error::BankFull`] when the bank
    /// holds `K` instances. The bank is then unchanged.
    pub fn add(&mut self, mechanism: M, state: State<T, N>) -> Result<Id, Error> {
        state.check_finite()?;
        let full = Error::BankFull { capacity: K };
        let index = match self.free.last() {
            Some(&index) => index,
            None if (self.fresh as usize) < K => self.fresh,
            None => return Err(full),
        };
        let place = self.slots.len();
        let stored = u32::try_from(place + 1).map_err(|_| full)?;
        let slot = Slot {
            mechanism,
            integrator: self.integrator.clone(),
            id: index,
            quiet: 0,
            failure: None,
        };
        let entry = self.entries.get_mut(index as usize).ok_or(full)?;
        if self.slots.push(slot).is_err() {
            return Err(full);
        }
        let state = State {
            t: self.time,
            ..state
        };
        self.current.set(place, &state);
        self.previous.set(place, &state);
        entry.place = stored;
        let generation = entry.generation;
        if self.free.pop().is_none() {
            self.fresh += 1;
        }
        self.keep(place);
        self.rouse(place);
        Ok(Id {
            index,
            generation,
            bank: self.key,
        })
    }

    /// Removes an instance, returning its mechanism and state. Its [`Id`] then names nothing.
    ///
    /// # Errors
    /// [`Error::NoSuchInstance`].
    pub fn remove(&mut self, id: Id) -> Result<(M, State<T, N>), Error> {
        let mut place = self.place(id)?;
        if place < self.awake {
            self.awake -= 1;
            self.swap(place, self.awake);
            place = self.awake;
        }
        // The last slot takes the place of the one removed.
        let last = self.slots.len().saturating_sub(1);
        self.swap(place, last);
        let state = self.current.get(last);
        let slot = self.slots.pop().ok_or(Error::NoSuchInstance)?;
        if let Some(entry) = self.entries.get_mut(id.index as usize) {
            *entry = Entry {
                place: 0,
                generation: entry.generation.wrapping_add(1),
            };
        }
        // The index was taken from `free` or `fresh`, so there is room to give it back.
        let _ = self.free.push(id.index);
        Ok((slot.mechanism, state))
    }

    /// The instance's state after the last step (a copy: the bank keeps its states as
    /// structure of arrays).
    ///
    /// # Errors
    /// [`Error::NoSuchInstance`].
    pub fn state(&self, id: Id) -> Result<State<T, N>, Error> {
        Ok(self.current.get(self.place(id)?))
    }

    /// The state to draw: linear interpolation between the instance's last two states by
    /// `alpha` (the scene's [`Scene::alpha`](super::Scene::alpha), in `[0, 1]`), as
    /// [`FixedTimestep::interpolated`](crate::FixedTimestep::interpolated) does. A sleeper is
    /// drawn where it rests.
    ///
    /// # Errors
    /// [`Error::NoSuchInstance`]; [`Error::InvalidParameter`] `alpha` outside `[0, 1]`.
    pub fn interpolated(&self, id: Id, alpha: T) -> Result<State<T, N>, Error> {
        let place = self.place(id)?;
        if !(alpha >= T::zero() && alpha <= T::one()) {
            return Err(Error::InvalidParameter {
                name: "alpha",
                reason: "must be in [0, 1]",
            });
        }
        let (p, c) = (self.previous.get(place), self.current.get(place));
        Ok(State {
            t: c.t + (alpha - T::one()) * (c.t - p.t),
            q: p.q + (c.q - p.q) * alpha,
            qd: p.qd + (c.qd - p.qd) * alpha,
        })
    }

    /// The instance's mechanism: its parameters and input.
    ///
    /// # Errors
    /// [`Error::NoSuchInstance`].
    pub fn mechanism(&self, id: Id) -> Result<&M, Error> {
        Ok(&self.slot(id)?.mechanism)
    }

    /// The instance's integrator, to read what it keeps of its steps (an
    /// [`ImpulseStepper`](crate::ImpulseStepper)'s report of its work).
    ///
    /// # Errors
    /// [`Error::NoSuchInstance`].
    pub fn integrator(&self, id: Id) -> Result<&I, Error> {
        Ok(&self.slot(id)?.integrator)
    }

    /// Awake, asleep, or failed.
    ///
    /// # Errors
    /// [`Error::NoSuchInstance`].
    pub fn status(&self, id: Id) -> Result<Status, Error> {
        let place = self.place(id)?;
        let slot = self.slots.get(place).ok_or(Error::NoSuchInstance)?;
        Ok(match slot.failure {
            _ if place < self.awake => Status::Awake,
            Some(e) => Status::Failed(e),
            None => Status::Asleep,
        })
    }

    /// Kinetic and potential energy of the instance's state (computed now, never inside a
    /// step). Finite or an error: a state may be finite and its energy not (a speed of
    /// `1e200` m/s squared).
    ///
    /// # Errors
    /// [`Error::NoSuchInstance`]; [`Error::NonFiniteState`] when either energy, or their sum
    /// ([`Energies::total`]), is not finite.
    pub fn energies(&self, id: Id) -> Result<Energies<T>, Error> {
        let (mechanism, state) = (&self.slot(id)?.mechanism, self.state(id)?);
        let energies = Energies {
            kinetic: mechanism.kinetic_energy(&state),
            potential: mechanism.potential_energy(&state),
        };
        if energies.total().is_finite() {
            Ok(energies)
        } else {
            Err(Error::NonFiniteState)
        }
    }

    /// Writes the instance's state (finite; its time becomes the bank's) and wakes it, with
    /// a fresh integrator. It is drawn at the new state at once (no interpolation from the
    /// old one).
    ///
    /// # Errors
    /// [`Error::NoSuchInstance`]; [`Error::NonFiniteState`] (nothing changes).
    pub fn set_state(&mut self, id: Id, state: State<T, N>) -> Result<(), Error> {
        let place = self.place(id)?;
        state.check_finite()?;
        self.current.set(place, &state);
        self.previous.set(place, &state);
        // Its time becomes the bank's here.
        self.restart(place)
    }

    /// Applies a generalized impulse (N s on a length, N m s on an angle; finite) to the
    /// instance: its velocities jump by [`Mechanism::velocity_jump`] (a constrained
    /// mechanism keeps its constraints), and it wakes with a fresh integrator.
    ///
    /// # Errors
    /// [`Error::NoSuchInstance`]; [`Error::InvalidParameter`] `impulse` when not finite;
    /// the mechanism's errors (a singular mass matrix), and [`Error::NonFiniteState`] when
    /// the new velocities are not finite. Nothing changes on an error.
    pub fn apply_impulse(&mut self, id: Id, impulse: &SVector<T, N>) -> Result<(), Error> {
        let place = self.place(id)?;
        if !all_finite(impulse.as_slice()) {
            return Err(Error::InvalidParameter {
                name: "impulse",
                reason: "must be finite",
            });
        }
        let mut state = self.current.get(place);
        let mechanism = &self
            .slots
            .get(place)
            .ok_or(Error::NoSuchInstance)?
            .mechanism;
        let qd = state.qd + mechanism.velocity_jump(&state, impulse)?;
        if !all_finite(qd.as_slice()) {
            return Err(Error::NonFiniteState);
        }
        state.qd = qd;
        self.current.set(place, &state);
        self.restart(place)
    }

    /// Sets the instance's input ([`Controlled`]). An input equal to the one in force
    /// changes nothing, and does not wake a sleeper; any other wakes it.
    ///
    /// # Errors
    /// [`Error::NoSuchInstance`]; the mechanism's refusal of the value (nothing changes).
    pub fn set_input(&mut self, id: Id, input: M::Input) -> Result<(), Error>
    where
        M: Controlled<T>,
    {
        let place = self.place(id)?;
        let mechanism = &mut self.at_mut(place)?.mechanism;
        if mechanism.input() == input {
            return Ok(());
        }
        mechanism.set_input(input)?;
        self.keep(place);
        self.restart(place)
    }

    /// Changes the instance's mechanism (its parameters, its input) by `change`, which may
    /// refuse with an error. A change that leaves the mechanism equal to what it was does
    /// not wake a sleeper; any other wakes it.
    ///
    /// ```
    /// # use lagrange_integrators::prelude::*;
    /// # use lagrange_integrators::scene::Bank;
    /// # use lagrange_systems::CartPole;
    /// let mut bank: Bank<f64, 2, 4, CartPole<f64>, Rk4> = Bank::new(Rk4, Default::default())?;
    /// let cart = bank.add(CartPole::new(1.0, 0.1, 0.5, 9.8)?, State::at_rest([0.0, 0.1]))?;
    /// bank.modify(cart, |c| c.set_force(2.0))?;
    /// assert_eq!(bank.mechanism(cart)?.force(), 2.0);
    /// // A refused change changes nothing.
    /// assert!(bank.modify(cart, |c| c.set_force(f64::NAN)).is_err());
    /// assert_eq!(bank.mechanism(cart)?.force(), 2.0);
    /// # Ok::<(), lagrange_core::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::NoSuchInstance`]; whatever `change` returns (nothing changes).
    pub fn modify<R>(
        &mut self,
        id: Id,
        change: impl FnOnce(&mut M) -> Result<R, Error>,
    ) -> Result<R, Error>
    where
        M: Clone + PartialEq,
    {
        let place = self.place(id)?;
        let mechanism = &mut self.at_mut(place)?.mechanism;
        let mut changed = mechanism.clone();
        let result = change(&mut changed)?;
        if changed != *mechanism {
            *mechanism = changed;
            self.keep(place);
            self.restart(place)?;
        }
        Ok(result)
    }

    /// Wakes the instance (an asleep or failed one; an awake one is left as it is).
    ///
    /// # Errors
    /// [`Error::NoSuchInstance`].
    pub fn wake(&mut self, id: Id) -> Result<(), Error> {
        let place = self.place(id)?;
        if place >= self.awake {
            self.restart(place)?;
        }
        Ok(())
    }

    /// A contact event from outside the bank (a body of the game touched this instance, a
    /// trigger fired): wakes it, as [`Bank::wake`]. Contacts inside the instance's own law
    /// (a [`ContactStepper`](crate::ContactStepper)'s floor) need no event.
    ///
    /// # Errors
    /// [`Error::NoSuchInstance`].
    pub fn contact(&mut self, id: Id) -> Result<(), Error> {
        self.wake(id)
    }

    /// The instances in the bank, awake ones first, with their states (copies, as
    /// [`Bank::state`]).
    pub fn iter(&self) -> impl Iterator<Item = (Id, State<T, N>)> + '_ {
        self.slots.iter().enumerate().map(|(place, slot)| {
            let index = slot.id;
            let generation = self.entries.get(index as usize).map_or(0, |e| e.generation);
            let id = Id {
                index,
                generation,
                bank: self.key,
            };
            (id, self.current.get(place))
        })
    }

    /// Instances in the bank.
    #[must_use]
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    /// True when the bank holds no instance.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// Instances awake (stepped every step).
    #[must_use]
    pub fn awake(&self) -> usize {
        self.awake
    }

    /// The bank's time: the time of its last step.
    #[must_use]
    pub fn time(&self) -> T {
        self.time
    }

    /// The sleep rule.
    #[must_use]
    pub fn sleep(&self) -> &Z {
        &self.sleep
    }

    /// Steps every awake instance by `dt`, landing at time `t`, in place order; then, every
    /// [`Sleeps::interval`] steps where the bank sleeps, checks the awake instances for
    /// rest. Returns how many instances failed this step (they keep their last good state
    /// and are set aside: [`Status::Failed`]).
    pub(crate) fn step(&mut self, dt: T, t: T) -> u32 {
        self.time = t;
        let awake = Awake {
            slots: self.slots.get_mut(..self.awake).unwrap_or_default(),
            current: &mut self.current,
            previous: &mut self.previous,
            states: core::marker::PhantomData,
        };
        let failed = Y::step(&self.kept, awake, dt, t);
        if failed > 0 {
            self.set_aside_failures();
        }
        if let Some(rule) = self.sleep.rule() {
            let interval = u64::from(rule.interval());
            self.steps += 1;
            if self.steps.checked_rem(interval) == Some(0) {
                self.settle();
            }
        }
        failed
    }

    /// Sets the bank's time, and every instance's, to `t` (a scene's start).
    pub(crate) fn set_time(&mut self, t: T) {
        self.time = t;
        for place in 0..self.slots.len() {
            self.current.set_time(place, t);
            self.previous.set_time(place, t);
        }
    }

    /// Moves the awake instances whose step failed out of the awake region.
    #[cold]
    #[inline(never)]
    fn set_aside_failures(&mut self) {
        let mut place = self.awake;
        while place > 0 {
            place -= 1;
            let Some(slot) = self.slots.get_mut(place) else {
                continue;
            };
            if slot.failure.is_some() {
                slot.quiet = 0;
                self.previous.set(place, &self.current.get(place));
                self.awake -= 1;
                self.swap(place, self.awake);
            }
        }
    }

    /// The rest check of the awake instances (from the back, so that one put to sleep is
    /// replaced by one already checked). Out of line: it runs one step in `interval`, and
    /// inlined it would crowd the step loop.
    #[inline(never)]
    fn settle(&mut self) {
        let Some(rule) = self.sleep.rule().copied() else {
            return;
        };
        let (interval, steps) = (rule.interval(), rule.steps());
        let mut place = self.awake;
        while place > 0 {
            place -= 1;
            let Some(slot) = self.slots.get_mut(place) else {
                continue;
            };
            let state = self.current.get(place);
            if !rule.rests(&slot.mechanism, &slot.integrator, &state) {
                slot.quiet = 0;
                continue;
            }
            slot.quiet = if slot.quiet == 0 {
                1
            } else {
                slot.quiet.saturating_add(interval)
            };
            if slot.quiet > steps {
                slot.quiet = 0;
                let still = State {
                    qd: SVector::zeros(),
                    ..state
                };
                self.current.set(place, &still);
                self.previous.set(place, &still);
                self.awake -= 1;
                self.swap(place, self.awake);
            }
        }
    }

    /// Puts the instance at `place` among the awake (if it is not), with a fresh copy of the
    /// bank's integrator, at the bank's time, cleared of any failure.
    fn restart(&mut self, place: usize) -> Result<(), Error> {
        let (time, integrator) = (self.time, self.integrator.clone());
        let slot = self.at_mut(place)?;
        slot.integrator = integrator;
        slot.quiet = 0;
        slot.failure = None;
        self.current.set_time(place, time);
        self.previous.set_time(place, time);
        self.rouse(place);
        Ok(())
    }

    /// Moves the instance at `place` into the awake region when it is outside it.
    fn rouse(&mut self, place: usize) {
        if place >= self.awake && place < self.slots.len() {
            self.swap(place, self.awake);
            self.awake += 1;
        }
    }

    /// Swaps two places, keeping the entries in step.
    fn swap(&mut self, a: usize, b: usize) {
        let (low, high) = (a.min(b), a.max(b));
        // Two disjoint borrows and a plain swap: `slice::swap` pulls in `memmove` on targets
        // without it in hardware, which alone outweighs a bank's code.
        let Some((front, back)) = self.slots.split_at_mut_checked(high) else {
            return;
        };
        let (Some(x), Some(y)) = (front.get_mut(low), back.first_mut()) else {
            return;
        };
        core::mem::swap(x, y);
        for (slot, place) in [(x, low), (y, high)] {
            if let Some(entry) = self.entries.get_mut(slot.id as usize) {
                entry.place = u32::try_from(place + 1).unwrap_or(0);
            }
            Y::put(&mut self.kept, place, &slot.mechanism);
        }
        self.current.swap(low, high);
        self.previous.swap(low, high);
    }

    /// The place of the instance `id` names.
    fn place(&self, id: Id) -> Result<usize, Error> {
        match self.entries.get(id.index as usize) {
            Some(e) if e.place != 0 && e.generation == id.generation && id.bank == self.key => {
                Ok(e.place as usize - 1)
            }
            _ => Err(Error::NoSuchInstance),
        }
    }

    /// Writes the mechanism at `place` into what the layout keeps of it.
    fn keep(&mut self, place: usize) {
        if let Some(slot) = self.slots.get(place) {
            Y::put(&mut self.kept, place, &slot.mechanism);
        }
    }

    /// The slot of the instance `id` names.
    fn slot(&self, id: Id) -> Result<&Slot<M, I>, Error> {
        self.slots.get(self.place(id)?).ok_or(Error::NoSuchInstance)
    }

    /// The slot at `place`.
    fn at_mut(&mut self, place: usize) -> Result<&mut Slot<M, I>, Error> {
        self.slots.get_mut(place).ok_or(Error::NoSuchInstance)
    }
}

impl<T, const N: usize, const K: usize, M, I, Y> Bank<T, N, K, M, I, Sleeps<T>, Y>
where
    T: Real,
    M: Mechanism<T, N>,
    I: Integrator<T, N, M> + Clone,
    Y: Layout<T, N, K, M>,
{
    /// Adds an instance already at rest, asleep: at `q` with zero velocities (a prop placed
    /// in a level). It costs nothing until something wakes it.
    ///
    /// # Errors
    /// As [`Bank::add`].
    pub fn add_asleep(&mut self, mechanism: M, q: [T; N]) -> Result<Id, Error> {
        let id = self.add(mechanism, State::at_rest(q))?;
        let place = self.place(id)?;
        self.awake -= 1;
        self.swap(place, self.awake);
        Ok(id)
    }
}

impl<T: Real, const N: usize, const K: usize, M, I, Z, Y: Layout<T, N, K, M>>
    Bank<T, N, K, M, I, Z, Y>
{
    /// The bank's capacity, `K`.
    #[must_use]
    pub const fn capacity(&self) -> usize {
        K
    }
}
