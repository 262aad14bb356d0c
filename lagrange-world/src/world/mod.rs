//! [`World`]: instances of a mechanism (bodies) with shapes on their links, static geometry,
//! and the contacts between them, stepped together.

mod block;
mod bodies;
mod detect;
mod islands;
mod limits;
mod lists;
mod locks;
mod merge;
mod mobilities;
mod outran;
mod own;
mod places;
mod profile;
mod rows;
mod settings;
mod solve;
mod twins;

pub use limits::{CoordinateLimits, Limits, NoLimits, MAX_OWN_ROWS};
pub use profile::{Clock, Profile};
pub use settings::WorldSettings;

use crate::broad::BroadPhase;
use crate::collide::HalfPlane;
use crate::query::RayHit;
use crate::shape::Shape;
use crate::vec2::{dot, Vec2};
use bodies::{Attached, Body};
use core::cmp::Ordering;
use heapless::Vec;
use islands::Islands;
use lagrange_core::links::Links;
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, Mechanism, Real, State};
use locks::Locks;
use merge::merge_pairs;
use places::Place;
use profile::Stopwatch;
use rows::{Contact, Kept};
use solve::{Order, Ordered};

/// The first key of a body's own rows' contacts, `(OWN_ROWS, body, row)`: a key no shape
/// or half-plane may take.
pub(crate) const OWN_ROWS: u32 = u32::MAX;

/// How many times the drift's sweeps may run over the contacts in a step, the settings'
/// `sweeps` each time, while a contact is left more than a slop deeper than it asks: a
/// pile's weight is carried down one body a sweep, and ten ragdolls piled sank into each
/// other with one (median depths of 19 to 36 mm over the pile test's eight throws; with up
/// to four, 9 to 10 mm over 24 throws). A tolerance of a slop, not less: at a hundredth of
/// one the rounds ran in every step of 1,000 balls poured into a box (its drift 3.5 times
/// as long) and one pile of ragdolls took 942 steps to fall asleep, not 787.
const DRIFT_ROUNDS: u32 = 4;

/// Static half-planes a world holds at most (floors and walls).
pub const MAX_PLANES: usize = 8;

/// What the last [`World::step`] did: the counts its work is bounded by.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WorldReport {
    /// Contact points solved (at most `K`).
    pub contacts: u32,
    /// Islands of awake bodies (bodies joined by contacts; a body alone is one).
    pub islands: u32,
    /// Bodies stepped.
    pub awake: u32,
    /// Bodies asleep at the step's end.
    pub asleep: u32,
    /// Bodies an awake body's touch woke.
    pub woke: u32,
    /// Times the drift correction swept the contacts (the settings' `sweeps` each time):
    /// 0 where no contact was deeper than the slop, 1 where the first sweeps left none
    /// more than a slop deeper than it asks, at most 4 (a pile whose weight the sweeps
    /// carry down one body at a time).
    pub drift_rounds: u32,
    /// Whether the impulses sent a body where its contacts were not looked for (a limb
    /// whipped by a landing), into a shape or half-plane it had no contact with, so that
    /// the step took a second phase of impacts: the contacts looked for again as far as
    /// the velocities before and after the first take each body, and solved from the
    /// velocities the first left (an impact it caused struck as Newton's law says), at
    /// most once a step. Not where the second look would find more contact points than the
    /// world holds (`K`): that step is taken with the first phase alone, never failed.
    pub looked_again: bool,
    /// Whether the impulses would have added kinetic energy (rebounds of several contacts
    /// at once, or last step's impulses applied again), so that the step was solved again
    /// (from them scaled back, or from none) without rebounds: never more kinetic energy
    /// than the free step's.
    pub guarded: bool,
    /// Where the step's time went, in the ticks of the clock given to
    /// [`World::set_clock`] (all zero without one).
    pub profile: Profile,
}

/// Two shapes began or ended touching (pushing on each other) in the last step.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ContactEvent<T> {
    /// The two shapes' keys, lesser first (a static half-plane's key where one is).
    pub shapes: (u32, u32),
    /// Began (true) or ended.
    pub began: bool,
    /// The normal impulse of the step it began in (N s, or the generalized unit of the
    /// rows; a speculative contact that closes within the step stops only what would
    /// overshoot, the rest the next step); zero when it ended.
    pub impulse: T,
    /// How fast the two closed at its points when it began, the fastest (m/s, or the
    /// rows' unit): what a game plays a sound by; zero when it ended.
    pub speed: T,
    /// Where, world coordinates (the first contact point of the pair; for a pair met later
    /// in the step, where they meet; the origin when it ended).
    pub point: Vec2<T>,
    /// The unit normal there, from the first shape to the second.
    pub normal: Vec2<T>,
}

/// A shape of a world where it is now ([`World::placed_shapes`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlacedShape<T> {
    /// The shape's key.
    pub key: u32,
    /// Its body's key; `None` for a static shape.
    pub body: Option<u32>,
    /// Whether its body sleeps.
    pub asleep: bool,
    /// The shape in world coordinates.
    pub shape: Shape<T>,
}

/// A ray's hit in a world: the shape's key and where.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WorldHit<T> {
    /// The key of the shape (or half-plane) hit.
    pub shape: u32,
    /// Where.
    pub hit: RayHit<T>,
}

