//! The impulse solve of a [`World`](super::World)'s step: projected Gauss-Seidel over the
//! contact rows (sequential impulses) in an order of rounds fixed by their keys
//! ([`Order`]), in the bodies' generalized velocities, and the same over pseudo-velocities
//! for the drift.

use super::lists::{BodyLists, NONE};
use super::locks::Locks;
use super::rows::{Contact, Part, Phase, Row};
use super::twins;
use heapless::Vec;
use lagrange_core::nalgebra::SVector;
use lagrange_core::Real;

/// Velocities of the bodies, by index.
pub(crate) type Velocities<'a, T, const N: usize> = &'a mut [SVector<T, N>];

/// `v[body] += b * d` on each side (`b` a row's mobilities).
#[inline(always)]
fn apply<T: Real, const N: usize>(
    v: &mut [SVector<T, N>],
    bodies: [Option<usize>; 2],
    b: &[SVector<T, N>; 2],
    d: T,
) {
    for (body, b) in bodies.iter().zip(b) {
        if let Some(x) = body.and_then(|k| v.get_mut(k)) {
            *x += b * d;
        }
    }
}

/// The row's velocity at `v`.
#[inline(always)]
fn speed<T: Real, const N: usize>(
    v: &[SVector<T, N>],
    bodies: [Option<usize>; 2],
    row: &Row<T, N>,
) -> T {
    row.speed(bodies.map(|b| b.and_then(|k| v.get(k))))
}

/// The impulses the contacts took last step, applied again (warm start): a row locked on a
/// body (see `locks`) takes with its own mobility what the others' locked mobilities do not
/// apply for it.
pub(crate) fn warm_start<T: Real, const N: usize, const B: usize>(
    v: Velocities<'_, T, N>,
    contacts: &mut [Contact<T, N>],
    locks: &Locks<T, B>,
) {
    let implied = |contacts: &mut [Contact<T, N>], sign: T| {
        for i in 0..contacts.len() {
            let Some(c) = contacts.get(i) else { continue };
            let (bodies, normal, tangent) = (c.bodies, c.normal, c.tangent);
            let velocity = Phase::Velocity;
            locks.hold(
                contacts,
                bodies,
                &normal.locks,
                sign * normal.lambda,
                velocity,
            );
            locks.hold(
                contacts,
                bodies,
                &tangent.locks,
                sign * tangent.lambda,
                velocity,
            );
        }
    };
    if locks.any() {
        implied(contacts, -T::one());
    }
    for c in contacts.iter() {
        apply(v, c.bodies, &c.normal.b, c.normal.lambda);
        apply(v, c.bodies, &c.tangent.b, c.tangent.lambda);
    }
    if locks.any() {
        implied(contacts, T::one());
    }
}

/// `sweeps` sweeps over the contacts `order` names, solving for `phase`'s impulses at the
/// velocities `v` (the bodies' or, for the drift, pseudo-velocities): each tangent within
/// `friction` times its normal impulse (Coulomb's cone), then each normal row to no less
/// than its target speed with a push that never pulls (its accumulated impulse stays `>=
/// 0`). Each plain update (`locking` off, or a row with none locked in it) is the
/// program's minimum along it (the program whose minimum the impulses are), so that with
/// targets `<= 0` (no rebound) and plain updates alone the kinetic energy never rises; a
/// locked update need not be (see `locks`).
#[allow(clippy::too_many_arguments)]
pub(crate) fn sweep<T: Real, const N: usize, const B: usize>(
    v: Velocities<'_, T, N>,
    contacts: &mut [Contact<T, N>],
    locks: &Locks<T, B>,
    order: &[u32],
    friction: T,
    sweeps: u32,
    phase: Phase,
    locking: bool,
) {
    let run = Run {
        order,
        friction,
        sweeps,
        locking,
    };
    // Each phase's sweeps compiled on their own: its accessors' matches folded away.
    match phase {
        Phase::Velocity => run.sweeps::<N, B, false>(v, contacts, locks),
        Phase::Drift => run.sweeps::<N, B, true>(v, contacts, locks),
    }
}

/// What [`sweep`] was asked for.
struct Run<'a, T> {
    order: &'a [u32],
    friction: T,
    sweeps: u32,
    locking: bool,
}

