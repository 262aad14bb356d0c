//! A body's holding limits locked in its contacts' rows: each contact row's mobility on a
//! body taken with the body's own rows that pushed in the last step held still (a joint at
//! its limit moves as one piece with its parent), and the impulses those rows take for it.
//!
//! Why: projected Gauss-Seidel takes one row at a time. A ragdoll that falls on a forearm
//! bent to its elbow's limit met the floor's row, which stopped the light forearm alone (its
//! own mobility), then the limit's, which took the forearm back down with the torso: each
//! sweep stopped the doll by the forearm's share of its mass, and a forearm was driven
//! 170 mm into the floor over a few steps of a pile (the slop is 5). With the limit locked,
//! the floor's row stops the whole doll in one update.
//!
//! A row's update on a body whose rows `L` are locked moves along `e + mu` in the impulses:
//! the row's own `t` and `mu t` on `L` (`mu = -W_LL^-1 J_L b`, `b = M^-1 j^T` the row's own
//! mobility), which leaves `L`'s speeds as they were: the row's mobility is `b + B_L mu`.
//! The update brings the row to its target speed; where it would leave a locked row
//! pulling (a contact pushing a limb off its limit), the rows that would pull are let go
//! and the row is solved again with the others held ([`Locks::let_go`], a small system of
//! at most [`LOCKS`] rows a side). Every row's impulse stays what it takes in all. Such an
//! update does not always lower the program whose minimum the impulses are (it leaves the
//! locked rows' own residuals to their own sweeps), so the kinetic energy may rise where a
//! plain update's would not: the world's guard then solves again with plain updates.
//!
//! Measured on ten ragdolls thrown into a pit at 60 Hz with 8 sweeps (the pile test's throw,
//! 2.8 m apart, 100 throws in f32 and f64): the deepest overlap sampled every 30 steps,
//! median 83 -> 19 mm, 9 in 10 under 195 -> 62 mm, the worst 456 -> 176 mm; piles not
//! asleep after 900 steps 19 -> 6 of 200; the world bench's ten-ragdoll step 256 -> 228 us
//! (the own rows no longer sweep the tangents they do not have). Tried, with the same
//! spread: the program's exact minimum along the locked line (the row's residual and `mu`
//! times the locked rows'), which lowers the program, but left a forearm held at a wall
//! 40 mm deep where its limit's target was a rebound that never came; a plain update where
//! a locked row would pull, in place of letting it go; every touching limit locked, pushing
//! or not (later asleep).

use super::block::{Block, Locked, LOCKS};
use super::limits::MAX_OWN_ROWS;
use super::rows::{Contact, Part, Phase, Row};
use core::marker::PhantomData;
use heapless::Vec;
use lagrange_core::nalgebra::SVector;
use lagrange_core::Real;

/// The end of a list.
const END: u32 = u32::MAX;

/// The least share of a row's `W` (on a side) that locking must take for the side to be
/// locked: a contact on a torso barely turns the limbs held to it, and its plain update is
/// as good; a contact on a forearm held at its elbow loses most of its `W` (the forearm
/// alone is light) and is what locking is for. Fewer locked rows, fewer locked updates.
const WEAK: f64 = 0.1;

/// One body's locked rows: their places among the step's contacts, in their places in the
/// body's [`Block`].
type Held = Vec<u32, LOCKS>;

/// Each body's locked rows, by the body's place.
#[derive(Debug, Clone)]
pub(crate) struct Locks<T, const B: usize> {
    held: Vec<Held, B>,
    any: bool,
    scalar: PhantomData<T>,
}

impl<T: Real, const B: usize> Locks<T, B> {
    /// None.
    pub(crate) fn new() -> Self {
        Self {
            held: Vec::new(),
            any: false,
            scalar: PhantomData,
        }
    }

    /// Whether any body has a locked row.
    pub(crate) fn any(&self) -> bool {
        self.any
    }

