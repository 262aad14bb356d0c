//! A scene's errors (issue 14): bad input gets its specific error and changes nothing, and an
//! instance whose step fails is set aside with its last good state while the others go on.

use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, Mechanism, Real, State};
use lagrange_integrators::scene::{Bank, Id, NeverSleeps, Scene, Sleep, Sleeps, Status};
use lagrange_integrators::{ExplicitEuler, FixedTimestep, Integrator, Rk4, StormerVerlet};
use lagrange_systems::{CartPole, SimplePendulum, SphericalPendulum, SpringMassDamper};
use lagrange_tests::for_f32_and_f64;

const DT: f64 = 1.0 / 120.0;
const G: f64 = 9.81;

/// `Err(InvalidParameter { name, .. })` with exactly this name.
fn refuses<V: core::fmt::Debug>(result: Result<V, Error>, expected: &str) {
    assert!(
        matches!(result, Err(Error::InvalidParameter { name, .. }) if name == expected),
        "expected InvalidParameter {{ name: {expected} }}, got {result:?}"
    );
}

/// The values no non-negative parameter may take.
fn negative_or_not_finite<T: Real>() -> [T; 4] {
    [-T::one(), T::from_f64(f64::NAN), T::INFINITY, -T::INFINITY]
}

/// Everything about a bank's instances: id, state and drawn state bits, status, mechanism;
/// and its size, awake count and time.
fn picture<T, const N: usize, const K: usize, M, I, Z>(bank: &Bank<T, N, K, M, I, Z>) -> String
where
    T: Real,
    M: Mechanism<T, N> + core::fmt::Debug,
    I: Integrator<T, N, M> + Clone,
    Z: Sleep<T>,
{
    let mut out = format!(
        "len {} awake {} time {:?}\n",
        bank.len(),
        bank.awake(),
        bank.time().to_f64().to_bits()
    );
    for (id, s) in bank.iter() {
        let drawn = bank.interpolated(id, T::HALF).map(|d| bits(&d));
        let m = bank.mechanism(id).map(|m| format!("{m:?}"));
        out += &format!(
            "{id:?} {:?} {drawn:?} {:?} {m:?}\n",
            bits(&s),
            bank.status(id)
        );
    }
    out
}

fn bits<T: Real, const N: usize>(s: &State<T, N>) -> Vec<u64> {
    core::iter::once(s.t)
        .chain(s.q.iter().copied())
        .chain(s.qd.iter().copied())
        .map(|x| x.to_f64().to_bits())
        .collect()
}

/// Constructors refuse what they cannot use, by name: a sleep rule's thresholds (negative or
/// not finite), its step count (0) and check interval (0, or above the steps); a bank of
/// capacity 0; a scene's step (not positive and finite) and cap (0).
fn constructors_refuse_bad_parameters<T: Real>() -> Result<(), Error> {
    let (kinetic, accel) = (T::from_f64(1e-6), T::from_f64(1e-3));
    for bad in negative_or_not_finite::<T>() {
        refuses(Sleeps::new(bad, accel, 60), "kinetic");
        refuses(Sleeps::new(kinetic, bad, 60), "acceleration");
    }
    refuses(Sleeps::new(kinetic, accel, 0), "steps");
    // Zero thresholds are a rule (asleep only exactly at rest), and one step is enough.
    let exact = Sleeps::new(T::zero(), T::zero(), 1)?;
    assert_eq!(
        (exact.interval(), exact.kinetic(), exact.acceleration()),
        (1, T::zero(), T::zero())
    );
    let rule = Sleeps::new(kinetic, accel, 60)?;
    assert_eq!(rule.interval(), 8);
    assert_eq!(Sleeps::new(kinetic, accel, 5)?.interval(), 5);
    refuses(rule.checked_every(0), "interval");
    refuses(rule.checked_every(61), "interval");
    refuses(rule.checked_every(u32::MAX), "interval");
    assert_eq!(rule.checked_every(60)?.interval(), 60);
    assert_eq!(rule.checked_every(1)?.interval(), 1);
    assert!(!rule.driven_too() && rule.even_when_driven().driven_too());

    refuses(
        Bank::<T, 1, 0, SimplePendulum<T>, Rk4>::new(Rk4, NeverSleeps),
        "K",
    );
    refuses(
        Bank::<T, 1, 0, SimplePendulum<T>, Rk4, Sleeps<T>>::new(Rk4, rule),
        "K",
    );
    let bank = || Bank::<T, 1, 2, SimplePendulum<T>, Rk4>::new(Rk4, NeverSleeps);
    for bad in [T::zero(), -T::one(), T::from_f64(f64::NAN), T::INFINITY] {
        refuses(Scene::new(bank()?, bad, 4), "dt");
    }
    refuses(
        Scene::new(bank()?, T::from_f64(DT), 0),
        "max_steps_per_frame",
    );
    Ok(())
}

