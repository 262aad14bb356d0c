//! [`Bank`]: up to `K` instances of one mechanism type, stepped by one kind of integrator,
//! with the awake instances packed in front.

use super::{NeverSleeps, Sleep, Sleeps};
use crate::Integrator;
use heapless::Vec;
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Controlled, Error, Mechanism, Real, State};

/// A handle to an instance of a [`Bank`], given by [`Bank::add`]. It stays valid until the
/// instance is removed; after that, and in any other bank, it names nothing
/// ([`Error::NoSuchInstance`]), even when its slot has been given to a new instance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Id {
    index: u32,
    generation: u32,
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

/// One instance: its mechanism (parameters and input), its integrator (and what that keeps
/// between steps), its last two states.
#[derive(Debug, Clone)]
struct Slot<T: Real, const N: usize, M, I> {
    mechanism: M,
    integrator: I,
    current: State<T, N>,
    previous: State<T, N>,
    /// Its [`Id::index`].
    id: u32,
    /// 0 while not found at rest; else 1 + the steps spanned by its consecutive checks at
    /// rest.
    quiet: u32,
}

impl<T: Real, const N: usize, M: Mechanism<T, N>, I: Integrator<T, N, M>> Slot<T, N, M, I> {
    /// One step of `dt`, landing at the scene's time `t`; the error when the step failed
    /// (the state is then untouched).
    #[inline(always)]
    fn advance(&mut self, dt: T, t: T) -> Option<Error> {
        match self.integrator.step(&self.mechanism, &self.current, dt) {
            Ok(mut next) => {
                next.t = t;
                self.previous = self.current;
                self.current = next;
                None
            }
            Err(e) => Some(e),
        }
    }
}

/// Marks an index with no instance in [`Bank`]'s table of places.
const VACANT: u32 = u32::MAX;

/// Up to `K` instances of the mechanism type `M`, each with its own parameters and input
/// (its own value of `M`), its own state and its own copy of the integrator `I` (made from
/// the bank's, so that what a method keeps between steps is per instance), stepped
/// together by a [`Scene`](super::Scene). `Z` chooses sleeping: [`NeverSleeps`] (the
/// default) or [`Sleeps`](super::Sleeps).
///
/// ```text
/// slots:  [ awake ........ | asleep or failed ...... | free ]
///           stepped every step, in slot order         nothing touches them
/// ```
///
/// The awake instances are packed at the front of one array, so that a step is one tight
/// loop over them and an asleep instance costs nothing but its memory. Falling asleep and
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
pub struct Bank<T: Real, const N: usize, const K: usize, M, I, Z = NeverSleeps> {
    integrator: I,
    sleep: Z,
    slots: Vec<Slot<T, N, M, I>, K>,
    awake: usize,
    /// By id index: the instance's place in `slots`, or [`VACANT`].
    places: [u32; K],
    /// By id index: the generation of the id now (or next) given out.
    generations: [u32; K],
    /// By id index: why the instance's last step failed.
    failures: [Option<Error>; K],
    /// Id indices free to give out.
    free: Vec<u32, K>,
    time: T,
    steps: u64,
}

