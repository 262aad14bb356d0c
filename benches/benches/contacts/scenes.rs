//! The scenes: the thrown ragdoll, the double pendulum on the floor and the bouncing ball,
//! each with lagrange's two contact steppers and a free RK4, ready to be timed.

use lagrange_core::constraints::contact::{ContactModel, Contacts};
use lagrange_core::nalgebra::{SVector, Vector4};
use lagrange_core::{
    Error, Holonomic, HolonomicConstraints, Mechanism, Projection, Real, Scalar, State,
};
use lagrange_integrators::{
    ContactStepper, ImpulseSettings, ImpulseStepper, Integrator, Rk4, SemiImplicitEuler,
};
use lagrange_systems::{
    DoublePendulum, FallingParticle, Ragdoll, RagdollBody, RagdollContacts,
    RAGDOLL_COORDINATES as N, RAGDOLL_FLOOR_POINTS,
};

use crate::run::{figures, timed_run, Figures};
use crate::Candidate;

/// The ragdoll's step, s (the example's).
pub const RAGDOLL_DT: f64 = 1.0 / 240.0;

/// The time-stepping stepper's slop, m (or rad, on a limit): a contact may rest this deep,
/// which keeps it in touch from step to step (warm-started, quiet) rather than lifted and
/// caught again. 2 mm is below what a viewer sees on a human-sized body and above the
/// `dt^2 g = 0.17 mm` a resting body sinks in one step at 1/240 s.
pub const SLOP: f64 = 2e-3;

/// The time-stepping stepper's cap on the rounds of a step's plastic solve (and the friction
/// sweeps of a round): four, a game's usual budget; the normal rows are solved exactly each
/// round, so the cap only bounds the friction's alternation with them.
pub const MAX_ITERATIONS: u32 = 4;

/// `for_f32` in f32, `for_f64` in f64.
fn pick<T: Real>(for_f32: f64, for_f64: f64) -> T {
    T::from_f64(if T::EPSILON.to_f64() > 1e-10 {
        for_f32
    } else {
        for_f64
    })
}

/// The time-stepping stepper's settings.
fn settings<T: Real>() -> Result<ImpulseSettings<T>, Error> {
    ImpulseSettings::new(T::from_f64(SLOP), MAX_ITERATIONS)
}

/// The example's throw: torso 1.6 m up, tilted 0.6 rad, limbs spread, moving at (2, 1) m/s,
/// turning at 3 rad/s.
pub fn thrown() -> State<f64, N> {
    let mut q = [0.0; N];
    let mut qd = [0.0; N];
    q[1] = 1.6;
    q[2] = 0.6;
    for (k, spread) in [
        (4, -1.0),
        (6, 1.0),
        (8, -0.4),
        (9, 0.5),
        (10, 0.4),
        (11, -0.5),
    ] {
        q[k] = spread;
    }
    qd[0] = 2.0;
    qd[1] = 1.0;
    qd[2] = 3.0;
    State::new(0.0, q, qd)
}

/// Sixteen other throws of the same ragdoll (`ragdoll_throws`): the example's turned by
/// -1.0 to +0.74 rad, its limbs spread 34% to 90% as far, thrown at -0.5 to 3.4 m/s
/// sideways and 0.6 to 2.5 m/s up, spun at -1.0 to 5.2 rad/s (throw `v`, 1 to 16, moves
/// each by `v mod 6` steps of one size and `v / 6` of another). Each lands otherwise (the
/// solves' rounds depend on how the limbs meet the floor), so the spread of their costs
/// says what one throw's figures do not.
pub fn other_throws() -> Vec<State<f64, N>> {
    (1..=16)
        .map(|v: u32| {
            let (a, b) = (f64::from(v % 6), f64::from(v / 6));
            let mut s = thrown();
            s.q[2] += -0.2 * a + 0.37 * b;
            for k in [4, 6, 8, 9, 10, 11] {
                s.q[k] *= 1.0 - 0.1 * a - 0.13 * b;
            }
            s.qd[0] += -0.5 * a + 0.7 * b;
            s.qd[1] += 0.3 * a - 0.2 * b;
            s.qd[2] += -0.8 * a + 1.1 * b;
            s
        })
        .collect()
}

/// The scene of one mechanism: what its steppers share.
pub struct Scene<T: Real, M, K, const N: usize> {
    /// The mechanism.
    pub mechanism: M,
    /// Its contact rows.
    pub contacts: K,
    /// The first rows of `contacts` are the floor's (the others joint limits).
    pub floor_rows: usize,
    /// Where every run starts.
    pub start: State<T, N>,
    /// The step, s.
    pub dt: T,
    /// Steps of a run.
    pub steps: usize,
    /// Restitution, rest speed, time tolerance (the event stepper's), friction.
    pub model: ContactModel<T>,
    /// The event stepper's projection.
    pub projection: Projection<T>,
}

