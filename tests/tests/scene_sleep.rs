//! When a scene's instances fall asleep (issue 14): never while they move or are driven (the
//! zero-velocity acceleration is what keeps a swinging prop awake at its turning points), in
//! a measured time once a damped one settles, and a ball at rest on the floor.

use lagrange_core::nalgebra::SVector;
use lagrange_core::{
    Error, Holonomic, HolonomicConstraints, Lagrangian, Mechanism, Projection, Real, Scalar, State,
};
use lagrange_integrators::scene::{Bank, Scene, Sleeps, Status};
use lagrange_integrators::{ContactModel, ContactStepper, Rk4, StormerVerlet};
use lagrange_systems::{BeadOnRotatingHoop, CartPole, FallingParticle, SimplePendulum};
use lagrange_tests::{for_f32_and_f64, pick};

const DT: f64 = 1.0 / 120.0;
const G: f64 = 9.81;
/// 30 degrees.
const TH0: f64 = core::f64::consts::PI / 6.0;

/// The rule of the issue: `T <= 1e-6 J`, `|q''(q, 0)| <= 1e-3`, over 60 steps.
fn usual<T: Real>() -> Result<Sleeps<T>, Error> {
    Sleeps::new(T::from_f64(1e-6), T::from_f64(1e-3), 60)
}

type Props<T> = Bank<T, 1, 1, SimplePendulum<T>, StormerVerlet<T, 1>, Sleeps<T>>;

/// A bank of one pendulum (`m = l = 1`, damping `b`) from `th0` at rest.
fn one_prop<T: Real>(rule: Sleeps<T>, b: f64, th0: f64) -> Result<Props<T>, Error> {
    let mut bank: Props<T> = Bank::new(StormerVerlet::default(), rule)?;
    let p = SimplePendulum::new(T::one(), T::one(), T::from_f64(G), T::from_f64(b))?;
    bank.add(p, State::at_rest([T::from_f64(th0)]))?;
    Ok(bank)
}

/// The state of a bank's only instance.
fn only<T, const N: usize, const K: usize, M, I, Z>(
    bank: &Bank<T, N, K, M, I, Z>,
) -> Result<State<T, N>, Error>
where
    T: Real,
    M: Mechanism<T, N>,
    I: lagrange_integrators::Integrator<T, N, M> + Clone,
    Z: lagrange_integrators::scene::Sleep<T>,
{
    bank.iter()
        .next()
        .map(|(_, s)| s)
        .ok_or(Error::NoSuchInstance)
}