/// Bodies (up to `B` instances of a mechanism `M` with `N` coordinates and [`Links`]), shapes
/// on their links and static shapes (up to `S`), static half-planes, and the contacts between
/// them (up to `K` points), stepped together. `no_std`, no heap: every capacity is a
/// constant.
///
/// **A step** of `dt` (Moreau's time stepping, in each body's generalized coordinates):
///
/// ```text
/// 1. free       v* = v + dt a(q, v)                          each awake body's own law
/// 2. detect     contacts at q: broad phase, narrow phase     rows J (normal, tangent) at q
///               within the margin (plus how far a body moves), mobilities M^-1 J^T;
///               a pair closing farther than the thinner of them is half thick: at the
///               features where their paths first bring them within the margin
///               (conservative advancement), or where they come closest
/// 3. solve      impulses by projected Gauss-Seidel, `sweeps` sweeps over the contacts in
///               their keys' order, warm-started from the last step's: each tangent within
///               mu times its normal impulse, each normal row to J v >= lower:
///               -gap / dt while open (speculative: it may close, no more), 0 touching,
///               -e J v* for a contact that strikes (and would leave at the rest speed
///               or faster); a body's limits that pushed in the last step held still in
///               the updates of its contacts' rows (a limb at its limit moves with its
///               body), the bodies' own rows last: each body's solved exactly with
///               the contacts' impulses held
///               where v+ sends a body into a shape it has no contact with (beyond the
///               reach it was looked for with), a second phase: 2 and 3 again from v+,
///               looked for as far as v* or v+ takes a body, at most once a step
/// 4. move       q+ = q + dt v+                                v+ the solved velocities
/// 5. drift      q+ += dt p, pseudo-velocities p that bring every row the move leaves
///               deeper than the slop back to it, and close no other past it (split
///               impulses: the velocities are untouched); swept again while a row is
///               left more than a slop deeper than that, up to four times
/// 6. sleep      islands (bodies joined by contacts) at rest for the set time fall asleep
/// ```
///
/// The rows are taken at the step's start, so an impulse acts on both bodies at the same point,
/// equal and opposite: linear and angular momentum are kept to rounding through every contact's
/// impulses (no other scheme of the library's keeps them through friction off the centre). A
/// pair met later in the step is pushed at the start, each body at the point of it that will
/// touch: the two points are apart by the pair's move to the meeting, and the angular momentum
/// moves by the impulse times that lever (the linear is kept); the drift correction, which
/// moves positions alone, keeps the linear momentum but moves the angular momentum of bodies
/// that slide across the contact it corrects. The scheme is first order; between contacts each
/// body moves by semi-implicit Euler, whose energy error stays bounded. Impulses never add
/// kinetic energy: where the solve would (rebounds of several contacts at once, or last step's
/// impulses warm-starting a contact that let go), it is done again ([`WorldReport::guarded`]):
/// from its own impulses scaled back to where they leave the least kinetic energy, without
/// rebounds, and where that still adds some, from zero impulses.
///
/// **Cost.** Detection: each awake body's links posed twice (where they are and where the step
/// takes them: [`Links::poses`]), the broad phase's sweep and prune over the shapes, one narrow
/// phase a pair that may touch (a pair closing farther than the thinner is half thick: up to 24
/// distances of their cores on the way: two where they strike head-on, more the more slantwise,
/// each closing the share of the gap that is the cosine of their path's angle off the normal:
/// some 6 at 50 degrees and 13 at 70 from 4 m with a 2 cm margin); then per contact point its
/// rows' Jacobians, and their mobilities from each body's mass solve, eight contact points of a
/// body to a call of [`Mechanism::velocity_jumps`] (one factorisation of a ragdoll's mass
/// matrix for them; a constant mass matrix: a multiply a row). The solve: `sweeps` passes over
/// the contacts, `8 N` multiply-adds a contact a pass, in an order that lets rows of bodies
/// apart go at once; the drift: `sweeps` passes again, up to `4 sweeps` where a pile is left
/// deep (each time one pass more over the contacts to see whether). A body the solve changed is
/// posed once more where its new velocity takes it; a step whose impulses send one into a shape
/// it has no contact with (a limb whipped by a landing: 3 to 16 steps of the 900 of ten
/// ragdolls thrown into a pile) detects and solves twice; a solve the guard takes again sweeps
/// at most twice more. Asleep bodies cost nothing but their shapes' place in the broad phase.
///
/// **Determinism.** Contacts are solved in the order of their keys (the shapes' keys and
/// the features that meet), islands are named by their least body key (and, asleep, the
/// count of steps in which islands fell asleep before), and each body's free
/// motion is its own: the same world gives the same bits whatever order its bodies and
/// shapes were added in.
///
/// ```
/// use lagrange_core::constraints::contact::ContactModel;
/// use lagrange_core::State;
/// use lagrange_systems::RigidBody;
/// use lagrange_world::{HalfPlane, Shape, World, WorldSettings};
///
/// // A crate dropped onto the floor comes to rest on it, and falls asleep.
/// let model = ContactModel::new(0.2, 0.1, 1e-6)?.with_friction(0.5)?;
/// let settings = WorldSettings::new(model, 1e-3, 8)?.with_sleep(0.01, 0.5)?;
/// let mut world = World::<f64, RigidBody<f64>, 3, 4, 4, 16>::new(settings);
/// world.add_plane(100, HalfPlane::floor())?;
/// let body = RigidBody::rectangle(1.0, 0.5, 0.5, 9.81)?;
/// world.add_body(1, body, State::new(0.0, [0.0, 1.0, 0.3], [0.0; 3]))?;
/// world.add_shape(10, 1, 0, Shape::rectangle(0.5, 0.5)?)?;
/// for _ in 0..300 {
///     world.step(1.0 / 60.0)?;
/// }
/// let s = world.state(1).unwrap();
/// // Resting flat on a face, its centre 0.25 m up, within the slop.
/// assert!((s.q[1] - 0.25).abs() < 2e-3, "{s:?}");
/// assert_eq!(world.asleep(1), Some(true));
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct World<
    T: Real,
    M,
    const N: usize,
    const B: usize,
    const S: usize,
    const K: usize,
    L = NoLimits,
