//! The scenes as lagrange `World`s, and what they share with their rapier2d builds: where
//! every body starts. Each world is wrapped in a [`Sim`] that steps it, counts its awake
//! bodies and probes it from outside (the deepest overlap, found again with the crate's own
//! public broad and narrow phases, each timed).

use std::time::Instant;

use lagrange_core::constraints::contact::ContactModel;
use lagrange_core::links::Links;
use lagrange_core::{Error, Mechanism, Real, State};
use lagrange_systems::{
    Ragdoll, RagdollBody, RigidBody, ADULT_JOINT_LIMITS, RAGDOLL_COORDINATES as RN,
};
use lagrange_world::{
    collide, collide_half_plane, BroadPhase, CoordinateLimits, HalfPlane, Limits, NoLimits, Proxy,
    Shape, World, WorldSettings,
};

/// Gravity, m/s^2.
pub const G: f64 = 9.81;

/// Every scene's step, s: 60 Hz, a game's.
pub const DT: f64 = 1.0 / 60.0;

/// The slop, m (and rad, on a ragdoll's joint limit): rapier2d's default allowed linear
/// error is the same 5 mm.
pub const SLOP: f64 = 5e-3;

/// Sweeps of lagrange's impulse solve a step.
pub const SWEEPS: u32 = 8;

/// Sweeps a step for a pyramid of `rows` rows: [`SWEEPS`] up to the 10 rows of the stacking
/// test, 12 for more. The 20-row pyramid falls apart with 8 (its top box 1.6 m across and its
/// boxes 22 mm into each other after 5 s, costing as much a step as it does standing, from
/// the contacts of the fall); with 12 it stands (the top box 13 mm from its start after 10 s,
/// nothing past the 5 mm slop), and a step costs less than with 8.
pub fn pyramid_sweeps(rows: usize) -> u32 {
    if rows <= 10 {
        SWEEPS
    } else {
        12
    }
}

/// The balls' radius, m, and mass, kg.
pub const BALL: (f64, f64) = (0.1, 1.0);

/// The balls' pit: half its width, m (walls at `x = +-BALL_PIT`, the floor at `y = 0`).
pub const BALL_PIT: f64 = 2.6;

/// The surfaces of a scene: restitution, rest speed (m/s), friction.
#[derive(Debug, Clone, Copy)]
pub struct Surfaces {
    /// Restitution.
    pub restitution: f64,
    /// Below this closing speed a contact rests rather than bounces, m/s.
    pub rest_speed: f64,
    /// Friction coefficient.
    pub friction: f64,
}

/// The pyramids' (the stacking test's, `tests/tests/world.rs`): no rebound, friction 0.6.
pub const PYRAMID: Surfaces = Surfaces {
    restitution: 0.0,
    rest_speed: 0.1,
    friction: 0.6,
};

/// The balls': a little rebound, friction 0.5.
pub const BALLS: Surfaces = Surfaces {
    restitution: 0.1,
    rest_speed: 0.1,
    friction: 0.5,
};

/// The ragdoll piles' (`tests/tests/world_pile.rs`): restitution 0.2, friction 0.6.
pub const PILE: Surfaces = Surfaces {
    restitution: 0.2,
    rest_speed: 0.2,
    friction: 0.6,
};

/// What a pile's bodies sleep below: every rate under 0.05 (m/s or rad/s) for 0.5 s (the
/// pile test's).
pub const PILE_SLEEP: (f64, f64) = (0.05, 0.5);

/// The centres of a pyramid of `rows` rows of 1 m boxes on the floor (Box2D's stacking
/// test), the boxes of a row 5 cm apart, each row resting on the one below, from the
/// bottom row up.
pub fn pyramid(rows: usize) -> Vec<[f64; 2]> {
    let mut boxes = Vec::new();
    for r in 0..rows {
        let n = rows - r;
        for i in 0..n {
            let x = (i as f64 - (n as f64 - 1.0) / 2.0) * 1.05;
            boxes.push([x, 0.5 + r as f64]);
        }
    }
    boxes
}

/// The centres of `count` balls poured into the pit: rows of 20, 0.25 m apart, every
/// other row shifted by 5 cm, the lowest 0.5 m up (the top one of 1,000 at 12.75 m).
pub fn balls(count: usize) -> Vec<[f64; 2]> {
    (0..count)
        .map(|k| {
            let (row, col) = (k / 20, k % 20);
            let shift = if row % 2 == 0 { -0.05 } else { 0.05 };
            [(col as f64 - 9.5) * 0.25 + shift, 0.5 + row as f64 * 0.25]
        })
        .collect()
}

