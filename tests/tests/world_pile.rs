//! A pile of ragdolls in a `lagrange_world::World`: capsules on every link, the joints held by
//! `CoordinateLimits` in the same impulse solve as the contacts, thrown together into a pit
//! (a floor and two walls), eight throws of each. Joint limits hold to the slop (and 5% in a
//! pile of ten), impulses never raise the kinetic energy over the free step's, the total
//! energy never rises above the throw's, and the pile falls asleep; how deep capsules
//! overlap (each other, or the floor and walls), over the throws. Both precisions.

use lagrange_core::constraints::contact::ContactModel;
use lagrange_core::links::Links;
use lagrange_core::{Error, Lagrangian, Mechanism, Real, State};
use lagrange_systems::{
    Ragdoll, RagdollBody, ADULT_JOINT_LIMITS, RAGDOLL_COORDINATES as N, RAGDOLL_LINKS,
};
use lagrange_tests::{for_f32_and_f64, pick, Rng};
use lagrange_world::{
    collide, collide_half_plane, CoordinateLimits, HalfPlane, Shape, World, WorldSettings,
};

/// Up to 16 ragdolls of 10 capsules, 1,024 contact points (the rows of their joints among
/// them).
type Pile<T> = World<T, Ragdoll<T>, N, 16, 160, 1024, CoordinateLimits<9>>;

/// The slop, m (and rad, on a joint's limit).
const SLOP: f64 = 5e-3;

/// What a pile's run measured.
#[derive(Debug)]
struct Measured {
    /// The furthest any joint went past a limit, rad.
    limits: f64,
    /// The deepest overlap of two capsules or a capsule and the floor or walls, m, after
    /// every 30th step.
    depth: f64,
    /// The largest rise of the awake bodies' kinetic energy over a step from the free step's
    /// velocities (at the step's start) to the step's, over 1 J plus that energy.
    kinetic: f64,
    /// The largest total energy over the run less the throw's, J.
    energy: f64,
    /// The first step at which every ragdoll was asleep.
    asleep: Option<usize>,
    /// The fastest a joint past a limit at a step's start still moved further past it
    /// after the step, rad/s.
    into_limits: f64,
}

/// How far apart in height a throw's dolls start, m: no point of the adult ragdoll is
/// further than 1.3 m from its torso's centre, so that dolls this far apart cannot start
/// overlapping (1.2 m apart, as this test once threw them, they could: two capsules whose
/// cores start side by side along one line are pushed apart by nothing that knows which way,
/// and such a throw's depth was its start's, 85 mm, whatever the solve). The world bench's.
const SPACING: f64 = 2.8;

/// The throws, by the seed of their positions, angles and rates.
const THROWS: [u64; 8] = [12345, 1, 2, 3, 4, 5, 6, 7];

