//! The scene cases: a scripted scene whose instances fall asleep and are woken by every kind
//! of event, compared bit for bit between the host and the M4F; and a scene of one swinging
//! pendulum beside 0 or [`SLEEPERS`] asleep, whose difference is what a sleeper costs a frame.

use core::hint::black_box;

use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, Real, State};
use lagrange_integrators::scene::{Bank, InLanes, Layout, Scene, Sleeps, Status};
use lagrange_integrators::{Rk4, StormerVerlet};
use lagrange_systems::{CartPole, SimplePendulum};

use crate::{Outcome, Precision};

/// The fixed step of the scenes, s: 120 Hz.
const DT: f64 = 1.0 / 120.0;

/// Frame times of the scripted scene, cycled: 60 Hz, 120 Hz, a hitch, an empty frame, 144 Hz
/// and a frame beyond the cap of 4 steps.
const FRAME_TIMES: [f64; 8] = [
    1.0 / 60.0,
    1.0 / 120.0,
    1.0 / 60.0,
    0.05,
    0.0,
    1.0 / 60.0,
    1.0 / 144.0,
    0.2,
];

/// Swinging props: 1 m pendulums, damped nearly critically (6 N m s against the critical
/// 6.26): at rest within about 4 s. Laid out in lanes, as the cart-poles: where there is a
/// vector unit (the host, the page's `simd128` build) the banks step in lanes, on the
/// firmware's cores one by one, and the outcome is the same bits everywhere (Stormer-Verlet
/// does not step lanes: its groups go one by one after trying).
type Props<T> = Bank<T, 1, 8, SimplePendulum<T>, StormerVerlet<T, 1>, Sleeps<T>, InLanes>;
/// Cart-poles hanging, pushed by their inputs now and then.
type Carts<T> = Bank<T, 2, 4, CartPole<T>, Rk4, Sleeps<T>, InLanes>;

/// The sleep rule: 1e-6 J, 1e-3 (m or rad)/s^2, 60 steps.
fn rule<T: Real>() -> Result<Sleeps<T>, Error> {
    Sleeps::new(T::from_f64(1e-6), T::from_f64(1e-3), 60)
}

/// FNV-1a over 64-bit words.
fn fnv(hash: u64, word: u64) -> u64 {
    (hash ^ word).wrapping_mul(0x0000_0100_0000_01b3)
}

/// Folds every instance of `bank` (by id index, so the order the bank keeps does not enter)
/// into `hash`: its state's bits and its status.
fn digest<T: Precision, const N: usize, const K: usize, M, I, Y>(
    mut hash: u64,
    bank: &Bank<T, N, K, M, I, Sleeps<T>, Y>,
) -> u64
where
    M: lagrange_core::Mechanism<T, N>,
    I: lagrange_integrators::Integrator<T, N, M> + Clone,
    Y: Layout<T, N, K, M>,
{
    for index in 0..K {
        let Some((id, s)) = bank.iter().find(|(id, _)| id.index() == index) else {
            continue;
        };
        let status = match bank.status(id) {
            Ok(Status::Awake) => 1,
            Ok(Status::Asleep) => 2,
            _ => 3,
        };
        hash = fnv(hash, status);
        for x in core::iter::once(s.t)
            .chain(s.q.iter().copied())
            .chain(s.qd.iter().copied())
        {
            hash = fnv(hash, x.bits());
        }
    }
    hash
}