> {
    /// In the order they were added (a shape names its body by its place here).
    bodies: Vec<Body<T, M, L, N>, B>,
    /// Each body's key and place in `bodies`, sorted by key: a body found by its key in
    /// `log2 B` steps (a linear search made reading every body of a world of 1,000 cost a
    /// million comparisons).
    by_key: Vec<(u32, usize), B>,
    /// Sorted by key.
    shapes: Vec<Attached<T>, S>,
    /// The shapes on bodies as `(body, shape)`, their places in `bodies` and `shapes`,
    /// sorted: a body's shapes placed together from its links posed once.
    by_body: Vec<(u32, u32), S>,
    /// Each shape where it is at the step's start and how far it may move (in `shapes`'
    /// order): kept so that a step makes none.
    places: Vec<Place<T>, S>,
    /// Sorted by key.
    planes: Vec<(u32, HalfPlane<T>), MAX_PLANES>,
    settings: WorldSettings<T>,
    /// The last step's contacts, sorted by key.
    contacts: Vec<Contact<T, N>, K>,
    /// The bodies' own rows locked in the last step's contacts.
    locks: Locks<T, B>,
    /// The order the last step's sweeps took its contacts in.
    ordered: Ordered<K>,
    /// The last step's impulses, sorted by key (the next step's warm start).
    kept: Vec<Kept<T>, K>,
    /// A step's first phase of impulses, sorted by key, where it takes a second (see
    /// [`WorldReport::looked_again`]).
    first: Vec<Kept<T>, K>,
    /// The pairs of shapes that pushed on each other in the last step, sorted.
    touching: Vec<(u32, u32), K>,
    events: Vec<ContactEvent<T>, K>,
    broad: BroadPhase<T, S>,
    report: WorldReport,
    /// What the steps' profiles are read from, if anything.
    clock: Option<Clock>,
    /// Steps in which an island fell asleep: the second part of an island's name.
    naps: u64,
}

impl<T, M, L, const N: usize, const B: usize, const S: usize, const K: usize>
    World<T, M, N, B, S, K, L>