/// The thrown ragdoll for `seconds`: the example's body, contacts, model (e = 0.3, rest
/// speed 0.3 m/s, events to 1e-7 s, friction 0.8) and projection (to 1e-9 m in f64, 1e-5 m
/// in f32, where 1e-9 is below the rounding of a coordinate, as the contact tests use).
///
/// # Errors
/// Never, for these parameters.
pub fn ragdoll<T: Real>(
    seconds: f64,
) -> Result<Scene<T, Ragdoll<T>, RagdollContacts<T>, N>, Error> {
    ragdoll_from(seconds, &thrown())
}

/// The ragdoll of [`ragdoll`] thrown from `s`.
///
/// # Errors
/// Never, for these parameters.
pub fn ragdoll_from<T: Real>(
    seconds: f64,
    s: &State<f64, N>,
) -> Result<Scene<T, Ragdoll<T>, RagdollContacts<T>, N>, Error> {
    let doll = Ragdoll::new(RagdollBody::<T>::adult())?;
    Ok(Scene {
        mechanism: doll,
        contacts: RagdollContacts::adult(&doll, T::zero())?,
        floor_rows: RAGDOLL_FLOOR_POINTS,
        start: State::new(
            T::zero(),
            s.q.map(T::from_f64).into(),
            s.qd.map(T::from_f64).into(),
        ),
        dt: T::from_f64(RAGDOLL_DT),
        steps: steps(seconds, RAGDOLL_DT),
        model: ContactModel::new(T::from_f64(0.3), T::from_f64(0.3), T::from_f64(1e-7))?
            .with_friction(T::from_f64(0.8))?,
        projection: Projection::new(pick(1e-5, 1e-9), 8)?,
    })
}

/// Steps in `seconds` of `dt`.
fn steps(seconds: f64, dt: f64) -> usize {
    (seconds / dt).round() as usize
}

/// The floor 0.8 m below the pivot and the bend limited to +-2.5 rad (the repository's
/// `tests/tests/double_pendulum_floor.rs`): rows 0 and 1 the masses' heights above the
/// floor, rows 2 and 3 the limits.
#[derive(Debug, Clone, Copy)]
pub struct FloorAndLimits;

impl<T: Real> HolonomicConstraints<T, 2, 4> for FloorAndLimits {
    fn phi<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 2>) -> SVector<S, 4> {
        let (floor, bend) = (S::from_f64(0.8), S::from_f64(2.5));
        let y1 = -q[0].cos();
        let y2 = y1 - q[1].cos();
        let relative = q[1] - q[0];
        Vector4::new(y1 + floor, y2 + floor, bend - relative, bend + relative)
    }
}

/// The double pendulum on the floor for `seconds`, as the repository's test: unit masses and
/// rods, from (1.6, 2.2) rad moving at (2, -6) rad/s, dt = 1e-3 s, e = 0.8, rest speed
/// 0.1 m/s, events to 1e-9 s (1e-6 in f32), projection to 1e-10 (1e-5 in f32), no friction.
///
/// # Errors
/// Never, for these parameters.
pub fn double_pendulum<T: Real>(
    seconds: f64,
) -> Result<Scene<T, DoublePendulum<T>, Holonomic<FloorAndLimits>, 2>, Error> {
    let one = T::one();
    Ok(Scene {
        mechanism: DoublePendulum::new(one, one, one, one, T::from_f64(9.81))?,
        contacts: Holonomic::new(FloorAndLimits),
        floor_rows: 2,
        start: State::new(
            T::zero(),
            [T::from_f64(1.6), T::from_f64(2.2)],
            [T::from_f64(2.0), T::from_f64(-6.0)],
        ),
        dt: T::from_f64(1e-3),
        steps: steps(seconds, 1e-3),
        model: ContactModel::new(T::from_f64(0.8), T::from_f64(0.1), pick(1e-6, 1e-9))?,
        projection: Projection::new(pick(1e-5, 1e-10), 6)?,
    })
}

/// The ground at y = 0 under a falling particle.
#[derive(Debug, Clone, Copy)]
pub struct Ground;

impl<T: Real> HolonomicConstraints<T, 1, 1> for Ground {
    fn phi<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 1>) -> SVector<S, 1> {
        *q
    }
}

