//! The lane cases: 16 `f32` pendulums of different lengths stepped by RK4 one by one, the
//! same in lanes of 4 (gathered once), and the same in a scene's bank laid out in lanes
//! (`InLanes`, which steps one by one where there is no vector unit, as here): the same bits,
//! and what each costs per instance and step on the M4F.

use core::hint::black_box;

use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, Gather, Lanes, State};
use lagrange_integrators::scene::{Bank, InLanes, NeverSleeps, Scene};
use lagrange_integrators::{Integrator, Rk4};
use lagrange_systems::SimplePendulum;

use crate::Outcome;

/// Pendulums in a lane case.
pub const LANE_INSTANCES: usize = 16;

/// Lanes per group on the M4F case.
const WIDTH: usize = 4;

/// The step, s.
const DT: f32 = 1e-3;

/// A pendulum and its start.
type Pendulum = (SimplePendulum<f32>, State<f32, 1>);

/// The pendulums: lengths from 0.5 to 2 m, released from 0.1 to 1.6 rad.
fn pendulums() -> Result<[Pendulum; LANE_INSTANCES], Error> {
    let mut out = [(
        SimplePendulum::new(1.0, 1.0, 9.81, 0.0)?,
        State::at_rest([0.0]),
    ); LANE_INSTANCES];
    for (i, (p, s)) in out.iter_mut().enumerate() {
        let k = i as f32 / LANE_INSTANCES as f32;
        *p = SimplePendulum::new(1.0, black_box(0.5 + 1.5 * k), 9.81, 0.0)?;
        *s = State::at_rest([0.1 + 1.5 * k]);
    }
    Ok(out)
}

/// FNV-1a of the final states' bits.
fn digest(states: impl Iterator<Item = State<f32, 1>>) -> Outcome {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for s in states {
        for word in [s.t.to_bits(), s.q[0].to_bits(), s.qd[0].to_bits()] {
            hash = (hash ^ u64::from(word)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    Outcome::from_words(&[hash])
}

/// The pendulums stepped `steps` times one by one.
///
/// # Errors
/// A step's error (none for these values).
pub fn pendulums_alone(steps: u32) -> Result<Outcome, Error> {
    Ok(digest(alone(steps)?.into_iter()))
}

/// The pendulums' states after `steps` steps one by one.
fn alone(steps: u32) -> Result<[State<f32, 1>; LANE_INSTANCES], Error> {
    let mut all = pendulums()?;
    let dt = black_box(DT);
    for _ in 0..black_box(steps) {
        for (p, s) in &mut all {
            *s = Rk4.step(p, s, dt)?;
        }
    }
    Ok(all.map(|(_, s)| s))
}

/// [`pendulums_alone`] with the times left out, as [`pendulums_in_a_bank`] digests them.
#[cfg(test)]
pub(crate) fn alone_untimed(steps: u32) -> Result<Outcome, Error> {
    Ok(digest(
        alone(steps)?.map(|s| State { t: 0.0, ..s }).into_iter(),
    ))
}

/// The pendulums in a scene's bank, one step of the same `dt` a frame for `steps` frames.
/// Their times are the scene's (the bank lands each step there), so the outcome digests
/// their angles and rates only.
///
/// # Errors
/// A step's error (none for these values), or a frame that did not take one step.
pub fn pendulums_in_a_bank(steps: u32) -> Result<Outcome, Error> {
    let mut bank: Bank<f32, 1, LANE_INSTANCES, SimplePendulum<f32>, Rk4, NeverSleeps, InLanes> =
        Bank::new(Rk4, NeverSleeps)?;
    let mut ids = [None; LANE_INSTANCES];
    for (id, (p, s)) in ids.iter_mut().zip(pendulums()?) {
        *id = Some(bank.add(p, s)?);
    }
    let dt = black_box(DT);
    let mut scene = Scene::new(&mut bank, dt, 1)?;
    for _ in 0..black_box(steps) {
        if scene.advance(dt)?.steps != 1 {
            return Err(Error::InvalidParameter {
                name: "dt",
                reason: "a frame of one dt took other than one step",
            });
        }
    }
    let bank = scene.banks();
    let mut out = [State::at_rest([0.0f32]); LANE_INSTANCES];
    for (state, id) in out.iter_mut().zip(ids.into_iter().flatten()) {
        *state = State {
            t: 0.0,
            ..bank.state(id)?
        };
    }
    Ok(digest(out.into_iter()))
}

/// The pendulums stepped `steps` times in lanes of 4 (their parameters gathered once).
///
/// # Errors
/// A step's error (none for these values).
pub fn pendulums_in_lanes(steps: u32) -> Result<Outcome, Error> {
    let all = pendulums()?;
    let dt = black_box(DT);
    let mut out = [State::at_rest([0.0f32]); LANE_INSTANCES];
    for (group, states) in all.chunks_exact(WIDTH).zip(out.chunks_exact_mut(WIDTH)) {
        let instances: [&SimplePendulum<f32>; WIDTH] = core::array::from_fn(|i| &group[i].0);
        let lanes = SimplePendulum::gather(instances);
        let starts: [&State<f32, 1>; WIDTH] = core::array::from_fn(|i| &group[i].1);
        let mut s = State {
            t: Lanes::gather(&starts, |s| s.t),
            q: SVector::from_fn(|j, _| Lanes::gather(&starts, |s| s.q[j])),
            qd: SVector::from_fn(|j, _| Lanes::gather(&starts, |s| s.qd[j])),
        };
        for _ in 0..black_box(steps) {
            s = Rk4.step(&lanes, &s, Lanes::splat(dt))?;
        }
        for (i, state) in states.iter_mut().enumerate() {
            *state = State {
                t: s.t.0[i],
                q: s.q.map(|x| x.0[i]),
                qd: s.qd.map(|x| x.0[i]),
            };
        }
    }
    Ok(digest(out.into_iter()))
}