where
    T: Real,
    M: Mechanism<T, N> + Links<T, N> + Clone,
    L: Limits<T, N>,
{
    /// No bodies, shapes or planes.
    #[must_use]
    pub fn new(settings: WorldSettings<T>) -> Self {
        Self {
            bodies: Vec::new(),
            by_key: Vec::new(),
            shapes: Vec::new(),
            by_body: Vec::new(),
            places: Vec::new(),
            planes: Vec::new(),
            settings,
            contacts: Vec::new(),
            locks: Locks::new(),
            ordered: Ordered::new(),
            kept: Vec::new(),
            first: Vec::new(),
            touching: Vec::new(),
            events: Vec::new(),
            broad: BroadPhase::new(),
            report: WorldReport::default(),
            clock: None,
            naps: 0,
        }
    }

    /// Steps from now on read `clock` before and after each of their parts, and say where
    /// their time went in [`WorldReport::profile`] (in the clock's ticks); `None` (the
    /// default) reads no clock. The clock changes no result: the same bits come out with
    /// and without it.
    ///
    /// ```
    /// use lagrange_core::constraints::contact::ContactModel;
    /// use lagrange_core::State;
    /// use lagrange_systems::RigidBody;
    /// use lagrange_world::{HalfPlane, Shape, World, WorldSettings};
    ///
    /// /// A clock that ticks once a read (a desktop would read nanoseconds, firmware a cycle
    /// /// counter).
    /// fn reads() -> u64 {
    ///     use core::sync::atomic::{AtomicU64, Ordering};
    ///     static TICKS: AtomicU64 = AtomicU64::new(0);
    ///     TICKS.fetch_add(1, Ordering::Relaxed)
    /// }
    ///
    /// let settings = WorldSettings::new(ContactModel::new(0.2, 0.1, 1e-6)?, 1e-3, 8)?;
    /// let mut world = World::<f64, RigidBody<f64>, 3, 4, 4, 16>::new(settings);
    /// world.add_plane(100, HalfPlane::floor())?;
    /// let body = RigidBody::rectangle(1.0, 0.5, 0.5, 9.81)?;
    /// world.add_body(1, body, State::new(0.0, [0.0, 1.0, 0.3], [0.0; 3]))?;
    /// world.add_shape(10, 1, 0, Shape::rectangle(0.5, 0.5)?)?;
    /// world.set_clock(Some(reads));
    /// let report = world.step(1.0 / 60.0)?;
    /// // A read at the start and at least one after each of the six parts.
    /// assert_eq!(report.profile.free, 1);
    /// assert!(report.profile.total() >= 6);
    /// # Ok::<(), lagrange_core::Error>(())
    /// ```
    pub fn set_clock(&mut self, clock: Option<Clock>) {
        self.clock = clock;
    }

    /// The settings.
    #[must_use]
    pub fn settings(&self) -> &WorldSettings<T> {
        &self.settings
    }

    /// A body: `mechanism` at `state`, known by `key`, awake, its links where the
    /// mechanism puts them, with the world's default limits (none, for [`NoLimits`]).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `key` when taken, `capacity` when `B` bodies are there;
    /// [`Error::NonFiniteState`] for a state that is not finite.
    pub fn add_body(&mut self, key: u32, mechanism: M, state: State<T, N>) -> Result<(), Error>
    where
        L: Default,
    {
        self.add_body_with(key, mechanism, L::default(), state, [T::zero(); 2])
    }

    /// As [`World::add_body`], the mechanism's origin moved to `origin` (a pendulum whose
    /// pivot is there: the five of a Newton's cradle).
    ///
    /// # Errors
    /// As [`World::add_body`], and `origin` when not finite.
    pub fn add_body_at(
        &mut self,
        key: u32,
        mechanism: M,
        state: State<T, N>,
        origin: Vec2<T>,
    ) -> Result<(), Error>
    where
        L: Default,
    {
        self.add_body_with(key, mechanism, L::default(), state, origin)
    }

    /// A body with its own rows `limits` (a ragdoll's joint limits), its mechanism's origin
    /// at `origin`.
    ///
    /// # Errors
    /// As [`World::add_body_at`].
    pub fn add_body_with(
        &mut self,
        key: u32,
        mechanism: M,
        limits: L,
        state: State<T, N>,
        origin: Vec2<T>,
    ) -> Result<(), Error> {
        state.check_finite()?;
        if !origin.iter().all(|x| x.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "origin",
                reason: "must be finite",
            });
        }
        if self.body(key).is_some() {
            return Err(taken());
        }
        let place = self.bodies.len();
        self.bodies
            .push(Body::new(key, mechanism, limits, state, origin))
            .map_err(|_| full())?;
        // Room for it: by_key holds as many as bodies.
        let at = self.by_key.partition_point(|(k, _)| *k < key);
        self.by_key.insert(at, (key, place)).map_err(|_| full())
    }

    /// A shape on link `link` of body `body` (in the link's frame), known by `key`, in
    /// collision group 1 colliding with every group.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `key` when taken (by a shape or a half-plane; `u32::MAX`
    /// is the world's own), `shape` when not finite (offset by a NaN), `body` when
    /// no body has that key, `link` when the mechanism has no such link, `capacity` when `S`
    /// shapes are there.
    pub fn add_shape(
        &mut self,
        key: u32,
        body: u32,
        link: usize,
        shape: Shape<T>,
    ) -> Result<(), Error> {
        let Some(index) = self.body(body) else {
            return Err(Error::InvalidParameter {
                name: "body",
                reason: "no body has that key",
            });
        };
        if link >= M::LINKS {
            return Err(Error::InvalidParameter {
                name: "link",
                reason: "the mechanism has no such link",
            });
        }
        self.insert_shape(Attached::new(key, Some((index, link)), shape))
    }

    /// A static shape (world coordinates), known by `key`.
    ///
    /// # Errors
    /// As [`World::add_shape`], but for `body` and `link`.
    pub fn add_static(&mut self, key: u32, shape: Shape<T>) -> Result<(), Error> {
        self.insert_shape(Attached::new(key, None, shape))
    }

    /// A static half-plane (a floor, a wall), known by `key`; it touches every shape.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `key` when taken, `capacity` when [`MAX_PLANES`] are
    /// there.
    pub fn add_plane(&mut self, key: u32, plane: HalfPlane<T>) -> Result<(), Error> {
        if self.key_taken(key) {
            return Err(taken());
        }
        let at = self.planes.partition_point(|(k, _)| *k < key);
        self.planes.insert(at, (key, plane)).map_err(|_| full())
    }

    /// Shape `shape`'s collision group bits and the groups it collides with: two shapes
    /// collide where each one's group meets the other's mask.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `shape` when no shape has that key.
    pub fn set_filter(&mut self, shape: u32, group: u32, mask: u32) -> Result<(), Error> {
        let at = self.shape(shape).ok_or(Error::InvalidParameter {
            name: "shape",
            reason: "no shape has that key",
        })?;
        if let Some(s) = self.shapes.get_mut(at) {
            (s.group, s.mask) = (group, mask);
        }
        Ok(())
    }

    /// Body `key`'s state, if there is such a body.
    #[must_use]
    pub fn state(&self, key: u32) -> Option<State<T, N>> {
        self.body(key)
            .and_then(|i| self.bodies.get(i))
            .map(|b| b.state)
    }

    /// Sets body `key`'s state, and wakes it.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `body` when no body has that key;
    /// [`Error::NonFiniteState`] for a state that is not finite.
    pub fn set_state(&mut self, key: u32, state: State<T, N>) -> Result<(), Error> {
        state.check_finite()?;
        let body = self.body_mut(key)?;
        body.state = state;
        body.wake();
        Ok(())
    }

    /// Wakes body `key` (alone: its island wakes when it touches the others).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `body` when no body has that key.
    pub fn wake(&mut self, key: u32) -> Result<(), Error> {
        self.body_mut(key)?.wake();
        Ok(())
    }

    /// Whether body `key` is asleep, if there is such a body.
    #[must_use]
    pub fn asleep(&self, key: u32) -> Option<bool> {
        self.body(key)
            .and_then(|i| self.bodies.get(i))
            .map(|b| b.asleep)
    }

    /// Every shape where it is now, in its keys' order: what a renderer draws. Each shape
    /// placed at its body's link (a static shape where it is), with its body's key and
    /// whether that body sleeps (`None` and `false` for a static shape).
    pub fn placed_shapes(&self) -> impl Iterator<Item = PlacedShape<T>> + '_ {
        self.shapes.iter().map(|s| {
            let body = s.on.and_then(|(i, _)| self.bodies.get(i));
            PlacedShape {
                key: s.key,
                body: body.map(|b| b.key),
                asleep: body.is_some_and(|b| b.asleep),
                shape: self.placed(s),
            }
        })
    }

    /// What the last step did.
    #[must_use]
    pub fn report(&self) -> WorldReport {
        self.report
    }

    /// The pairs of shapes that began or ended touching in the last step, in their keys'
    /// order.
    #[must_use]
    pub fn events(&self) -> &[ContactEvent<T>] {
        &self.events
    }

    /// The total normal impulse on each contact of the last step, in their keys' order:
    /// `((shape, shape, feature), impulse)`. A step that failed changes none of them.
    pub fn impulses(&self) -> impl Iterator<Item = ((u32, u32, u32), T)> + '_ {
        // Read from what the last step kept for warm starting: its contacts' impulses, by
        // key (the contacts themselves are the step's working set, cleared by one that fails).
        self.kept.iter().map(|k| (k.key, k.normal))
    }

    /// Where the ray `origin + t direction`, `0 <= t <= t_max`, first meets a shape or a
    /// half-plane (the lesser key of two met at once).
    #[must_use]
    pub fn ray(&self, origin: Vec2<T>, direction: Vec2<T>, t_max: T) -> Option<WorldHit<T>> {
        let shapes = self.shapes.iter().filter_map(|s| {
            let hit = self.placed(s).ray(origin, direction, t_max)?;
            Some(WorldHit { shape: s.key, hit })
        });
        let planes = self.planes.iter().filter_map(|&(key, p)| {
            let (n, along) = (p.normal(), dot(p.normal(), direction));
            let t = (p.offset() - dot(n, origin)) / along;
            let point = [origin[0] + direction[0] * t, origin[1] + direction[1] * t];
            let met = along < T::zero() && t >= T::zero() && t <= t_max;
            (met && point.iter().all(|x| x.is_finite())).then_some(WorldHit {
                shape: key,
                hit: RayHit {
                    t,
                    point,
                    normal: n,
                },
            })
        });
        shapes
            .chain(planes)
            .fold(None, |best: Option<WorldHit<T>>, h| match best {
                Some(b) if b.hit.t < h.hit.t || (b.hit.t == h.hit.t && b.shape < h.shape) => {
                    Some(b)
                }
                _ => Some(h),
            })
    }

    /// The least key of the shapes (or half-planes) that hold `point` (on or inside).
    #[must_use]
    pub fn shape_at(&self, point: Vec2<T>) -> Option<u32> {
        let shapes = self
            .shapes
            .iter()
            .filter(|s| self.placed(s).distance(point) <= T::zero())
            .map(|s| s.key);
        let planes = self
            .planes
            .iter()
            .filter(|(_, p)| dot(p.normal(), point) <= p.offset())
            .map(|&(k, _)| k);
        shapes.chain(planes).min()
    }

    /// One step of `dt`; see [`World`]. A step that fails leaves the world as it was.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `dt` unless positive and finite, `capacity` when more
    /// pairs or contact points than `K` are found; a mechanism's law or mass solve's errors;
    /// [`Error::NonFiniteState`] when a body's state would not be finite.
    pub fn step(&mut self, dt: T) -> Result<WorldReport, Error> {
        if !(dt > T::zero() && dt.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "dt",
                reason: "must be positive and finite",
            });
        }
        let mut watch = Stopwatch::start(self.clock);
        let saved: Vec<Body<T, M, L, N>, B> = self.bodies.clone();
        let result = self.advance(dt, &mut watch, &saved, true);
        if result.is_err() {
            // The impulses kept for warm starting are still the last step's: a failed step
            // keeps them only when it ends.
            self.bodies = saved;
            self.contacts.clear();
        }
        result
    }

    /// The step, unchecked, from the bodies `saved`, its parts timed by `watch`; with a second
    /// phase of impacts where it is needed and `second` allows it.
    fn advance(
        &mut self,
        dt: T,
        watch: &mut Stopwatch,
        saved: &Vec<Body<T, M, L, N>, B>,
        second: bool,
    ) -> Result<WorldReport, Error> {
        let mut report = WorldReport::default();
        for body in self.bodies.iter_mut().filter(|b| !b.asleep) {
            body.free(dt)?;
        }
        let mut profile = Profile {
            free: watch.lap(),
            ..Profile::default()
        };
        report.woke = self.detect(dt, None, watch, &mut profile)?;
        let free = self.velocities();
        report.guarded = self.solve();
        let outran = second && self.outran(&free, dt);
        profile.solve = watch.lap();
        // A body the impulses sent where its shapes were not looked for (a limb whipped by
        // a landing) may cross a shape it has no contact with: a second phase of impacts,
        // from the velocities the first left, with the contacts looked for again as far
        // as either velocity takes a body (see `outran`).
        if outran {
            impulses_of(&self.contacts, &mut self.first);
            let solved = self.velocities();
            match self.detect(dt, Some(&free), watch, &mut profile) {
                Ok(woke) => report.woke += woke,
                // No room for what the second look finds (more contact points than K, as
                // far as either velocity takes the bodies): the step is taken again without
                // it, so that it never fails a step the first phase alone would take.
                Err(_) => {
                    self.bodies.clone_from(saved);
                    return self.advance(dt, watch, saved, false);
                }
            }
            if self.solve() {
                // The second phase would have added energy (a rebound with a contact of
                // the first held: the balls of a cradle a little apart): the first's
                // velocities stand, and what they cross is the drift's, then the next
                // step's first phase.
                self.set_velocities(&solved);
                for c in self.contacts.iter_mut() {
                    c.normal.lambda = T::zero();
                    c.tangent.lambda = T::zero();
                }
            } else {
                report.looked_again = true;
            }
            self.add_first_impulses();
            profile.solve += watch.lap();
        }
        let mut pseudo = [SVector::<T, N>::zeros(); B];
        let velocities: [SVector<T, N>; B] =
            core::array::from_fn(|i| self.bodies.get(i).map_or(SVector::zeros(), |b| b.state.qd));
        let slop = self.settings.slop;
        if solve::drift(&velocities, &mut self.contacts, slop, dt) {
            // The bodies' own rows have the last word here too. Swept again while a row is
            // still left more than a slop deeper than it asks, up to DRIFT_ROUNDS times the
            // settings' sweeps in all (a scene whose drift the first sweeps settle is
            // stepped as before, bit for bit).
            let quiet = slop / dt;
            for round in 1..=DRIFT_ROUNDS {
                report.drift_rounds = round;
                sweep(
                    &mut pseudo,
                    &mut self.contacts,
                    &self.locks,
                    self.ordered.order(),
                    (T::zero(), self.settings.sweeps),
                    (rows::Phase::Drift, true),
                );
                if round == DRIFT_ROUNDS || !solve::left_deep(&pseudo, &self.contacts, quiet) {
                    break;
                }
            }
        }
        for (body, p) in self
            .bodies
            .iter_mut()
            .zip(&pseudo)
            .filter(|(b, _)| !b.asleep)
        {
            body.state.q += (body.state.qd + p) * dt;
            body.state.t += dt;
            body.state.check_finite()?;
            report.awake += 1;
        }
        profile.drift = watch.lap();
        report.contacts = count(self.contacts.len());
        report.islands = self.sleep(dt);
        report.asleep = count(self.bodies.iter().filter(|b| b.asleep).count());
        self.record_events();
        self.keep_impulses();
        profile.sleep = watch.lap();
        report.profile = profile;
        self.report = report;
        Ok(report)
    }

    /// Step 3 of the scheme: the impulses, into the awake bodies' velocities. Whether the
    /// guard solved again (see [`WorldReport::guarded`]).
    fn solve(&mut self) -> bool {
        let own = self.contacts.partition_point(|c| c.key.0 != OWN_ROWS);
        self.locks
            .lock::<N, K>(&mut self.contacts, own, self.bodies.len());
        twins::mark::<T, N, B, K>(&mut self.contacts);
        // The order of the contacts' bodies decides it: a pile at rest takes the last one
        // (read where it is kept, not copied: a copy is the size of the capacity, every
        // step, asleep or not).
        self.ordered.of::<T, N, B>(&self.contacts);
        let order = self.ordered.order();
        let free = self.velocities();
        let before = self.kinetic(&free);
        let mut v = free;
        solve::warm_start(&mut v, &mut self.contacts, &self.locks);
        let solve = (self.settings.model.friction(), self.settings.sweeps);
        sweep(
            &mut v,
            &mut self.contacts,
            &self.locks,
            order,
            solve,
            (rows::Phase::Velocity, true),
        );
        // Whether kinetic energy `after` is more than the free step's, past 16 ulps of the
        // energies (the rounding of sums of a few products). As a difference: `before +
        // rounding` rounds too (by half an ulp of the energy).
        let added = |after: T| {
            after - before > T::from_f64(16.0) * T::EPSILON * (before.abs() + after.abs())
        };
        let guarded = added(self.kinetic(&v));
        // First the solve's own impulses, scaled back along their ray to where they leave
        // the least kinetic energy (less than the free step's, as zero impulses leave it),
        // and swept again with plain updates. A column of ten boxes a little off true
        // tripped the guard as its weight came down through it, every tenth step; solved
        // again from zero impulses, it dropped most of its weight each time and sank and
        // leaned further each cycle: it fell within 10 s at 8 sweeps. Scaled back, it trips
        // the guard once and stands. Where that still adds energy (or the least is at
        // zero), from zero impulses. Either way without rebounds, and by plain updates, no
        // rows locked: each lowers the program (from zero impulses, its value is the
        // kinetic energy's change).
        if guarded {
            for scale in [self.least_along(&free, &v), T::zero()] {
                let back = scale > T::zero();
                for (v, free) in v.iter_mut().zip(&free) {
                    *v = if back {
                        free + (*v - free) * scale
                    } else {
                        *free
                    };
                }
                for c in self.contacts.iter_mut() {
                    for row in [&mut c.normal, &mut c.tangent] {
                        row.lambda = if back { row.lambda * scale } else { T::zero() };
                    }
                    c.lower = c.lower.min(T::zero());
                }
                sweep(
                    &mut v,
                    &mut self.contacts,
                    &self.locks,
                    order,
                    solve,
                    (rows::Phase::Velocity, false),
                );
                if !back || !added(self.kinetic(&v)) {
                    break;
                }
            }
        }
        self.set_velocities(&v);
        guarded
    }

    /// Where along the ray from the free velocities `free` to `v` (every impulse that took
    /// them there scaled by the same factor) the kinetic energy is least, as that factor
    /// within `[0, 1]`: the energy is `before + s a + s^2 c / 2` at `s`, with `a = sum
    /// free^T M dv` and `c = sum dv^T M dv` over the awake bodies (`dv = v - free`); zero
    /// where it does not fall from `s = 0` (or is not finite).
    fn least_along(&self, free: &[SVector<T, N>; B], v: &[SVector<T, N>; B]) -> T {
        let (mut a, mut c) = (T::zero(), T::zero());
        for ((body, free), v) in self.bodies.iter().zip(free).zip(v) {
            if body.asleep {
                continue;
            }
            let m = body.mechanism.mass_matrix(&body.state);
            let dv = v - free;
            let m_dv = m * dv;
            a += free.dot(&m_dv);
            c += dv.dot(&m_dv);
        }
        let least = -a / c;
        if least > T::zero() {
            least.min(T::one())
        } else {
            T::zero()
        }
    }

    /// The bodies' velocities by index (zero past the last).
    fn velocities(&self) -> [SVector<T, N>; B] {
        core::array::from_fn(|i| self.bodies.get(i).map_or(SVector::zeros(), |b| b.state.qd))
    }

    /// The awake bodies' velocities set to `v`.
    fn set_velocities(&mut self, v: &[SVector<T, N>; B]) {
        for (body, v) in self.bodies.iter_mut().zip(v).filter(|(b, _)| !b.asleep) {
            body.state.qd = *v;
        }
    }

    /// The kinetic energy of the awake bodies at velocities `v`.
    fn kinetic(&self, v: &[SVector<T, N>; B]) -> T {
        self.bodies
            .iter()
            .zip(v)
            .filter(|(b, _)| !b.asleep)
            .map(|(b, v)| {
                let state = State { qd: *v, ..b.state };
                (v.transpose() * b.mechanism.mass_matrix(&state) * v)[0] * T::HALF
            })
            .fold(T::zero(), |a, x| a + x)
    }

    /// Step 6: islands of the awake bodies, and those at rest long enough asleep. The number
    /// of islands.
    fn sleep(&mut self, dt: T) -> u32 {
        let mut islands = Islands::<B>::new();
        let keys: [u32; B] =
            core::array::from_fn(|i| self.bodies.get(i).map_or(u32::MAX, |b| b.key));
        for c in &self.contacts {
            if let [Some(a), Some(b)] = c.bodies {
                islands.join(a, b, |i| keys.get(i).copied().unwrap_or(u32::MAX));
            }
        }
        let (speed, time) = (self.settings.sleep_speed, self.settings.sleep_time);
        // Each island's least time at rest.
        let mut still = [T::INFINITY; B];
        for (i, body) in self
            .bodies
            .iter_mut()
            .enumerate()
            .filter(|(_, b)| !b.asleep)
        {
            let fast = body.state.qd.iter().any(|x| x.abs() >= speed);
            body.still = if fast { T::zero() } else { body.still + dt };
            let root = islands.root(i);
            if let Some(s) = still.get_mut(root) {
                *s = s.min(body.still);
            }
        }
        let (mut count, mut slept) = (0, false);
        for i in 0..self.bodies.len() {
            let root = islands.root(i);
            let Some(body) = self.bodies.get_mut(i) else {
                continue;
            };
            if body.asleep {
                continue;
            }
            if root == i {
                count += 1;
            }
            if still.get(root).is_some_and(|&s| s >= time) {
                body.sleep((keys.get(root).copied().unwrap_or(body.key), self.naps));
                slept = true;
            }
        }
        self.naps = self.naps.wrapping_add(u64::from(slept));
        count
    }

    /// The first phase's impulses added to the second's, contact by contact: what each
    /// took in the step (a contact of the first is one of the second's: the second looks
    /// at least as far).
    fn add_first_impulses(&mut self) {
        // Both sorted by key: matched in one walk.
        let mut first = self.first.iter().peekable();
        for c in self.contacts.iter_mut() {
            while first.next_if(|k| k.key < c.key).is_some() {}
            if let Some(k) = first.next_if(|k| k.key == c.key) {
                c.normal.lambda += k.normal;
                c.tangent.lambda += k.tangent;
            }
        }
    }

    /// The step's impulses, kept for the next step's warm start (the last step's until
    /// now: the step that ends here matched its contacts with them).
    fn keep_impulses(&mut self) {
        impulses_of(&self.contacts, &mut self.kept);
    }

    /// The events of the step: pairs that pushed now and not before, or before and not now.
    fn record_events(&mut self) {
        self.events.clear();
        // A world asleep found no contacts, and every pair that touched is a sleeping
        // body's: none began, none ended, the pairs are as they were (and a pile asleep
        // costs nothing here: looking each pair's bodies up was most of its step).
        if self.contacts.is_empty() && self.bodies.iter().all(|b| b.asleep) {
            return;
        }
        // Each pushing pair once, its impulses summed, at its first point (contacts are in
        // their keys' order, so a pair's points are together).
        let mut now: Vec<ContactEvent<T>, K> = Vec::new();
        for c in self
            .contacts
            .iter()
            .filter(|c| c.normal.lambda > T::zero() && c.key.0 != OWN_ROWS)
        {
            let pair = (c.key.0.min(c.key.1), c.key.0.max(c.key.1));
            match now.last_mut() {
                Some(e) if e.shapes == pair => {
                    e.impulse += c.normal.lambda;
                    e.speed = e.speed.max(-c.approach);
                }
                _ => {
                    let _ = now.push(ContactEvent {
                        shapes: pair,
                        began: true,
                        impulse: c.normal.lambda,
                        speed: -c.approach,
                        point: c.point,
                        normal: c.direction,
                    });
                }
            }
        }
        now.sort_unstable_by_key(|e| e.shapes);
        // A pair of a sleeping body is not solved, and still touches. (In place: a copy of
        // the pairs is the world's capacity for them, whatever the pairs.)
        let (shapes, bodies) = (&self.shapes, &self.bodies);
        // Looked up only where some body sleeps (two binary searches a pair: most of this
        // part of a pyramid's step, all awake, where none is).
        let some_asleep = bodies.iter().any(|b| b.asleep);
        let asleep = |(a, b): (u32, u32)| {
            some_asleep && (sleeping(shapes, bodies, a) || sleeping(shapes, bodies, b))
        };
        // The pairs pushing now and those that touched, both sorted: one walk of the two
        // finds the pairs that began (now only) and ended (before only, awake), in order,
        // and keeps in place the sleeping pairs that touched (a search of one list per pair
        // of the other, and sorting the events, were a twentieth of a pyramid's step).
        let (mut i, mut j, mut kept) = (0, 0, 0);
        loop {
            let (e, before) = (now.get(i), self.touching.get(j).copied());
            let order = match (e, before) {
                (Some(e), Some(b)) => e.shapes.cmp(&b),
                (Some(_), None) => Ordering::Less,
                (None, Some(_)) => Ordering::Greater,
                (None, None) => break,
            };
            match (order, e, before) {
                (Ordering::Less, Some(e), _) => {
                    let _ = self.events.push(*e);
                    i += 1;
                }
                (Ordering::Greater, _, Some(b)) => {
                    if asleep(b) {
                        if let Some(slot) = self.touching.get_mut(kept) {
                            *slot = b;
                        }
                        kept += 1;
                    } else {
                        let _ = self.events.push(ContactEvent {
                            shapes: b,
                            began: false,
                            impulse: T::zero(),
                            speed: T::zero(),
                            point: [T::zero(); 2],
                            normal: [T::zero(); 2],
                        });
                    }
                    j += 1;
                }
                _ => (i, j) = (i + 1, j + 1),
            }
        }
        self.touching.truncate(kept);
        merge_pairs(&mut self.touching, now.iter().map(|e| e.shapes));
    }

    /// The index of body `key`.
    fn body(&self, key: u32) -> Option<usize> {
        let at = self.by_key.binary_search_by_key(&key, |(k, _)| *k).ok()?;
        self.by_key.get(at).map(|(_, place)| *place)
    }

    fn body_mut(&mut self, key: u32) -> Result<&mut Body<T, M, L, N>, Error> {
        let i = self.body(key).ok_or(Error::InvalidParameter {
            name: "body",
            reason: "no body has that key",
        })?;
        self.bodies.get_mut(i).ok_or(Error::InvalidParameter {
            name: "body",
            reason: "no body has that key",
        })
    }

    /// The index of shape `key`.
    fn shape(&self, key: u32) -> Option<usize> {
        self.shapes.binary_search_by_key(&key, |s| s.key).ok()
    }

    fn key_taken(&self, key: u32) -> bool {
        key == OWN_ROWS || self.shape(key).is_some() || self.planes.iter().any(|(k, _)| *k == key)
    }

    fn insert_shape(&mut self, shape: Attached<T>) -> Result<(), Error> {
        if self.key_taken(shape.key) {
            return Err(taken());
        }
        // A shape offset or placed by values that are not finite.
        let s = &shape.shape;
        if !(s.vertices().iter().flatten().all(|x| x.is_finite()) && s.radius().is_finite()) {
            return Err(Error::InvalidParameter {
                name: "shape",
                reason: "its vertices and radius must be finite",
            });
        }
        let at = self.shapes.partition_point(|s| s.key < shape.key);
        let index = u32::try_from(at).map_err(|_| full())?;
        let entry = match shape.on {
            Some((body, _)) => Some((u32::try_from(body).map_err(|_| full())?, index)),
            None => None,
        };
        self.shapes.insert(at, shape).map_err(|_| full())?;
        // The shapes after it moved up one; it joins its body's (there is room: by_body
        // holds fewer than the shapes).
        for (_, i) in self.by_body.iter_mut().filter(|(_, i)| *i >= index) {
            *i += 1;
        }
        if let Some(entry) = entry {
            let place = self.by_body.partition_point(|e| *e < entry);
            let _ = self.by_body.insert(place, entry);
        }
        Ok(())
    }

    /// Shape `s` where its body's link is now (a static shape where it is).
    fn placed(&self, s: &Attached<T>) -> Shape<T> {
        match s.on.and_then(|(i, link)| Some((self.bodies.get(i)?, link))) {
            Some((body, link)) => s.shape.placed(&body.pose(&body.state.q, link)),
            None => s.shape,
        }
    }
}

