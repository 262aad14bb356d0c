//! The ragdoll cases: the adult ragdoll thrown onto the floor in `f32`, landing and settling
//! under [`ImpulseStepper`] (semi-implicit Euler inside, the ragdoll's 31 rows), and the same
//! throw with no floor stepped by RK4, the free step the landing's cost is compared with.
//! Both take their steps through a [`Stopwatch`], so that the firmware can time the worst.

use core::hint::black_box;

use lagrange_core::{Error, Real, State};
use lagrange_integrators::{
    ContactModel, ImpulseReport, ImpulseSettings, ImpulseStepper, Integrator, Rk4,
    SemiImplicitEuler,
};
use lagrange_systems::{
    Ragdoll, RagdollBody, RagdollContacts, RAGDOLL_CONTACTS, RAGDOLL_COORDINATES as N,
};

use crate::{Outcome, Precision, Stopwatch};

/// The step of the ragdoll cases, s: 240 Hz.
pub const RAGDOLL_DT: f64 = 1.0 / 240.0;

/// The name of the landing case in [`CASES`](crate::CASES).
pub const RAGDOLL_LANDING: &str = "ragdoll landing (31 rows)";

/// The name of the free case (no floor, RK4) in [`CASES`](crate::CASES).
pub const RAGDOLL_FREE: &str = "ragdoll thrown, no floor";

/// Rows of the landing's contact set: 13 floor points, a lower and an upper limit for each of
/// the 9 joints.
pub const RAGDOLL_ROWS: usize = RAGDOLL_CONTACTS;

/// The landing's contact solver: restitution 0.3, rest speed 0.3 m/s, friction 0.8 (the
/// model's time tolerance, 1 s, is not used by the stepper).
fn model() -> Result<ContactModel<f32>, Error> {
    ContactModel::new(black_box(0.3), black_box(0.3), 1.0)?.with_friction(black_box(0.8))
}

/// The slop, 2 mm (and 2 mrad at the joint limits), and at most
/// [`RAGDOLL_ITERATIONS`] rounds for a step's plastic solve.
fn settings() -> Result<ImpulseSettings<f32>, Error> {
    ImpulseSettings::new(black_box(2e-3), RAGDOLL_ITERATIONS)
}

/// The landing's cap on the rounds of a step's plastic solve
/// (`ImpulseSettings::max_iterations`; a step takes at most three more).
pub const RAGDOLL_ITERATIONS: u32 = 4;

/// The throw of `examples/ragdoll.rs`: the torso 1.6 m up, tilted 0.6 rad, limbs spread,
/// moving at (2, 1) m/s, turning at 3 rad/s.
#[must_use]
pub fn ragdoll_thrown<T: Real>() -> State<T, N> {
    let mut q = [T::zero(); N];
    let mut qd = [T::zero(); N];
    q[1] = T::from_f64(1.6);
    q[2] = T::from_f64(0.6);
    for (k, spread) in [
        (4, -1.0),
        (6, 1.0),
        (8, -0.4),
        (9, 0.5),
        (10, 0.4),
        (11, -0.5),
    ] {
        q[k] = T::from_f64(spread);
    }
    qd[0] = T::from_f64(2.0);
    qd[1] = T::one();
    qd[2] = T::from_f64(3.0);
    State::new(T::zero(), q, qd)
}

/// FNV-1a over the bits of every coordinate and velocity of `s`.
fn digest(s: &State<f32, N>) -> u64 {
    s.q.iter()
        .chain(s.qd.iter())
        .fold(0xcbf2_9ce4_8422_2325, |hash, x| {
            (hash ^ x.bits()).wrapping_mul(0x0000_0100_0000_01b3)
        })
}

/// `steps` steps of `integrator` from the throw at [`RAGDOLL_DT`], each through `watch`; the
/// end state. The ragdoll's parameters, the step and the count pass through [`black_box`].
fn throw<I: Integrator<f32, N, Ragdoll<f32>>>(
    integrator: &mut I,
    doll: &Ragdoll<f32>,
    steps: u32,
    watch: &mut dyn Stopwatch,
) -> Result<State<f32, N>, Error> {
    let dt = black_box(RAGDOLL_DT as f32);
    let mut s = black_box(ragdoll_thrown());
    for _ in 0..black_box(steps) {
        watch.time(&mut || {
            s = integrator.step(doll, &s, dt)?;
            Ok(())
        })?;
    }
    Ok(s)
}

/// The adult ragdoll.
fn adult() -> Result<Ragdoll<f32>, Error> {
    Ragdoll::new(black_box(RagdollBody::adult())).map(black_box)
}

/// The thrown ragdoll landing on a floor at height 0 and settling: `ImpulseStepper` with
/// semi-implicit Euler inside and the ragdoll's 31 rows (13 floor points, 18 joint limits),
/// restitution 0.3, friction 0.8, slop 2 mm, at most [`RAGDOLL_ITERATIONS`] + 3 rounds a step,
/// `steps` steps of [`RAGDOLL_DT`] (1000: 4.2 s, down and at rest), each through `watch`.
///
/// The outcome's 9 words: `t`; an FNV-1a digest of the bits of the final `q` and `q'`; the
/// torso's `q[0]`, `q[1]`, `q[2]` (x, y, angle); then the stepper's peak report, the worst of
/// any step: rows solved, of them speculative, with friction, and rounds.
///
/// # Errors
/// A constructor's or a step's error (none for these values).
pub fn ragdoll_landing(steps: u32, watch: &mut dyn Stopwatch) -> Result<Outcome, Error> {
    let doll = adult()?;
    let contacts = RagdollContacts::adult(&doll, black_box(0.0))?;
    let mut stepper = ImpulseStepper::new(SemiImplicitEuler, contacts, model()?, settings()?);
    let s = throw(&mut stepper, &doll, steps, watch)?;
    let ImpulseReport {
        rows,
        speculative,
        frictional,
        rounds,
        ..
    } = stepper.peak_report();
    Ok(Outcome::from_words(&[
        s.t.bits(),
        digest(&s),
        s.q[0].bits(),
        s.q[1].bits(),
        s.q[2].bits(),
        u64::from(rows),
        u64::from(speculative),
        u64::from(frictional),
        u64::from(rounds),
    ]))
}

/// The same throw with no floor and no joint limits, stepped by RK4: the free step of the
/// ragdoll (four accelerations of its articulated-body recursion), `steps` steps of
/// [`RAGDOLL_DT`], each through `watch`.
///
/// The outcome's 5 words: `t`; the digest of the final `q` and `q'`; the torso's `q[0]`,
/// `q[1]`, `q[2]`.
///
/// # Errors
/// A constructor's or a step's error (none for these values).
pub fn ragdoll_free(steps: u32, watch: &mut dyn Stopwatch) -> Result<Outcome, Error> {
    let doll = adult()?;
    let s = throw(&mut Rk4, &doll, steps, watch)?;
    Ok(Outcome::from_words(&[
        s.t.bits(),
        digest(&s),
        s.q[0].bits(),
        s.q[1].bits(),
        s.q[2].bits(),
    ]))
}
