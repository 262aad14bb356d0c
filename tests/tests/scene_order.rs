//! A scene's bits do not depend on the order its instances were added in (issue 14): the same
//! instances added in shuffled orders, put to sleep, woken, removed and added along the way,
//! end with the same bits, label by label.

use lagrange_core::{Error, Real, State};
use lagrange_integrators::scene::{Bank, Id, Scene, Sleeps, Status};
use lagrange_integrators::{Rk4, StormerVerlet};
use lagrange_systems::{DoublePendulum, SimplePendulum};
use lagrange_tests::{for_f32_and_f64, Rng};
use std::collections::BTreeMap;

const DT: f64 = 1.0 / 120.0;
const G: f64 = 9.81;

/// Pendulums, damped or not, that sleep.
type Props<T> = Bank<T, 1, 16, SimplePendulum<T>, StormerVerlet<T, 1>, Sleeps<T>>;
/// Double pendulums that sleep.
type Chains<T> = Bank<T, 2, 8, DoublePendulum<T>, Rk4, Sleeps<T>>;
type World<T> = Scene<T, (Props<T>, Chains<T>)>;

/// An instance to add.
#[derive(Debug, Clone, Copy)]
enum Spec<T: Real> {
    Prop(SimplePendulum<T>, State<T, 1>),
    Chain(DoublePendulum<T>, State<T, 2>),
}

/// Where a label's instance is.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Which {
    Prop(Id),
    Chain(Id),
}

/// What happens to a label at a frame.
#[derive(Debug, Clone, Copy)]
enum Act<T: Real> {
    Add(Spec<T>),
    Remove,
    /// A state written: its coordinates plus this, at rest.
    Nudge(T),
    /// An impulse of this on every coordinate.
    Impulse(T),
    Wake,
    Contact,
    /// A prop's damping set to this.
    Damp(T),
}

fn prop<T: Real>(damping: f64, th: f64) -> Result<Spec<T>, Error> {
    let p = SimplePendulum::new(T::one(), T::one(), T::from_f64(G), T::from_f64(damping))?;
    Ok(Spec::Prop(p, State::at_rest([T::from_f64(th)])))
}

fn chain<T: Real>(th1: f64, th2: f64) -> Result<Spec<T>, Error> {
    let p = DoublePendulum::new(T::one(), T::HALF, T::one(), T::HALF, T::from_f64(G))?;
    Ok(Spec::Chain(
        p,
        State::at_rest([T::from_f64(th1), T::from_f64(th2)]),
    ))
}

/// Labels 0 to 14, added first: props that swing forever (undamped), settle in seconds, or
/// rest from the start, and chains at rest (they sleep) or swinging.
fn initial<T: Real>() -> Result<Vec<Spec<T>>, Error> {
    Ok(vec![
        prop(2.0, 0.3)?,
        prop(0.0, 5e-5)?,
        prop(3.0, 1.0)?,
        prop(0.0, 0.5)?,
        prop(5.0, -0.4)?,
        prop(0.5, 0.2)?,
        prop(2.0, 0.0)?,
        prop(0.0, -1.0)?,
        prop(4.0, 2.0)?,
        prop(1.0, -0.05)?,
        chain(0.0, 0.0)?,
        chain(1e-5, -1e-5)?,
        chain(0.5, -0.3)?,
        chain(0.0, 1e-5)?,
        chain(1.2, 0.4)?,
    ])
}

/// The script: `(frame, label, act)`, the acts of one frame applied in a shuffled order.
fn script<T: Real>() -> Result<Vec<(usize, usize, Act<T>)>, Error> {
    let h = T::from_f64;
    Ok(vec![
        (60, 3, Act::Remove),
        (60, 11, Act::Remove),
        (60, 6, Act::Wake),
        (90, 15, Act::Add(prop(1.5, 0.8)?)),
        (90, 16, Act::Add(chain(0.3, 0.3)?)),
        (90, 17, Act::Add(prop(0.0, 0.0)?)),
        (600, 1, Act::Impulse(h(0.5))),
        (600, 6, Act::Nudge(h(0.4))),
        (600, 10, Act::Contact),
        (600, 13, Act::Impulse(h(0.2))),
        (600, 9, Act::Wake),
        (600, 4, Act::Damp(h(0.2))),
        (700, 15, Act::Remove),
        (700, 0, Act::Remove),
        (710, 18, Act::Add(prop(3.0, -0.6)?)),
        (710, 19, Act::Add(chain(0.0, 0.0)?)),
        (900, 17, Act::Contact),
        (900, 19, Act::Nudge(h(0.1))),
    ])
}