/// The impulse solve of `phase` over `contacts` in `order`: `sweeps` sweeps over every row,
/// then the bodies' own rows solved exactly with the others held (`own`; where that fails,
/// sweeps over them alone): a joint's limit has the last word over
/// the contacts that strike its limb (their leftover depth is the drift's to remove; a limit
/// passed is what a viewer sees).
fn sweep<T: Real, const N: usize, const B: usize, const K: usize>(
    v: &mut [SVector<T, N>],
    contacts: &mut [Contact<T, N>],
    locks: &Locks<T, B>,
    order: &Order<K>,
    (friction, sweeps): (T, u32),
    (phase, locking): (rows::Phase, bool),
) {
    solve::sweep(
        v, contacts, locks, &order.all, friction, sweeps, phase, locking,
    );
    // Each body's own rows come last (their keys' first part is OWN_ROWS); `settle` does
    // nothing where there are none.
    let first = contacts.partition_point(|c| c.key.0 != OWN_ROWS);
    own::settle(v, contacts, locks, first, phase, sweeps, locking);
}

/// Whether shape `key` of `shapes` (sorted by key) is on a sleeping body of `bodies`.
fn sleeping<T: Real, M, L, const N: usize>(
    shapes: &[Attached<T>],
    bodies: &[Body<T, M, L, N>],
    key: u32,
) -> bool {
    shapes
        .binary_search_by_key(&key, |s| s.key)
        .ok()
        .and_then(|i| shapes.get(i))
        .and_then(|s| s.on)
        .is_some_and(|(i, _)| bodies.get(i).is_some_and(|b| b.asleep))
}