type Props<T> = Bank<T, 1, 4, SimplePendulum<T>, StormerVerlet<T, 1>, Sleeps<T>>;
type Carts<T> = Bank<T, 2, 2, CartPole<T>, Rk4, Sleeps<T>>;

/// The picture of a whole scene: its time and alpha, and each bank's.
fn scene_picture<T: Real>(scene: &Scene<T, (Props<T>, Carts<T>)>) -> String {
    let (props, carts) = scene.banks();
    format!(
        "t {:?} alpha {:?}\n{}{}",
        scene.time().to_f64().to_bits(),
        scene.alpha().to_f64().to_bits(),
        picture(props),
        picture(carts)
    )
}

/// Bad input to a scene with sleeping and awake instances of two banks, one of them full:
/// each call gets its specific error and changes nothing at all (every instance's state,
/// drawn state, status and mechanism, the banks' sizes and times, the scene's time and
/// alpha), and nothing panics. Non-finite states on add and write (`NonFiniteState`); a full
/// bank (`BankFull`); non-finite impulses (`impulse`), and a finite one whose velocities
/// overflow (`NonFiniteState`); a non-finite input (`input`, the name of `set_input`'s own
/// parameter) or refused modification (the
/// modification's error, even after it changed its copy); negative and non-finite frame
/// times (`frame_time`); `alpha` outside `[0, 1]` (`alpha`). Then handles that name nothing
/// (`NoSuchInstance`) for every method: one removed (also once its index is given to a new
/// instance, which it does not touch), and one of a larger bank with an index beyond this
/// bank's capacity.
fn bad_input_changes_nothing<T: Real>() -> Result<(), Error> {
    let (one, nan, inf) = (T::one(), T::from_f64(f64::NAN), T::INFINITY);
    let rule = Sleeps::new(T::from_f64(1e-6), T::from_f64(1e-3), 60)?;
    let props: Props<T> = Bank::new(StormerVerlet::default(), rule)?;
    let carts: Carts<T> = Bank::new(Rk4, rule)?;
    let mut scene = Scene::new((props, carts), T::from_f64(DT), 4)?;
    let (props, carts) = scene.banks_mut();
    // Light (m l^2 = 1/8): an impulse of T::MAX overflows its velocity.
    let light = SimplePendulum::new(T::HALF, T::HALF, T::from_f64(G), T::zero())?;
    let sleeper = props.add(light, State::at_rest([T::from_f64(5e-5)]))?;
    let swinging = props.add(light, State::at_rest([T::HALF]))?;
    let cart = CartPole::new(one, T::from_f64(0.1), T::HALF, T::from_f64(G))?;
    let hanging = carts.add(cart, State::at_rest([T::zero(), T::PI]))?;
    let mut pushed = cart;
    pushed.set_force(one)?;
    let driven = carts.add(pushed, State::at_rest([T::zero(), T::from_f64(0.1)]))?;
    for _ in 0..100 {
        scene.advance(T::from_f64(DT))?;
    }
    scene.advance(T::from_f64(0.3 * DT))?;
    let (props, carts) = scene.banks();
    assert_eq!(props.status(sleeper)?, Status::Asleep);
    assert_eq!(carts.status(hanging)?, Status::Asleep);
    assert_eq!(props.status(swinging)?, Status::Awake);
    assert_eq!(carts.status(driven)?, Status::Awake);
    assert!(scene.alpha() > T::zero());

    let before = scene_picture(&scene);
    let unchanged = |scene: &Scene<T, _>, what: &str| {
        assert_eq!(scene_picture(scene), before, "{what} changed the scene");
    };
    let ok = State::at_rest([T::zero()]);
    let bad_states = [
        State::at_rest([nan]),
        State::new(T::zero(), [T::zero()], [inf]),
        State::new(nan, [T::zero()], [T::zero()]),
        State::new(-inf, [T::zero()], [T::zero()]),
    ];
    for bad in bad_states {
        let (props, _) = scene.banks_mut();
        assert_eq!(props.add(light, bad), Err(Error::NonFiniteState));
        for id in [sleeper, swinging] {
            assert_eq!(props.set_state(id, bad), Err(Error::NonFiniteState));
        }
        unchanged(&scene, "a non-finite state");
    }
    let (_, carts) = scene.banks_mut();
    assert_eq!(
        carts.add(cart, State::at_rest([T::zero(), T::zero()])),
        Err(Error::BankFull { capacity: 2 })
    );
    unchanged(&scene, "adding to a full bank");
    for bad in [nan, inf, -inf] {
        let (props, carts) = scene.banks_mut();
        for id in [sleeper, swinging] {
            refuses(props.apply_impulse(id, &SVector::from([bad])), "impulse");
        }
        refuses(
            carts.apply_impulse(hanging, &SVector::from([T::zero(), bad])),
            "impulse",
        );
        for id in [hanging, driven] {
            refuses(carts.set_input(id, bad), "input");
            refuses(carts.modify(id, |c| c.set_force(bad)), "force");
        }
        unchanged(&scene, "a non-finite impulse or input");
    }
    let (props, _) = scene.banks_mut();
    for id in [sleeper, swinging] {
        for p in [T::MAX, -T::MAX] {
            assert_eq!(
                props.apply_impulse(id, &SVector::from([p])),
                Err(Error::NonFiniteState)
            );
        }
        let refused = props.modify(id, |p| {
            *p = SimplePendulum::new(one, one, one, one)?;
            SimplePendulum::new(one, -one, one, one)
        });
        refuses(refused, "length");
    }
    unchanged(&scene, "an overflowing impulse or a refused modification");
    for bad in [-one, -T::MIN_POSITIVE, nan, inf, -inf] {
        refuses(scene.advance(bad), "frame_time");
        unchanged(&scene, "a bad frame time");
    }
    for bad in [-T::from_f64(0.1), T::from_f64(1.1), nan, inf, -inf] {
        let (props, carts) = scene.banks();
        refuses(props.interpolated(sleeper, bad), "alpha");
        refuses(props.interpolated(swinging, bad), "alpha");
        refuses(carts.interpolated(driven, bad), "alpha");
    }

    // A removed instance's handle, before and after its index is given to another.
    let (props, _) = scene.banks_mut();
    let (_, last) = props.remove(swinging)?;
    assert!(last.is_finite());
    let before = scene_picture(&scene);
    check_names_nothing(&mut scene, swinging, &before)?;
    let (props, _) = scene.banks_mut();
    let newcomer = props.add(light, ok)?;
    assert_eq!(newcomer.index(), swinging.index());
    assert_ne!(newcomer, swinging);
    let before = scene_picture(&scene);
    check_names_nothing(&mut scene, swinging, &before)?;
    // A handle of a larger bank, beyond this bank's capacity.
    let mut large: Bank<T, 1, 16, SimplePendulum<T>, Rk4> = Bank::new(Rk4, NeverSleeps)?;
    let mut foreign = None;
    for _ in 0..16 {
        foreign = Some(large.add(light, ok)?);
    }
    let foreign = foreign.ok_or(Error::NoSuchInstance)?;
    assert_eq!(foreign.index(), 15);
    check_names_nothing(&mut scene, foreign, &before)?;
    Ok(())
}