    /// Locks, for each of `bodies` bodies, its own rows (`contacts[own..]`) that touch and
    /// were warm-started pushing, the most pushing first, as many as stay independent (at
    /// most [`LOCKS`]); then rewrites every other contact's rows on a body with locked rows
    /// for them.
    pub(crate) fn lock<const N: usize, const K: usize>(
        &mut self,
        contacts: &mut [Contact<T, N>],
        own: usize,
        bodies: usize,
    ) {
        self.held.clear();
        self.any = false;
        for _ in 0..bodies.min(B) {
            let _ = self.held.push(Held::new());
        }
        // A world of bodies without own rows (boxes, balls) builds no lists.
        let Some((shared, own_rows)) = contacts
            .split_at_mut_checked(own)
            .filter(|(_, own_rows)| !own_rows.is_empty())
        else {
            return;
        };
        // Each body's contacts on each side as a list: `first[side][body]`, then
        // `next[side][c]` after contact `c` (built from the last contact back).
        let mut first = [[END; B]; 2];
        let mut next = [[END; K]; 2];
        for (c, contact) in shared.iter().enumerate().rev() {
            for (side, body) in contact.bodies.iter().enumerate() {
                let (Some(head), Some(after)) = (
                    body.and_then(|b| first[side & 1].get_mut(b)),
                    next[side & 1].get_mut(c),
                ) else {
                    continue;
                };
                *after = *head;
                *head = u32::try_from(c).unwrap_or(END);
            }
        }
        // A body's own rows are together (their keys are `(OWN_ROWS, body, row)`).
        let mut start = 0;
        while let Some(body) = own_rows.get(start).map(|c| c.bodies[0]) {
            let end = start
                + own_rows
                    .iter()
                    .skip(start)
                    .take_while(|c| c.bodies[0] == body)
                    .count();
            let rows = own_rows.get(start..end).unwrap_or(&[]);
            let from = own + start;
            start = end.max(start + 1);
            let Some((body, held)) = body.and_then(|b| Some((b, self.held.get_mut(b)?))) else {
                continue;
            };
            let block = chosen(rows, from, held);
            if block.is_empty() {
                continue;
            }
            self.any = true;
            for (side, first) in first.iter().enumerate() {
                let mut at = first.get(body).copied().unwrap_or(END);
                while let Some(c) = shared.get_mut(at as usize) {
                    lock_side(&block, &mut c.normal, side);
                    lock_side(&block, &mut c.tangent, side);
                    at = next[side & 1].get(at as usize).copied().unwrap_or(END);
                }
            }
        }
    }

    /// Whether an update `t` along a row with locks `mu` on `bodies` leaves every locked
    /// row's impulse in `phase` pushing (or nothing).
    pub(crate) fn allows<const N: usize>(
        &self,
        contacts: &[Contact<T, N>],
        bodies: [Option<usize>; 2],
        mu: &[[T; LOCKS]; 2],
        t: T,
        phase: Phase,
    ) -> bool {
        self.each(bodies, mu, |row, m| {
            contacts
                .get(row)
                .is_none_or(|c| phase.impulse_of(c, Part::Normal) + m * t >= T::zero())
        })
    }

    /// Adds `mu t` of a row with locks `mu` on `bodies` to the locked rows' impulses in
    /// `phase`: what an update `t` of the row took on them.
    pub(crate) fn hold<const N: usize>(
        &self,
        contacts: &mut [Contact<T, N>],
        bodies: [Option<usize>; 2],
        mu: &[[T; LOCKS]; 2],
        t: T,
        phase: Phase,
    ) {
        self.each(bodies, mu, |row, m| {
            if let Some(c) = contacts.get_mut(row) {
                *phase.impulse(c, Part::Normal) += m * t;
            }
            true
        });
    }

