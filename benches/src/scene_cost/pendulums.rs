//! 1,000 damped pendulums at dt = 1/120 s: a frame's cost against the fraction awake (a bank
//! one by one, and for RK4 in `f32` also in lanes), and against the loops a scene replaces.

use super::frames::{ns_per_frame, ratio};
use super::{Ratio, Row};
use lagrange_benches::precision;
use lagrange_benches::timing::Budget;
use lagrange_integrators::prelude::*;
use lagrange_integrators::scene::{InLanes, Layout, OneByOne};
use lagrange_integrators::FrameClock;
use lagrange_systems::SimplePendulum;

/// Pendulums in the scene.
pub const INSTANCES: usize = 1000;
/// The fixed step, s: one step per frame at 120 Hz.
const DT: f64 = 1.0 / 120.0;
/// Fractions of the pendulums awake.
const FRACTIONS: [f64; 4] = [1.0, 0.5, 0.1, 0.01];
/// Most steps per frame.
const CAP: u32 = 8;
/// The goal for a frame with everything awake against the hand loop.
const OVERHEAD_GOAL: f64 = 1.03;
/// The goal for all awake against 10% awake.
const SLEEP_GOAL: f64 = 8.0;

/// A 1 m, 1 kg pendulum with light damping (0.01 N m s): swinging from 1 rad it keeps an
/// amplitude of a radian for minutes, so the swinging ones stay awake while measured.
fn pendulum<T: Real>() -> Result<SimplePendulum<T>, Error> {
    SimplePendulum::new(T::one(), T::one(), T::from_f64(9.81), T::from_f64(0.01))
}

/// The sleep rule: below 1e-6 J and 1e-3 rad/s^2 for 60 steps (half a second).
fn rule<T: Real>() -> Result<Sleeps<T>, Error> {
    Sleeps::new(T::from_f64(1e-6), T::from_f64(1e-3), 60)
}

/// The pendulum bank with sleeping by `Z`, laid out by `Y`.
type Pendulums<T, I, Z, Y = OneByOne> = Bank<T, 1, INSTANCES, SimplePendulum<T>, I, Z, Y>;

/// A scene of one [`Pendulums`] bank.
type PendulumScene<T, I, Z, Y> = Scene<T, Pendulums<T, I, Z, Y>>;

/// A scene of [`INSTANCES`] pendulums, `awake` of them swinging from 1 rad and the rest
/// asleep at the bottom, the two kinds added interleaved.
fn scene<T, I, Z, Y>(
    integrator: I,
    sleep: Z,
    awake: usize,
) -> Result<PendulumScene<T, I, Z, Y>, Error>
where
    T: Real,
    I: Integrator<T, 1, SimplePendulum<T>> + Clone,
    Z: lagrange_integrators::scene::Sleep<T>,
    Y: Layout<T, 1, INSTANCES, SimplePendulum<T>>,
{
    let mut bank = Bank::new(integrator, sleep)?;
    let p = pendulum()?;
    let mut added = 0;
    for k in 0..INSTANCES {
        // Spread the swinging ones evenly through the order of adding.
        if (k * awake) / INSTANCES >= added && added < awake {
            bank.add(p, State::at_rest([T::one()]))?;
            added += 1;
        } else {
            bank.add(p, State::at_rest([T::zero()]))?;
        }
    }
    Scene::new(bank, T::from_f64(DT), CAP)
}

/// Steps the scene's frames until the resting ones are asleep (a second of frames).
fn settle<T, I, Z, Y>(scene: &mut PendulumScene<T, I, Z, Y>) -> Result<(), Error>
where
    T: Real,
    I: Integrator<T, 1, SimplePendulum<T>> + Clone,
    Z: lagrange_integrators::scene::Sleep<T>,
    Y: Layout<T, 1, INSTANCES, SimplePendulum<T>>,
{
    for _ in 0..120 {
        scene.advance(T::from_f64(DT))?;
    }
    Ok(())
}

/// One `FixedTimestep` per pendulum: the loop of a program without scenes.
struct Clocks<T: Real, I> {
    mechanisms: Vec<SimplePendulum<T>>,
    clocks: Vec<FixedTimestep<T, 1, I>>,
}

/// The hand loop a scene replaces: the same slots (mechanism, integrator, last two states),
/// one clock.
struct HandLoop<T: Real, I> {
    clock: FrameClock<T>,
    slots: Vec<HandSlot<T, I>>,
}