/// `dolls` ragdolls dropped from 1.5 m up, [`SPACING`] apart in height, at random angles
/// (drawn from `seed`), joint angles within their limits and rates up to 2 rad/s, into a pit
/// 5 m wide; `steps` steps of 1/60 s with 8 sweeps, friction 0.6, restitution 0.2, sleep
/// below 0.05 for 0.5 s.
fn pile<T: Real>(seed: u64, dolls: u32, steps: usize) -> Result<Measured, Error> {
    let model = ContactModel::new(T::from_f64(0.2), T::from_f64(0.2), T::one())?
        .with_friction(T::from_f64(0.6))?;
    let settings =
        WorldSettings::new(model, T::from_f64(SLOP), 8)?.with_sleep(T::from_f64(0.05), T::HALF)?;
    let mut world = Box::new(Pile::<T>::new(settings));
    let walls = [
        HalfPlane::floor(),
        HalfPlane::new([T::one(), T::zero()], T::from_f64(-2.5))?,
        HalfPlane::new([-T::one(), T::zero()], T::from_f64(-2.5))?,
    ];
    for (key, wall) in (60_000..).zip(walls) {
        world.add_plane(key, wall)?;
    }
    let doll = Ragdoll::new(RagdollBody::<T>::adult())?;
    let shapes = lagrange_cases::ragdoll_capsules(&doll)?;
    let limits = CoordinateLimits::new(core::array::from_fn(|j| j + 3), ADULT_JOINT_LIMITS)?;
    let mut rng = Rng::new(seed);
    for d in 0..dolls {
        let mut q = [T::zero(); N];
        q[0] = rng.uniform(-1.5, 1.5);
        q[1] = T::from_f64(1.5 + SPACING * f64::from(d));
        q[2] = rng.uniform(-3.0, 3.0);
        for (k, [lo, hi]) in ADULT_JOINT_LIMITS.into_iter().enumerate() {
            q[k + 3] = rng.uniform(lo, hi);
        }
        let qd = core::array::from_fn(|_| rng.uniform(-2.0, 2.0));
        world.add_body_with(
            d,
            doll,
            limits,
            State::new(T::zero(), q, qd),
            [T::zero(); 2],
        )?;
        for (k, shape) in (0..).zip(shapes) {
            world.add_shape(1000 * (d + 1) + k, d, k as usize, shape)?;
        }
    }
    let states = |w: &Pile<T>| -> std::vec::Vec<State<T, N>> {
        (0..dolls).filter_map(|d| w.state(d)).collect()
    };
    let total = |s: &[State<T, N>]| -> f64 { s.iter().map(|s| doll.energy(s).to_f64()).sum() };
    let kinetic = |s: &State<T, N>| -> f64 { (doll.energy(s) - doll.potential_energy(s)).to_f64() };
    let start = total(&states(&world));
    let dt = T::from_f64(1.0 / 60.0);
    let mut m = Measured {
        limits: 0.0,
        depth: 0.0,
        kinetic: f64::NEG_INFINITY,
        energy: f64::NEG_INFINITY,
        asleep: None,
        into_limits: 0.0,
    };
    for step in 0..steps {
        let before = states(&world);
        let report = world.step(dt)?;
        let after = states(&world);
        // The awake bodies' kinetic energy at the step's start configuration, at the free
        // step's velocities and at the step's (impulses pass energy from one body to
        // another: the sum is what they may not raise).
        let (mut free, mut solved) = (0.0, 0.0);
        for (s0, s1) in before.iter().zip(&after).filter(|(s0, s1)| s1.t != s0.t) {
            free += kinetic(&State {
                qd: s0.qd + doll.acceleration(s0)? * dt,
                ..*s0
            });
            solved += kinetic(&State { qd: s1.qd, ..*s0 });
        }
        m.kinetic = m.kinetic.max((solved - free) / (1.0 + free));
        m.energy = m.energy.max(total(&after) - start);
        for (s0, s1) in before.iter().zip(&after).filter(|(s0, s1)| s1.t != s0.t) {
            for (k, [lo, hi]) in ADULT_JOINT_LIMITS.into_iter().enumerate() {
                let (x, v) = (s0.q[k + 3].to_f64(), s1.qd[k + 3].to_f64());
                let into = if x > hi {
                    v
                } else if x < lo {
                    -v
                } else {
                    0.0
                };
                m.into_limits = m.into_limits.max(into);
            }
        }
        for s in &after {
            for (k, [lo, hi]) in ADULT_JOINT_LIMITS.into_iter().enumerate() {
                let x = s.q[k + 3].to_f64();
                m.limits = m.limits.max(lo - x).max(x - hi);
            }
        }
        if step % 30 == 29 {
            m.depth = m.depth.max(deepest(&doll, &shapes, &after, &walls));
        }
        if report.asleep == dolls && m.asleep.is_none() {
            m.asleep = Some(step);
        }
    }
    Ok(m)
}

