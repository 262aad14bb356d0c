//! Scenes, bit for bit (issue 14): a sleeper does not change at all, a woken instance runs as
//! a fresh start from the state it woke with, and a scene that never sleeps gives the very
//! states of independent fixed-timestep runs of its instances.

use lagrange_core::{Error, Mechanism, Real, State};
use lagrange_integrators::scene::{
    Bank, Id, NeverSleeps, Scene, SceneFrame, Sleep, Sleeps, Status,
};
use lagrange_integrators::{
    AdaptiveSettings, Clock, DormandPrince54, FixedTimestep, ImplicitMidpoint, Integrator, Rk4,
    StormerVerlet,
};
use lagrange_systems::{CartPole, DoublePendulum, SimplePendulum};
use lagrange_tests::{for_f32_and_f64, pick, Rng};

/// The fixed step of every scene here: 120 Hz.
const DT: f64 = 1.0 / 120.0;
/// Steps per frame at most.
const CAP: u32 = 4;
const G: f64 = 9.81;

/// The bits of a state: time, coordinates, velocities (`f32` widened to `f64`, which is
/// exact, so that equal bits are equal values, and `-0` is told from `+0`).
fn bits<T: Real, const N: usize>(s: &State<T, N>) -> (u64, [u64; N], [u64; N]) {
    (
        s.t.to_f64().to_bits(),
        core::array::from_fn(|i| s.q[i].to_f64().to_bits()),
        core::array::from_fn(|i| s.qd[i].to_f64().to_bits()),
    )
}

/// The same coordinates and velocities, bit for bit, and times within two ulps (the scene's
/// clock counts steps from 0, a fresh run's from the time it started at: the two compensated
/// sums may round apart by an ulp).
fn same_motion<T: Real, const N: usize>(got: &State<T, N>, fresh: &State<T, N>, what: &str) {
    let (_, gq, gqd) = bits(got);
    let (_, fq, fqd) = bits(fresh);
    assert!(
        gq == fq && gqd == fqd,
        "{what}: {got:?} differs from the fresh run's {fresh:?}"
    );
    let slack = T::TWO * T::EPSILON * got.t.abs();
    assert!(
        (got.t - fresh.t).abs() <= slack,
        "{what}: time {:e} against the fresh run's {:e}",
        got.t.to_f64(),
        fresh.t.to_f64()
    );
}

/// A mechanism stepped by a [`FixedTimestep`] of its own: what an instance of a bank should
/// match.
struct Twin<T: Real, const N: usize, M, I> {
    id: Id,
    mechanism: M,
    sim: FixedTimestep<T, N, I>,
}

/// Adds `instances` to `bank` and makes their twins: the same mechanism and start, a fresh
/// copy of `integrator`, the scene's `dt` and cap.
fn add_twins<T, const N: usize, const K: usize, M, I, Z>(
    bank: &mut Bank<T, N, K, M, I, Z>,
    integrator: &I,
    instances: Vec<(M, State<T, N>)>,
) -> Result<Vec<Twin<T, N, M, I>>, Error>
where
    T: Real,
    M: Mechanism<T, N> + Clone,
    I: Integrator<T, N, M> + Clone,
    Z: Sleep<T>,
{
    instances
        .into_iter()
        .map(|(mechanism, start)| {
            let id = bank.add(mechanism.clone(), start)?;
            let sim = FixedTimestep::new(integrator.clone(), T::from_f64(DT), CAP, start)?;
            Ok(Twin { id, mechanism, sim })
        })
        .collect()
}

/// Advances every twin by `frame_time` and checks that each took the frame as the scene did
/// and that its instance in `bank` holds, bit for bit, the twin's state and interpolated
/// state.
fn follow<T, const N: usize, const K: usize, M, I, Z>(
    bank: &Bank<T, N, K, M, I, Z>,
    twins: &mut [Twin<T, N, M, I>],
    frame_time: T,
    frame: &SceneFrame<T>,
    alpha: T,
) -> Result<(), Error>
where
    T: Real,
    M: Mechanism<T, N>,
    I: Integrator<T, N, M> + Clone,
    Z: Sleep<T>,
{
    for twin in twins {
        let f = twin.sim.advance(&twin.mechanism, frame_time)?;
        assert_eq!(f.steps, frame.steps);
        assert_eq!(
            f.dropped.to_f64().to_bits(),
            frame.dropped.to_f64().to_bits()
        );
        assert_eq!(
            twin.sim.alpha().to_f64().to_bits(),
            alpha.to_f64().to_bits()
        );
        let state = bank.state(twin.id)?;
        assert_eq!(
            bits(&state),
            bits(twin.sim.current()),
            "{state:?} against {:?}",
            twin.sim.current()
        );
        assert_eq!(
            bits(&bank.interpolated(twin.id, alpha)?),
            bits(&twin.sim.interpolated())
        );
        assert_eq!(bank.status(twin.id)?, Status::Awake);
    }
    Ok(())
}