/// Every method of the props' bank given `id` answers `NoSuchInstance`, and so do the
/// carts' when `id`'s index is beyond their capacity; the scene's picture stays `before`.
fn check_names_nothing<T: Real>(
    scene: &mut Scene<T, (Props<T>, Carts<T>)>,
    id: Id,
    before: &str,
) -> Result<(), Error> {
    let none = Err::<(), _>(Error::NoSuchInstance);
    let (props, carts) = scene.banks_mut();
    assert_eq!(props.state(id).map(|_| ()), none);
    assert_eq!(props.interpolated(id, T::HALF).map(|_| ()), none);
    assert_eq!(props.interpolated(id, T::from_f64(2.0)).map(|_| ()), none);
    assert_eq!(props.mechanism(id).map(|_| ()), none);
    assert_eq!(props.status(id).map(|_| ()), none);
    assert_eq!(props.energies(id).map(|_| ()), none);
    assert_eq!(props.set_state(id, State::at_rest([T::one()])), none);
    assert_eq!(props.apply_impulse(id, &SVector::from([T::one()])), none);
    assert_eq!(props.modify(id, |_| Ok(())), none);
    assert_eq!(props.wake(id), none);
    assert_eq!(props.contact(id), none);
    assert_eq!(props.remove(id).map(|_| ()), none);
    if id.index() >= carts.capacity() {
        assert_eq!(carts.state(id).map(|_| ()), none);
        assert_eq!(carts.set_input(id, T::one()), none);
        assert_eq!(carts.wake(id), none);
        assert_eq!(carts.remove(id).map(|_| ()), none);
    }
    assert_eq!(
        scene_picture(scene),
        before,
        "a handle that names nothing changed the scene"
    );
    Ok(())
}