impl<T: Real> Run<'_, T> {
    /// [`sweep`] in the drift's phase (`DRIFT`) or the velocities'.
    fn sweeps<const N: usize, const B: usize, const DRIFT: bool>(
        &self,
        v: Velocities<'_, T, N>,
        contacts: &mut [Contact<T, N>],
        locks: &Locks<T, B>,
    ) {
        let frictional = !DRIFT && self.friction > T::zero();
        let push = (T::zero(), T::INFINITY);
        let twin_friction = if frictional { self.friction } else { T::zero() };
        for _ in 0..self.sweeps {
            let mut order = self.order.iter().peekable();
            while let Some(&i) = order.next() {
                // Twins are next to each other in an order (see `Order`): taken at once.
                if contacts.get(i as usize).is_some_and(|c| c.twin.is_some())
                    && order.next_if(|&&n| n == i.wrapping_add(1)).is_some()
                {
                    twins::twins::<T, N, DRIFT>(v, contacts, i as usize, twin_friction);
                    continue;
                }
                let i = i as usize;
                // A row with no tangent (a body's own) has no friction to sweep.
                let tangent = contacts
                    .get(i)
                    .filter(|c| frictional && c.tangent.inverse > T::zero())
                    .map(|c| {
                        (
                            self.friction * c.normal.lambda,
                            c.normal.held || c.tangent.held,
                        )
                    });
                if let Some((_, false)) = tangent {
                    if pair(v, contacts, i, self.friction) {
                        continue;
                    }
                }
                if let Some((bound, _)) = tangent {
                    self.update::<N, B, DRIFT>(
                        v,
                        contacts,
                        locks,
                        i,
                        Part::Tangent,
                        (-bound, bound),
                    );
                }
                self.update::<N, B, DRIFT>(v, contacts, locks, i, Part::Normal, push);
            }
        }
    }

    /// Row `part` of contact `i` updated to its target speed in the phase `DRIFT` says, its
    /// impulse within `bounds`: along its mobility; or where rows are locked in it (see
    /// `locks`) and `locking`, along its locked mobility where that leaves every locked row
    /// pushing, else with those that would pull let go.
    #[inline(always)]
    fn update<const N: usize, const B: usize, const DRIFT: bool>(
        &self,
        v: &mut [SVector<T, N>],
        contacts: &mut [Contact<T, N>],
        locks: &Locks<T, B>,
        i: usize,
        part: Part,
        (lo, hi): (T, T),
    ) {
        let (phase, locking) = (
            if DRIFT { Phase::Drift } else { Phase::Velocity },
            self.locking,
        );
        let Some(c) = contacts.get(i) else {
            return;
        };
        let (bodies, row) = (c.bodies, part.of(c));
        let residual = speed(v, bodies, row) - phase.target(c, part);
        let lambda = phase.impulse_of(c, part);
        let next = if !row.held {
            let next = (lambda - residual * row.inverse).max(lo).min(hi);
            apply(v, bodies, &row.b, next - lambda);
            next
        } else {
            let locked = (lambda - residual * row.inverse).max(lo).min(hi);
            let (next, b, mu) =
                if locking && locks.allows(contacts, bodies, &row.locks, locked - lambda, phase) {
                    (locked, row.b, row.locks)
                } else {
                    locks.let_go(
                        contacts,
                        bodies,
                        row,
                        residual,
                        lambda,
                        (lo, hi),
                        phase,
                        locking,
                    )
                };
            apply(v, bodies, &b, next - lambda);
            locks.hold(contacts, bodies, &mu, next - lambda, phase);
            next
        };
        if let Some(c) = contacts.get_mut(i) {
            *phase.impulse(c, part) = next;
        }
    }
}