/// Frame times from a seeded generator, in steps of `DT`: a tenth of them 0, a tenth far
/// beyond the cap (from `CAP + 1` to `3 CAP` steps), one `T::MAX` (a debugger's pause), the
/// rest from 0 to 2.5 steps.
fn frame_times<T: Real>(seed: u64, count: usize) -> Vec<T> {
    let mut rng = Rng::new(seed);
    let cap = f64::from(CAP);
    (0..count)
        .map(|i| {
            let u = rng.unit();
            if i == count / 3 {
                T::MAX
            } else if u < 0.1 {
                T::zero()
            } else if u < 0.2 {
                rng.uniform(DT * (cap + 1.0), DT * 3.0 * cap)
            } else {
                rng.uniform(0.0, 2.5 * DT)
            }
        })
        .collect()
}

/// Mechanisms and their starts, to add to a bank.
type Instances<M, T, const N: usize> = Vec<(M, State<T, N>)>;

/// Pendulums of random mass, length and light damping, from random angles and rates.
fn pendulums<T: Real>(
    rng: &mut Rng,
    count: usize,
) -> Result<Instances<SimplePendulum<T>, T, 1>, Error> {
    (0..count)
        .map(|_| {
            let p = SimplePendulum::new(
                rng.uniform(0.5, 2.0),
                rng.uniform(0.5, 2.0),
                T::from_f64(G),
                rng.uniform(0.0, 0.3),
            )?;
            Ok((
                p,
                State::new(
                    T::zero(),
                    [rng.uniform(-2.0, 2.0)],
                    [rng.uniform(-2.0, 2.0)],
                ),
            ))
        })
        .collect()
}

/// Double pendulums of random masses and lengths, from random angles and rates (chaotic:
/// any difference of a bit would grow).
fn double_pendulums<T: Real>(
    rng: &mut Rng,
    count: usize,
) -> Result<Instances<DoublePendulum<T>, T, 2>, Error> {
    (0..count)
        .map(|_| {
            let p = DoublePendulum::new(
                rng.uniform(0.5, 2.0),
                rng.uniform(0.5, 2.0),
                rng.uniform(0.5, 1.5),
                rng.uniform(0.5, 1.5),
                T::from_f64(G),
            )?;
            let q = [rng.uniform(-1.5, 1.5), rng.uniform(-1.5, 1.5)];
            let qd = [rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)];
            Ok((p, State::new(T::zero(), q, qd)))
        })
        .collect()
}

/// Cart-poles of random masses, each pushed by its own constant input force (-5 to 5 N),
/// from near upright.
fn cart_poles<T: Real>(rng: &mut Rng, count: usize) -> Result<Instances<CartPole<T>, T, 2>, Error> {
    (0..count)
        .map(|_| {
            let mut c = CartPole::new(
                rng.uniform(0.5, 2.0),
                rng.uniform(0.05, 0.5),
                rng.uniform(0.3, 0.8),
                T::from_f64(G),
            )?;
            c.set_force(rng.uniform(-5.0, 5.0))?;
            let q = [rng.uniform(-1.0, 1.0), rng.uniform(-0.5, 0.5)];
            let qd = [rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5)];
            Ok((c, State::new(T::zero(), q, qd)))
        })
        .collect()
}

/// The adaptive Dormand-Prince 5(4) pair, tolerances for `T`.
fn dopri<T: Real, const N: usize>() -> Result<DormandPrince54<T, N>, Error> {
    let (rtol, atol) = (pick::<T>(1e-4, 1e-8), pick::<T>(1e-6, 1e-10));
    Ok(DormandPrince54::new(AdaptiveSettings::new(
        T::from_f64(rtol),
        T::from_f64(atol),
    )?))
}

