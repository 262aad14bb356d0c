//! What wakes a scene's sleeper and what does not, and what an impulse does (issue 14): an
//! unchanged input or mechanism leaves a sleeper as it is; a changed one, a state written, an
//! impulse, an explicit wake and a contact wake it; an impulse keeps a constrained
//! mechanism's velocity constraints and jumps a free one's velocities by `M^-1 p`.

use lagrange_core::nalgebra::SVector;
use lagrange_core::{Constrained, Error, Mechanism, Real, State};
use lagrange_integrators::scene::{Bank, Id, NeverSleeps, Scene, Sleeps, Status};
use lagrange_integrators::{AdaptiveSettings, DormandPrince54, Rk4, StormerVerlet};
use lagrange_systems::{CartPole, CartesianPendulum, DoublePendulum, SimplePendulum};
use lagrange_tests::{for_f32_and_f64, pick, Rng};

const DT: f64 = 1.0 / 120.0;
const G: f64 = 9.81;

/// The bits of a state (`f32` widened to `f64`, exactly).
fn bits<T: Real, const N: usize>(s: &State<T, N>) -> Vec<u64> {
    core::iter::once(s.t)
        .chain(s.q.iter().copied())
        .chain(s.qd.iter().copied())
        .map(|x| x.to_f64().to_bits())
        .collect()
}

type Props<T> = Bank<T, 1, 8, SimplePendulum<T>, StormerVerlet<T, 1>, Sleeps<T>>;
type Carts<T> = Bank<T, 2, 2, CartPole<T>, Rk4, Sleeps<T>>;

/// The usual rule: `T <= 1e-6 J`, `|q''(q, 0)| <= 1e-3`, over 60 steps.
fn usual<T: Real>() -> Result<Sleeps<T>, Error> {
    Sleeps::new(T::from_f64(1e-6), T::from_f64(1e-3), 60)
}

fn pendulum<T: Real>(damping: f64) -> Result<SimplePendulum<T>, Error> {
    SimplePendulum::new(T::one(), T::one(), T::from_f64(G), T::from_f64(damping))
}