/// A slot of the hand loop: mechanism, integrator, previous and current state.
type HandSlot<T, I> = (SimplePendulum<T>, I, State<T, 1>, State<T, 1>);

impl<T: Real, I: Integrator<T, 1, SimplePendulum<T>> + Clone> HandLoop<T, I> {
    fn new(integrator: &I) -> Result<Self, Error> {
        let start = State::at_rest([T::one()]);
        Ok(Self {
            clock: FrameClock::new(T::from_f64(DT), CAP, T::zero())?,
            slots: (0..INSTANCES)
                .map(|_| Ok((pendulum()?, integrator.clone(), start, start)))
                .collect::<Result<_, Error>>()?,
        })
    }

    fn frame(&mut self) -> Result<(), Error> {
        let dt = self.clock.dt();
        let slots = &mut self.slots;
        self.clock.advance(dt, |t| {
            for (m, integrator, previous, current) in slots.iter_mut() {
                let mut next = integrator.step(m, current, dt)?;
                next.t = t;
                *previous = *current;
                *current = next;
            }
            Ok(())
        })?;
        Ok(())
    }
}

impl<T: Real, I: Integrator<T, 1, SimplePendulum<T>> + Clone> Clocks<T, I> {
    fn new(integrator: &I) -> Result<Self, Error> {
        let start = State::at_rest([T::one()]);
        Ok(Self {
            mechanisms: vec![pendulum()?; INSTANCES],
            clocks: (0..INSTANCES)
                .map(|_| FixedTimestep::new(integrator.clone(), T::from_f64(DT), CAP, start))
                .collect::<Result<_, Error>>()?,
        })
    }

    fn frame(&mut self) -> Result<(), Error> {
        let dt = T::from_f64(DT);
        for (m, c) in self.mechanisms.iter().zip(&mut self.clocks) {
            c.advance(m, dt)?;
        }
        Ok(())
    }
}

/// Every row and ratio of the pendulum scene, for Stormer-Verlet and RK4 in `f32`, and
/// Stormer-Verlet in `f64`, one by one; and the fractions awake for RK4 in `f32` in lanes.
pub fn measure(budget: Budget, rows: &mut Vec<Row>, ratios: &mut Vec<Ratio>) -> Result<(), Error> {
    one::<f32, _>(StormerVerlet::default(), budget, rows, ratios)?;
    one::<f32, _>(Rk4, budget, rows, ratios)?;
    one::<f64, _>(StormerVerlet::default(), budget, rows, ratios)?;
    by_fraction::<f32, _, InLanes>(Rk4, "lanes", budget, rows, ratios)?;
    Ok(())
}

/// A row of the pendulum scene, printed.
fn row<T: Real, I: Method>(
    scene: &str,
    layout: &'static str,
    awake_fraction: f64,
    ns_per_frame: f64,
) -> Row {
    println!(
        "{:<44} {:<10} {:<16} {}  {:>5.1}% awake  {:>10.0} ns/frame",
        scene,
        layout,
        I::NAME,
        precision::<T>(),
        awake_fraction * 100.0,
        ns_per_frame
    );
    Row {
        scene: scene.into(),
        layout,
        instances: INSTANCES,
        awake_fraction,
        integrator: I::NAME,
        scalar: precision::<T>(),
        ns_per_frame,
    }
}