/// One bank that never sleeps against its instances' twins, over 300 frames of
/// [`frame_times`].
fn one_bank_matches<T, const N: usize, const K: usize, M, I>(
    integrator: I,
    instances: Vec<(M, State<T, N>)>,
    seed: u64,
) -> Result<(), Error>
where
    T: Real,
    M: Mechanism<T, N> + Clone,
    I: Integrator<T, N, M> + Clone,
{
    let bank: Bank<T, N, K, M, I, NeverSleeps> = Bank::new(integrator.clone(), NeverSleeps)?;
    let mut scene = Scene::new(bank, T::from_f64(DT), CAP)?;
    let mut twins = add_twins(scene.banks_mut(), &integrator, instances)?;
    let mut steps = 0;
    for frame_time in frame_times::<T>(seed, 300) {
        let frame = scene.advance(frame_time)?;
        assert_eq!(frame.failed, 0);
        steps += frame.steps;
        follow(scene.banks(), &mut twins, frame_time, &frame, scene.alpha())?;
    }
    // The frames' mean of about 1.6 steps, less the cap: some 400 steps.
    assert!(steps > 300, "{steps} steps");
    Ok(())
}

/// Every instance of a bank that never sleeps is, bit for bit (state and interpolated
/// state), an independent `FixedTimestep` run of its mechanism: the same integrator, `dt`
/// and cap, and frame times from a seeded generator with zero frames, frames beyond the cap
/// and one of `T::MAX`. For pendulums (RK4), double pendulums (Stormer-Verlet, which keeps a
/// first guess between steps), cart-poles pushed by inputs (implicit midpoint) and pendulums
/// stepped by the adaptive Dormand-Prince pair (which runs ahead of the landing and keeps
/// its step size).
fn never_sleeping_banks_are_fixed_timestep_runs<T: Real>() -> Result<(), Error> {
    let mut rng = Rng::new(14);
    one_bank_matches::<T, 1, 8, _, _>(Rk4, pendulums(&mut rng, 6)?, 1)?;
    one_bank_matches::<T, 2, 8, _, _>(StormerVerlet::default(), double_pendulums(&mut rng, 5)?, 2)?;
    one_bank_matches::<T, 2, 4, _, _>(ImplicitMidpoint::default(), cart_poles(&mut rng, 4)?, 3)?;
    one_bank_matches::<T, 1, 4, _, _>(dopri::<T, 1>()?, pendulums(&mut rng, 4)?, 4)?;
    Ok(())
}

/// A tuple of five banks of three mechanism types and four integrators (the adaptive one
/// twice), and an array of three banks: every instance is, bit for bit, its own
/// `FixedTimestep` run.
fn banks_of_several_kinds_are_fixed_timestep_runs<T: Real>() -> Result<(), Error> {
    let mut rng = Rng::new(1414);
    let dt = T::from_f64(DT);
    let a: Bank<T, 1, 4, SimplePendulum<T>, DormandPrince54<T, 1>> =
        Bank::new(dopri()?, NeverSleeps)?;
    let b: Bank<T, 2, 4, DoublePendulum<T>, Rk4> = Bank::new(Rk4, NeverSleeps)?;
    let c: Bank<T, 2, 4, CartPole<T>, StormerVerlet<T, 2>> =
        Bank::new(StormerVerlet::default(), NeverSleeps)?;
    let d: Bank<T, 2, 4, DoublePendulum<T>, ImplicitMidpoint<T>> =
        Bank::new(ImplicitMidpoint::default(), NeverSleeps)?;
    let e: Bank<T, 2, 4, CartPole<T>, DormandPrince54<T, 2>> = Bank::new(dopri()?, NeverSleeps)?;
    let mut scene = Scene::new((a, b, c, d, e), dt, CAP)?;
    let (a, b, c, d, e) = scene.banks_mut();
    let mut ta = add_twins(a, &dopri()?, pendulums(&mut rng, 3)?)?;
    let mut tb = add_twins(b, &Rk4, double_pendulums(&mut rng, 3)?)?;
    let mut tc = add_twins(c, &StormerVerlet::default(), cart_poles(&mut rng, 3)?)?;
    let mut td = add_twins(
        d,
        &ImplicitMidpoint::default(),
        double_pendulums(&mut rng, 2)?,
    )?;
    let mut te = add_twins(e, &dopri()?, cart_poles(&mut rng, 2)?)?;
    for frame_time in frame_times::<T>(5, 250) {
        let frame = scene.advance(frame_time)?;
        assert_eq!(frame.failed, 0);
        let alpha = scene.alpha();
        let (a, b, c, d, e) = scene.banks();
        follow(a, &mut ta, frame_time, &frame, alpha)?;
        follow(b, &mut tb, frame_time, &frame, alpha)?;
        follow(c, &mut tc, frame_time, &frame, alpha)?;
        follow(d, &mut td, frame_time, &frame, alpha)?;
        follow(e, &mut te, frame_time, &frame, alpha)?;
    }

    let banks: [Bank<T, 1, 4, SimplePendulum<T>, StormerVerlet<T, 1>>; 3] = [
        Bank::new(StormerVerlet::default(), NeverSleeps)?,
        Bank::new(StormerVerlet::default(), NeverSleeps)?,
        Bank::new(StormerVerlet::default(), NeverSleeps)?,
    ];
    let mut scene = Scene::new(banks, dt, CAP)?;
    let mut twins = Vec::new();
    for bank in scene.banks_mut() {
        twins.push(add_twins(
            bank,
            &StormerVerlet::default(),
            pendulums(&mut rng, 3)?,
        )?);
    }
    for frame_time in frame_times::<T>(6, 250) {
        let frame = scene.advance(frame_time)?;
        assert_eq!(frame.failed, 0);
        let alpha = scene.alpha();
        for (bank, twins) in scene.banks().iter().zip(&mut twins) {
            follow(bank, twins, frame_time, &frame, alpha)?;
        }
    }
    Ok(())
}