/// The deepest overlap of the capsules of ragdolls at `states` (of different ragdolls: a
/// ragdoll's own links overlap at its joints by design) and of a capsule and a wall, m.
fn deepest<T: Real>(
    doll: &Ragdoll<T>,
    shapes: &[Shape<T>; RAGDOLL_LINKS],
    states: &[State<T, N>],
    walls: &[HalfPlane<T>],
) -> f64 {
    let placed: std::vec::Vec<std::vec::Vec<Shape<T>>> = states
        .iter()
        .map(|s| {
            (0..RAGDOLL_LINKS)
                .map(|k| shapes[k].placed(&doll.pose(&s.q, k)))
                .collect()
        })
        .collect();
    let mut worst: f64 = 0.0;
    for (i, a) in placed.iter().enumerate() {
        for x in a {
            for w in walls {
                worst = worst.max(
                    -collide_half_plane(w, x, T::zero())
                        .gap()
                        .map_or(0.0, |g| g.to_f64()),
                );
            }
            for b in &placed[i + 1..] {
                for y in b {
                    worst = worst.max(-collide(x, y, T::zero()).gap().map_or(0.0, |g| g.to_f64()));
                }
            }
        }
    }
    worst
}

/// Three ragdolls for 3 s, each of the [`THROWS`] (the ten of `a_pile_of_ten_ragdolls`
/// take long unoptimised): limits within the slop and 2% of it (the last step's drift, as
/// the pile's), a joint past its limit moving no further past it than 1e-3 rad/s, impulses
/// never raise the kinetic energy (to 16 ulps of it), the total never above the throw's;
/// the depths' median within the slop and 2% (a resting contact rests at the slop) and the
/// worst within 20 mm.
///
/// Measured over the throws (f32, f64): the median depth 4.9 mm and 5.0 mm, the worst 6.4
/// and 5.1 mm (7.6 and 5.5 before fast pairs were taken where they meet); a joint past its
/// limit moving 2.8e-5 and 2.1e-13 rad/s at worst further past it (2.6e-3 when the limits
/// were swept 32 times, not solved).
/// The solve without locked limits (see `lagrange_world`'s `locks`) fails these: depths 24
/// mm at worst, 1.4e-2 rad/s into a limit, a limit passed by 5.29 mm.
fn three_ragdolls_land<T: Real>() -> Result<(), Error> {
    let runs = throws::<T>(3, 180)?;
    // The joints' limits have the last word in each step's solve (each body's rows solved
    // exactly after the contacts'): a joint past its limit then moves no further past it,
    // to rounding (with 12 sweeps of their rows alone instead, 0.04 rad/s; with none, 5.6,
    // and the dolls never fall asleep).
    let bounds = Bounds {
        limits: SLOP * 1.02,
        into: 1e-3,
        median: SLOP * 1.02,
        worst: 0.02,
    };
    check::<T>(&runs, &bounds)
}

/// Each of the [`THROWS`] of `dolls` ragdolls for `steps` steps.
fn throws<T: Real>(dolls: u32, steps: usize) -> Result<std::vec::Vec<Measured>, Error> {
    let mut runs = std::vec::Vec::new();
    for seed in THROWS {
        let m = on_a_big_stack(move || pile::<T>(seed, dolls, steps))?;
        println!("{} seed {seed}: {m:?}", core::any::type_name::<T>());
        runs.push(m);
    }
    Ok(runs)
}

/// `f` on a thread with a 64 MB stack: a world of 1,024 contact points of ragdolls is 1 MB,
/// made on the stack before it is boxed (a firmware keeps such a world in a `static`).
fn on_a_big_stack<R: Send + 'static>(
    f: impl FnOnce() -> Result<R, Error> + Send + 'static,
) -> Result<R, Error> {
    let thread = std::thread::Builder::new()
        .stack_size(64 << 20)
        .spawn(f)
        .map_err(|_| Error::InvalidParameter {
            name: "thread",
            reason: "could not start one",
        })?;
    match thread.join() {
        Ok(r) => r,
        Err(panic) => std::panic::resume_unwind(panic),
    }
}

