//! A bank's bookkeeping seen from outside: how many instances it holds, its time and the time
//! an instance takes from it, an instance's energies, the scene's step, and a failure inside
//! a group of instances stepped side by side, counted once.

use lagrange_core::{Error, Lagrangian, Real, State};
use lagrange_integrators::scene::{Bank, InLanes, NeverSleeps, Scene, Sleeps, Status};
use lagrange_integrators::{ExplicitEuler, FixedTimestep, Rk4};
use lagrange_systems::{SimplePendulum, SpringMassDamper};
use lagrange_tests::for_f32_and_f64;

const G: f64 = 9.81;

/// Counts, time and energies: a bank counts what it holds; the scene keeps the step it was
/// given; an instance added or written takes the bank's time, not its state's; `total` is
/// `T + V`, exactly the mechanism's energy.
fn counts_times_and_energies<T: Real>() -> Result<(), Error> {
    let dt = T::from_f64(0.01);
    let m = SimplePendulum::new(T::one(), T::one(), T::from_f64(G), T::zero())?;
    let bank: Bank<T, 1, 3, SimplePendulum<T>, Rk4> = Bank::new(Rk4, NeverSleeps)?;
    assert!(bank.is_empty());
    assert_eq!(bank.len(), 0);
    let mut scene = Scene::new(bank, dt, 4)?;
    assert_eq!(scene.dt(), dt);
    for _ in 0..3 {
        scene.advance(dt)?;
    }
    // Three steps of 0.01 from zero, within an ulp.
    let now = scene.time();
    assert!((now.to_f64() - 0.03).abs() <= 0.03 * T::EPSILON.to_f64());
    let bank = scene.banks_mut();
    assert_eq!(bank.time(), now);
    // A state of another time: the instance takes the bank's.
    let s = State::new(T::from_f64(7.0), [T::one()], [T::TWO]);
    let a = bank.add(m, s)?;
    assert_eq!(bank.state(a)?.t, now);
    assert_eq!(bank.state(a)?.q, s.q);
    let b = bank.add(m, State::at_rest([T::HALF]))?;
    assert!(!bank.is_empty() && bank.len() == 2);
    bank.set_state(b, State::new(T::from_f64(-5.0), [T::zero()], [T::one()]))?;
    assert_eq!(bank.state(b)?.t, now);
    assert_eq!(bank.status(b)?, Status::Awake);
    // T = m l^2 q'^2 / 2 = 2 exactly at q' = 2; V from the mechanism.
    let e = bank.energies(a)?;
    assert_eq!(e.kinetic, T::TWO);
    assert_eq!(e.potential, m.potential_energy(&s));
    assert_eq!(e.total(), e.kinetic + e.potential);
    assert_eq!(e.total(), m.energy(&bank.state(a)?));
    assert!(e.potential != T::zero() && e.total() != e.kinetic);
    bank.remove(a)?;
    assert_eq!(bank.len(), 1);
    Ok(())
}

/// Twenty-one springs in one bank, the first sixteen stepped side by side (a whole group of
/// lanes, where there is a vector unit) and the last five in the groups of the tail, one
/// spring in each part stiff enough for explicit Euler to overflow: each group falls back to
/// one by one, both stiff springs fail in the frame a fixed-timestep run of one fails, each
/// counted once, and the others go on.
fn a_failure_in_a_group_of_lanes_counts_once<T: Real>() -> Result<(), Error> {
    const SPRINGS: usize = 21;
    const STIFF: [usize; 2] = [3, 18];
    let dt = T::from_f64(0.01);
    let soft = SpringMassDamper::new(T::one(), T::one(), T::from_f64(0.1))?;
    // h w = 100: the amplitude grows a hundredfold a step.
    let stiff = SpringMassDamper::new(T::one(), T::from_f64(1e8), T::zero())?;
    let start = State::at_rest([T::one()]);
    let mut bank: Bank<T, 1, SPRINGS, SpringMassDamper<T>, ExplicitEuler, NeverSleeps, InLanes> =
        Bank::new(ExplicitEuler, NeverSleeps)?;
    // Lent to the scene, so that the count goes through `Banks for &mut B` too.
    let mut scene = Scene::new(&mut bank, dt, 4)?;
    let mut ids = Vec::new();
    for k in 0..SPRINGS {
        let spring = if STIFF.contains(&k) { stiff } else { soft };
        ids.push(scene.banks_mut().add(spring, start)?);
    }
    let mut twin = FixedTimestep::new(ExplicitEuler, dt, 4, start)?;
    let (mut failures, mut failed_at, mut twin_failed_at) = (0, None, None);
    for frame in 0..400 {
        let f = scene.advance(dt)?;
        if twin_failed_at.is_none() && twin.advance(&stiff, dt).is_err() {
            twin_failed_at = Some(frame);
        }
        failures += f.failed;
        if f.failed > 0 {
            assert_eq!(f.failed, 2, "frame {frame}");
            failed_at = Some(frame);
        }
    }
    assert!(failed_at.is_some());
    assert_eq!(failed_at, twin_failed_at);
    assert_eq!(failures, 2);
    assert_eq!(bank.awake(), SPRINGS - 2);
    for k in STIFF {
        assert_eq!(bank.status(ids[k])?, Status::Failed(Error::NonFiniteState));
    }
    Ok(())
}