/// A bank of pendulums that sleep by the rule `T <= 1e-6 J`, `|q''| <= 1e-3`, 60 steps.
type Sleepy<T> = Bank<T, 1, 4, SimplePendulum<T>, StormerVerlet<T, 1>, Sleeps<T>>;

/// A sleeper's state, time included, is bit for bit the one it fell asleep with over 10^5
/// frames of random lengths (0 to 3 steps), and it is drawn there whatever `alpha`, while
/// the bank keeps stepping an awake neighbour. One sleeper rests 5e-5 rad off the bottom,
/// where `|q''| = 4.9e-4 < 1e-3` lets it sleep but any step would move it; the other fell
/// asleep after its swing from 0.3 rad died out.
fn a_sleeper_does_not_change<T: Real>() -> Result<(), Error> {
    let (zero, one, g) = (T::zero(), T::one(), T::from_f64(G));
    let rule = Sleeps::new(T::from_f64(1e-6), T::from_f64(1e-3), 60)?;
    let bank: Sleepy<T> = Bank::new(StormerVerlet::default(), rule)?;
    let mut scene = Scene::new(bank, T::from_f64(DT), CAP)?;
    let bank = scene.banks_mut();
    let undamped = SimplePendulum::new(one, one, g, zero)?;
    let placed = bank.add(undamped, State::at_rest([T::from_f64(5e-5)]))?;
    let damped = SimplePendulum::new(one, one, g, T::from_f64(3.0))?;
    let settled = bank.add(damped, State::at_rest([T::from_f64(0.3)]))?;
    let swinging = bank.add(undamped, State::at_rest([T::HALF]))?;
    let mut frames = 0;
    while scene.banks().awake() > 1 {
        assert_eq!(scene.advance(T::from_f64(DT))?.failed, 0);
        frames += 1;
        assert!(frames < 30 * 120, "not asleep after 30 s");
    }
    let bank = scene.banks();
    assert_eq!(bank.status(placed)?, Status::Asleep);
    assert_eq!(bank.status(settled)?, Status::Asleep);
    assert_eq!(bank.status(swinging)?, Status::Awake);
    let frozen = [bits(&bank.state(placed)?), bits(&bank.state(settled)?)];
    assert_ne!(bank.state(placed)?.q[0], zero);
    let slept_at = scene.time();
    let mut rng = Rng::new(7);
    for _ in 0..100_000 {
        assert_eq!(scene.advance(rng.uniform(0.0, 3.0 * DT))?.failed, 0);
        let bank = scene.banks();
        for (id, frozen) in [placed, settled].into_iter().zip(&frozen) {
            assert_eq!(&bits(&bank.state(id)?), frozen);
            assert_eq!(&bits(&bank.interpolated(id, scene.alpha())?), frozen);
            assert_eq!(bank.status(id)?, Status::Asleep);
        }
    }
    // The neighbour kept time: some 1.5 10^5 steps (833 s at 120 Hz, less what the cap of
    // 4 dropped) since the sleepers' time stopped.
    let bank = scene.banks();
    assert_eq!(bank.state(swinging)?.t, scene.time());
    assert!(
        (scene.time() - slept_at).to_f64() > 1000.0,
        "{}",
        scene.time().to_f64()
    );
    assert_eq!(bank.awake(), 1);
    Ok(())
}