/// Contact `i`'s tangent, then its normal row, in the velocities' phase, neither with rows
/// locked in it and its sides on two bodies (or one and static geometry): the updates of
/// [`Run::update`], the same operations in the same order, on a copy of the two bodies'
/// velocities written back once. The normal row reads the velocities the tangent's impulse
/// has just changed from the copy, not from memory: a vector of three `f32` written as two
/// and one and read as one and two cannot be forwarded from the store, and a pyramid's
/// sweeps spent a fifth of their time waiting there. Whether it took the contact.
#[inline(always)]
fn pair<T: Real, const N: usize>(
    v: &mut [SVector<T, N>],
    contacts: &mut [Contact<T, N>],
    i: usize,
    friction: T,
) -> bool {
    let Some(c) = contacts.get_mut(i) else {
        return false;
    };
    let bodies = c.bodies;
    if bodies[0].is_some() && bodies[0] == bodies[1] {
        return false;
    }
    let mut near = bodies.map(|b| b.and_then(|k| v.get(k)).copied());
    let mut update = |row: &mut Row<T, N>, target: T, (lo, hi): (T, T)| {
        let residual = row.speed([near[0].as_ref(), near[1].as_ref()]) - target;
        let lambda = row.lambda;
        let next = (lambda - residual * row.inverse).max(lo).min(hi);
        for (x, b) in near.iter_mut().zip(&row.b) {
            if let Some(x) = x {
                *x += b * (next - lambda);
            }
        }
        row.lambda = next;
    };
    let bound = friction * c.normal.lambda;
    update(&mut c.tangent, T::zero(), (-bound, bound));
    update(&mut c.normal, c.lower, (T::zero(), T::INFINITY));
    for (body, x) in bodies.iter().zip(near) {
        if let (Some(slot), Some(x)) = (body.and_then(|k| v.get_mut(k)), x) {
            *slot = x;
        }
    }
    true
}

/// The drift's targets: each row's gap where the velocities `v` take it over the step `dt`,
/// linearised (`gap + dt J v`), to be brought back to `-slop` by pseudo-velocities `p`
/// (zero at first) with pushes only, `J p >= -(that + slop) / dt` (the [`sweep`]s of
/// [`Phase::Drift`]). A row the velocities leave open takes no push but may not be closed
/// past the slop by the others' (a joint's limit while its limb is pushed out of another
/// body). They move the
/// coordinates only, never the velocities: the drift is removed without kinetic energy
/// (split impulses). Whether any row is deeper than the slop (else none needs a push).
pub(crate) fn drift<T: Real, const N: usize>(
    v: &[SVector<T, N>],
    contacts: &mut [Contact<T, N>],
    slop: T,
    dt: T,
) -> bool {
    for c in contacts.iter_mut() {
        let reach = c.gap + dt * speed(v, c.bodies, &c.normal);
        c.drift = T::zero();
        c.reach = -(reach + slop) / dt;
    }
    contacts.iter().any(|c| c.reach > T::zero())
}

/// Whether the drift's pseudo-velocities `p` leave a normal row slower than its target by
/// more than `quiet`: a contact the drift would leave deeper than it asks (by `quiet dt`),
/// for more sweeps to push out.
pub(crate) fn left_deep<T: Real, const N: usize>(
    p: &[SVector<T, N>],
    contacts: &[Contact<T, N>],
    quiet: T,
) -> bool {
    contacts
        .iter()
        .any(|c| speed(p, c.bodies, &c.normal) - c.reach < -quiet)
}

/// How many contacts ahead of the keys' order the solve may take one: far enough to reach
/// past a ragdoll's nine joint-limit rows to the next body's (measured, three runs each: 8
/// ahead, ten ragdolls 0.117 ms a step, 55 boxes 72 us, 1,000 balls 1.68 ms; 16: 0.103,
/// 71, 1.63; 32: 0.096, 63, 1.55; 64 no faster).
const AHEAD: usize = 32;

/// How many of the contacts just taken the next one should share no body with.
const APART: usize = 2;

/// The order the sweeps take the contacts in: the keys' order, but each next contact the
/// first of the next [`AHEAD`] not yet taken that is ready (every contact before it that
/// shares a body with it taken) and shares no body with the [`APART`] taken last (else the
/// first not yet taken, always ready). A row's impulse waits on its speed, and the next
/// row's speed on that impulse where they share a body: rows of other bodies one after
/// another let a processor work on several at once (a pyramid of 55 boxes: 78 -> 70 us a
/// step; ten ragdolls in a pile: 0.137 -> 0.114 ms). Twins (see `twins`) go one right
/// after the other, taken as one. Rows of bodies apart commute, so this order gives the
/// keys' order's bits: a sweep is the same Gauss-Seidel sweep, only faster.
/// (Orders that do not keep each body's rows in the keys' order go faster still, 59 us,
/// but change the solve: by rounds of disjoint contacts, or pairs taken ahead, a pyramid's
/// top crept twice as far in 10 s and a ragdoll pile sank 64 mm where it sinks 31.)
#[derive(Debug, Clone)]
pub(crate) struct Order<const K: usize> {
    /// Every contact.
    pub(crate) all: Vec<u32, K>,
}

