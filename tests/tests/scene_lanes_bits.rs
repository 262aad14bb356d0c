//! Banks in lanes, bit for bit (issue 35): every instance of a bank laid out [`InLanes`] has
//! the trajectory it has stepped alone, while instances come and go (its group changes under
//! it), and the trajectory it has in the same bank one by one while instances fall asleep, wake,
//! take impulses, new states and inputs. (`scene_bits.rs` holds a bank one by one to fresh runs
//! across sleeping and waking: the two together hold a bank in lanes to them.)

use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, Gather, Real, State};
use lagrange_integrators::scene::{
    Bank, Id, InLanes, Layout, NeverSleeps, OneByOne, Scene, Sleeps, LANES,
};
use lagrange_integrators::{Integrator, Rk4, SemiImplicitEuler, VelocityVerlet};
use lagrange_systems::{CartPole, DoublePendulum, SimplePendulum};
use lagrange_tests::{for_f32_and_f64, Rng};

/// The fixed step: 120 Hz.
const DT: f64 = 1.0 / 120.0;
/// Steps per frame at most.
const CAP: u32 = 4;
/// Capacity: three whole groups and a short one of more than half a group, so that as
/// instances come and go the last group is stepped in lanes and one by one in turn.
const K: usize = 3 * LANES + LANES / 2 + 5;
/// Frames per run.
const FRAMES: usize = 900;

/// The bits of a state's coordinates and velocities (`f32` widened to `f64`, exactly).
fn bits<T: Real, const N: usize>(s: &State<T, N>) -> ([u64; N], [u64; N]) {
    (
        core::array::from_fn(|i| s.q[i].to_f64().to_bits()),
        core::array::from_fn(|i| s.qd[i].to_f64().to_bits()),
    )
}

/// An instance stepped alone beside the bank: what its lane must give.
struct Alone<T: Real, const N: usize, M, I> {
    id: Id,
    mechanism: M,
    state: State<T, N>,
    integrator: I,
}

/// A bank in lanes that never sleeps, with instances added and removed as it runs (so that
/// instances change groups and the last group changes length), against each instance stepped
/// alone by its own copy of `integrator`, bit for bit after every frame.
fn in_lanes_equals_alone<T, const N: usize, M, I>(
    integrator: I,
    make: impl Fn(&mut Rng) -> Result<(M, State<T, N>), Error>,
    seed: u64,
) -> Result<(), Error>
where
    T: Real,
    M: Gather<T, N> + Clone,
    I: Integrator<T, N, M> + Clone,
{
    let mut rng = Rng::new(seed);
    let dt = T::from_f64(DT);
    let bank: Bank<T, N, K, M, I, NeverSleeps, InLanes> =
        Bank::new(integrator.clone(), NeverSleeps)?;
    let mut scene = Scene::new(bank, dt, CAP)?;
    let mut alone = Vec::new();
    let (mut added, mut removed) = (0, 0);
    for frame in 0..FRAMES {
        if alone.len() < K && (frame < 20 || rng.unit() < 0.1) {
            let (mechanism, state) = make(&mut rng)?;
            let id = scene.banks_mut().add(mechanism.clone(), state)?;
            let state = scene.banks().state(id)?;
            let integrator = integrator.clone();
            alone.push(Alone {
                id,
                mechanism,
                state,
                integrator,
            });
            added += 1;
        }
        if !alone.is_empty() && rng.unit() < 0.08 {
            let at = (rng.unit() * alone.len() as f64) as usize % alone.len();
            let gone = alone.swap_remove(at);
            let (_, state) = scene.banks_mut().remove(gone.id)?;
            assert_eq!(bits(&state), bits(&gone.state), "removed at frame {frame}");
            removed += 1;
        }
        let f = scene.advance(T::from_f64(rng.uniform::<f64>(0.3, 2.5) * DT))?;
        assert_eq!(f.failed, 0);
        for a in &mut alone {
            for _ in 0..f.steps {
                a.state = a.integrator.run_step(&a.mechanism, &a.state, dt)?;
            }
            let got = scene.banks().state(a.id)?;
            assert_eq!(
                bits(&got),
                bits(&a.state),
                "{} frame {frame}: {got:?} alone {:?}",
                I::NAME,
                a.state
            );
        }
    }
    assert!(
        added > K && removed > 20,
        "{added} added, {removed} removed"
    );
    Ok(())
}

/// Sets an instance's input.
type SetInput<M, T> = fn(&mut M, T) -> Result<(), Error>;

/// A scene of one bank of `M` with sleeping, laid out by `Y`.
type Sleepy<T, const N: usize, M, I, Y> = Scene<T, Bank<T, N, K, M, I, Sleeps<T>, Y>>;

/// What one frame does to both banks, chosen once and done to each.
#[derive(Debug, Clone, Copy)]
enum Act<T: Real, const N: usize> {
    Nothing,
    Wake(usize),
    Impulse(usize, T),
    Write(usize, State<T, N>),
    Remove(usize),
    Add(usize, State<T, N>),
    AddAsleep(usize, [T; N]),
    Input(usize, T),
}