/// How a sleeper is woken.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Way {
    /// A state written: 0.3 rad, at rest.
    State,
    /// An angular impulse of 2 N m s.
    Impulse,
    /// Its damping changed, from 30 to 0 N m s/rad: it swings.
    Modify,
    /// An explicit wake.
    Wake,
    /// A contact event.
    Contact,
}

/// An overdamped pendulum (`b = 30 N m s/rad`, `m = l = 1`) creeps back to the bottom at
/// `th' = -0.331 th`: it falls asleep by the rule `T <= 1e-6 J`, `|q''| <= 0.5`, 60 steps, at
/// `th` near 4e-3 rad, away from the bottom, so that a woken one moves (and an explicit wake
/// or contact is not a no-op).
fn creeper<T: Real>() -> Result<SimplePendulum<T>, Error> {
    SimplePendulum::new(T::one(), T::one(), T::from_f64(G), T::from_f64(30.0))
}

/// Frames of 0, 1 or 2 steps exactly, so that the scene's accumulator stays at zero and a
/// fresh `FixedTimestep` started between two frames takes the same steps.
fn whole_frame<T: Real>(rng: &mut Rng) -> T {
    let u = rng.unit();
    let steps = if u < 0.1 {
        0.0
    } else if u < 0.2 {
        2.0
    } else {
        1.0
    };
    T::from_f64(steps) * T::from_f64(DT)
}

