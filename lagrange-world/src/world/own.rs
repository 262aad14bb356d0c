//! The bodies' own rows (joint limits) after each pass over the contacts: each body's solved
//! exactly, with the contacts' impulses held, so that they have the last word.
//!
//! Why exactly: the rows of one body are coupled through its mass matrix (a ragdoll's hand
//! and torso differ 20 times in mass), and projected Gauss-Seidel over them alone converges
//! slowly. With 32 sweeps over a ragdoll's 18 limit rows (`4 x` the world's 8 sweeps) a
//! joint past its limit still moved 0.03 rad/s further past it after a step in a pile of ten
//! (the pile test's bound, met by some throws and not others: a change in the rounding of
//! the contacts' rows elsewhere moved one throw to 0.037). Solved exactly, it moves none,
//! to rounding, and the solve costs about what the sweeps did.
//!
//! The problem of one body's own rows, their impulses `lambda` on velocities `v0` without
//! them (the body's velocity less what its own rows gave it):
//! `a = W lambda + J v0 - target >= 0`, `lambda >= 0`, `lambda a = 0`
//! ([`Delassus::complementary_from`], from the rows that push now). It is the limit of the
//! sweeps over these rows alone, so it changes nothing that the sweeps would not have
//! reached: where it has no solution the method finds (its passes' cap: a degenerate set
//! that cycles) the body's rows are swept as before.

use super::limits::MAX_OWN_ROWS;
use super::locks::Locks;
use super::rows::{Contact, Part, Phase};
use super::solve;
use heapless::Vec;
use lagrange_core::constraints::contact::{Delassus, Row as Kind};
use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::Real;

/// The own rows of every body, `contacts[own..]` (their keys put them last, each body's
/// together), solved exactly in `phase`, one body at a time, at the velocities `v`; a body
/// whose exact solve fails takes `fallback` sweeps over its rows instead.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
pub(crate) fn settle<T: Real, const N: usize, const B: usize>(
    v: &mut [SVector<T, N>],
    contacts: &mut [Contact<T, N>],
    locks: &Locks<T, B>,
    own: usize,
    phase: Phase,
    fallback: u32,
    locking: bool,
) {
    if own >= contacts.len() {
        return;
    }
    // One set of rows for every body (the capacity's storage is made once a pass).
    let mut delassus = Delassus::<T, N, MAX_OWN_ROWS>::empty();
    let mut start = own;
    while start < contacts.len() {
        let body = contacts.get(start).and_then(|c| c.bodies[0]);
        let count = contacts
            .get(start..)
            .map_or(0, |rest| {
                rest.iter().take_while(|c| c.bodies[0] == body).count()
            })
            .max(1);
        let end = start + count;
        let exact = body.is_some_and(|i| {
            contacts
                .get_mut(start..end)
                .is_some_and(|rows| exactly(&mut delassus, v, i, rows, phase))
        });
        if !exact {
            let order: Vec<u32, MAX_OWN_ROWS> = (start..end)
                .filter_map(|k| u32::try_from(k).ok())
                .take(MAX_OWN_ROWS)
                .collect();
            solve::sweep(
                v,
                contacts,
                locks,
                &order,
                T::zero(),
                fallback,
                phase,
                locking,
            );
        }
        start = end;
    }
}

/// Body `i`'s own rows `rows` (at most [`MAX_OWN_ROWS`]) solved exactly in `phase`: their
/// impulses set and `v[i]` moved by what they changed. Whether it was solved (nothing is
/// changed where it was not).
fn exactly<T: Real, const N: usize>(
    delassus: &mut Delassus<T, N, MAX_OWN_ROWS>,
    v: &mut [SVector<T, N>],
    i: usize,
    rows: &mut [Contact<T, N>],
    phase: Phase,
) -> bool {
    let Some(&velocity) = v.get(i) else {
        return false;
    };
    if rows.len() > MAX_OWN_ROWS {
        return false;
    }
    let mut jacobian = SMatrix::<T, MAX_OWN_ROWS, N>::zeros();
    let mut candidate = [false; MAX_OWN_ROWS];
    let mut pushing = [false; MAX_OWN_ROWS];
    // The velocity without the rows' own impulses.
    let mut base = velocity;
    for ((k, c), on) in rows.iter().enumerate().zip(candidate.iter_mut()) {
        for (col, &x) in c.normal.j[0].iter().enumerate() {
            if let Some(slot) = jacobian.get_mut((k, col)) {
                *slot = x;
            }
        }
        *on = true;
        let impulse = phase.impulse_of(c, Part::Normal);
        if let Some(p) = pushing.get_mut(k) {
            *p = impulse > T::zero();
        }
        base -= c.normal.b[0] * impulse;
    }
    let mobilities = |m: &mut SMatrix<T, N, MAX_OWN_ROWS>| {
        for (column, c) in m.as_mut_slice().chunks_exact_mut(N).zip(rows.iter()) {
            column.copy_from_slice(c.normal.b[0].as_slice());
        }
        Ok(())
    };
    if delassus.rebuild(&jacobian, mobilities, &candidate).is_err() {
        return false;
    }
    let rhs = SVector::<T, MAX_OWN_ROWS>::from_fn(|k, _| {
        rows.get(k).map_or(T::zero(), |c| {
            c.normal.j[0].dot(&base) - phase.target(c, Part::Normal)
        })
    });
    let kinds = [Kind::Unilateral; MAX_OWN_ROWS];
    let Ok(solved) = delassus.complementary_from(&rhs, &kinds, &pushing) else {
        return false;
    };
    let mut moved = base;
    for (c, &impulse) in rows.iter_mut().zip(solved.lambda.iter()) {
        moved += c.normal.b[0] * impulse;
        *phase.impulse(c, Part::Normal) = impulse;
    }
    if let Some(slot) = v.get_mut(i) {
        *slot = moved;
    }
    true
}