/// Does `act` to `bank` (ids by position in `ids`), keeping `ids` in step.
fn act<T, const N: usize, M, I, Y>(
    bank: &mut Bank<T, N, K, M, I, Sleeps<T>, Y>,
    ids: &mut Vec<Id>,
    act: Act<T, N>,
    made: &[M],
    input: impl Fn(&mut Bank<T, N, K, M, I, Sleeps<T>, Y>, Id, T) -> Result<(), Error>,
) -> Result<(), Error>
where
    T: Real,
    M: Gather<T, N> + Clone,
    I: Integrator<T, N, M> + Clone,
    Y: Layout<T, N, K, M>,
{
    let id = |i: usize| ids.get(i).copied().ok_or(Error::NoSuchInstance);
    match act {
        Act::Nothing => {}
        Act::Wake(i) => bank.wake(id(i)?)?,
        Act::Impulse(i, p) => bank.apply_impulse(id(i)?, &SVector::from_element(p))?,
        Act::Write(i, s) => bank.set_state(id(i)?, s)?,
        Act::Remove(i) => {
            bank.remove(id(i)?)?;
            ids.remove(i);
        }
        Act::Add(m, s) => {
            let m = made.get(m).cloned().ok_or(Error::NoSuchInstance)?;
            ids.push(bank.add(m, s)?);
        }
        Act::AddAsleep(m, q) => {
            let m = made.get(m).cloned().ok_or(Error::NoSuchInstance)?;
            ids.push(bank.add_asleep(m, q)?);
        }
        Act::Input(i, u) => input(bank, id(i)?, u)?,
    }
    Ok(())
}

/// A bank in lanes and the same bank one by one, both with sleeping, given the same frames and
/// the same acts (instances woken, pushed, written, removed, added awake and asleep, inputs
/// set): after every frame each instance has the same bits, interpolated state and status in
/// both. Some must have fallen asleep and woken again on the way.
fn in_lanes_equals_one_by_one_asleep_and_awake<T, const N: usize, M, I>(
    integrator: I,
    make: impl Fn(&mut Rng) -> Result<(M, State<T, N>), Error>,
    input: Option<SetInput<M, T>>,
    seed: u64,
) -> Result<(), Error>
where
    T: Real,
    M: Gather<T, N> + Clone + PartialEq,
    I: Integrator<T, N, M> + Clone,
{
    let mut rng = Rng::new(seed);
    let dt = T::from_f64(DT);
    let rule = Sleeps::new(T::from_f64(1e-6), T::from_f64(1e-3), 30)?;
    let mut lanes: Sleepy<T, N, M, I, InLanes> =
        Scene::new(Bank::new(integrator.clone(), rule)?, dt, CAP)?;
    let mut each: Sleepy<T, N, M, I, OneByOne> =
        Scene::new(Bank::new(integrator.clone(), rule)?, dt, CAP)?;
    let (mut lane_ids, mut each_ids) = (Vec::new(), Vec::new());
    let mut made = Vec::new();
    let (mut most_asleep, mut most_awake, mut woke) = (0, 0, 0);
    for frame in 0..FRAMES {
        let pick = |rng: &mut Rng, n: usize| (rng.unit() * n as f64) as usize % n.max(1);
        let n = lane_ids.len();
        let r = rng.unit();
        let chosen = if n < K && (frame < 24 || r < 0.04) {
            let (m, s) = make(&mut rng)?;
            made.push(m);
            if rng.unit() < 0.3 {
                Act::AddAsleep(made.len() - 1, s.q.into())
            } else {
                Act::Add(made.len() - 1, s)
            }
        } else if n == 0 {
            Act::Nothing
        } else if r < 0.08 {
            Act::Wake(pick(&mut rng, n))
        } else if r < 0.12 {
            Act::Impulse(pick(&mut rng, n), rng.uniform(-0.5, 0.5))
        } else if r < 0.14 {
            let (_, s) = make(&mut rng)?;
            Act::Write(pick(&mut rng, n), s)
        } else if r < 0.17 {
            Act::Remove(pick(&mut rng, n))
        } else if r < 0.22 && input.is_some() {
            let u = if rng.unit() < 0.5 {
                T::zero()
            } else {
                rng.uniform(-2.0, 2.0)
            };
            Act::Input(pick(&mut rng, n), u)
        } else {
            Act::Nothing
        };
        let set = |bank: &mut Bank<T, N, K, M, I, Sleeps<T>, _>, id, u| {
            let change = input.ok_or(Error::NoSuchInstance)?;
            bank.modify(id, |m| change(m, u))
        };
        act(lanes.banks_mut(), &mut lane_ids, chosen, &made, set)?;
        let set = |bank: &mut Bank<T, N, K, M, I, Sleeps<T>, _>, id, u| {
            let change = input.ok_or(Error::NoSuchInstance)?;
            bank.modify(id, |m| change(m, u))
        };
        act(each.banks_mut(), &mut each_ids, chosen, &made, set)?;

        let asleep_before = lanes.banks().len() - lanes.banks().awake();
        let frame_time = T::from_f64(rng.uniform::<f64>(0.3, 2.5) * DT);
        let (a, b) = (lanes.advance(frame_time)?, each.advance(frame_time)?);
        assert_eq!(a, b);
        let (x, y) = (lanes.banks(), each.banks());
        assert_eq!(x.awake(), y.awake(), "frame {frame}");
        most_asleep = most_asleep.max(x.len() - x.awake());
        most_awake = most_awake.max(x.awake());
        if matches!(chosen, Act::Wake(_) | Act::Impulse(..)) && asleep_before > 0 {
            woke += 1;
        }
        for (&i, &j) in lane_ids.iter().zip(&each_ids) {
            let (s, t) = (x.state(i)?, y.state(j)?);
            assert_eq!(bits(&s), bits(&t), "{} frame {frame}", I::NAME);
            assert_eq!(s.t.to_f64().to_bits(), t.t.to_f64().to_bits());
            let alpha = lanes.alpha();
            assert_eq!(
                bits(&x.interpolated(i, alpha)?),
                bits(&y.interpolated(j, alpha)?)
            );
            assert_eq!(x.status(i)?, y.status(j)?);
        }
    }
    assert!(
        most_asleep >= LANES.min(8) && most_awake >= 2 * LANES.min(8) && woke > 5,
        "{most_asleep} asleep at most, {most_awake} awake at most, {woke} woken"
    );
    Ok(())
}