/// After each way of waking (a state written, an impulse, a parameter changed, an explicit
/// wake, a contact event, a changed input), the instance's trajectory is, bit for bit (and
/// its time to two ulps), a fresh `FixedTimestep` run of a new integrator from the state it
/// woke with, for as long as it stays awake. (Stormer-Verlet keeps only a first guess from
/// its last step, which does not change these bits, and RK4 nothing: that a wake restarts
/// the integrator shows with the adaptive pair, in the next test.)
fn a_woken_instance_is_a_fresh_start<T: Real>() -> Result<(), Error> {
    let dt = T::from_f64(DT);
    let creepers: Bank<T, 1, 8, SimplePendulum<T>, StormerVerlet<T, 1>, Sleeps<T>> = Bank::new(
        StormerVerlet::default(),
        Sleeps::new(T::from_f64(1e-6), T::HALF, 60)?,
    )?;
    let carts: Bank<T, 2, 2, CartPole<T>, Rk4, Sleeps<T>> =
        Bank::new(Rk4, Sleeps::new(T::from_f64(1e-6), T::from_f64(1e-3), 60)?)?;
    let mut scene = Scene::new((creepers, carts), dt, CAP)?;
    let (creepers, carts) = scene.banks_mut();
    let ways = [
        Way::State,
        Way::Impulse,
        Way::Modify,
        Way::Wake,
        Way::Contact,
    ];
    let starts = [0.02, -0.017, 0.015, -0.02, 0.018];
    let mut ids = Vec::new();
    for start in starts {
        ids.push(creepers.add(creeper()?, State::at_rest([T::from_f64(start)]))?);
    }
    // Hanging (th = pi), pushed by nothing.
    let cart = carts.add(
        CartPole::new(T::one(), T::from_f64(0.1), T::HALF, T::from_f64(G))?,
        State::at_rest([T::zero(), T::PI]),
    )?;
    let mut rng = Rng::new(41);
    let mut frames = 0;
    while scene.banks().0.awake() + scene.banks().1.awake() > 0 {
        assert_eq!(scene.advance(whole_frame(&mut rng))?.failed, 0);
        frames += 1;
        assert!(frames < 20 * 120, "not asleep after some 20 s");
    }
    assert_eq!(scene.alpha(), T::zero());
    for &id in &ids {
        let th = scene.banks().0.state(id)?.q[0].to_f64();
        println!("asleep at {th:e} rad");
        // Asleep off the bottom, where the fresh run moves.
        assert!(th.abs() > 1e-3 && th.abs() < 1e-2, "asleep at {th}");
    }

    let (creepers, carts) = scene.banks_mut();
    for (&id, way) in ids.iter().zip(ways) {
        match way {
            Way::State => creepers.set_state(id, State::at_rest([T::from_f64(0.3)]))?,
            Way::Impulse => {
                creepers.apply_impulse(id, &[T::TWO].into())?;
            }
            Way::Modify => creepers.modify(id, |p| {
                *p = SimplePendulum::new(p.mass(), p.length(), p.gravity(), T::zero())?;
                Ok(())
            })?,
            Way::Wake => creepers.wake(id)?,
            Way::Contact => creepers.contact(id)?,
        }
        assert_eq!(creepers.status(id)?, Status::Awake, "{way:?}");
    }
    carts.set_input(cart, T::HALF)?;
    assert_eq!(carts.status(cart)?, Status::Awake);
    let now = scene.time();
    let twin = |id: Id| -> Result<_, Error> {
        let state = scene.banks().0.state(id)?;
        assert_eq!(state.t, now, "a woken instance takes the bank's time");
        let mechanism = *scene.banks().0.mechanism(id)?;
        Ok((
            mechanism,
            FixedTimestep::new(StormerVerlet::default(), dt, CAP, state)?,
        ))
    };
    let mut twins = ids
        .iter()
        .map(|&id| twin(id))
        .collect::<Result<Vec<_>, _>>()?;
    let cart_start = scene.banks().1.state(cart)?;
    let cart_mechanism = *scene.banks().1.mechanism(cart)?;
    let mut cart_twin = FixedTimestep::new(Rk4, dt, CAP, cart_start)?;
    // Compared while awake; a creeper woken where it slept creeps on and sleeps again, at
    // the end of one of the frame's steps: at the fresh run's last state or, in a frame of
    // two steps, the one before.
    let mut compared = [0u32; 5];
    let mut slept_again = [false; 5];
    let mut cart_compared = 0;
    for _ in 0..600 {
        let frame_time = whole_frame(&mut rng);
        let frame = scene.advance(frame_time)?;
        assert_eq!(frame.failed, 0);
        let (creepers, carts) = scene.banks();
        for (i, (mechanism, sim)) in twins.iter_mut().enumerate() {
            if slept_again[i] {
                continue;
            }
            let f = sim.advance(mechanism, frame_time)?;
            assert_eq!(f.steps, frame.steps);
            let (id, way) = (ids[i], ways[i]);
            if creepers.status(id)? == Status::Awake {
                same_motion(&creepers.state(id)?, sim.current(), &format!("{way:?}"));
                compared[i] += frame.steps;
                continue;
            }
            slept_again[i] = true;
            let s = creepers.state(id)?;
            let at = bits(&s).1;
            let last = at == bits(sim.current()).1;
            let one_before = frame.steps == 2 && at == bits(sim.previous()).1;
            assert!(
                last || one_before,
                "{way:?}: asleep at {s:?}, {:?}",
                sim.current()
            );
            assert_eq!(s.qd[0], T::zero());
            compared[i] += if last { frame.steps } else { 1 };
        }
        cart_twin.advance(&cart_mechanism, frame_time)?;
        assert_eq!(carts.status(cart)?, Status::Awake);
        same_motion(&carts.state(cart)?, cart_twin.current(), "input");
        cart_compared += frame.steps;
    }
    println!("steps compared after waking: {compared:?} (creepers), {cart_compared} (cart)");
    for (way, &n) in ways.iter().zip(&compared) {
        // Written, pushed and undamped ones move all along (some 600 steps: 8 s and more
        // for the first two to creep back below the kinetic threshold; the third swings);
        // woken where they slept, they stay awake at least the rule's 60 steps.
        let least = if matches!(way, Way::Wake | Way::Contact) {
            60
        } else {
            500
        };
        assert!(n >= least, "{way:?}: {n} steps compared");
    }
    Ok(())
}

/// A mechanism stepped by hand by an integrator of its own, at the times the caller gives.
#[derive(Debug, Clone)]
struct ByHand<T: Real, const N: usize, M, I> {
    mechanism: M,
    integrator: I,
    state: State<T, N>,
}