impl<const K: usize> Order<K> {
    /// The order of `contacts` (sorted by key) of a world of `B` bodies.
    pub(crate) fn of<T: Real, const N: usize, const B: usize>(contacts: &[Contact<T, N>]) -> Self {
        Self {
            all: interleaved::<T, N, B, K>(contacts),
        }
    }
}

/// The last [`Order`] made and what it was made of (each contact's bodies and whether it is
/// the first of twins, in order): an order depends on nothing else, so contacts that join
/// the same bodies in the same way (a pile at rest, step after step) take it again.
#[derive(Debug, Clone)]
pub(crate) struct Ordered<const K: usize> {
    order: Order<K>,
    bodies: Vec<[u32; 3], K>,
}

impl<const K: usize> Ordered<K> {
    /// None made yet.
    pub(crate) fn new() -> Self {
        Self {
            order: Order { all: Vec::new() },
            bodies: Vec::new(),
        }
    }

    /// The order made last.
    pub(crate) fn order(&self) -> &Order<K> {
        &self.order
    }

    /// The order of `contacts` in a world of `B` bodies: [`Order::of`] them, or the last
    /// one where it was made of the same bodies.
    pub(crate) fn of<T: Real, const N: usize, const B: usize>(
        &mut self,
        contacts: &[Contact<T, N>],
    ) -> &Order<K> {
        // A body's index as stored (bodies are fewer than u32::MAX: none is `u32::MAX`).
        let packed = |c: &Contact<T, N>| {
            let [a, b] = c
                .bodies
                .map(|b| b.map_or(u32::MAX, |i| u32::try_from(i).unwrap_or(u32::MAX - 1)));
            [a, b, u32::from(c.twin.is_some())]
        };
        let same = self.bodies.len() == contacts.len()
            && contacts
                .iter()
                .zip(&self.bodies)
                .all(|(c, b)| packed(c) == *b);
        if !same {
            self.order = Order::of::<T, N, B>(contacts);
            self.bodies.clear();
            for c in contacts {
                // Capacity K holds every contact of a step.
                let _ = self.bodies.push(packed(c));
            }
        }
        &self.order
    }
}

/// The contacts, interleaved (see [`Order`]).
fn interleaved<T: Real, const N: usize, const B: usize, const K: usize>(
    contacts: &[Contact<T, N>],
) -> Vec<u32, K> {
    if contacts.is_empty() {
        return Vec::new();
    }
    // Each body's contacts as a list: `front[body]` its first not yet taken.
    let BodyLists { mut front, after } = BodyLists::<B, K>::of(contacts);
    let bodies = |c: usize| contacts.get(c).map_or([None; 2], |c| c.bodies);
    // The first of twins stands for both in the window, and brings the second (the next by
    // key, on the same bodies: the next of each of their lists) right after it.
    let twin = |c: usize| contacts.get(c).is_some_and(|t| t.twin.is_some());
    let mut order = Vec::new();
    let mut window: Vec<usize, AHEAD> = Vec::new();
    let mut next = 0;
    let mut last = [[None; 2]; APART];
    loop {
        while !window.is_full() && next < contacts.len() {
            let _ = window.push(next);
            next += if twin(next) { 2 } else { 1 };
        }
        let ready = |c: usize| {
            bodies(c)
                .iter()
                .flatten()
                .all(|&b| front.get(b).is_some_and(|&f| f as usize == c))
        };
        let apart = |c: usize| {
            bodies(c)
                .iter()
                .flatten()
                .all(|b| !last.iter().flatten().flatten().any(|l| l == b))
        };
        let Some(pick) = window
            .iter()
            .position(|&c| ready(c) && apart(c))
            .or((!window.is_empty()).then_some(0))
        else {
            break;
        };
        let c = window.remove(pick);
        for c in [Some(c), twin(c).then_some(c + 1)].into_iter().flatten() {
            let _ = order.push(u32::try_from(c).unwrap_or(NONE));
            for (side, body) in bodies(c).iter().enumerate() {
                let (Some(head), Some(&next)) = (
                    body.and_then(|b| front.get_mut(b)),
                    after.get(side).and_then(|a| a.get(c)),
                ) else {
                    continue;
                };
                *head = next;
            }
        }
        last.rotate_right(1);
        last[0] = bodies(c);
    }
    order
}

#[cfg(test)]
pub(crate) mod tests {
    use super::{sweep, twins, Order, Ordered, Run};
    use crate::world::locks::Locks;
    use crate::world::rows::{Contact, Part, Phase, Row};
    use lagrange_core::nalgebra::SVector;