/// An undamped 30-degree pendulum (`l = 1`, `g = 9.81`, total energy 1.31 J above the
/// bottom) never falls asleep by the usual rule (`1e-6 J`, `1e-3`, 60 steps) over 10^6 steps
/// (2.3 hours at 120 Hz), nor over 10^5 steps by two looser ones:
///
/// - a kinetic threshold of 10 J, above the whole energy, so that the kinetic test passes at
///   every step and only the acceleration test keeps it awake;
/// - a kinetic threshold of `1e-2 J` over 4 steps, checked every step: at each turning point
///   the kinetic test passes for 7 steps in a row (measured; asserted at least 5), long
///   enough to sleep on it alone, and the acceleration (`g sin 30 = 4.9`) keeps it awake.
///
/// The same two loose rules with an acceleration threshold of 10 (above `g sin 30`) put it to
/// sleep within 150 steps, the second frozen at the top of a swing: the classic bug the
/// acceleration test prevents.
fn a_swinging_pendulum_never_sleeps<T: Real>() -> Result<(), Error> {
    let (kinetic, loose, fast) = (T::from_f64(1e-2), T::from_f64(10.0), 4);
    let dt = T::from_f64(DT);
    let mut scene = Scene::new(one_prop::<T>(usual()?, 0.0, TH0)?, dt, 1)?;
    let (mut lowest, mut highest) = (f64::INFINITY, f64::NEG_INFINITY);
    for _ in 0..1_000_000 {
        let frame = scene.advance(dt)?;
        assert_eq!(
            (frame.steps, frame.failed, scene.banks().awake()),
            (1, 0, 1)
        );
    }
    let e0 = -G * TH0.cos();
    let end = only(scene.banks())?;
    let e = energy_f64(0.0, &end)?;
    println!(
        "after 10^6 steps: energy {e} J, {:.1e} J from the start",
        e - e0
    );
    // Still swinging at 30 degrees: Stormer-Verlet's energy error stays within 1.3e-3 J, 1e-3
    // of the 1.31 J of the swing (measured at most 2.6e-4 J).
    assert!((e - e0).abs() < 1.3e-3);

    let b = one_prop::<T>(Sleeps::new(loose, T::from_f64(1e-3), 60)?, 0.0, TH0)?;
    let c = one_prop::<T>(
        Sleeps::new(kinetic, T::from_f64(1e-3), fast)?.checked_every(1)?,
        0.0,
        TH0,
    )?;
    let mut scene = Scene::new((b, c), dt, 1)?;
    let (mut run, mut longest) = (0u32, 0u32);
    for _ in 0..100_000 {
        let frame = scene.advance(dt)?;
        assert_eq!((frame.steps, frame.failed), (1, 0));
        let (b, c) = scene.banks();
        assert_eq!((b.awake(), c.awake()), (1, 1));
        let s = only(c)?;
        let e = energy_f64(0.0, &s)?;
        lowest = lowest.min(e);
        highest = highest.max(e);
        // T = m l^2 th'^2 / 2, with m = l = 1.
        run = if s.qd[0].to_f64().powi(2) / 2.0 <= 1e-2 {
            run + 1
        } else {
            0
        };
        longest = longest.max(run);
    }
    println!("longest run of steps with T <= 1e-2 J: {longest}; energy in [{lowest}, {highest}] J");
    assert!(longest > fast, "{longest}");
    assert!((lowest - e0).abs() < 1.3e-3 && (highest - e0).abs() < 1.3e-3);

    // The controls: with the acceleration test out of the way, both rules freeze it where
    // it would not stay, the first wherever its swing is after 60 steps and a check, the
    // second at the top of its first swing back, at 1.02 s (the 3.5 steps at rest after
    // letting go are too few).
    let d = one_prop::<T>(Sleeps::new(loose, loose, 60)?, 0.0, TH0)?;
    let e = one_prop::<T>(
        Sleeps::new(kinetic, loose, fast)?.checked_every(1)?,
        0.0,
        TH0,
    )?;
    let mut scene = Scene::new((d, e), dt, 1)?;
    for _ in 0..150 {
        scene.advance(dt)?;
    }
    let (d, e) = scene.banks();
    assert_eq!((d.awake(), e.awake()), (0, 0));
    assert!(
        G * only(d)?.q[0].to_f64().sin().abs() > 0.1,
        "{:?}",
        only(d)?
    );
    let frozen = only(e)?;
    assert!(frozen.q[0].to_f64() < -(TH0 - 0.01), "{frozen:?}");
    Ok(())
}

/// The force on a slowly driven cart at scene time `t`: `2e-5 N` times a level that follows
/// `sin(2 pi t / 20 s)` in four steps (`+-1/2`, `+-1`), never zero, and held for seconds.
fn slow_push(t: f64) -> f64 {
    let s = (2.0 * core::f64::consts::PI * t / 20.0).sin();
    let level = if s.abs() < 0.5 { 0.5 } else { 1.0 };
    2e-5 * if s < 0.0 { -level } else { level }
}