impl<T: Real, const N: usize, M: Mechanism<T, N>, I: Integrator<T, N, M>> ByHand<T, N, M, I> {
    /// One step of `dt`, landing at `t` as a scene's step does.
    fn step(&mut self, dt: T, t: T) -> Result<(), Error> {
        let mut next = self.integrator.step(&self.mechanism, &self.state, dt)?;
        next.t = t;
        self.state = next;
        Ok(())
    }
}

/// A new input or new parameters restart an awake instance too: from then on it is a fresh
/// run of the integrator from the state it had. Shown with the adaptive Dormand-Prince pair,
/// which runs ahead of its landings and, when a step starts where its last ended, continues
/// from there. Two pushed carts are, bit for bit, runs by hand at the scene's step times
/// until one gets a new input and the other new masses and force; from then on each is, bit
/// for bit, a run by a fresh integrator from its state, and parts from a run that took the
/// new mechanism but kept its integrator.
///
/// (A fresh `FixedTimestep` would count its time from the change, an ulp or so away from the
/// scene's clock, and the adaptive pair lands on `t + dt`: its bits would differ by that
/// alone. The fixed-step methods of the test above do not read `t`.)
fn a_change_restarts_an_awake_instance<T: Real>() -> Result<(), Error> {
    let dt = T::from_f64(DT);
    let bank: Bank<T, 2, 2, CartPole<T>, DormandPrince54<T, 2>> = Bank::new(dopri()?, NeverSleeps)?;
    let mut scene = Scene::new(bank, dt, CAP)?;
    let (mut ids, mut runs) = (Vec::new(), Vec::new());
    for (force, th) in [(1.0, 0.1), (-2.0, -0.2)] {
        let mut mechanism = CartPole::new(T::one(), T::from_f64(0.1), T::HALF, T::from_f64(G))?;
        mechanism.set_force(T::from_f64(force))?;
        let state = State::at_rest([T::zero(), T::from_f64(th)]);
        ids.push(scene.banks_mut().add(mechanism, state)?);
        runs.push(ByHand {
            mechanism,
            integrator: dopri()?,
            state,
        });
    }
    // The scene's clock: its start plus the steps taken, compensated.
    let mut clock = Clock::new(T::zero());
    let mut rng = Rng::new(43);
    let mut kept = Vec::new();
    let mut parted = 0;
    for frame in 0..400 {
        if frame == 200 {
            let bank = scene.banks_mut();
            bank.set_input(ids[0], T::from_f64(-1.5))?;
            bank.modify(ids[1], |c| {
                *c = CartPole::new(T::TWO, T::from_f64(0.2), T::HALF, T::from_f64(G))?;
                c.set_force(T::from_f64(3.0))
            })?;
            kept = runs.clone();
            for ((run, keeping), &id) in runs.iter_mut().zip(&mut kept).zip(&ids) {
                let mechanism = *scene.banks().mechanism(id)?;
                assert_eq!(bits(&scene.banks().state(id)?), bits(&run.state));
                keeping.mechanism = mechanism;
                *run = ByHand {
                    mechanism,
                    integrator: dopri()?,
                    state: run.state,
                };
            }
        }
        let f = scene.advance(rng.uniform(0.0, 2.5 * DT))?;
        assert_eq!(f.failed, 0);
        for _ in 0..f.steps {
            clock.tick(dt);
            for run in runs.iter_mut().chain(kept.iter_mut()) {
                run.step(dt, clock.time())?;
            }
        }
        let bank = scene.banks();
        for (run, &id) in runs.iter().zip(&ids) {
            assert_eq!(bits(&bank.state(id)?), bits(&run.state), "frame {frame}");
        }
        for (run, &id) in kept.iter().zip(&ids) {
            if bits(&bank.state(id)?) != bits(&run.state) {
                parted += 1;
            }
        }
    }
    println!("states of runs that kept their integrator that differ: {parted} of 400");
    assert!(parted > 0);
    Ok(())
}

for_f32_and_f64!(
    never_sleeping_banks_are_fixed_timestep_runs,
    banks_of_several_kinds_are_fixed_timestep_runs,
    a_sleeper_does_not_change,
    a_woken_instance_is_a_fresh_start,
    a_change_restarts_an_awake_instance
);
