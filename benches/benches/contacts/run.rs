//! Runs of lagrange's steppers: timed runs (ns of every step) and an untimed run that
//! measures the depth of the floor rows and the energy the contacts added.

use std::hint::black_box;
use std::time::Instant;

use lagrange_core::constraints::contact::Contacts;
use lagrange_core::{Mechanism, Real, State};
use lagrange_integrators::Integrator;

/// One timed run: `steps` steps of `stepper` from `start`. With `per_step`, each step timed
/// (ns of each); without, the whole run (one entry: its ns), so that the clock's own cost
/// (some 20 ns a reading) does not weigh on a mean of short steps. A step that fails ends the
/// run.
///
/// # Errors
/// The failing step's error, with the time it started from.
pub fn timed_run<T, M, I, const N: usize>(
    mechanism: &M,
    start: &State<T, N>,
    dt: T,
    steps: usize,
    mut stepper: I,
    per_step: bool,
) -> Result<Vec<f64>, String>
where
    T: Real,
    M: Mechanism<T, N>,
    I: Integrator<T, N, M>,
{
    let mut s = *start;
    if !per_step {
        let clock = Instant::now();
        for _ in 0..steps {
            s = stepper
                .step(mechanism, black_box(&s), dt)
                .map_err(|e| failed(&s, &e))?;
        }
        let ns = clock.elapsed().as_nanos() as f64;
        black_box(s);
        return Ok(vec![ns]);
    }
    let mut ns = Vec::with_capacity(steps);
    for _ in 0..steps {
        let clock = Instant::now();
        let next = stepper.step(mechanism, black_box(&s), dt);
        ns.push(clock.elapsed().as_nanos() as f64);
        s = next.map_err(|e| failed(&s, &e))?;
    }
    black_box(s);
    Ok(ns)
}

/// "failed at t = ...: error".
fn failed<T: Real, const N: usize>(s: &State<T, N>, e: &lagrange_core::Error) -> String {
    format!("failed at t = {:.4} s: {e}", s.t.to_f64())
}

/// What the untimed run of a stepper measured.
#[derive(Debug, Clone, Copy)]
pub struct Figures {
    /// The deepest negative gap of a floor row at the end of any step, m (zero when none).
    pub depth: f64,
    /// The deepest negative gap of a joint-limit row, rad (zero when none, or no limits).
    pub limit_depth: f64,
    /// `T + V` after a step less the larger of before and after the free step from the same
    /// state, the largest over the steps the contacts changed (their end differs from the
    /// free step's), J; `-inf` when no step touched.
    pub energy_gain: f64,
    /// Steps the contacts changed.
    pub contact_steps: usize,
}

/// The untimed run: `steps` steps of `stepper` from `start`, each beside the free step of
/// `free` (the stepper's inner method, contacts ignored) from the same state; depth over the
/// first `floor_rows` rows of `contacts` (the floor) and apart over the others (limits);
/// `observe` sees the stepper after each step (its report).
///
/// # Errors
/// As [`timed_run`].
#[allow(clippy::too_many_arguments)]
pub fn figures<T, M, I, F, K, const N: usize, const C: usize>(
    mechanism: &M,
    contacts: &K,
    floor_rows: usize,
    start: &State<T, N>,
    dt: T,
    steps: usize,
    mut stepper: I,
    mut free: F,
    mut observe: impl FnMut(&I),
) -> Result<Figures, String>
where
    T: Real,
    M: Mechanism<T, N>,
    I: Integrator<T, N, M>,
    F: Integrator<T, N, M>,
    K: Contacts<T, N, C>,
{
    let mut f = Figures {
        depth: 0.0,
        limit_depth: 0.0,
        energy_gain: f64::NEG_INFINITY,
        contact_steps: 0,
    };
    let mut s = *start;
    let depth = |s: &State<T, N>, f: &mut Figures| {
        for (i, g) in contacts.position_residual(&s.q).iter().enumerate() {
            let d = -g.to_f64();
            if i < floor_rows {
                f.depth = f.depth.max(d);
            } else {
                f.limit_depth = f.limit_depth.max(d);
            }
        }
    };
    depth(&s, &mut f);
    for _ in 0..steps {
        let before = mechanism.energy(&s).to_f64();
        let unconstrained = free.step(mechanism, &s, dt).map_err(|e| failed(&s, &e))?;
        let next = stepper
            .step(mechanism, &s, dt)
            .map_err(|e| failed(&s, &e))?;
        if next.q != unconstrained.q || next.qd != unconstrained.qd {
            f.contact_steps += 1;
            let allowed = before.max(mechanism.energy(&unconstrained).to_f64());
            f.energy_gain = f
                .energy_gain
                .max(mechanism.energy(&next).to_f64() - allowed);
        }
        observe(&stepper);
        s = next;
        depth(&s, &mut f);
    }
    Ok(f)
}
