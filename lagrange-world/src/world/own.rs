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

/// The sweeps over a body's own rows alone after each solve, per sweep of the settings, where
/// their exact solve (below) fails: a body's rows are coupled through its mass matrix
/// (a ragdoll's hand and torso differ 20 times in mass), and they are few and cheap (one dot
/// product of `N` a row). Measured on ten ragdolls thrown into a pile at 60 Hz, 8 sweeps,
/// when they were all there was: limits passed by 0.038 rad at worst with one, 0.0051 with
/// four (the slop is 0.005).
const OWN_SWEEPS: u32 = 4;

/// The own rows of every body, `contacts[own..]` (their keys put them last, each body's
/// together), solved exactly in `phase`, one body at a time, at the velocities `v`; a body
/// whose exact solve fails takes [`OWN_SWEEPS`] times `sweeps` sweeps over its rows
/// instead.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
pub(crate) fn settle<T: Real, const N: usize, const B: usize>(
    v: &mut [SVector<T, N>],
    contacts: &mut [Contact<T, N>],
    locks: &Locks<T, B>,
    own: usize,
    phase: Phase,
    sweeps: u32,
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
                OWN_SWEEPS.saturating_mul(sweeps),
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

#[cfg(test)]
mod tests {
    use super::settle;
    use crate::world::limits::MAX_OWN_ROWS;
    use crate::world::locks::Locks;
    use crate::world::rows::{Contact, Phase, Row};
    use crate::world::solve::tests::draws;
    use crate::world::OWN_ROWS;
    use lagrange_core::nalgebra::{Matrix3, SVector};

    /// Row `row` of body 0's own: Jacobian `j`, mobility `inverse j` (`inverse` the mass
    /// matrix's), lowest speed `lower`, impulse `lambda` already taken.
    fn own(
        row: u32,
        j: SVector<f64, 3>,
        inverse: &Matrix3<f64>,
        lower: f64,
        lambda: f64,
    ) -> Contact<f64, 3> {
        let zero = SVector::zeros();
        let mut normal = Row::new([j, zero], [inverse * j, zero]);
        normal.lambda = lambda;
        Contact {
            key: (OWN_ROWS, 0, row),
            bodies: [Some(0), None],
            normal,
            tangent: Row::new([zero; 2], [zero; 2]),
            gap: 0.0,
            lower,
            approach: 0.0,
            drift: 0.0,
            reach: 0.0,
            point: [0.0; 2],
            direction: [0.0; 2],
            twin: None,
        }
    }

    /// A mass matrix's inverse that couples every coordinate to the others nearly as much
    /// as to itself (positive definite: its leading minors 1, 0.0975 and 0.0095), as a
    /// ragdoll's limits are coupled through its links.
    fn coupled() -> Matrix3<f64> {
        Matrix3::new(1.0, 0.95, 0.9, 0.95, 1.0, 0.95, 0.9, 0.95, 1.0)
    }

    /// Three own rows of one body, coupled (`coupled`), their lowest speeds, impulses taken
    /// and the body's velocity drawn, 200 times: after `settle` with no sweeps to fall back
    /// on, each row meets its conditions (impulse >= 0, speed >= its lowest, one of them an
    /// equality) to 1e-12, and the velocity moved by exactly what the impulses changed.
    /// Gauss-Seidel's 32 sweeps over the same rows (what the world did before) leave a row
    /// 1e-3 off at worst over the draws: the exact solve is what closes that.
    #[test]
    fn each_bodys_rows_meet_their_conditions() {
        let mut draw = draws(41);
        let inverse = coupled();
        let locks = Locks::<f64, 1>::new();
        let (mut worst, mut swept) = (0.0_f64, 0.0_f64);
        for _ in 0..200 {
            let mut rows: [Contact<f64, 3>; 3] = core::array::from_fn(|k| {
                let mut j = SVector::<f64, 3>::zeros();
                j[k] = if draw() < 0.0 { -1.0 } else { 1.0 };
                let taken = (draw() + 0.5).max(0.0) * f64::from(u8::from(draw() < 0.0));
                own(k as u32, j, &inverse, draw(), taken)
            });
            let v0 = [SVector::<f64, 3>::new(draw(), draw(), draw())];
            let conditions = |rows: &[Contact<f64, 3>], v: &SVector<f64, 3>| {
                rows.iter().fold(0.0_f64, |m, c| {
                    let (l, a) = (c.normal.lambda, c.normal.j[0].dot(v) - c.lower);
                    m.max(-l).max(-a).max((l * a).abs())
                })
            };
            let mut gs = (rows, v0);
            let order = [0_u32, 1, 2];
            crate::world::solve::sweep(
                &mut gs.1,
                &mut gs.0,
                &locks,
                &order,
                0.0,
                32,
                Phase::Velocity,
                true,
            );
            swept = swept.max(conditions(&gs.0, &gs.1[0]));
            let before: [f64; 3] = core::array::from_fn(|k| rows[k].normal.lambda);
            let mut v = v0;
            settle(&mut v, &mut rows, &locks, 0, Phase::Velocity, 0, true);
            worst = worst.max(conditions(&rows, &v[0]));
            let moved = rows
                .iter()
                .zip(before)
                .fold(v0[0], |x, (c, l)| x + c.normal.b[0] * (c.normal.lambda - l));
            assert!((moved - v[0]).amax() < 1e-12, "{moved} {}", v[0]);
        }
        assert!(worst < 1e-12, "{worst:e}");
        assert!(swept > 1e-3, "{swept:e}");
    }

    /// Rows the exact method cannot solve (two opposed rows of one coordinate, both asked to
    /// move it at unit speed its way: no impulses reach both) are swept [`OWN_SWEEPS`] times
    /// `sweeps` instead. Each sweep moves the coordinate to `+1` and back to `-1` (a unit
    /// mass): the first row takes 1 then 2 a sweep, the second 2 a sweep, `4 s - 1` in all
    /// after `s` sweeps, exactly; with no sweeps asked, none.
    #[test]
    fn rows_with_no_solution_are_swept() {
        let inverse = Matrix3::identity();
        let locks = Locks::<f64, 1>::new();
        let e0 = SVector::<f64, 3>::new(1.0, 0.0, 0.0);
        for sweeps in [0_u32, 2] {
            let mut rows = [
                own(0, e0, &inverse, 1.0, 0.0),
                own(1, -e0, &inverse, 1.0, 0.0),
            ];
            let mut v = [SVector::<f64, 3>::zeros()];
            settle(&mut v, &mut rows, &locks, 0, Phase::Velocity, sweeps, true);
            let s = f64::from(super::OWN_SWEEPS * sweeps);
            let expected = if sweeps == 0 { 0.0 } else { 4.0 * s - 1.0 };
            assert_eq!(rows[0].normal.lambda + rows[1].normal.lambda, expected);
        }
    }

    /// A body with as many own rows as a body may have ([`MAX_OWN_ROWS`]), one of them
    /// closing (the others far open, their lowest speeds far below): the exact solve takes
    /// them all (the closing row stops, to 1e-12), not the fallback.
    #[test]
    fn a_body_with_all_its_rows_is_solved_exactly() {
        let inverse = coupled();
        let locks = Locks::<f64, 1>::new();
        let mut rows: [Contact<f64, 3>; MAX_OWN_ROWS] = core::array::from_fn(|k| {
            let mut j = SVector::<f64, 3>::zeros();
            j[k % 3] = 1.0;
            let lower = if k == 0 { 0.0 } else { -1e3 };
            own(k as u32, j, &inverse, lower, 0.0)
        });
        let mut v = [SVector::<f64, 3>::new(-1.0, 0.5, 0.2)];
        settle(&mut v, &mut rows, &locks, 0, Phase::Velocity, 0, true);
        assert!(v[0][0].abs() < 1e-12, "{}", v[0]);
        assert!(rows[0].normal.lambda > 0.0);
    }
}