impl<T, const N: usize, const K: usize, M, I, Z> Bank<T, N, K, M, I, Z>
where
    T: Real,
    M: Mechanism<T, N>,
    I: Integrator<T, N, M> + Clone,
    Z: Sleep<T>,
{
    /// An empty bank of capacity `K` (at least 1) whose instances are stepped by copies of
    /// `integrator`, and fall asleep by `sleep`, at time 0.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `K` when zero or above `u32::MAX - 1`.
    pub fn new(integrator: I, sleep: Z) -> Result<Self, Error> {
        if K == 0 || K >= VACANT as usize {
            return Err(Error::InvalidParameter {
                name: "K",
                reason: "a bank holds at least 1 and fewer than u32::MAX instances",
            });
        }
        let mut free = Vec::new();
        for index in (0..K).rev() {
            // K indices fit in a Vec of capacity K, and in u32 (checked above).
            let _ = free.push(u32::try_from(index).unwrap_or(VACANT));
        }
        Ok(Self {
            integrator,
            sleep,
            slots: Vec::new(),
            awake: 0,
            places: [VACANT; K],
            generations: [0; K],
            failures: [None; K],
            free,
            time: T::zero(),
            steps: 0,
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
        let Some(&index) = self.free.last() else {
            return Err(Error::BankFull { capacity: K });
        };
        let current = State {
            t: self.time,
            ..state
        };
        let slot = Slot {
            mechanism,
            integrator: self.integrator.clone(),
            current,
            previous: current,
            id: index,
            quiet: 0,
        };
        if self.slots.push(slot).is_err() {
            return Err(Error::BankFull { capacity: K });
        }
        self.free.pop();
        let i = index as usize;
        self.places[i] = self.last_place();
        self.failures[i] = None;
        self.rouse(self.slots.len() - 1);
        Ok(Id {
            index,
            generation: self.generations[i],
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
        let slot = self.slots.swap_remove(place);
        if place < self.slots.len() {
            let moved = self.slots[place].id as usize;
            self.places[moved] = u32::try_from(place).unwrap_or(VACANT);
        }
        let i = id.index as usize;
        self.places[i] = VACANT;
        self.failures[i] = None;
        self.generations[i] = self.generations[i].wrapping_add(1);
        // The index was taken from `free`, so there is room to give it back.
        let _ = self.free.push(id.index);
        Ok((slot.mechanism, slot.current))
    }

    /// The instance's state after the last step.
    ///
    /// # Errors
    /// [`Error::NoSuchInstance`].
    pub fn state(&self, id: Id) -> Result<&State<T, N>, Error> {
        Ok(&self.slots[self.place(id)?].current)
    }

    /// The state to draw: linear interpolation between the instance's last two states by
    /// `alpha` (the scene's [`Scene::alpha`](super::Scene::alpha), in `[0, 1]`), as
    /// [`FixedTimestep::interpolated`](crate::FixedTimestep::interpolated) does. A sleeper is
    /// drawn where it rests.
    ///
    /// # Errors
    /// [`Error::NoSuchInstance`]; [`Error::InvalidParameter`] `alpha` outside `[0, 1]`.
    pub fn interpolated(&self, id: Id, alpha: T) -> Result<State<T, N>, Error> {
        let slot = &self.slots[self.place(id)?];
        if !(alpha >= T::zero() && alpha <= T::one()) {
            return Err(Error::InvalidParameter {
                name: "alpha",
                reason: "must be in [0, 1]",
            });
        }
        let (p, c) = (&slot.previous, &slot.current);
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
        Ok(&self.slots[self.place(id)?].mechanism)
    }

    /// Awake, asleep, or failed.
    ///
    /// # Errors
    /// [`Error::NoSuchInstance`].
    pub fn status(&self, id: Id) -> Result<Status, Error> {
        let place = self.place(id)?;
        Ok(if place < self.awake {
            Status::Awake
        } else if let Some(e) = self.failures[id.index as usize] {
            Status::Failed(e)
        } else {
            Status::Asleep
        })
    }

    /// Kinetic and potential energy of the instance's state (computed now, never inside a
    /// step).
    ///
    /// # Errors
    /// [`Error::NoSuchInstance`].
    pub fn energies(&self, id: Id) -> Result<Energies<T>, Error> {
        let slot = &self.slots[self.place(id)?];
        Ok(Energies {
            kinetic: slot.mechanism.kinetic_energy(&slot.current),
            potential: slot.mechanism.potential_energy(&slot.current),
        })
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
        let slot = &mut self.slots[place];
        slot.current = State {
            t: self.time,
            ..state
        };
        slot.previous = slot.current;
        self.restart(place);
        Ok(())
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
        if !impulse.iter().all(|x| x.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "impulse",
                reason: "must be finite",
            });
        }
        let slot = &mut self.slots[place];
        let qd = slot.current.qd + slot.mechanism.velocity_jump(&slot.current, impulse)?;
        if !qd.iter().all(|x| x.is_finite()) {
            return Err(Error::NonFiniteState);
        }
        slot.current.qd = qd;
        slot.current.t = self.time;
        slot.previous.t = self.time;
        self.restart(place);
        Ok(())
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
        let mechanism = &mut self.slots[place].mechanism;
        if mechanism.input() == input {
            return Ok(());
        }
        mechanism.set_input(input)?;
        self.restart(place);
        Ok(())
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
        let mut changed = self.slots[place].mechanism.clone();
        let result = change(&mut changed)?;
        if changed != self.slots[place].mechanism {
            self.slots[place].mechanism = changed;
            self.restart(place);
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
            self.restart(place);
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

    /// The instances in the bank, awake ones first, with their states.
    pub fn iter(&self) -> impl Iterator<Item = (Id, &State<T, N>)> + '_ {
        self.slots.iter().map(|slot| {
            let index = slot.id;
            let id = Id {
                index,
                generation: self.generations[index as usize],
            };
            (id, &slot.current)
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
    /// [`Sleeps::interval`](super::Sleeps::interval) steps where the bank sleeps, checks the
    /// awake instances for rest. Returns how many instances failed this step (they keep
    /// their last good state and are set aside: [`Status::Failed`]).
    pub(crate) fn step(&mut self, dt: T, t: T) -> u32 {
        self.time = t;
        let mut failed = 0;
        for slot in &mut self.slots[..self.awake] {
            if let Some(e) = slot.advance(dt, t) {
                self.failures[slot.id as usize] = Some(e);
                failed += 1;
            }
        }
        if failed > 0 {
            self.set_aside_failures();
        }
        if let Some(rule) = self.sleep.rule() {
            let interval = u64::from(rule.interval());
            self.steps += 1;
            if self.steps % interval == 0 {
                self.settle();
            }
        }
        failed
    }

    /// Sets the bank's time, and every instance's, to `t` (a scene's start).
    pub(crate) fn set_time(&mut self, t: T) {
        self.time = t;
        for slot in &mut self.slots {
            slot.current.t = t;
            slot.previous.t = t;
        }
    }

    /// Moves the awake instances whose step failed out of the awake region.
    #[cold]
    #[inline(never)]
    fn set_aside_failures(&mut self) {
        let mut place = self.awake;
        while place > 0 {
            place -= 1;
            let slot = &mut self.slots[place];
            if self.failures[slot.id as usize].is_some() {
                slot.previous = slot.current;
                slot.quiet = 0;
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
            let slot = &mut self.slots[place];
            if !rule.rests(&slot.mechanism, &slot.integrator, &slot.current) {
                slot.quiet = 0;
                continue;
            }
            slot.quiet = if slot.quiet == 0 {
                1
            } else {
                slot.quiet.saturating_add(interval)
            };
            if slot.quiet > steps {
                slot.current.qd = SVector::zeros();
                slot.previous = slot.current;
                slot.quiet = 0;
                self.awake -= 1;
                self.swap(place, self.awake);
            }
        }
    }

    /// Puts the instance at `place` among the awake (if it is not), with a fresh copy of the
    /// bank's integrator, at the bank's time, cleared of any failure.
    fn restart(&mut self, place: usize) {
        let slot = &mut self.slots[place];
        slot.integrator = self.integrator.clone();
        slot.quiet = 0;
        slot.current.t = self.time;
        slot.previous.t = self.time;
        self.failures[slot.id as usize] = None;
        self.rouse(place);
    }

    /// Moves the instance at `place` into the awake region when it is outside it.
    fn rouse(&mut self, place: usize) {
        if place >= self.awake {
            self.swap(place, self.awake);
            self.awake += 1;
        }
    }

    /// Swaps two places, keeping the table of places in step.
    fn swap(&mut self, a: usize, b: usize) {
        if a == b {
            return;
        }
        self.slots.swap(a, b);
        for place in [a, b] {
            let id = self.slots[place].id as usize;
            self.places[id] = u32::try_from(place).unwrap_or(VACANT);
        }
    }

    /// The place of the last slot.
    fn last_place(&self) -> u32 {
        u32::try_from(self.slots.len().saturating_sub(1)).unwrap_or(VACANT)
    }

    /// The place of the instance `id` names.
    fn place(&self, id: Id) -> Result<usize, Error> {
        let i = id.index as usize;
        match self.places.get(i) {
            Some(&place) if place != VACANT && self.generations[i] == id.generation => {
                Ok(place as usize)
            }
            _ => Err(Error::NoSuchInstance),
        }
    }
}

impl<T, const N: usize, const K: usize, M, I> Bank<T, N, K, M, I, Sleeps<T>>
where
    T: Real,
    M: Mechanism<T, N>,
    I: Integrator<T, N, M> + Clone,
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

impl<T: Real, const N: usize, const K: usize, M, I, Z> Bank<T, N, K, M, I, Z> {
    /// The bank's capacity, `K`.
    #[must_use]
    pub const fn capacity(&self) -> usize {
        K
    }
}