    /// A contact between `bodies` (of 2 coordinates), its rows drawn from `draw`.
    fn contact(bodies: [Option<usize>; 2], draw: &mut impl FnMut() -> f64) -> Contact<f64, 2> {
        let mut row = || {
            let j = [0, 1].map(|_| SVector::<f64, 2>::new(draw(), draw()));
            Row::new(j, j.map(|j| j * 0.5))
        };
        Contact {
            key: (0, 0, 0),
            bodies,
            normal: row(),
            tangent: row(),
            gap: 0.0,
            lower: draw(),
            approach: 0.0,
            drift: 0.0,
            reach: 0.0,
            point: [0.0; 2],
            direction: [0.0; 2],
            twin: None,
        }
    }

    /// Uniform draws in `[-0.5, 0.5)` from a xorshift generator seeded with `seed`.
    pub(crate) fn draws(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        }
    }

    /// `count` contacts drawn from `draw`, each between two of 6 bodies or one and static
    /// geometry (on either side).
    fn random_contacts<const K: usize>(
        count: usize,
        draw: &mut impl FnMut() -> f64,
    ) -> heapless::Vec<Contact<f64, 2>, K> {
        let mut contacts = heapless::Vec::new();
        for _ in 0..count {
            let body = |x: f64| ((x + 0.5) * 6.0) as usize;
            let (a, b) = (body(draw()), body(draw()));
            let first = (draw() > -0.3).then_some(a);
            let second = if b == a { None } else { Some(b) };
            assert!(contacts.push(contact([first, second], draw)).is_ok());
        }
        contacts
    }

    /// Rows of bodies apart go one after another: of contacts between bodies (0, 1), (0, 2)
    /// and (3, 4), the third (ready: no contact before it shares a body with it) goes before
    /// the second (which shares body 0 with the first); a contact with no body before it
    /// that shares one goes in its keys' place.
    #[test]
    fn rows_of_bodies_apart_take_turns() {
        let mut draw = || 0.25;
        let contacts = [
            contact([Some(0), Some(1)], &mut draw),
            contact([Some(0), Some(2)], &mut draw),
            contact([Some(3), Some(4)], &mut draw),
            contact([Some(2), None], &mut draw),
        ];
        let order = Order::<8>::of::<f64, 2, 6>(&contacts);
        assert_eq!(order.all.as_slice(), &[0, 2, 1, 3]);
    }

    /// A contact's two rows taken at once (`pair`, on a copy of the two bodies' velocities)
    /// give the bits of the tangent's update and then the normal's, each on the velocities
    /// in memory: 100 random sets of contacts among 6 bodies, three sweeps.
    #[test]
    fn a_contacts_two_rows_at_once_are_its_two_updates() {
        let mut draw = draws(0x9e37_79b9_7f4a_7c15);
        for round in 0..100 {
            let count = 1 + round % 30;
            let mut contacts = random_contacts::<32>(count, &mut draw);
            for c in contacts.iter_mut() {
                c.normal.lambda = draw() + 0.5;
                c.tangent.lambda = draw() * 0.2;
            }
            let keys: heapless::Vec<u32, 32> = (0..count as u32).collect();
            let start = [0; 6].map(|_| SVector::<f64, 2>::new(draw(), draw()));
            let (mut v, mut w) = (start, start);
            let mut other = contacts.clone();
            let locks = Locks::<f64, 6>::new();
            let friction = 0.5;
            sweep(
                &mut v,
                &mut contacts,
                &locks,
                &keys,
                friction,
                3,
                Phase::Velocity,
                true,
            );
            let run = Run {
                order: &keys,
                friction,
                sweeps: 3,
                locking: true,
            };
            for _ in 0..3 {
                for i in 0..count {
                    let bound = friction * other[i].normal.lambda;
                    if other[i].tangent.inverse > 0.0 {
                        let tangent = (Part::Tangent, (-bound, bound));
                        run.update::<2, 6, false>(
                            &mut w, &mut other, &locks, i, tangent.0, tangent.1,
                        );
                    }
                    let normal = (0.0, f64::INFINITY);
                    run.update::<2, 6, false>(&mut w, &mut other, &locks, i, Part::Normal, normal);
                }
            }
            assert_eq!(v, w, "round {round}");
            for (a, b) in contacts.iter().zip(&other) {
                assert_eq!(
                    (a.normal.lambda, a.tangent.lambda),
                    (b.normal.lambda, b.tangent.lambda)
                );
            }
        }
    }

    /// Every tangent stays within mu times its normal's impulse as the sweep found it (a
    /// contact's tangent is updated before its normal, against the normal's impulse then: by
    /// the sweep's end the normal may have moved on), on the plain path and on the path of
    /// rows with locks (taken here with no locked row, which updates as the plain path
    /// does): 100 random sets of contacts among 6 bodies, four sweeps each.
    #[test]
    fn friction_stays_in_its_cone_on_either_path() {
        let mut draw = draws(0x2545_f491_4f6c_dd1d);
        let friction = 0.3;
        for round in 0..100 {
            let count = 1 + round % 30;
            let mut contacts = random_contacts::<32>(count, &mut draw);
            for (k, c) in contacts.iter_mut().enumerate() {
                c.lower = 0.0;
                c.normal.held = k % 2 == 0;
                c.tangent.held = k % 2 == 0;
            }
            let keys: heapless::Vec<u32, 32> = (0..count as u32).collect();
            let mut v = [0; 6].map(|_| SVector::<f64, 2>::new(4.0 * draw(), 4.0 * draw()));
            let locks = Locks::<f64, 6>::new();
            for _ in 0..4 {
                let before: heapless::Vec<f64, 32> =
                    contacts.iter().map(|c| c.normal.lambda).collect();
                let velocity = Phase::Velocity;
                sweep(
                    &mut v,
                    &mut contacts,
                    &locks,
                    &keys,
                    friction,
                    1,
                    velocity,
                    true,
                );
                for (c, normal) in contacts.iter().zip(before) {
                    let tangent = c.tangent.lambda;
                    assert!(tangent.abs() <= friction * normal, "round {round}: {c:?}");
                }
            }
        }
    }

    /// A kept order serves only contacts of the same bodies: over 200 steps of contacts
    /// kept, drawn again (as many, or more), or one contact's body changed, the kept order is
    /// the one made afresh.
    #[test]
    fn a_kept_order_is_that_of_the_same_bodies() {
        let mut draw = draws(0x5851_f42d_4c95_7f2d);
        let mut ordered = Ordered::<64>::new();
        let mut count = 20;
        let mut contacts = random_contacts::<64>(count, &mut draw);
        for round in 0..200 {
            match round % 4 {
                0 => {}
                1 => contacts = random_contacts::<64>(count, &mut draw),
                2 => {
                    count = 1 + round % 40;
                    contacts = random_contacts::<64>(count, &mut draw);
                }
                _ => {
                    let last = count - 1;
                    contacts[last].bodies[1] = Some((round % 6 + 1) % 6);
                }
            }
            let kept = ordered.of::<f64, 2, 6>(&contacts).clone();
            let fresh = Order::<64>::of::<f64, 2, 6>(&contacts);
            assert_eq!(kept.all, fresh.all, "round {round}");
        }
    }

    /// Over 200 random sets of contacts among 6 bodies (some on static geometry), the
    /// interleaved order takes every contact once, and its sweeps give the
    /// keys' order's bits.
    #[test]
    fn the_interleaved_order_is_the_keys_bits() {
        let mut draw = draws(0x2545_f491_4f6c_dd1d);
        for round in 0..200 {
            let count = 1 + round % 40;
            let mut contacts = random_contacts::<64>(count, &mut draw);
            if round % 2 == 1 {
                // Contacts of the same two bodies one after the other are twins here.
                for i in 1..count {
                    if draw() > 0.0 {
                        contacts[i].bodies = contacts[i - 1].bodies;
                    }
                }
                twins::mark::<f64, 2, 6, 64>(&mut contacts);
            }
            let order = Order::<64>::of::<f64, 2, 6>(&contacts);
            let mut all = order.all.clone();
            all.sort_unstable();
            assert!(all.iter().copied().eq(0..count as u32), "{all:?}");
            let keys: heapless::Vec<u32, 64> = (0..count as u32).collect();
            let start = [0; 6].map(|_| SVector::<f64, 2>::new(draw(), draw()));
            let (mut v, mut w) = (start, start);
            let mut other = contacts.clone();
            let locks = Locks::<f64, 6>::new();
            let velocity = Phase::Velocity;
            sweep(&mut v, &mut contacts, &locks, &keys, 0.5, 3, velocity, true);
            sweep(
                &mut w, &mut other, &locks, &order.all, 0.5, 3, velocity, true,
            );
            assert_eq!(v, w, "round {round}");
        }
    }
}