/// A 1 kg ball dropped from 1 m for `seconds`, e = 0.5, rest speed 0.05 m/s, dt = 1e-3 s,
/// events to 1e-10 s (1e-6 in f32), projection to 1e-12 m (1e-6 in f32), as the
/// repository's bouncing-ball test but for its restitution.
///
/// # Errors
/// Never, for these parameters.
pub fn ball<T: Real>(
    seconds: f64,
) -> Result<Scene<T, FallingParticle<T>, Holonomic<Ground>, 1>, Error> {
    Ok(Scene {
        mechanism: FallingParticle::new(T::one(), T::from_f64(9.81))?,
        contacts: Holonomic::new(Ground),
        floor_rows: 1,
        start: State::at_rest([T::one()]),
        dt: T::from_f64(1e-3),
        steps: steps(seconds, 1e-3),
        model: ContactModel::new(T::from_f64(0.5), T::from_f64(0.05), pick(1e-6, 1e-10))?,
        projection: Projection::new(pick(1e-6, 1e-12), 4)?,
    })
}

/// The scene's candidates: a free RK4 (no contacts: the cost to compare with), the
/// time-stepping stepper (semi-implicit Euler inside) and the event-driven one (RK4 inside).
///
/// # Errors
/// The time-stepping settings' (never, for these).
pub fn candidates<T, M, K, const N2: usize, const C: usize>(
    scene: Scene<T, M, K, N2>,
) -> Result<Vec<Candidate>, Error>
where
    T: Real,
    M: Mechanism<T, N2> + Copy + 'static,
    K: Contacts<T, N2, C> + Copy + 'static,
    ImpulseStepper<T, N2, C, SemiImplicitEuler, K>: Integrator<T, N2, M>,
    ContactStepper<T, N2, C, Rk4, K>: Integrator<T, N2, M>,
{
    let Scene {
        mechanism,
        contacts,
        floor_rows,
        start,
        dt,
        steps,
        model,
        projection,
    } = scene;
    let settings = settings::<T>()?;
    let time_stepping = move || ImpulseStepper::new(SemiImplicitEuler, contacts, model, settings);
    let event = move || ContactStepper::new(Rk4, contacts, model, projection);
    let as_figures = |f: Figures| crate::Measured {
        depth: f.depth,
        limit_depth: Some(f.limit_depth),
        energy_gain: f.energy_gain,
        contact_steps: f.contact_steps,
        note: String::new(),
    };
    Ok(vec![
        Candidate {
            stepper: crate::FREE,
            run: Box::new(move |per_step| timed_run(&mechanism, &start, dt, steps, Rk4, per_step)),
            figures: None,
        },
        Candidate {
            stepper: "time_stepping",
            run: Box::new(move |per_step| {
                timed_run(&mechanism, &start, dt, steps, time_stepping(), per_step)
            }),
            figures: Some(Box::new(move || {
                // What the steps did, from the stepper's report: rows and rounds.
                let (mut rows, mut most_rows, mut rounds, mut most_rounds) = (0u64, 0, 0u64, 0);
                let (mut unsettled, mut guarded, mut touching) = (0u64, 0u64, 0u64);
                let f = figures(
                    &mechanism,
                    &contacts,
                    floor_rows,
                    &start,
                    dt,
                    steps,
                    time_stepping(),
                    SemiImplicitEuler,
                    |st: &ImpulseStepper<T, N2, C, SemiImplicitEuler, K>| {
                        let r = st.last_report();
                        if r.rows > 0 {
                            touching += 1;
                            rows += u64::from(r.rows);
                            rounds += u64::from(r.rounds);
                        }
                        most_rows = most_rows.max(r.rows);
                        most_rounds = most_rounds.max(r.rounds);
                        unsettled += u64::from(!r.settled);
                        guarded += u64::from(r.energy_guard);
                    },
                )?;
                let per = |x: u64| x as f64 / touching.max(1) as f64;
                Ok(crate::Measured {
                    note: format!(
                        "steps with rows: {touching}, rows {:.1} on average (at most \
                         {most_rows}), rounds {:.1} (at most {most_rounds}); friction \
                         unsettled in {unsettled} steps, energy guard in {guarded}",
                        per(rows),
                        per(rounds)
                    ),
                    ..as_figures(f)
                })
            })),
        },
        Candidate {
            stepper: crate::EVENT,
            run: Box::new(move |per_step| {
                timed_run(&mechanism, &start, dt, steps, event(), per_step)
            }),
            figures: Some(Box::new(move || {
                let (mut impacts, mut most) = (0u64, 0u64);
                let f = figures(
                    &mechanism,
                    &contacts,
                    floor_rows,
                    &start,
                    dt,
                    steps,
                    event(),
                    Rk4,
                    |st: &ContactStepper<T, N2, C, Rk4, K>| {
                        most = most.max(st.impacts() - impacts);
                        impacts = st.impacts();
                    },
                )?;
                Ok(crate::Measured {
                    note: format!("impacts: {impacts}, at most {most} in a step"),
                    ..as_figures(f)
                })
            })),
        },
    ])
}