/// A stiff spring (`k = 1e8`, `m = 1`) stepped by explicit Euler at `dt = 0.01` (`h w =
/// 100`, far past its stability limit: the amplitude grows 100 times a step) overflows in
/// some 20 steps (f32) or 155 (f64), and a spherical pendulum let go on its axis (`sin th =
/// 0`, where its equations are singular) fails at its first step. Each is reported in
/// `SceneFrame::failed` in exactly the frame it fails, gets `Status::Failed` with the step's
/// error, keeps its last good state (finite: bit for bit the last state of a
/// `FixedTimestep` run, which stops there too), drawn there, and is not stepped any more; the
/// two soft springs in its bank go on, bit for bit as in a bank without it. A wake retries:
/// the spring fails again at the next step; a state written runs it again until it
/// overflows again. Both with a bank that sleeps and one that does not.
fn a_failed_step_sets_one_instance_aside<T: Real, Z: Sleep<T>>(sleep: Z) -> Result<(), Error> {
    let dt = T::from_f64(0.01);
    type Springs<T, Z> = Bank<T, 1, 4, SpringMassDamper<T>, ExplicitEuler, Z>;
    let soft = [
        SpringMassDamper::new(T::one(), T::one(), T::from_f64(0.1))?,
        SpringMassDamper::new(T::TWO, T::from_f64(4.0), T::zero())?,
    ];
    let stiff = SpringMassDamper::new(T::one(), T::from_f64(1e8), T::zero())?;
    let start = State::at_rest([T::one()]);
    let with: Springs<T, Z> = Bank::new(ExplicitEuler, sleep)?;
    let without: Springs<T, Z> = Bank::new(ExplicitEuler, sleep)?;
    let spherical: Bank<T, 2, 2, SphericalPendulum<T>, Rk4, Z> = Bank::new(Rk4, sleep)?;
    let mut scene = Scene::new((with, spherical), dt, 4)?;
    let mut reference = Scene::new(without, dt, 4)?;
    let (with, spherical) = scene.banks_mut();
    let a = with.add(soft[0], start)?;
    let bad = with.add(stiff, start)?;
    let b = with.add(soft[1], start)?;
    let ra = reference.banks_mut().add(soft[0], start)?;
    let rb = reference.banks_mut().add(soft[1], start)?;
    let ball = SphericalPendulum::new(T::one(), T::one(), T::from_f64(G))?;
    let on_axis = spherical.add(ball, State::at_rest([T::zero(), T::zero()]))?;
    let off_axis = spherical.add(
        ball,
        State::new(T::zero(), [T::HALF, T::zero()], [T::zero(), T::one()]),
    )?;
    let mut twin = FixedTimestep::new(ExplicitEuler, dt, 4, start)?;
    let mut twin_failed_at = None;
    let (mut failed_at, mut failures) = (None, 0);
    for frame in 0..300 {
        let f = scene.advance(dt)?;
        reference.advance(dt)?;
        if twin_failed_at.is_none() {
            match twin.advance(&stiff, dt) {
                Ok(_) => {}
                Err(e) => {
                    assert_eq!(e, Error::NonFiniteState);
                    twin_failed_at = Some(frame);
                }
            }
        }
        failures += f.failed;
        let (with, spherical) = scene.banks();
        if frame == 0 {
            // The pendulum on its axis, at its first step.
            let status = spherical.status(on_axis)?;
            assert!(
                matches!(status, Status::Failed(Error::Singularity { .. })),
                "{status:?}"
            );
            assert_eq!(f.failed, 1);
            assert_eq!(
                bits(&spherical.state(on_axis)?),
                bits(&State::at_rest([T::zero(), T::zero()]))
            );
        }
        if f.failed > u32::from(frame == 0) {
            assert!(failed_at.is_none(), "failed twice");
            failed_at = Some(frame);
        }
        if failed_at.is_some() {
            assert_eq!(with.status(bad)?, Status::Failed(Error::NonFiniteState));
            let s = with.state(bad)?;
            assert!(s.is_finite());
            assert_eq!(bits(&s), bits(twin.current()));
            assert_eq!(bits(&with.interpolated(bad, scene.alpha())?), bits(&s));
        } else {
            assert_eq!(with.status(bad)?, Status::Awake);
        }
        for (id, rid) in [(a, ra), (b, rb)] {
            assert_eq!(with.status(id)?, reference.banks().status(rid)?);
            assert_eq!(bits(&with.state(id)?), bits(&reference.banks().state(rid)?));
        }
        assert_eq!(spherical.status(off_axis)?, Status::Awake);
    }
    let failed_at = failed_at.ok_or(Error::NoConvergence { iterations: 0 })?;
    println!("the stiff spring failed at frame {failed_at}; the fixed-timestep run at {twin_failed_at:?}");
    assert_eq!(Some(failed_at), twin_failed_at);
    assert_eq!(failures, 2);
    assert_eq!(scene.banks().0.awake(), 2);

    // A wake retries: it fails again at once, from its last good state.
    let last = scene.banks().0.state(bad)?;
    scene.banks_mut().0.wake(bad)?;
    assert_eq!(scene.banks().0.status(bad)?, Status::Awake);
    assert_eq!(scene.advance(dt)?.failed, 1);
    assert_eq!(
        scene.banks().0.status(bad)?,
        Status::Failed(Error::NonFiniteState)
    );
    assert_eq!(scene.banks().0.state(bad)?.q, last.q);
    // A state written runs it again, until it overflows again.
    scene.banks_mut().0.set_state(bad, start)?;
    let mut steps = 0;
    while scene.banks().0.status(bad)? == Status::Awake {
        failures = scene.advance(dt)?.failed;
        steps += 1;
        assert!(steps < 300);
    }
    assert_eq!(failures, 1);
    assert_eq!(steps, failed_at + 1);
    Ok(())
}