    /// The update of `row` (on `bodies`) where its locked one would leave a locked row
    /// pulling: locked again with the rows that would pull let go, until none does (the
    /// row's solution with its bodies' locked rows, those pushing held and those let go
    /// moving as it takes them); with none left, or none `kept` from the start, its own
    /// update. `residual` is its speed less its target, `lambda` its impulse in `phase`,
    /// within `bounds`. Its new impulse, the mobilities it moves along and the impulses per
    /// unit of it on the rows still locked.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn let_go<const N: usize>(
        &self,
        contacts: &[Contact<T, N>],
        bodies: [Option<usize>; 2],
        row: &Row<T, N>,
        residual: T,
        lambda: T,
        (lo, hi): (T, T),
        phase: Phase,
        kept: bool,
    ) -> (T, [SVector<T, N>; 2], [[T; LOCKS]; 2]) {
        let mut blocks: [Block<T, N>; 2] = core::array::from_fn(|side| {
            let held = bodies[side & 1].and_then(|b| self.held.get(b));
            Block::of(held.into_iter().flatten().filter_map(|&r| {
                let c = contacts.get(r as usize)?;
                Some(Locked {
                    j: c.normal.j[0],
                    b: c.normal.b[0],
                    impulse: phase.impulse_of(c, Part::Normal),
                })
            }))
        });
        // The row's own mobility on each side: its locked one less its locked rows'.
        let own: [SVector<T, N>; 2] = core::array::from_fn(|side| {
            let (block, mu) = (&blocks[side & 1], &row.locks[side & 1]);
            block.mobility(&row.b[side & 1], &mu.map(|m| -m))
        });
        if !kept {
            blocks = [Block::none(); 2];
        }
        loop {
            let mu = [0, 1].map(|side| blocks[side].impulses(&own[side]));
            let b = [0, 1].map(|side| blocks[side].mobility(&own[side], &mu[side]));
            let w = row.j[0].dot(&b[0]) + row.j[1].dot(&b[1]);
            let inverse = if w > T::EPSILON { w.recip() } else { T::zero() };
            let next = (lambda - residual * inverse).max(lo).min(hi);
            let t = next - lambda;
            let mut pulled = false;
            for (block, mu) in blocks.iter_mut().zip(&mu) {
                for (p, &m) in mu.iter().enumerate() {
                    let rows = block.rows();
                    if rows
                        .get(p)
                        .copied()
                        .flatten()
                        .is_some_and(|r| r.impulse + m * t < T::zero())
                    {
                        block.let_go(p);
                        pulled = true;
                    }
                }
            }
            if !pulled {
                return (next, b, mu);
            }
        }
    }

    /// Whether `f(row, mu)` holds for every locked row of `bodies` and its share `mu` of
    /// `mu` (stopping at the first that does not).
    fn each(
        &self,
        bodies: [Option<usize>; 2],
        mu: &[[T; LOCKS]; 2],
        mut f: impl FnMut(usize, T) -> bool,
    ) -> bool {
        for (body, mu) in bodies.iter().zip(mu) {
            let Some(held) = body.and_then(|b| self.held.get(b)) else {
                continue;
            };
            for (&row, &m) in held.iter().zip(mu) {
                if !f(row as usize, m) {
                    return false;
                }
            }
        }
        true
    }
}

/// The block of rows of `rows` (one body's own, the step's contacts from `from` on) to
/// lock, their places put in `held`: those touching and pushing, the most pushing first,
/// each taken where independent of those taken before it.
fn chosen<T: Real, const N: usize>(
    rows: &[Contact<T, N>],
    from: usize,
    held: &mut Held,
) -> Block<T, N> {
    let pushing = |c: &Contact<T, N>| {
        c.gap <= T::zero() && c.normal.lambda > T::zero() && c.normal.inverse > T::zero()
    };
    let mut candidates: Vec<(usize, T), MAX_OWN_ROWS> = rows
        .iter()
        .enumerate()
        .filter(|(_, c)| pushing(c))
        .map(|(k, c)| (k, c.normal.lambda))
        .take(MAX_OWN_ROWS)
        .collect();
    // The most pushing first; ties in the rows' order (deterministic).
    candidates.sort_unstable_by(|a, b| {
        b.1.partial_cmp(&a.1)
            .map_or(a.0.cmp(&b.0), |o| o.then(a.0.cmp(&b.0)))
    });
    let mut block = Block::none();
    for &(k, _) in &candidates {
        if held.is_full() {
            break;
        }
        let Some(c) = rows.get(k) else { continue };
        let row = Locked {
            j: c.normal.j[0],
            b: c.normal.b[0],
            impulse: T::zero(),
        };
        if block.push(row) {
            let _ = held.push(u32::try_from(from + k).unwrap_or(END));
        }
    }
    block
}