/// The rows of a bank laid out by `Y` (named `layout`) with each fraction awake, and the ratio
/// of all awake to 10% awake, timed interleaved (a ratio of two medians taken apart moved by
/// 15% between runs with the load of the machine).
fn by_fraction<T, I, Y>(
    integrator: I,
    layout: &'static str,
    budget: Budget,
    rows: &mut Vec<Row>,
    ratios: &mut Vec<Ratio>,
) -> Result<(), Error>
where
    T: Real,
    I: Integrator<T, 1, SimplePendulum<T>> + Clone,
    Y: Layout<T, 1, INSTANCES, SimplePendulum<T>>,
{
    let dt = T::from_f64(DT);
    let (mut all, mut tenth) = (None, None);
    for fraction in FRACTIONS {
        let awake = ((INSTANCES as f64) * fraction).round() as usize;
        let mut s = scene::<T, I, _, Y>(integrator.clone(), rule::<T>()?, awake)?;
        settle(&mut s)?;
        let mut failure = None;
        let ns = ns_per_frame(budget, || {
            if let Err(e) = s.advance(dt) {
                failure = Some(e);
            }
        });
        if let Some(e) = failure {
            return Err(e);
        }
        if s.banks().awake() != awake {
            println!("  (expected {awake} awake, found {})", s.banks().awake());
        }
        let measured = s.banks().awake() as f64 / INSTANCES as f64;
        rows.push(row::<T, I>("pendulums", layout, measured, ns));
        if fraction == 1.0 {
            all = Some(s);
        } else if fraction == 0.1 {
            tenth = Some(s);
        }
    }
    let (Some(mut all), Some(mut tenth)) = (all, tenth) else {
        return Ok(());
    };
    let (mut r1, mut r2) = (Ok(()), Ok(()));
    let (r, _, _) = ratio(
        budget,
        || {
            if let Err(e) = all.advance(dt) {
                r1 = Err(e);
            }
        },
        || {
            if let Err(e) = tenth.advance(dt) {
                r2 = Err(e);
            }
        },
    );
    r1?;
    r2?;
    ratios.push(Ratio {
        what: format!(
            "{} {}, {layout}: all awake / 10% awake",
            I::NAME,
            precision::<T>()
        ),
        ratio: r,
        goal: ">= 8",
        met: r >= SLEEP_GOAL,
    });
    Ok(())
}

/// The rows and ratios of one integrator in one precision, one by one.
fn one<T, I>(
    integrator: I,
    budget: Budget,
    rows: &mut Vec<Row>,
    ratios: &mut Vec<Ratio>,
) -> Result<(), Error>
where
    T: Real,
    I: Integrator<T, 1, SimplePendulum<T>> + Clone,
{
    by_fraction::<T, I, OneByOne>(integrator.clone(), "one_by_one", budget, rows, ratios)?;

    // All awake, against the loops a scene replaces.
    let dt = T::from_f64(DT);
    let row = |scene: &str, fraction: f64, ns: f64| row::<T, I>(scene, "one_by_one", fraction, ns);
    let mut never = scene::<T, I, _, OneByOne>(integrator.clone(), NeverSleeps, INSTANCES)?;
    let mut sleeps = scene::<T, I, _, OneByOne>(integrator.clone(), rule::<T>()?, INSTANCES)?;
    let mut hand = HandLoop::new(&integrator)?;
    let mut clocks = Clocks::new(&integrator)?;
    let mut failures = [None, None, None, None];
    let [f0, f1, f2, f3] = &mut failures;
    let (r_never, ns_never, ns_hand) = ratio(
        budget,
        || {
            if let Err(e) = never.advance(dt) {
                *f0 = Some(e);
            }
        },
        || {
            if let Err(e) = hand.frame() {
                *f1 = Some(e);
            }
        },
    );
    let (r_sleeps, ns_sleeps, _) = ratio(
        budget,
        || {
            if let Err(e) = sleeps.advance(dt) {
                *f2 = Some(e);
            }
        },
        || {
            let _ = hand.frame();
        },
    );
    let (r_clocks, _, ns_clocks) = ratio(
        budget,
        || {
            let _ = never.advance(dt);
        },
        || {
            if let Err(e) = clocks.frame() {
                *f3 = Some(e);
            }
        },
    );
    if let Some(e) = failures.into_iter().flatten().next() {
        return Err(e);
    }
    rows.push(row("pendulums, never sleeping", 1.0, ns_never));
    rows.push(row("pendulums, sleeping, all awake", 1.0, ns_sleeps));
    rows.push(row("hand loop (same slots, one clock)", 1.0, ns_hand));
    rows.push(row("plain loop (a FixedTimestep each)", 1.0, ns_clocks));
    let name = format!("{} {}", I::NAME, precision::<T>());
    for (what, r) in [
        (format!("{name}: scene never sleeping / hand loop"), r_never),
        (
            format!("{name}: scene sleeping, all awake / hand loop"),
            r_sleeps,
        ),
    ] {
        ratios.push(Ratio {
            what,
            ratio: r,
            goal: "<= 1.03",
            met: r <= OVERHEAD_GOAL,
        });
    }
    ratios.push(Ratio {
        what: format!("{name}: scene never sleeping / a FixedTimestep each"),
        ratio: r_clocks,
        goal: "<= 1.03",
        met: r_clocks <= OVERHEAD_GOAL,
    });
    Ok(())
}