/// A cart-pole (pole hanging, `th = pi`) driven by a small, slowly varying force written every
/// frame (the same value most frames: no wake) never falls asleep over 10^5 frames (14 min):
/// the force is nonzero, and that alone keeps it awake. Its kinetic energy (measured at most
/// 1.3e-8 J) and its zero-velocity accelerations (at most 1.0e-4 in f64, 2.7e-4 in f32,
/// where the pole's small swing about `pi` is resolved to only 2.4e-7 rad) stay below the
/// thresholds all along, so that the same cart under `even_when_driven` falls asleep on
/// each level the force holds (measured 251 times), and is woken by each change.
fn a_driven_cart_never_sleeps<T: Real>() -> Result<(), Error> {
    let rule = usual::<T>()?;
    type Carts<T> = Bank<T, 2, 1, CartPole<T>, Rk4, Sleeps<T>>;
    let mut held: Carts<T> = Bank::new(Rk4, rule)?;
    let mut free: Carts<T> = Bank::new(Rk4, rule.even_when_driven())?;
    let cart = CartPole::new(T::one(), T::from_f64(0.1), T::HALF, T::from_f64(G))?;
    let hanging = State::at_rest([T::zero(), T::PI]);
    let a = held.add(cart, hanging)?;
    let b = free.add(cart, hanging)?;
    let dt = T::from_f64(DT);
    let mut scene = Scene::new((held, free), dt, 1)?;
    let (mut kinetic, mut accel) = (0.0f64, 0.0f64);
    let (mut sleeps, mut was_asleep) = (0, false);
    for _ in 0..100_000 {
        let force = T::from_f64(slow_push(scene.time().to_f64()));
        let (held, free) = scene.banks_mut();
        held.set_input(a, force)?;
        free.set_input(b, force)?;
        assert_eq!(scene.advance(dt)?.failed, 0);
        let (held, free) = scene.banks();
        assert_eq!(held.status(a)?, Status::Awake);
        let s = held.state(a)?;
        kinetic = kinetic.max(held.energies(a)?.kinetic.to_f64());
        let still = State {
            qd: SVector::zeros(),
            ..s
        };
        let q2 = held.mechanism(a)?.acceleration(&still)?;
        accel = q2.iter().fold(accel, |m, x| m.max(x.abs().to_f64()));
        let asleep = free.status(b)? == Status::Asleep;
        if asleep && !was_asleep {
            sleeps += 1;
        }
        was_asleep = asleep;
    }
    println!("driven cart: kinetic at most {kinetic:.2e} J, |q''(q, 0)| at most {accel:.2e}; the same cart even_when_driven fell asleep {sleeps} times");
    assert!(kinetic < 1e-6 && accel < 1e-3);
    // 42 periods of the force, each of 6 levels held for 3 to 7 s.
    assert!(sleeps >= 200, "{sleeps}");
    Ok(())
}

/// The bead on a hoop spun at `omega = 2 rad/s` (below `sqrt(g/R)`, so that its bottom is a
/// stable equilibrium) rests at the bottom, where its kinetic energy and acceleration are
/// exactly zero: driven, it never sleeps by default (10^4 steps); under `even_when_driven` it
/// falls asleep within the rule's 60 steps and a check.
fn a_driven_hoop_sleeps_only_when_allowed<T: Real>() -> Result<(), Error> {
    type Hoops<T> = Bank<T, 1, 1, BeadOnRotatingHoop<T>, Rk4, Sleeps<T>>;
    let hoop = BeadOnRotatingHoop::new(T::from_f64(0.1), T::HALF, T::TWO, T::from_f64(G))?;
    let mut held: Hoops<T> = Bank::new(Rk4, usual()?)?;
    let mut free: Hoops<T> = Bank::new(Rk4, usual::<T>()?.even_when_driven())?;
    let a = held.add(hoop, State::at_rest([T::zero()]))?;
    let b = free.add(hoop, State::at_rest([T::zero()]))?;
    let dt = T::from_f64(DT);
    let mut scene = Scene::new((held, free), dt, 1)?;
    let mut asleep_after = None;
    for step in 1..=10_000 {
        scene.advance(dt)?;
        let (held, free) = scene.banks();
        assert_eq!(held.status(a)?, Status::Awake);
        if asleep_after.is_none() && free.status(b)? == Status::Asleep {
            asleep_after = Some(step);
        }
    }
    assert!(
        matches!(asleep_after, Some(n) if n <= 72),
        "{asleep_after:?}"
    );
    assert_eq!(scene.banks().1.status(b)?, Status::Asleep);
    Ok(())
}

/// A pendulum's energy `T + V`, J, evaluated in `f64` from its state (so that an `f32`
/// state's energy is not rounded to the `f32` ulp of 9.81 J, 1e-6 J: the kinetic threshold).
fn energy_f64(damping: f64, s: &State<impl Real, 1>) -> Result<f64, Error> {
    let p = SimplePendulum::new(1.0, 1.0, G, damping)?;
    let s = State::new(s.t.to_f64(), [s.q[0].to_f64()], [s.qd[0].to_f64()]);
    Ok(p.kinetic_energy(&s) + p.potential_energy(&s))
}

