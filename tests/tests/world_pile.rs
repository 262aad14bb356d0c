//! A pile of ragdolls in a `lagrange_world::World`: capsules on every link, the joints held by
//! `CoordinateLimits` in the same impulse solve as the contacts, thrown together into a pit
//! (a floor and two walls). Joint limits hold to the slop, no two capsules (nor a capsule and
//! the floor) overlap past it, impulses never raise the kinetic energy over the free step's,
//! the total energy never rises above the throw's, and the pile falls asleep. Both
//! precisions.

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
    /// The deepest overlap of two capsules or a capsule and the floor or walls, m.
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

/// `dolls` ragdolls dropped from 1.5 m up, 1.2 m apart in height, at random angles, joint
/// angles within their limits and rates up to 2 rad/s, into a pit 5 m wide; `steps` steps of
/// 1/60 s with 8 sweeps, friction 0.6, restitution 0.2, sleep below 0.05 for 0.5 s.
fn pile<T: Real>(dolls: u32, steps: usize) -> Result<Measured, Error> {
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
    let mut rng = Rng::new(12345);
    for d in 0..dolls {
        let mut q = [T::zero(); N];
        q[0] = rng.uniform(-1.5, 1.5);
        q[1] = T::from_f64(1.5 + 1.2 * f64::from(d));
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
            let d = deepest(&doll, &shapes, &after, &walls);
            if d > 0.006 {
                println!("step {step} depth {d}");
            }
            m.depth = m.depth.max(d);
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

/// Three ragdolls for 3 s (the ten of `a_pile_of_ten_ragdolls` take long unoptimised):
/// limits within the slop and 2% of it (the last step's drift, as the pile's), a joint past
/// its limit moving no further past it (1e-3 rad/s), depth within the slop and 2%, impulses
/// never raise the kinetic energy (to 16 ulps of it), the total never above the throw's.
fn three_ragdolls_land<T: Real>() -> Result<(), Error> {
    let m = on_a_big_stack(|| pile::<T>(3, 180))?;
    println!("{}: {m:?}", core::any::type_name::<T>());
    // The joints' limits have the last word in each step's solve (sweeps of their rows
    // alone after the contacts'): a joint past its limit then moves no further past it, to
    // the solve's convergence (2e-5 to 5e-5 rad/s measured; with 12 such sweeps instead of
    // 32, 0.04; with none, 5.6, and the dolls never fall asleep).
    check::<T>(&m, SLOP * 1.02, 1e-3)
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

/// The assertions of both runs, the depth within `depth`, no joint past its limit moving
/// further past it faster than `into` rad/s after a step.
fn check<T: Real>(m: &Measured, depth: f64, into: f64) -> Result<(), Error> {
    let within = SLOP * 1.02;
    assert!(m.limits <= within, "{m:?}");
    assert!(m.into_limits <= into, "{m:?}");
    assert!(m.depth <= depth, "{m:?}");
    assert!(m.kinetic <= 16.0 * T::EPSILON.to_f64(), "{m:?}");
    assert!(m.energy <= pick::<T>(1e-2, 1e-9), "{m:?}");
    Ok(())
}

for_f32_and_f64!(three_ragdolls_land);

/// Ten ragdolls thrown together for 30 s: limits within the slop, impulses and energy as
/// the three, all asleep within 15 s (steps 349 and 420, 5.8 s and 7 s, f64 and f32, now;
/// 349 and 291 when this was written). Not the slop for depth: where the pile lands, a
/// forearm struck hard passes into another limb within a step (capsules' cores crossing), or
/// the pile presses the lowest doll into the floor, and the drift takes some steps to push
/// them apart; 31 mm at worst in f64, and in f32 27, 39 and 41 mm as the solve's rounding
/// changed (the landing is chaotic: other throws of this kind reach 25 to 170 mm), within
/// 50 mm here: a gap to the slop that is still open.
#[test]
#[ignore = "long: cargo xtask test runs it optimised"]
fn a_pile_of_ten_ragdolls() -> Result<(), Error> {
    fn run<T: Real>() -> Result<(), Error> {
        let m = on_a_big_stack(|| pile::<T>(10, 1800))?;
        println!("{}: {m:?}", core::any::type_name::<T>());
        // 5.2e-3 and 1.3e-3 rad/s measured (f64, f32): more dolls pressing on each limb.
        check::<T>(&m, 0.05, 0.02)?;
        assert!(m.asleep.is_some_and(|s| s < 900), "{m:?}");
        Ok(())
    }
    run::<f64>()?;
    run::<f32>()
}
