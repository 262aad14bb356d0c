//! The impulse solve of a [`World`](super::World)'s step: projected Gauss-Seidel over the
//! contact rows in their keys' order (sequential impulses), in the bodies' generalized
//! velocities, and the same over pseudo-velocities for the drift.

use super::rows::{Contact, Row};
use lagrange_core::nalgebra::SVector;
use lagrange_core::Real;

/// Velocities of the bodies, by index.
pub(crate) type Velocities<'a, T, const N: usize> = &'a mut [SVector<T, N>];

/// `v[body] += b * d` on each side of `row`.
fn apply<T: Real, const N: usize>(
    v: &mut [SVector<T, N>],
    bodies: [Option<usize>; 2],
    row: &Row<T, N>,
    d: T,
) {
    for (body, b) in bodies.iter().zip(&row.b) {
        if let Some(x) = body.and_then(|k| v.get_mut(k)) {
            *x += b * d;
        }
    }
}

/// The row's velocity at `v`.
fn speed<T: Real, const N: usize>(
    v: &[SVector<T, N>],
    bodies: [Option<usize>; 2],
    row: &Row<T, N>,
) -> T {
    row.speed(bodies.map(|b| b.and_then(|k| v.get(k))))
}

/// The impulses the contacts took last step, applied again (warm start).
pub(crate) fn warm_start<T: Real, const N: usize>(
    v: Velocities<'_, T, N>,
    contacts: &[Contact<T, N>],
) {
    for c in contacts {
        apply(v, c.bodies, &c.normal, c.normal.lambda);
        apply(v, c.bodies, &c.tangent, c.tangent.lambda);
    }
}

/// `sweeps` sweeps over the contacts: each tangent within `friction` times its normal
/// impulse (Coulomb's cone), then each normal row to no less than its `lower` speed with a
/// push that never pulls (its accumulated impulse stays `>= 0`). Each change lowers the
/// program whose minimum the impulses are, so that with `lower <= 0` (no rebound) the
/// kinetic energy never rises.
pub(crate) fn velocities<T: Real, const N: usize>(
    v: Velocities<'_, T, N>,
    contacts: &mut [Contact<T, N>],
    friction: T,
    sweeps: u32,
) {
    for _ in 0..sweeps {
        for c in contacts.iter_mut() {
            if friction > T::zero() {
                let bound = friction * c.normal.lambda;
                let a = speed(v, c.bodies, &c.tangent);
                let lambda = (c.tangent.lambda - a * c.tangent.inverse)
                    .max(-bound)
                    .min(bound);
                let d = lambda - c.tangent.lambda;
                c.tangent.lambda = lambda;
                apply(v, c.bodies, &c.tangent, d);
            }
            let a = speed(v, c.bodies, &c.normal);
            let lambda = (c.normal.lambda + (c.lower - a) * c.normal.inverse).max(T::zero());
            let d = lambda - c.normal.lambda;
            c.normal.lambda = lambda;
            apply(v, c.bodies, &c.normal, d);
        }
    }
}

/// Pseudo-velocities `p` (zero at first) that leave no row deeper than `slop` where the
/// velocities `v` take it over the step `dt`: each row's gap there, linearised (`gap + dt J
/// v`), and `sweeps` sweeps of the normal rows to `J p >= -(that + slop) / dt` with pushes
/// only. A row the velocities leave open takes no push but may not be closed past the slop
/// by the others' (a joint's limit while its limb is pushed out of another body). They move
/// the coordinates only, never the velocities: the drift is removed without kinetic energy
/// (split impulses).
pub(crate) fn drift<T: Real, const N: usize>(
    p: Velocities<'_, T, N>,
    v: &[SVector<T, N>],
    contacts: &mut [Contact<T, N>],
    slop: T,
    dt: T,
    sweeps: u32,
) {
    for c in contacts.iter_mut() {
        let reach = c.gap + dt * speed(v, c.bodies, &c.normal);
        c.drift = T::zero();
        c.reach = -(reach + slop) / dt;
    }
    // Nothing deeper than the slop: no row pushes, and the others only hold.
    if contacts.iter().all(|c| c.reach <= T::zero()) {
        return;
    }
    pseudo(p, contacts, sweeps);
}

/// `sweeps` sweeps of the drift's rows (see [`drift`]).
pub(crate) fn pseudo<T: Real, const N: usize>(
    p: Velocities<'_, T, N>,
    contacts: &mut [Contact<T, N>],
    sweeps: u32,
) {
    for _ in 0..sweeps {
        for c in contacts.iter_mut() {
            let a = speed(p, c.bodies, &c.normal);
            let lambda = (c.drift + (c.reach - a) * c.normal.inverse).max(T::zero());
            let d = lambda - c.drift;
            c.drift = lambda;
            apply(p, c.bodies, &c.normal, d);
        }
    }
}