/// The scripted scene of `frames` frames: six props (five swinging from different angles,
/// one at rest) and two hanging cart-poles; as they fall asleep, an impulse, a state
/// written, an input changed (and written again unchanged, which must not wake), an instance
/// removed and another added in its slot, an explicit wake, a contact and a parameter change
/// wake them. The outcome: a digest of every instance's bits and status, the awake counts,
/// the scene's time.
///
/// # Errors
/// A constructor's or an event's error (none for these values).
pub fn scripted<T: Precision>(frames: u32) -> Result<Outcome, Error> {
    let damped = SimplePendulum::new(T::one(), T::one(), T::from_f64(9.81), T::from_f64(6.0))?;
    let mut props: Props<T> = Bank::new(StormerVerlet::default(), rule()?)?;
    let at = |k: usize| State::at_rest([T::from_f64(0.1 * k as f64)]);
    let first = props.add(damped, at(0))?;
    let mut ids = [first; 6];
    for (k, id) in ids.iter_mut().enumerate().skip(1) {
        *id = props.add(damped, at(k))?;
    }
    let mut carts: Carts<T> = Bank::new(Rk4, rule()?)?;
    let cart = CartPole::new(
        T::one(),
        T::from_f64(0.1),
        T::from_f64(0.5),
        T::from_f64(9.8),
    )?;
    let hanging = State::at_rest([T::zero(), T::from_f64(core::f64::consts::PI)]);
    let pushed = carts.add(cart, hanging)?;
    let idle = carts.add(cart, hanging)?;
    // The scene borrows the banks: no copies of them on the stack.
    let mut scene = Scene::new((&mut props, &mut carts), T::from_f64(DT), 4)?;
    for frame in 0..black_box(frames) {
        let (props, carts) = scene.banks_mut();
        match frame {
            300 => props.apply_impulse(ids[1], &SVector::from([T::from_f64(0.7)]))?,
            320 => props.set_state(
                ids[2],
                State::new(T::zero(), [T::from_f64(0.4)], [T::zero()]),
            )?,
            340 => carts.set_input(pushed, T::from_f64(0.5))?,
            341 => {
                // Unchanged inputs: neither wakes anything.
                carts.set_input(pushed, T::from_f64(0.5))?;
                carts.set_input(idle, T::zero())?;
            }
            360 => {
                props.remove(ids[3])?;
                ids[3] = props.add(damped, State::at_rest([T::from_f64(-0.3)]))?;
            }
            380 => {
                props.wake(ids[0])?;
                props.contact(ids[4])?;
            }
            400 => props.modify(ids[5], |p| {
                *p = SimplePendulum::new(
                    T::one(),
                    T::from_f64(0.5),
                    T::from_f64(9.81),
                    T::from_f64(0.3),
                )?;
                Ok(())
            })?,
            420 => carts.set_input(pushed, T::zero())?,
            _ => {}
        }
        let time = FRAME_TIMES[frame as usize % FRAME_TIMES.len()];
        scene.advance(T::from_f64(time))?;
    }
    let (props, carts) = scene.banks();
    let hash = digest(digest(0xcbf2_9ce4_8422_2325, props), carts);
    Ok(Outcome::from_words(&[
        hash,
        props.awake() as u64,
        carts.awake() as u64,
        scene.time().bits(),
    ]))
}

/// Sleepers beside the one swinging pendulum of [`with_sleepers`].
pub const SLEEPERS: usize = 64;

/// One undamped pendulum swinging from 30 degrees and `sleepers` asleep at the bottom, in
/// `f32`, RK4, one step per frame for `frames` frames; the outcome is the swinging one's
/// state and the awake count. The difference in cost between `sleepers` = [`SLEEPERS`] and
/// 0 is what the sleepers cost a frame.
///
/// # Errors
/// A constructor's or a step's error (none for these values).
pub fn with_sleepers(sleepers: usize, frames: u32) -> Result<Outcome, Error> {
    let p = SimplePendulum::new(black_box(1.0f32), 1.0, 9.81, 0.0)?;
    let mut bank: Bank<f32, 1, { SLEEPERS + 1 }, SimplePendulum<f32>, Rk4, Sleeps<f32>> =
        Bank::new(Rk4, rule()?)?;
    let swinging = bank.add(p, State::at_rest([core::f32::consts::FRAC_PI_6]))?;
    for _ in 0..black_box(sleepers) {
        bank.add_asleep(p, [0.0])?;
    }
    let mut scene = Scene::new(&mut bank, DT as f32, 4)?;
    let dt = black_box(DT as f32);
    for _ in 0..black_box(frames) {
        scene.advance(dt)?;
    }
    let bank = scene.banks();
    let s = bank.state(swinging)?;
    Ok(Outcome::from_words(&[
        s.t.bits(),
        s.q[0].bits(),
        s.qd[0].bits(),
        bank.awake() as u64,
    ]))
}

/// [`with_sleepers`] with none.
pub fn no_sleepers(frames: u32) -> Result<Outcome, Error> {
    with_sleepers(0, frames)
}

/// [`with_sleepers`] with [`SLEEPERS`].
pub fn many_sleepers(frames: u32) -> Result<Outcome, Error> {
    with_sleepers(SLEEPERS, frames)
}