/// The Frobenius norm of a vector or matrix of `f64`.
fn norm<const R: usize, const C: usize>(m: &lagrange_core::nalgebra::SMatrix<f64, R, C>) -> f64 {
    m.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Asserts that `id` sleeps with the very state `before` (time included).
fn still_asleep<T: Real, const N: usize>(
    status: Status,
    state: &State<T, N>,
    before: &State<T, N>,
    what: &str,
) {
    assert_eq!(status, Status::Asleep, "{what}");
    assert_eq!(bits(state), bits(before), "{what}");
}

/// Writes that change nothing leave a sleeper asleep with its very bits: the input it has
/// (and `-0` for `0`, which is equal), a modification that changes nothing or puts back an
/// equal mechanism, a refused modification (even one that changed the mechanism before
/// refusing). Every other write wakes it, at the bank's time: a different input, a changed
/// parameter, a state written (even the same state), an impulse (velocity `p / (m l^2)`),
/// an explicit wake and a contact (state untouched).
fn what_wakes_a_sleeper<T: Real>() -> Result<(), Error> {
    let props: Props<T> = Bank::new(StormerVerlet::default(), usual()?)?;
    let carts: Carts<T> = Bank::new(Rk4, usual()?)?;
    let mut scene = Scene::new((props, carts), T::from_f64(DT), 4)?;
    let (props, carts) = scene.banks_mut();
    // At rest 5e-5 rad off the bottom: asleep after 60 steps and a check, where a step
    // would move them.
    let mut ids = Vec::new();
    for _ in 0..7 {
        ids.push(props.add(pendulum(0.5)?, State::at_rest([T::from_f64(5e-5)]))?);
    }
    let cart = carts.add(
        CartPole::new(T::one(), T::from_f64(0.1), T::HALF, T::from_f64(G))?,
        State::at_rest([T::zero(), T::PI]),
    )?;
    for _ in 0..90 {
        scene.advance(T::from_f64(DT))?;
    }
    assert_eq!((scene.banks().0.awake(), scene.banks().1.awake()), (0, 0));
    // More frames, so that the sleepers' time is behind the bank's.
    for _ in 0..10 {
        scene.advance(T::from_f64(DT))?;
    }
    let now = scene.time();
    let (props, carts) = scene.banks_mut();

    // The cart: its input.
    let before = carts.state(cart)?;
    assert!(before.t < now);
    carts.set_input(cart, T::zero())?;
    still_asleep(
        carts.status(cart)?,
        &carts.state(cart)?,
        &before,
        "the same input",
    );
    carts.set_input(cart, -T::zero())?;
    still_asleep(
        carts.status(cart)?,
        &carts.state(cart)?,
        &before,
        "-0 for 0",
    );
    carts.set_input(cart, T::from_f64(0.1))?;
    assert_eq!(carts.status(cart)?, Status::Awake);
    assert_eq!(carts.mechanism(cart)?.force(), T::from_f64(0.1));
    let woken = carts.state(cart)?;
    assert_eq!((woken.q, woken.qd, woken.t), (before.q, before.qd, now));

    // The pendulums.
    let [a, b, c, d, e, f, h] = <[Id; 7]>::try_from(ids).map_err(|_| Error::NoSuchInstance)?;
    let before = props.state(a)?;
    props.modify(a, |_| Ok(()))?;
    still_asleep(
        props.status(a)?,
        &props.state(a)?,
        &before,
        "modify: nothing",
    );
    props.modify(a, |p| {
        *p = pendulum(0.5)?;
        Ok(())
    })?;
    still_asleep(
        props.status(a)?,
        &props.state(a)?,
        &before,
        "modify: an equal pendulum",
    );
    let refused = props.modify(a, |p| {
        *p = pendulum(1.0)?;
        SimplePendulum::new(-T::one(), T::one(), T::one(), T::zero())
    });
    assert!(
        matches!(refused, Err(Error::InvalidParameter { name: "mass", .. })),
        "{refused:?}"
    );
    assert_eq!(props.mechanism(a)?.damping(), T::HALF);
    still_asleep(
        props.status(a)?,
        &props.state(a)?,
        &before,
        "modify: refused",
    );
    props.modify(a, |p| {
        *p = pendulum(1.0)?;
        Ok(())
    })?;
    assert_eq!(props.status(a)?, Status::Awake, "modify: damping 0.5 to 1");
    assert_eq!(props.mechanism(a)?.damping(), T::one());

    let before = props.state(b)?;
    props.set_state(b, before)?;
    assert_eq!(props.status(b)?, Status::Awake, "set_state: the same state");
    let s = props.state(b)?;
    assert_eq!((s.q, s.qd, s.t), (before.q, before.qd, now));
    for alpha in [0.0, 0.5, 1.0] {
        assert_eq!(bits(&props.interpolated(b, T::from_f64(alpha))?), bits(&s));
    }

    let before = props.state(c)?;
    props.apply_impulse(c, &SVector::from([T::from_f64(0.25)]))?;
    assert_eq!(props.status(c)?, Status::Awake, "impulse");
    let s = props.state(c)?;
    // m l^2 = 1: the velocity is the impulse, exactly.
    assert_eq!((s.q, s.qd[0], s.t), (before.q, T::from_f64(0.25), now));

    for (id, way) in [(d, "wake"), (e, "contact")] {
        let before = props.state(id)?;
        if way == "wake" {
            props.wake(id)?;
        } else {
            props.contact(id)?;
        }
        assert_eq!(props.status(id)?, Status::Awake, "{way}");
        let s = props.state(id)?;
        assert_eq!((s.q, s.qd, s.t), (before.q, before.qd, now), "{way}");
    }
    // The others still sleep.
    for id in [f, h] {
        assert_eq!(props.status(id)?, Status::Asleep);
    }
    assert_eq!(props.awake(), 5);
    // The woken ones move: each from 5e-5 rad, at rest or pushed.
    scene.advance(T::from_f64(DT))?;
    let props = &scene.banks().0;
    for id in [a, b, c, d, e] {
        let s = props.state(id)?;
        assert!(s.qd[0] != T::zero() && s.t == scene.time(), "{s:?}");
    }
    Ok(())
}

/// An explicit wake or contact leaves an awake instance as it is: two identical swinging
/// pendulums stepped by the adaptive Dormand-Prince pair (which keeps its step size and runs
/// ahead of its landings), one woken and touched every frame, stay identical bit for bit over
/// 300 frames. A third, written its own state every frame, is restarted each time: it parts
/// from them (the test would see a wake that restarts).
fn waking_an_awake_instance_changes_nothing<T: Real>() -> Result<(), Error> {
    let settings = AdaptiveSettings::new(
        T::from_f64(pick::<T>(1e-4, 1e-8)),
        T::from_f64(pick::<T>(1e-6, 1e-10)),
    )?;
    let bank: Bank<T, 1, 4, SimplePendulum<T>, DormandPrince54<T, 1>, Sleeps<T>> =
        Bank::new(DormandPrince54::new(settings), usual()?)?;
    let mut scene = Scene::new(bank, T::from_f64(DT), 4)?;
    let bank = scene.banks_mut();
    let start = State::new(T::zero(), [T::one()], [T::HALF]);
    let (plain, touched, written) = (
        bank.add(pendulum(0.0)?, start)?,
        bank.add(pendulum(0.0)?, start)?,
        bank.add(pendulum(0.0)?, start)?,
    );
    let mut rng = Rng::new(3);
    let mut parted = 0;
    for _ in 0..300 {
        let bank = scene.banks_mut();
        bank.wake(touched)?;
        bank.contact(touched)?;
        let s = bank.state(written)?;
        bank.set_state(written, s)?;
        scene.advance(rng.uniform(0.0, 2.5 * DT))?;
        let bank = scene.banks();
        assert_eq!(bits(&bank.state(touched)?), bits(&bank.state(plain)?));
        if bits(&bank.state(written)?) != bits(&bank.state(plain)?) {
            parted += 1;
        }
    }
    println!("frames where the pendulum written every frame differs: {parted} of 300");
    assert!(parted > 0);
    Ok(())
}

/// The Cartesian pendulum (a particle held at `l` by a rod: `Constrained`), hanging at rest
/// asleep, given impulses `p` in random directions (up to 2 N s) at random angles: each wakes
/// it, keeps the rod's velocity constraint `J q' = (x x' + y y') / l = 0` to rounding
/// (measured at most 5.4 epsilons of `|q'|`: 1.2e-15 in f64, 5.9e-7 in f32; asserted 16),
/// and its velocity is the tangential part of `p / m` (the rod takes the rest), to the same
/// rounding (measured at most 6 epsilons). Its position does not change.
fn an_impulse_keeps_the_constraints<T: Real>() -> Result<(), Error> {
    type Held<T> = Constrained<T, 1, CartesianPendulum<T>>;
    let mut bank: Bank<T, 2, 8, Held<T>, Rk4, Sleeps<T>> = Bank::new(Rk4, usual()?)?;
    let (m, l) = (2.0, 1.5);
    let parts = CartesianPendulum::new(T::from_f64(m), T::from_f64(l), T::from_f64(G))?;
    let mut rng = Rng::new(9);
    let mut ids = Vec::new();
    for _ in 0..8 {
        let th: T = rng.uniform(-2.5, 2.5);
        ids.push(bank.add(
            Constrained::new(parts),
            parts.state_from_angle(T::zero(), th, T::zero()),
        )?);
    }
    let mut worst = (0.0f64, 0.0f64);
    for &id in &ids {
        let before = bank.state(id)?;
        let p = SVector::from([rng.uniform::<T>(-2.0, 2.0), rng.uniform::<T>(-2.0, 2.0)]);
        bank.apply_impulse(id, &p)?;
        assert_eq!(bank.status(id)?, Status::Awake);
        let s = bank.state(id)?;
        assert_eq!(s.q, before.q);
        let [x, y] = [s.q[0].to_f64(), s.q[1].to_f64()];
        let [vx, vy] = [s.qd[0].to_f64(), s.qd[1].to_f64()];
        let speed = vx.hypot(vy);
        let along_rod = (x * vx + y * vy) / l;
        // The tangential part of p / m, in f64.
        let r = x.hypot(y);
        let (nx, ny) = (x / r, y / r);
        let (px, py) = (p[0].to_f64() / m, p[1].to_f64() / m);
        let radial = px * nx + py * ny;
        let miss = (vx - (px - radial * nx)).hypot(vy - (py - radial * ny));
        worst = (
            worst.0.max(along_rod.abs() / speed),
            worst.1.max(miss / speed),
        );
        let eps = T::EPSILON.to_f64();
        assert!(
            along_rod.abs() <= 16.0 * eps * speed,
            "J q' = {along_rod:e} at {speed} m/s"
        );
        assert!(
            miss <= 16.0 * eps * speed,
            "{miss:e} from the tangential part of p / m"
        );
    }
    println!(
        "|J q'| / |q'| at most {:.1e}; velocity off p_t / m by at most {:.1e} of it",
        worst.0, worst.1
    );
    Ok(())
}

/// A free mechanism's velocities jump by `M^-1 p`: double pendulums at random states given
/// random impulses satisfy `M(q) dq' = p` to rounding: measured at most 0.8 epsilons of
/// `|M|` times the larger of `|dq'|` and `|q'|` (the new velocities are rounded to `T`),
/// asserted 16.
fn an_impulse_jumps_by_the_inverse_mass<T: Real>() -> Result<(), Error> {
    let mut bank: Bank<T, 2, 8, DoublePendulum<T>, Rk4, NeverSleeps> = Bank::new(Rk4, NeverSleeps)?;
    let mut rng = Rng::new(10);
    let mut worst = 0.0f64;
    for _ in 0..8 {
        let p = DoublePendulum::new(
            rng.uniform(0.5, 2.0),
            rng.uniform(0.5, 2.0),
            rng.uniform(0.5, 1.5),
            rng.uniform(0.5, 1.5),
            T::from_f64(G),
        )?;
        let start = State::new(
            T::zero(),
            [rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0)],
            [rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0)],
        );
        let id = bank.add(p, start)?;
        let impulse = SVector::from([rng.uniform::<T>(-3.0, 3.0), rng.uniform::<T>(-3.0, 3.0)]);
        bank.apply_impulse(id, &impulse)?;
        let s = bank.state(id)?;
        assert_eq!(s.q, start.q);
        // In f64: the jump, M and p as the bank had them.
        let dqd = s.qd.map(|x| x.to_f64()) - start.qd.map(|x| x.to_f64());
        let mass = bank.mechanism(id)?.mass_matrix(&s).map(|x| x.to_f64());
        let residual = norm(&(mass * dqd - impulse.map(|x| x.to_f64())));
        // The new velocities are rounded to T: the scale is that of the larger of the jump
        // and the new velocities.
        let scale = norm(&mass) * norm(&dqd).max(norm(&s.qd.map(|x| x.to_f64())));
        worst = worst.max(residual / scale);
        assert!(
            residual <= 16.0 * T::EPSILON.to_f64() * scale,
            "M dq' - p = {residual:e}"
        );
    }
    println!("|M dq' - p| at most {worst:.1e} of |M| |dq'|");
    Ok(())
}

for_f32_and_f64!(
    what_wakes_a_sleeper,
    waking_an_awake_instance_changes_nothing,
    an_impulse_keeps_the_constraints,
    an_impulse_jumps_by_the_inverse_mass
);