/// A Fisher-Yates shuffle by `rng`.
fn shuffle<X>(xs: &mut [X], rng: &mut Rng) {
    for i in (1..xs.len()).rev() {
        let j = ((rng.unit() * (i + 1) as f64) as usize).min(i);
        xs.swap(i, j);
    }
}

fn add<T: Real>(world: &mut World<T>, spec: Spec<T>) -> Result<Which, Error> {
    let (props, chains) = world.banks_mut();
    Ok(match spec {
        Spec::Prop(m, s) => Which::Prop(props.add(m, s)?),
        Spec::Chain(m, s) => Which::Chain(chains.add(m, s)?),
    })
}

fn act<T: Real>(world: &mut World<T>, which: Which, act: Act<T>) -> Result<(), Error> {
    let (props, chains) = world.banks_mut();
    match (which, act) {
        (_, Act::Add(_)) => return Err(Error::NoSuchInstance),
        (Which::Prop(id), Act::Remove) => drop(props.remove(id)?),
        (Which::Chain(id), Act::Remove) => drop(chains.remove(id)?),
        (Which::Prop(id), Act::Nudge(d)) => {
            let s = props.state(id)?;
            props.set_state(id, State::at_rest([s.q[0] + d]))?;
        }
        (Which::Chain(id), Act::Nudge(d)) => {
            let s = chains.state(id)?;
            chains.set_state(id, State::at_rest([s.q[0] + d, s.q[1] - d]))?;
        }
        (Which::Prop(id), Act::Impulse(p)) => props.apply_impulse(id, &[p].into())?,
        (Which::Chain(id), Act::Impulse(p)) => chains.apply_impulse(id, &[p, p].into())?,
        (Which::Prop(id), Act::Wake) => props.wake(id)?,
        (Which::Chain(id), Act::Wake) => chains.wake(id)?,
        (Which::Prop(id), Act::Contact) => props.contact(id)?,
        (Which::Chain(id), Act::Contact) => chains.contact(id)?,
        (Which::Prop(id), Act::Damp(b)) => props.modify(id, |p| {
            *p = SimplePendulum::new(p.mass(), p.length(), p.gravity(), b)?;
            Ok(())
        })?,
        (Which::Chain(_), Act::Damp(_)) => return Err(Error::NoSuchInstance),
    }
    Ok(())
}

/// One label's bits (time, coordinates, velocities) and status.
type Snapshot = (usize, Vec<u64>, Status);

fn snapshot<T: Real>(
    world: &World<T>,
    labels: &BTreeMap<usize, Which>,
) -> Result<Vec<Snapshot>, Error> {
    let (props, chains) = world.banks();
    labels
        .iter()
        .map(|(&label, &which)| {
            let (s, status): (Vec<T>, Status) = match which {
                Which::Prop(id) => {
                    let s = props.state(id)?;
                    (vec![s.t, s.q[0], s.qd[0]], props.status(id)?)
                }
                Which::Chain(id) => {
                    let s = chains.state(id)?;
                    (
                        vec![s.t, s.q[0], s.q[1], s.qd[0], s.qd[1]],
                        chains.status(id)?,
                    )
                }
            };
            Ok((
                label,
                s.iter().map(|x| x.to_f64().to_bits()).collect(),
                status,
            ))
        })
        .collect()
}

/// What one order of adding gave: the snapshots every 25 frames, and each label's id index
/// when it was added.
struct Run {
    snapshots: Vec<Vec<Snapshot>>,
    indices: BTreeMap<usize, usize>,
}