/// `Id`'s docs: after its instance is removed "and in any other bank, it names nothing
/// (`Error::NoSuchInstance`)". Two banks of the same type, one instance each: the first
/// bank's handle, given to the second, should name nothing there.
fn a_handle_names_nothing_in_another_bank<T: Real>() -> Result<(), Error> {
    let p = SimplePendulum::new(T::one(), T::one(), T::from_f64(G), T::zero())?;
    let mut first: Bank<T, 1, 2, SimplePendulum<T>, Rk4> = Bank::new(Rk4, NeverSleeps)?;
    let mut second: Bank<T, 1, 2, SimplePendulum<T>, Rk4> = Bank::new(Rk4, NeverSleeps)?;
    let mine = first.add(p, State::at_rest([T::HALF]))?;
    let theirs = second.add(p, State::at_rest([T::one()]))?;
    assert_eq!(second.state(theirs)?.q[0], T::one());
    assert_eq!(
        second.state(mine).map(|s| s.q[0]),
        Err(Error::NoSuchInstance),
        "the first bank's handle names the second bank's instance"
    );
    Ok(())
}

fn failures_never_sleeping<T: Real>() -> Result<(), Error> {
    a_failed_step_sets_one_instance_aside::<T, _>(NeverSleeps)
}

fn failures_sleeping<T: Real>() -> Result<(), Error> {
    a_failed_step_sets_one_instance_aside::<T, _>(Sleeps::new(
        T::from_f64(1e-6),
        T::from_f64(1e-3),
        60,
    )?)
}

/// Issue 15 (the scenes' hostile-input campaign): a finite state whose energy is not (a speed
/// of `sqrt(T::MAX)` squared) gets `NonFiniteState` from `energies`, never `Ok` with an
/// infinity, and the bank is unchanged; a state of finite energy gets it.
fn energies_are_finite_or_refused<T: Real>() -> Result<(), Error> {
    let mut bank: Bank<T, 1, 2, SimplePendulum<T>, Rk4> = Bank::new(Rk4, NeverSleeps)?;
    let m = SimplePendulum::new(T::one(), T::one(), T::from_f64(G), T::zero())?;
    let fast = bank.add(
        m,
        State::new(T::zero(), [T::one()], [T::MAX.sqrt() * T::TWO]),
    )?;
    let slow = bank.add(m, State::at_rest([T::one()]))?;
    let before = picture(&bank);
    assert_eq!(bank.energies(fast), Err(Error::NonFiniteState));
    assert_eq!(picture(&bank), before);
    let e = bank.energies(slow)?;
    assert!(e.kinetic == T::zero() && e.potential.is_finite() && e.total().is_finite());
    Ok(())
}

for_f32_and_f64!(
    energies_are_finite_or_refused,
    constructors_refuse_bad_parameters,
    bad_input_changes_nothing,
    a_handle_names_nothing_in_another_bank,
    failures_never_sleeping,
    failures_sleeping
);