/// A damped pendulum (`m = l = 1`, `g = 9.81`, `b = 3 N m s/rad`: decay rate 1.5/s) let go
/// from 30 degrees at 120 Hz falls asleep by the usual rule after 5.733 s (measured, f32 and
/// f64 alike). Asserted: asleep within 1.5 times that, 8.6 s; not before 5.5 s, when the
/// envelope of its swing, `0.52 * 1.14 * exp(-1.5 t)`, reaches 1.5e-4 rad, the largest that
/// keeps `|g sin th| <= 1e-3` at eight checks in a row; at sleep, its energy above the
/// bottom is at most the kinetic threshold plus the potential at `|g sin th| = 1e-3`
/// (`5.1e-8 J`). Falling asleep changes its energy by at most the kinetic threshold (the
/// step before against the step that slept, in `f64`), and leaves its velocity, drawn or
/// not, exactly zero.
fn a_damped_pendulum_sleeps_in_time<T: Real>() -> Result<(), Error> {
    let b = 3.0;
    let bank = one_prop::<T>(usual()?, b, TH0)?;
    let dt = T::from_f64(DT);
    let mut scene = Scene::new(bank, dt, 1)?;
    let bottom = -G;
    let mut before = only(scene.banks())?;
    let mut slept = None;
    for _ in 0..(20.0 / DT) as usize {
        assert_eq!(scene.advance(dt)?.failed, 0);
        if scene.banks().awake() == 0 {
            slept = Some(scene.time().to_f64());
            break;
        }
        before = only(scene.banks())?;
    }
    let slept = slept.ok_or(Error::NoConvergence { iterations: 0 })?;
    let after = only(scene.banks())?;
    let (e_before, e_after) = (energy_f64(b, &before)?, energy_f64(b, &after)?);
    println!(
        "asleep after {slept:.3} s at th = {:.2e} rad, energy above the bottom {:.2e} J, changed by {:.2e} J",
        after.q[0].to_f64(),
        e_after - bottom,
        e_after - e_before
    );
    assert!(slept > 5.5 && slept < 8.6, "{slept}");
    let threshold = 1e-6;
    let potential_at_rest = G * (1.0 - (1e-3 / G).asin().cos());
    // The step before the one that slept: its energy above the bottom is, besides what the
    // rule allows, what one step dissipates, `b th'^2 dt` (at most 5e-8 J).
    assert!(e_before - bottom <= threshold + potential_at_rest + 5e-8);
    assert!(e_after - bottom <= potential_at_rest * 1.01);
    assert!((e_after - e_before).abs() <= threshold);
    assert_eq!(after.qd[0], T::zero());
    let id = scene
        .banks()
        .iter()
        .next()
        .map(|(id, _)| id)
        .ok_or(Error::NoSuchInstance)?;
    assert_eq!(scene.banks().status(id)?, Status::Asleep);
    for alpha in [0.0, 0.5, 1.0] {
        assert_eq!(
            scene.banks().interpolated(id, T::from_f64(alpha))?.qd[0],
            T::zero()
        );
    }
    Ok(())
}

/// Props with heavy damping (`b` from 10 to 80 N m s/rad, `m = l = 1`: the slowest creeps
/// back at `0.123 th` per second) let go from 0.5 rad at 120 Hz settle and fall asleep
/// within 90 s; no step fails.
fn heavily_damped_props_settle_and_sleep<T: Real>() -> Result<(), Error> {
    let mut bank: Bank<T, 1, 8, SimplePendulum<T>, StormerVerlet<T, 1>, Sleeps<T>> =
        Bank::new(StormerVerlet::default(), usual()?)?;
    for b in [10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 80.0] {
        let p = SimplePendulum::new(T::one(), T::one(), T::from_f64(G), T::from_f64(b))?;
        bank.add(p, State::at_rest([T::HALF]))?;
    }
    let dt = T::from_f64(DT);
    let mut scene = Scene::new(bank, dt, 1)?;
    let mut failed = 0;
    for _ in 0..(90.0 / DT) as usize {
        failed += scene.advance(dt)?.failed;
    }
    let bank = scene.banks();
    let statuses: Vec<_> = bank
        .iter()
        .map(|(id, _)| bank.status(id))
        .collect::<Result<_, _>>()?;
    assert_eq!(failed, 0, "{statuses:?}");
    assert!(
        statuses.iter().all(|s| *s == Status::Asleep),
        "{statuses:?}"
    );
    Ok(())
}

/// The floor at `y = 0`: gap `y`.
#[derive(Debug, Clone, Copy)]
struct Floor;

impl<T: Real> HolonomicConstraints<T, 1, 1> for Floor {
    fn phi<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 1>) -> SVector<S, 1> {
        *q
    }
}