/// A bank stepped by one scene and then given to another (by `&mut`, alone and in an
/// array): the new scene starts it, and every instance, at its own time zero, and steps it
/// from there.
fn a_new_scene_restarts_the_clock<T: Real>() -> Result<(), Error> {
    let dt = T::from_f64(0.01);
    let m = SimplePendulum::new(T::one(), T::one(), T::from_f64(G), T::zero())?;
    let mut bank: Bank<T, 1, 2, SimplePendulum<T>, Rk4> = Bank::new(Rk4, NeverSleeps)?;
    let a = bank.add(m, State::at_rest([T::HALF]))?;
    let mut first = Scene::new(&mut bank, dt, 4)?;
    for _ in 0..10 {
        assert_eq!(first.advance(dt)?.steps, 1);
    }
    let ten = first.time();
    assert!(ten > T::from_f64(0.09));
    assert_eq!(bank.time(), ten);
    assert_eq!(bank.state(a)?.t, ten);
    let mut second = Scene::new([&mut bank], dt, 4)?;
    assert_eq!(second.time(), T::zero());
    assert_eq!(second.banks()[0].time(), T::zero());
    assert_eq!(second.banks()[0].state(a)?.t, T::zero());
    let frame = second.advance(dt)?;
    assert_eq!((frame.steps, frame.failed), (1, 0));
    assert_eq!(second.banks()[0].time(), second.time());
    assert_eq!(bank.time(), dt);
    assert_eq!(bank.state(a)?.t, dt);
    Ok(())
}

/// The sleep rule as given, a prop added asleep, and the step an instance at rest falls
/// asleep at: checked every step, after `steps` steps at rest (at the first check that has
/// found it at rest over at least that many steps, the docs of `Sleeps`), not before, with
/// thresholds that it meets exactly.
fn sleeping_by_the_rule<T: Real>() -> Result<(), Error> {
    let dt = T::from_f64(0.01);
    let (kinetic, acceleration) = (T::from_f64(1e-6), T::from_f64(1e-3));
    let rule = Sleeps::new(kinetic, acceleration, 5)?.checked_every(1)?;
    assert_eq!(
        (
            rule.kinetic(),
            rule.acceleration(),
            rule.steps(),
            rule.interval()
        ),
        (kinetic, acceleration, 5, 1)
    );
    // Thresholds of zero: they are inclusive, so a pendulum exactly at rest at the bottom
    // (no kinetic energy, no acceleration) still rests by them.
    let strict = Sleeps::new(T::zero(), T::zero(), 5)?.checked_every(1)?;
    let m = SimplePendulum::new(T::one(), T::one(), T::from_f64(G), T::zero())?;
    let mut bank: Bank<T, 1, 3, SimplePendulum<T>, Rk4, Sleeps<T>> = Bank::new(Rk4, strict)?;
    assert_eq!(bank.capacity(), 3);
    assert_eq!(bank.sleep(), &strict);
    // Placed off its equilibrium, asleep: nothing steps it until something wakes it.
    let prop = bank.add_asleep(m, [T::HALF])?;
    assert_eq!(bank.status(prop)?, Status::Asleep);
    assert_eq!((bank.len(), bank.awake()), (1, 0));
    let resting = bank.add(m, State::at_rest([T::zero()]))?;
    assert_eq!((bank.len(), bank.awake()), (2, 1));
    let mut scene = Scene::new(bank, dt, 4)?;
    for frame in 1..=6 {
        scene.advance(dt)?;
        let bank = scene.banks();
        let expected = if frame > 5 {
            Status::Asleep
        } else {
            Status::Awake
        };
        assert_eq!(bank.status(resting)?, expected, "frame {frame}");
        assert_eq!(bank.status(prop)?, Status::Asleep);
        assert_eq!(bank.state(prop)?, State::at_rest([T::HALF]));
    }
    Ok(())
}

for_f32_and_f64!(
    sleeping_by_the_rule,
    a_new_scene_restarts_the_clock,
    counts_times_and_energies,
    a_failure_in_a_group_of_lanes_counts_once
);