/// Side `side` of `row` (on the body of `block`) rewritten with the block's rows held: its
/// mobility `b + B_L mu`, `mu = -W_LL^-1 J_L b`, and its `1 / W` with them; left as it is
/// where they would lower its side's `W` by less than [`WEAK`].
fn lock_side<T: Real, const N: usize>(block: &Block<T, N>, row: &mut Row<T, N>, side: usize) {
    let (j, b) = (row.j[side & 1], row.b[side & 1]);
    let mu = block.impulses(&b);
    let locked = block.mobility(&b, &mu);
    let (w, held) = (j.dot(&b), j.dot(&locked));
    // False for a `W` not finite, too: left as it is.
    let strong = held < (T::one() - T::from_f64(WEAK)) * w;
    if !strong {
        return;
    }
    row.b[side & 1] = locked;
    row.locks[side & 1] = mu;
    row.inverse = row.inverse_now();
    row.held = true;
}

#[cfg(test)]
mod tests {
    use super::Locks;
    use crate::world::rows::Phase;
    use crate::world::rows::{Contact, Row};
    use crate::world::solve::sweep;
    use lagrange_core::nalgebra::{Matrix2, SVector, Vector2, Vector3};

    /// A contact of body 0 alone (a floor's, or its own row) with the row `normal`, pushing
    /// with `lambda` from the last step, touching, no tangent.
    fn on_one_body<const N: usize>(
        key: (u32, u32, u32),
        mut normal: Row<f64, N>,
        lambda: f64,
    ) -> Contact<f64, N> {
        normal.lambda = lambda;
        let zero = SVector::zeros();
        Contact {
            key,
            bodies: [Some(0), None],
            normal,
            tangent: Row::new([zero; 2], [zero; 2]),
            gap: 0.0,
            lower: 0.0,
            approach: 0.0,
            drift: 0.0,
            reach: 0.0,
            point: [0.0; 2],
            direction: [0.0; 2],
            twin: None,
        }
    }

    /// A torso (height `y`, 60 kg) and a light limb on it (angle `a`, 1.2 kg, 0.6 m, its tip
    /// at `y + 0.6 a` to first order) held at its upper limit, falling at 1 m/s onto the
    /// limb's tip: the floor's row and the limit's, their mobilities from the mass matrix.
    fn fall() -> ([Contact<f64, 2>; 2], [SVector<f64, 2>; 1]) {
        let (mt, ml, l) = (60.0, 1.2, 0.6);
        let (a, b, d) = (mt + ml, ml * l / 2.0, ml * l * l / 3.0);
        let inverse = Matrix2::new(d, -b, -b, a) / (a * d - b * b);
        let row =
            |j: Vector2<f64>| Row::new([j, Vector2::zeros()], [inverse * j, Vector2::zeros()]);
        let contact = |key, j, lambda| on_one_body(key, row(j), lambda);
        let floor = contact((1, 2, 0), Vector2::new(1.0, l), 0.0);
        // Pushing in the last step: the limit holds.
        let limit = contact((u32::MAX, 0, 1), Vector2::new(0.0, -1.0), 1e-3);
        ([floor, limit], [Vector2::new(-1.0, 0.0)])
    }

