//! The energy guard of an [`ImpulseStepper`](super::ImpulseStepper)'s step: never above
//! what the start, the mechanism's forces and the free step allow.

use lagrange_core::constraints::contact::within_kinetic_energy;
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Dual, Error, Mechanism, Real, State};

/// Potential evaluations the guard may spend finding how much of a move it can pay for.
const GUARD_REFINEMENTS: u32 = 4;

/// The rate at which the forces and the time dependence of `mechanism` change its energy
/// `T + V` at `s`: the power of its non-conservative forces (inputs, damping), `Q . q'`,
/// less `dL/dt` at fixed `q` and `q'` (one evaluation of `L` in dual numbers, none where `L`
/// does not read `t`: [`Lagrangian::READS_TIME`](lagrange_core::Lagrangian::READS_TIME)).
fn energy_rate<T: Real, M: Mechanism<T, N>, const N: usize>(mechanism: &M, s: &State<T, N>) -> T {
    let power = mechanism.non_conservative_force(s).dot(&s.qd);
    if !M::READS_TIME {
        return power;
    }
    let t = Dual::<T, 1>::variable(s.t, 0);
    let q = s.q.map(Dual::constant);
    let qd = s.qd.map(Dual::constant);
    let explicit = mechanism.kinetic(t, &q, &qd) - mechanism.potential(t, &q);
    power - explicit.eps[0]
}

/// The energy guard of a step from `start` (whose energy `T + V` is `known`, when the step
/// continues the last one) whose free step reached `free` and whose impulses and drift
/// correction reached `end` over `dt`: the end state, its energy, and whether the guard
/// acted. Allowed: the start's energy plus what the mechanism's forces and time dependence
/// can have added over the step (`dt` times the larger of their rates at the start and at
/// the free step's end, none where both take energy away), to rounding. Not the free step's
/// energy: at a coarse step its integration error can be large and positive, and a contact
/// step that kept it, step after step, pumped a ragdoll at 60 Hz until it blew up; nor
/// less than the forces' work (a block pushed up a slope must gain what the push gives it).
/// Above it, the velocities
/// are scaled down to the kinetic energy the allowance leaves; where the contacts' move of
/// the coordinates alone takes the potential energy above it (a body lifted out of the floor
/// with no kinetic energy to pay for it), the velocities are zeroed and the coordinates are
/// taken from the start's towards the end's only as far as the allowance pays (the start's,
/// at rest, are within it): a contact stays as deep as it began for a step rather than gain
/// energy, and never deeper.
///
/// # Errors
/// As [`within_kinetic_energy`].
pub(super) fn guard<T: Real, M: Mechanism<T, N>, const N: usize>(
    mechanism: &M,
    start: &State<T, N>,
    known: Option<T>,
    free: &State<T, N>,
    mut end: State<T, N>,
    dt: T,
) -> Result<(State<T, N>, T, bool), Error> {
    let before = match known {
        Some(e) if e.is_finite() => e,
        _ => mechanism.energy(start),
    };
    let energy = mechanism.energy(&end);
    // No more than the start's energy, to the rounding of the two: within what is allowed
    // whatever the free step did (most steps of a landing or a rest; two evaluations saved).
    let rounding = T::from_f64(16.0) * T::EPSILON * (before.abs() + energy.abs());
    // Compared as a difference (exact where they are close), not against `before +
    // rounding`, whose own rounding let a rise of half an ulp of the energy past the
    // allowance (a resting f32 ragdoll of 161 J: 6e-6 J).
    if energy - before <= rounding {
        return Ok((end, energy, false));
    }
    // Allowed: the start's energy and the work the forces can have done, plus the rounding
    // of the energies compared (16 ulps of the sizes of their terms: T + V may be near zero
    // while T and V are not).
    let work = energy_rate(mechanism, start)
        .max(energy_rate(mechanism, free))
        .max(T::zero())
        * dt;
    let allowed = before + work;
    let potential = mechanism.potential_energy(&end);
    let rounding =
        T::from_f64(16.0) * T::EPSILON * (allowed.abs() + energy.abs() + T::TWO * potential.abs());
    if energy - allowed <= rounding {
        return Ok((end, energy, false));
    }
    let kinetic = allowed - potential;
    if kinetic > T::zero() {
        end.qd = within_kinetic_energy(mechanism, &end, kinetic)?;
    } else {
        let rest = State {
            qd: SVector::zeros(),
            ..end
        };
        // From the start's coordinates, not the free step's: a contact the free step took
        // deeper than it began is not left there (the start's potential is within the
        // allowance too: V(start) <= T + V of the start).
        let moved = end.q - start.q;
        let at = |share: T| State {
            q: start.q + moved * share,
            ..rest
        };
        // The largest share of the move whose potential is within the allowance: regula
        // falsi between the start's coordinates (within it) and the end's (above it),
        // keeping the last share found within (the potential is not linear along the move
        // where it turns a link).
        let (mut lo, mut v_lo) = (T::zero(), mechanism.potential_energy(&at(T::zero())));
        let (mut hi, mut v_hi) = (T::one(), mechanism.potential_energy(&rest));
        end = at(T::zero());
        if v_lo < allowed {
            for _ in 0..GUARD_REFINEMENTS {
                if v_hi <= v_lo {
                    break;
                }
                let share = lo + (hi - lo) * (allowed - v_lo) / (v_hi - v_lo);
                let share = share.max(lo).min(hi) * (T::one() - T::from_f64(16.0) * T::EPSILON);
                let v = mechanism.potential_energy(&at(share));
                if v <= allowed {
                    (lo, v_lo) = (share, v);
                    end = at(share);
                } else {
                    (hi, v_hi) = (share, v);
                }
            }
        }
    }
    Ok((end, mechanism.energy(&end), true))
}