/// A small deterministic generator (64-bit LCG, Knuth's constants), so that both engines
/// get the same throw.
struct Lcg(u64);

impl Lcg {
    /// Uniform in `[lo, hi)`.
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// How far apart the thrown ragdolls start, m: up their column and between columns. No
/// point of the adult ragdoll is further than 1.3 m from its torso's centre (half the
/// torso, the thigh and the shin, a capsule's radius), so dolls this far apart cannot
/// overlap at the start whatever their angles (the pile test's 1.2 m can: its depth would
/// be the start's).
pub const PILE_SPACING: f64 = 2.8;

/// Half the width of the pit `dolls` ragdolls are thrown into, m: 2.5 for a column of
/// ten (the pile test's pit), half the spacing more either side for every further column.
pub fn pile_pit(dolls: usize) -> f64 {
    2.5 + PILE_SPACING / 2.0 * (columns(dolls) as f64 - 1.0)
}

/// The columns of ten the ragdolls fall in.
fn columns(dolls: usize) -> usize {
    dolls.div_ceil(10).max(1)
}

/// The throw of `dolls` ragdolls (as the pile test's, but for its generator and the
/// spacing): in columns of ten [`PILE_SPACING`] apart, each doll that much above the last
/// of its column (the lowest 1.5 m up; the top one of ten at 26.7 m), across within
/// +-1.5 m of its column's centre when there is one column (+-0.1 m when there are more,
/// so that no two columns' dolls start overlapping), at a random angle, joint angles
/// within their limits and every rate within +-2 (m/s, rad/s).
pub fn throw(dolls: usize) -> Vec<State<f64, RN>> {
    let mut rng = Lcg(12345);
    let c = columns(dolls);
    let across = if c == 1 { 1.5 } else { 0.1 };
    (0..dolls)
        .map(|d| {
            let (column, level) = (d % c, d / c);
            let centre = (column as f64 - (c as f64 - 1.0) / 2.0) * PILE_SPACING;
            let mut q = [0.0; RN];
            q[0] = centre + rng.uniform(-across, across);
            q[1] = 1.5 + PILE_SPACING * level as f64;
            q[2] = rng.uniform(-3.0, 3.0);
            for (k, [lo, hi]) in ADULT_JOINT_LIMITS.into_iter().enumerate() {
                q[k + 3] = rng.uniform(lo, hi);
            }
            let qd: [f64; RN] = core::array::from_fn(|_| rng.uniform(-2.0, 2.0));
            State::new(0.0, q, qd)
        })
        .collect()
}

/// What a probe of a world found, after a step.
#[derive(Debug, Clone, Copy, Default)]
pub struct Probe {
    /// The deepest overlap of two shapes of different bodies, or of a shape and a wall, m
    /// (zero when none).
    pub depth: f64,
    /// Contact points the engine solved in the step (lagrange's `WorldReport::contacts`).
    pub contacts: Option<f64>,
    /// Islands of awake bodies in the step (lagrange's `WorldReport::islands`).
    pub islands: Option<f64>,
    /// ns of each part of the step, as the `World`'s own profile reports them (its clock
    /// set by [`Sim::time_parts`]): free, broad, narrow, solve, drift, sleep.
    pub parts_ns: Option<[f64; 6]>,
}

/// A world of either engine, as the bench drives it.
pub trait Sim {
    /// One step of [`DT`].
    ///
    /// # Errors
    /// The engine's, as text.
    fn step(&mut self) -> Result<(), String>;
    /// Bodies awake after the last step.
    fn awake(&self) -> usize;
    /// The deepest overlap now, and what else the engine tells.
    fn probe(&mut self) -> Probe;
    /// From now on, time the parts of each step where the engine can say them (lagrange's
    /// `World::set_clock`); the timed runs never do.
    fn time_parts(&mut self) {}
}

/// Nanoseconds since the first call: the clock a lagrange world's profile is read from.
fn nanos() -> u64 {
    static START: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();
    u64::try_from(START.get_or_init(Instant::now).elapsed().as_nanos()).unwrap_or(u64::MAX)
}

/// A lagrange world, its bodies all of one mechanism, and what its probe needs: the
/// shapes, where they are, and a broad phase and pair list of its own (boxed: big).
pub struct Lagrange<T: Real, M, const N: usize, const B: usize, const S: usize, const K: usize, L> {
    world: Box<World<T, M, N, B, S, K, L>>,
    mechanism: M,
    /// `(body key, link, shape in the link's frame)`.
    shapes: Vec<(u32, usize, Shape<T>)>,
    planes: Vec<HalfPlane<T>>,
    broad: Box<BroadPhase<T, S>>,
    pairs: Box<heapless::Vec<(u32, u32), K>>,
    report: lagrange_world::WorldReport,
}

impl<T, M, L, const N: usize, const B: usize, const S: usize, const K: usize> Sim
    for Lagrange<T, M, N, B, S, K, L>
where
    T: Real,
    M: Mechanism<T, N> + Links<T, N> + Clone,
    L: Limits<T, N>,
{
    fn step(&mut self) -> Result<(), String> {
        self.report = self
            .world
            .step(T::from_f64(DT))
            .map_err(|e| e.to_string())?;
        Ok(())
    }

    fn awake(&self) -> usize {
        self.report.awake as usize
    }

    fn probe(&mut self) -> Probe {
        let margin = self.world.settings().margin();
        let mut placed = Vec::with_capacity(self.shapes.len());
        self.broad.clear();
        for (i, &(body, link, shape)) in self.shapes.iter().enumerate() {
            let Some(s) = self.world.state(body) else {
                continue;
            };
            let p = shape.placed(&self.mechanism.pose(&s.q, link));
            let (lo, hi) = p.bounds();
            let proxy = Proxy {
                bounds: (
                    [lo[0] - margin, lo[1] - margin],
                    [hi[0] + margin, hi[1] + margin],
                ),
                body,
                key: u32::try_from(i).unwrap_or(u32::MAX),
                group: 1,
                mask: u32::MAX,
                fixed: false,
                asleep: false,
            };
            if self.broad.add(proxy).is_err() {
                break;
            }
            placed.push(p);
        }
        let pairs_found = self.broad.pairs(&mut *self.pairs).is_ok();
        let mut deepest = 0.0_f64;
        for &(a, b) in self.pairs.iter() {
            let (Some(x), Some(y)) = (placed.get(a as usize), placed.get(b as usize)) else {
                continue;
            };
            let m = collide(x, y, margin);
            deepest = deepest.max(-m.gap().map_or(0.0, |g| g.to_f64()));
        }
        for p in &self.planes {
            for x in &placed {
                let m = collide_half_plane(p, x, margin);
                deepest = deepest.max(-m.gap().map_or(0.0, |g| g.to_f64()));
            }
        }
        let t = self.report.profile;
        let parts = [t.free, t.broad, t.narrow, t.solve, t.drift, t.sleep].map(|x| x as f64);
        Probe {
            depth: if pairs_found { deepest } else { f64::NAN },
            contacts: Some(f64::from(self.report.contacts)),
            islands: Some(f64::from(self.report.islands)),
            parts_ns: (t.total() > 0).then_some(parts),
        }
    }

    fn time_parts(&mut self) {
        self.world.set_clock(Some(nanos));
    }
}

/// A lagrange world's settings for `surfaces`, sleeping below `sleep` (speed, time) if any,
/// `sweeps` sweeps a step.
fn settings<T: Real>(
    surfaces: Surfaces,
    sleep: Option<(f64, f64)>,
    sweeps: u32,
) -> Result<WorldSettings<T>, Error> {
    let model = ContactModel::new(
        T::from_f64(surfaces.restitution),
        T::from_f64(surfaces.rest_speed),
        T::one(),
    )?
    .with_friction(T::from_f64(surfaces.friction))?;
    let s = WorldSettings::new(model, T::from_f64(SLOP), sweeps)?;
    match sleep {
        Some((speed, time)) => s.with_sleep(T::from_f64(speed), T::from_f64(time)),
        None => Ok(s),
    }
}

/// The walls of a pit `half` m either side of the origin, and its floor.
fn pit<T: Real>(half: Option<f64>) -> Result<Vec<HalfPlane<T>>, Error> {
    let mut planes = vec![HalfPlane::floor()];
    if let Some(h) = half {
        planes.push(HalfPlane::new([T::one(), T::zero()], T::from_f64(-h))?);
        planes.push(HalfPlane::new([-T::one(), T::zero()], T::from_f64(-h))?);
    }
    Ok(planes)
}

/// Rigid bodies: a world of up to `B` bodies and shapes, `K` contact points.
pub type Bodies<T, const B: usize, const K: usize> =
    Lagrange<T, RigidBody<T>, 3, B, B, K, NoLimits>;

/// Rigid bodies at rest at `centres`, each `body` with `shape`, in a pit (or on the floor
/// alone, for `half = None`), never asleep, `sweeps` sweeps a step.
fn rigid<T: Real, const B: usize, const K: usize>(
    centres: &[[f64; 2]],
    (body, shape): (RigidBody<T>, Shape<T>),
    surfaces: Surfaces,
    half: Option<f64>,
    sweeps: u32,
) -> Result<Bodies<T, B, K>, Error> {
    let mut world = Box::new(World::new(settings::<T>(surfaces, None, sweeps)?));
    let planes = pit::<T>(half)?;
    for (key, p) in (100_000..).zip(&planes) {
        world.add_plane(key, *p)?;
    }
    let mut shapes = Vec::new();
    for (key, c) in (0..).zip(centres) {
        let q = [c[0], c[1], 0.0].map(T::from_f64);
        world.add_body(key, body, State::new(T::zero(), q, [T::zero(); 3]))?;
        world.add_shape(key, key, 0, shape)?;
        shapes.push((key, 0, shape));
    }
    Ok(Lagrange {
        world,
        mechanism: body,
        shapes,
        planes,
        broad: Box::new(BroadPhase::new()),
        pairs: Box::new(heapless::Vec::new()),
        report: lagrange_world::WorldReport::default(),
    })
}

/// The pyramid of `rows` rows of 1 kg boxes of 1 m on the floor, in `T`.
///
/// # Errors
/// lagrange's, for a world too small.
pub fn lagrange_pyramid<T: Real, const B: usize, const K: usize>(
    rows: usize,
) -> Result<Bodies<T, B, K>, Error> {
    let body = RigidBody::rectangle(T::one(), T::one(), T::one(), T::from_f64(G))?;
    let shape = Shape::rectangle(T::one(), T::one())?;
    rigid(
        &pyramid(rows),
        (body, shape),
        PYRAMID,
        None,
        pyramid_sweeps(rows),
    )
}

/// `count` balls poured into the pit, in `T`.
///
/// # Errors
/// lagrange's, for a world too small.
pub fn lagrange_balls<T: Real, const B: usize, const K: usize>(
    count: usize,
) -> Result<Bodies<T, B, K>, Error> {
    let (r, m) = BALL;
    let body = RigidBody::disk(T::from_f64(m), T::from_f64(r), T::from_f64(G))?;
    let shape = Shape::circle(T::from_f64(r))?;
    rigid(&balls(count), (body, shape), BALLS, Some(BALL_PIT), SWEEPS)
}

/// Ragdolls with their joint limits: up to `B` of them, `S` capsules, `K` contact points.
pub type Pile<T, const B: usize, const S: usize, const K: usize> =
    Lagrange<T, Ragdoll<T>, RN, B, S, K, CoordinateLimits<9>>;

/// `dolls` ragdolls thrown into their pit ([`throw`], [`pile_pit`]), in `T`; with `sleep`
/// they fall asleep as the pile test's ([`PILE_SLEEP`]).
///
/// # Errors
/// lagrange's, for a world too small.
pub fn lagrange_pile<T: Real, const B: usize, const S: usize, const K: usize>(
    dolls: usize,
    sleep: bool,
) -> Result<Pile<T, B, S, K>, Error> {
    let mut world = Box::new(World::new(settings::<T>(
        PILE,
        sleep.then_some(PILE_SLEEP),
        SWEEPS,
    )?));
    let planes = pit::<T>(Some(pile_pit(dolls)))?;
    for (key, p) in (60_000..).zip(&planes) {
        world.add_plane(key, *p)?;
    }
    let doll = Ragdoll::new(RagdollBody::<T>::adult())?;
    let capsules = lagrange_cases::ragdoll_capsules(&doll)?;
    let limits = CoordinateLimits::new(core::array::from_fn(|j| j + 3), ADULT_JOINT_LIMITS)?;
    let mut shapes = Vec::new();
    for (d, s) in (0..).zip(throw(dolls)) {
        let q: [T; RN] = core::array::from_fn(|i| T::from_f64(s.q[i]));
        let qd: [T; RN] = core::array::from_fn(|i| T::from_f64(s.qd[i]));
        let state = State::new(T::zero(), q, qd);
        world.add_body_with(d, doll, limits, state, [T::zero(); 2])?;
        for (k, shape) in (0..).zip(capsules) {
            world.add_shape(1000 * (d + 1) + k, d, k as usize, shape)?;
            shapes.push((d, k as usize, shape));
        }
    }
    Ok(Lagrange {
        world,
        mechanism: doll,
        shapes,
        planes,
        broad: Box::new(BroadPhase::new()),
        pairs: Box::new(heapless::Vec::new()),
        report: lagrange_world::WorldReport::default(),
    })
}