/// What every run of a test must keep to, and its throws' depths.
struct Bounds {
    /// How far past a limit a joint may go, rad.
    limits: f64,
    /// How fast a joint past its limit may still move further past it after a step, rad/s.
    into: f64,
    /// The median of the runs' depths, m.
    median: f64,
    /// The worst, m.
    worst: f64,
}

/// `bounds` on every run of `runs`, and on the median and the worst of their depths (a
/// throw's landing is chaotic: its depth is a draw from a spread, which a median over
/// throws measures and one throw does not).
fn check<T: Real>(runs: &[Measured], bounds: &Bounds) -> Result<(), Error> {
    for m in runs {
        assert!(m.limits <= bounds.limits, "{m:?}");
        assert!(m.into_limits <= bounds.into, "{m:?}");
        assert!(m.kinetic <= 16.0 * T::EPSILON.to_f64(), "{m:?}");
        assert!(m.energy <= pick::<T>(1e-2, 1e-9), "{m:?}");
    }
    let mut depths: std::vec::Vec<f64> = runs.iter().map(|m| m.depth).collect();
    depths.sort_by(f64::total_cmp);
    let n = depths.len();
    let median = (depths[(n - 1) / 2] + depths[n / 2]) / 2.0;
    println!("depths, m: {depths:?}, median {median}");
    assert!(median <= bounds.median, "median {median} of {depths:?}");
    assert!(depths[n - 1] <= bounds.worst, "{depths:?}");
    Ok(())
}

for_f32_and_f64!(three_ragdolls_land);

/// Ten ragdolls thrown together for 30 s, each of the [`THROWS`] (the world bench's throw is
/// the first): limits within the slop and 5%, a joint past its limit moving 0.01 rad/s at
/// most further past it, impulses and energy as the three, the depths' median within 15 mm
/// and the worst within 70 mm, and all asleep within 20 s.
///
/// Measured over the throws (f32, f64): limits passed by 5.002 and 5.000 mm at worst, joints
/// moving 1.2e-3 and 1.0e-12 rad/s further past them (0.015 to 0.037 when the limits were
/// swept, not solved: the bound was 0.03, and throws not drawn here passed it); median
/// depths 8.4 and 9.8 mm, the worst 24 and 18 mm; asleep by steps 801 and 749. (Before fast
/// pairs were taken where they meet: 9.2 and 9.6 mm, 13 and 30 mm, asleep by 682 and 984,
/// where the f64 pile of seed 3 slid at step 700 and a doll crept at about the sleep speed
/// until 984.) With the drift swept once (the settings' 8 sweeps, not again while a contact is
/// left a slop deeper than it asks), the medians were 19 to 36 mm: the pile sank into
/// itself, its weight not carried down in 8 sweeps. Not the slop for depth: where a pile
/// lands at 20 m/s, a limb turning fast meets another at points its contact's manifold, taken
/// at the step's start, does not hold. Before a step looked again where the impulses sent a
/// limb beyond the reach its pairs were looked for with (`WorldReport::looked_again`),
/// the deepest overlap of any step over 24 throws was 25-144 mm (f32) and 35-220 mm (f64);
/// since, 17-135 and 20-99 mm. The solve without locked limits fails these: median depth
/// 89 mm and the worst 192 mm (f64), a limit passed by 5.38 mm, a pile asleep only at step
/// 1,521.
#[test]
#[ignore = "long: cargo xtask test runs it optimised"]
fn a_pile_of_ten_ragdolls() -> Result<(), Error> {
    fn run<T: Real>() -> Result<(), Error> {
        let runs = throws::<T>(10, 1800)?;
        let bounds = Bounds {
            limits: SLOP * 1.05,
            into: 0.01,
            median: 0.015,
            worst: 0.07,
        };
        check::<T>(&runs, &bounds)?;
        for m in &runs {
            assert!(m.asleep.is_some_and(|s| s < 1200), "{m:?}");
        }
        Ok(())
    }
    run::<f64>()?;
    run::<f32>()
}