/// The scene run with the initial instances added in the order `order`, and each frame's
/// acts applied in an order shuffled by `seed`; frame times from a fixed seed.
fn run<T: Real>(order: &[usize], seed: u64) -> Result<Run, Error> {
    let rule = Sleeps::new(T::from_f64(1e-6), T::from_f64(1e-3), 60)?;
    let props: Props<T> = Bank::new(StormerVerlet::default(), rule)?;
    let chains: Chains<T> = Bank::new(Rk4, rule)?;
    let mut world = Scene::new((props, chains), T::from_f64(DT), 4)?;
    let specs = initial::<T>()?;
    let mut labels = BTreeMap::new();
    let mut indices = BTreeMap::new();
    let index = |w: Which| match w {
        Which::Prop(id) | Which::Chain(id) => id.index(),
    };
    for &label in order {
        let which = add(&mut world, specs[label])?;
        indices.insert(label, index(which));
        labels.insert(label, which);
    }
    let script = script::<T>()?;
    let mut shuffler = Rng::new(seed);
    let mut frames = Rng::new(2024);
    let mut snapshots = Vec::new();
    for frame in 0..1200 {
        let mut acts: Vec<_> = script.iter().filter(|(f, _, _)| *f == frame).collect();
        shuffle(&mut acts, &mut shuffler);
        for &&(_, label, a) in &acts {
            if let Act::Add(spec) = a {
                let which = add(&mut world, spec)?;
                indices.insert(label, index(which));
                labels.insert(label, which);
            } else {
                let which = *labels.get(&label).ok_or(Error::NoSuchInstance)?;
                act(&mut world, which, a)?;
                if matches!(a, Act::Remove) {
                    labels.remove(&label);
                }
            }
        }
        let u = frames.unit();
        let frame_time = if u < 0.1 {
            0.0
        } else {
            2.5 * DT * frames.unit()
        };
        assert_eq!(world.advance(T::from_f64(frame_time))?.failed, 0);
        if frame % 25 == 0 || frame == 1199 {
            snapshots.push(snapshot(&world, &labels)?);
        }
    }
    Ok(Run { snapshots, indices })
}

/// Four orders of adding the 15 initial instances (as listed, reversed, two shuffles) and
/// of each frame's acts: every label's bits and status, every 25 frames over 1200 (some
/// 20 s), are the same. Along the way instances fall asleep, are woken by impulses, writes,
/// explicit wakes, contacts and a new damping, and are removed and added (taking ids freed
/// by others, in orders that differ).
fn bits_do_not_depend_on_the_order_of_adding<T: Real>() -> Result<(), Error> {
    let n = initial::<T>()?.len();
    let listed: Vec<usize> = (0..n).collect();
    let reversed: Vec<usize> = (0..n).rev().collect();
    let mut shuffled = [listed.clone(), listed.clone()];
    for (order, seed) in shuffled.iter_mut().zip([7, 8]) {
        shuffle(order, &mut Rng::new(seed));
    }
    let orders = [listed, reversed, shuffled[0].clone(), shuffled[1].clone()];
    let runs = orders
        .iter()
        .zip(1..)
        .map(|(order, seed)| run::<T>(order, seed))
        .collect::<Result<Vec<_>, _>>()?;
    let reference = &runs[0];
    for (other, order) in runs.iter().zip(&orders).skip(1) {
        assert_eq!(other.snapshots.len(), reference.snapshots.len());
        for (a, b) in reference.snapshots.iter().zip(&other.snapshots) {
            assert_eq!(a, b, "added in the order {order:?}");
        }
        // The orders did give the instances different ids.
        assert_ne!(other.indices, reference.indices, "{order:?}");
    }
    // Something happened: sleepers, and sleepers woken by the script.
    let count = |status: Status| {
        reference
            .snapshots
            .iter()
            .flatten()
            .filter(|s| s.2 == status)
            .count()
    };
    let (asleep, awake) = (count(Status::Asleep), count(Status::Awake));
    println!("label-snapshots asleep {asleep}, awake {awake}");
    assert!(asleep > 100 && awake > 100);
    // Labels 1, 10 and 13 rest from the start: asleep before frame 600, awake just after.
    let status_at = |frame: usize, label: usize| {
        reference.snapshots[frame / 25]
            .iter()
            .find(|s| s.0 == label)
            .map(|s| s.2)
    };
    for label in [1, 10, 13] {
        assert_eq!(status_at(575, label), Some(Status::Asleep), "label {label}");
        assert_eq!(status_at(600, label), Some(Status::Awake), "label {label}");
    }
    Ok(())
}

for_f32_and_f64!(bits_do_not_depend_on_the_order_of_adding);