    /// The limb locked to the torso, the floor's row stops the whole body in its first
    /// update: after one sweep the tip and the limit are still to rounding (the limit's
    /// impulse is what it took for the floor's). Without the lock, each sweep stops the body
    /// by 0.65%, about the limb's share of its mass: after 8 sweeps it still falls at
    /// 0.95 m/s.
    #[test]
    fn a_locked_limit_stops_the_body_in_one_update() {
        for locked in [true, false] {
            let (mut contacts, mut v) = fall();
            let mut locks = Locks::<f64, 1>::new();
            if locked {
                locks.lock::<2, 2>(&mut contacts, 1, 1);
            }
            let sweeps = if locked { 1 } else { 8 };
            let velocity = Phase::Velocity;
            sweep(
                &mut v,
                &mut contacts,
                &locks,
                &[0, 1],
                0.0,
                sweeps,
                velocity,
                true,
            );
            let tip = v[0][0] + 0.6 * v[0][1];
            if locked {
                assert!(tip.abs() < 1e-15 && v[0][1].abs() < 1e-15, "{v:?}");
                // Momentum: 61.2 kg stopped from 1 m/s by the floor's impulse; the limit took
                // what keeps the limb's angle (M's second row of the change: 0.6 * 61.2 - its
                // impulse = 0.36, the limb's share of the momentum), over its 1e-3.
                assert!(
                    (contacts[0].normal.lambda - 61.2).abs() < 1e-12,
                    "{contacts:?}"
                );
                let limit = 1e-3 + 0.6 * 61.2 - 0.36;
                assert!(
                    (contacts[1].normal.lambda - limit).abs() < 1e-12,
                    "{contacts:?}"
                );
            } else {
                assert!(tip < -0.94, "{v:?}");
            }
        }
    }

    /// A contact on a body with two locked rows: one its push would open (a locked row
    /// that would pull), one it would close. Let go, the first moves as the push takes it and
    /// keeps its impulse; the second keeps its speed and takes the push's share; the contact
    /// reaches its target speed (a mass matrix diagonal, 5, 1 and 0.5 kg: every figure by
    /// hand).
    #[test]
    fn the_rows_that_would_pull_are_let_go() {
        let mass = [5.0, 1.0, 0.5];
        let row = |j: Vector3<f64>| {
            let b = Vector3::from_fn(|i, _| j[i] / mass[i]);
            Row::new([j, Vector3::zeros()], [b, Vector3::zeros()])
        };
        let contact = |key, j, lambda| on_one_body(key, row(j), lambda);
        let mut contacts = [
            contact((1, 2, 0), Vector3::new(1.0, 0.7, -0.4), 0.0),
            contact((u32::MAX, 0, 0), Vector3::new(0.0, 1.0, 0.0), 1e-3),
            contact((u32::MAX, 0, 1), Vector3::new(0.0, 0.0, 1.0), 1e-3),
        ];
        let mut locks = Locks::<f64, 1>::new();
        locks.lock::<3, 3>(&mut contacts, 1, 1);
        let r = contacts[0].normal;
        // mu = -j_l . b / W_ll: -0.7 (the push opens the first), 0.4 (closes the second).
        assert!(
            r.held && (r.locks[0][0] + 0.7).abs() < 1e-15 && (r.locks[0][1] - 0.4).abs() < 1e-15
        );
        // A unit push's worth of approach: the first would pull.
        let velocity = Phase::Velocity;
        let bodies = [Some(0), None];
        let push = (0.0, f64::INFINITY);
        // The locked update of a unit approach: `inverse`.
        assert!(!locks.allows(&contacts, bodies, &r.locks, r.inverse, velocity));
        let (next, b, mu) = locks.let_go(&contacts, bodies, &r, -1.0, 0.0, push, velocity, true);
        // The second held: b = (1/5, 0.7, -0.4/0.5 + 0.4/0.5), W = 0.2 + 0.49.
        let w = 0.2 + 0.49;
        assert!((next - 1.0 / w).abs() < 1e-14, "{next}");
        assert!((b[0] - Vector3::new(0.2, 0.7, 0.0)).amax() < 1e-15, "{b:?}");
        assert_eq!(mu[0][0], 0.0);
        assert!((mu[0][1] - 0.4).abs() < 1e-15);
        // Nothing kept: the contact's own update.
        let (plain, b, mu) = locks.let_go(&contacts, bodies, &r, -1.0, 0.0, push, velocity, false);
        assert!((plain - 1.0 / (0.2 + 0.49 + 0.32)).abs() < 1e-14, "{plain}");
        assert!(
            (b[0] - Vector3::new(0.2, 0.7, -0.8)).amax() < 1e-15,
            "{b:?}"
        );
        assert_eq!(mu, [[0.0; 4]; 2]);
    }
}