/// A count as the report's `u32`.
fn count(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

fn taken() -> Error {
    Error::InvalidParameter {
        name: "key",
        reason: "is taken",
    }
}

fn full() -> Error {
    Error::InvalidParameter {
        name: "capacity",
        reason: "the world is full",
    }
}

/// Each of `contacts`' impulses by its key, in their order, into `out` (emptied first).
fn impulses_of<T: Real, const N: usize, const K: usize>(
    contacts: &[Contact<T, N>],
    out: &mut Vec<Kept<T>, K>,
) {
    out.clear();
    for c in contacts {
        // Capacity K holds every contact of a step.
        let _ = out.push(Kept {
            key: c.key,
            normal: c.normal.lambda,
            tangent: c.tangent.lambda,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::World;
    use crate::world::settings::WorldSettings;
    use lagrange_core::constraints::contact::ContactModel;
    use lagrange_core::nalgebra::SVector;
    use lagrange_core::{Error, State};
    use lagrange_systems::RigidBody;

    /// Where along the ray from the free velocities to the solve's the kinetic energy is
    /// least, worked out by hand for a box of 2 kg (inertia `I`): straight up through a
    /// fall, half way (`(-1 + 2 s)^2` least at 1/2); turning as well, `(2 m + I / 2) /
    /// (17 m / 4 + I)`; a move that only adds energy, none; one that takes it all the way
    /// and beyond, the whole move (capped at 1).
    #[test]
    fn the_least_energy_along_the_ray() -> Result<(), Error> {
        let settings = WorldSettings::new(ContactModel::new(0.0, 0.1, 1.0)?, 1e-3, 8)?;
        let mut world = World::<f64, RigidBody<f64>, 3, 4, 4, 16>::new(settings);
        let body = RigidBody::rectangle(2.0, 1.0, 0.5, 9.81)?;
        world.add_body(0, body, State::at_rest([0.0; 3]))?;
        let (m, i) = (body.mass(), body.inertia());
        let v = |x: f64, y: f64, w: f64| [SVector::from([x, y, w]); 4];
        let cases = [
            (v(0.0, -1.0, 0.0), v(0.0, 1.0, 0.0), 0.5),
            (
                v(1.0, 0.0, 0.5),
                v(-1.0, 0.5, -0.5),
                (2.0 * m + 0.5 * i) / (4.25 * m + i),
            ),
            (v(0.0, -1.0, 0.0), v(0.0, -2.0, 0.0), 0.0),
            (v(0.0, -1.0, 0.0), v(0.0, -0.5, 0.0), 1.0),
        ];
        for (free, solved, least) in cases {
            let s = world.least_along(&free, &solved);
            assert!((s - least).abs() <= 1e-15, "{s} against {least}");
        }
        Ok(())
    }
}