/// A ball (1 kg) dropped from 1 m onto the floor (restitution 0.5, resting below 0.5 m/s,
/// about `5 g dt`, so that a bounce lasts some ten steps), stepped by RK4 through a contact
/// stepper at 120 Hz: it bounces (4.43, 2.21, 1.11, 0.55 m/s up, then 0.28: resting), rests
/// on the floor from 1.242 s, and falls asleep there (its resting contact holds it, so that
/// its acceleration at rest is zero) 1.800 s after the drop (measured): asserted after the
/// 1.242 s and the rule's 60 steps, within 1.5 times the measured time. An upward impulse of
/// 3 N s wakes it; it flies to `v^2 / 2g = 0.459 m` (the highest step within `g dt^2 / 8` of
/// it), lands, rests from 1.07 s, and sleeps again 1.667 s after the impulse (measured;
/// asserted likewise). At rest it lies on the floor to the projection's tolerance, with zero
/// velocity, and it is never below the floor by more than that tolerance.
fn a_ball_sleeps_on_the_floor_and_wakes_to_an_impulse<T: Real>() -> Result<(), Error> {
    let tol = T::from_f64(pick::<T>(1e-6, 1e-12));
    let model = ContactModel::new(T::HALF, T::HALF, T::from_f64(pick::<T>(1e-6, 1e-10)))?;
    let stepper = ContactStepper::new(Rk4, Holonomic::new(Floor), model, Projection::new(tol, 4)?);
    let mut bank: Bank<T, 1, 1, FallingParticle<T>, _, Sleeps<T>> = Bank::new(stepper, usual()?)?;
    let ball = bank.add(
        FallingParticle::new(T::one(), T::from_f64(G))?,
        State::at_rest([T::one()]),
    )?;
    let dt = T::from_f64(DT);
    let mut scene = Scene::new(bank, dt, 1)?;
    let mut deepest = f64::INFINITY;
    let mut advance_until_asleep =
        |scene: &mut Scene<T, _>, limit: f64| -> Result<(f64, f64), Error> {
            let start = scene.time().to_f64();
            let mut highest = f64::NEG_INFINITY;
            loop {
                assert_eq!(scene.advance(dt)?.failed, 0);
                let bank: &Bank<T, 1, 1, FallingParticle<T>, _, Sleeps<T>> = scene.banks();
                let y = bank.state(ball)?.q[0].to_f64();
                deepest = deepest.min(y);
                highest = highest.max(y);
                if bank.status(ball)? == Status::Asleep {
                    return Ok((scene.time().to_f64() - start, highest));
                }
                assert!(
                    scene.time().to_f64() - start < limit,
                    "awake after {limit} s"
                );
            }
        };
    let (first, _) = advance_until_asleep(&mut scene, 5.0)?;
    let rest = scene.banks().state(ball)?;
    assert!(
        rest.q[0].abs().to_f64() <= tol.to_f64() && rest.qd[0] == T::zero(),
        "{rest:?}"
    );
    scene
        .banks_mut()
        .apply_impulse(ball, &[T::from_f64(3.0)].into())?;
    assert_eq!(scene.banks().status(ball)?, Status::Awake);
    assert_eq!(scene.banks().state(ball)?.qd[0], T::from_f64(3.0));
    let (second, highest) = advance_until_asleep(&mut scene, 5.0)?;
    let sleep = 60.0 * DT;
    assert!(first > 1.242 + sleep && first < 1.5 * 1.800, "{first}");
    assert!(second > 1.070 + sleep && second < 1.5 * 1.667, "{second}");
    let apex = 9.0 / (2.0 * G);
    println!("asleep {first:.3} s after the drop, {second:.3} s after the impulse; apex {highest:.6} m; deepest {deepest:.1e} m");
    assert!(
        (highest - apex).abs() <= G * DT * DT / 8.0 + pick::<T>(1e-6, 1e-12),
        "{highest}"
    );
    assert!(deepest >= -tol.to_f64());
    let rest = scene.banks().state(ball)?;
    assert!(
        rest.q[0].abs().to_f64() <= tol.to_f64() && rest.qd[0] == T::zero(),
        "{rest:?}"
    );
    Ok(())
}

for_f32_and_f64!(
    a_swinging_pendulum_never_sleeps,
    a_driven_cart_never_sleeps,
    a_driven_hoop_sleeps_only_when_allowed,
    a_damped_pendulum_sleeps_in_time,
    heavily_damped_props_settle_and_sleep,
    a_ball_sleeps_on_the_floor_and_wakes_to_an_impulse
);