/// A value of `T` uniform in `[lo, hi)`.
fn u<T: Real>(rng: &mut Rng, lo: f64, hi: f64) -> T {
    rng.uniform(lo, hi)
}

/// Pendulums of their own lengths and damping (some heavily damped, to sleep), from angles
/// small and large.
fn pendulum<T: Real>(r: &mut Rng) -> Result<(SimplePendulum<T>, State<T, 1>), Error> {
    let damping = if r.unit() < 0.5 { 0.0 } else { 8.0 };
    let p = SimplePendulum::new(
        u(r, 0.5, 2.0),
        u(r, 0.3, 2.0),
        T::from_f64(9.81),
        u(r, damping, damping + 4.0),
    )?;
    let th = if r.unit() < 0.3 {
        T::zero()
    } else {
        u(r, -2.5, 2.5)
    };
    Ok((p, State::new(T::zero(), [th], [u(r, -1.0, 1.0)])))
}

/// Double pendulums of their own masses and rods, anywhere (chaotic: a flipped bit grows).
fn double<T: Real>(r: &mut Rng) -> Result<(DoublePendulum<T>, State<T, 2>), Error> {
    let p = DoublePendulum::new(
        u(r, 0.5, 2.0),
        u(r, 0.5, 2.0),
        u(r, 0.5, 2.0),
        u(r, 0.5, 2.0),
        T::from_f64(9.81),
    )?;
    Ok((p, State::at_rest([u(r, -3.0, 3.0), u(r, -3.0, 3.0)])))
}

/// Cart-poles of their own masses, at rest at the bottom (to sleep) or swinging.
fn cart<T: Real>(r: &mut Rng) -> Result<(CartPole<T>, State<T, 2>), Error> {
    let p = CartPole::new(
        u(r, 0.5, 2.0),
        u(r, 0.05, 0.5),
        u(r, 0.2, 1.0),
        T::from_f64(9.8),
    )?;
    let th = if r.unit() < 0.5 {
        T::zero()
    } else {
        u(r, -1.0, 1.0)
    };
    Ok((p, State::at_rest([u(r, -1.0, 1.0), th])))
}

/// Every instance in lanes as alone, with instances added and removed: pendulums and double
/// pendulums, three methods, several seeds.
fn lanes_as_alone<T: Real>() -> Result<(), Error> {
    for seed in [1, 2] {
        in_lanes_equals_alone(Rk4, pendulum::<T>, seed)?;
        in_lanes_equals_alone(Rk4, double::<T>, seed + 10)?;
        in_lanes_equals_alone(Rk4, cart::<T>, seed + 20)?;
    }
    in_lanes_equals_alone(VelocityVerlet, double::<T>, 30)?;
    in_lanes_equals_alone(SemiImplicitEuler, pendulum::<T>, 31)?;
    Ok(())
}

/// Banks in lanes as banks one by one, through sleeping and waking: pendulums and cart-poles
/// (with inputs), two methods, several seeds.
fn lanes_as_one_by_one<T: Real>() -> Result<(), Error> {
    let force: SetInput<CartPole<T>, T> = |c, u| c.set_force(u);
    for seed in [3, 4] {
        in_lanes_equals_one_by_one_asleep_and_awake(Rk4, pendulum::<T>, None, seed)?;
        in_lanes_equals_one_by_one_asleep_and_awake(Rk4, cart::<T>, Some(force), seed + 10)?;
    }
    in_lanes_equals_one_by_one_asleep_and_awake(VelocityVerlet, pendulum::<T>, None, 40)?;
    Ok(())
}

for_f32_and_f64!(lanes_as_alone, lanes_as_one_by_one);
