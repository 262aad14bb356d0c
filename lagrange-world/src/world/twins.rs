//! Twins: the two points of one manifold (a box flat on the floor or on another box),
//! their normal rows solved as one 2 x 2 problem in each sweep rather than one after the
//! other.
//!
//! One after the other, the first corner of a resting box takes the weight the sweep finds
//! missing and the second the rest of what is left, and eight sweeps end before the two
//! even out: the box is left turning a little every step, its friction answers with a
//! sideways push, and a column of ten 1 m boxes crept off its base and fell within 20 s.
//! Solved together the two corners share the load as the exact solution of the pair does
//! (Box2D's block solver, v2): the pair's program minimised over both impulses at once,
//! which lowers it at least as much as two updates one after the other, so that a sweep
//! of them never raises the kinetic energy either.

use super::lists::BodyLists;
use super::rows::{Contact, Part, Phase};
use super::OWN_ROWS;
use crate::vec2::{dot, scale};
use lagrange_core::nalgebra::SVector;
use lagrange_core::Real;

/// How far from dependent a twin's two rows must be, as `W11 W22 / det W` at most: two
/// points nearly one (a box balanced on its corner) are solved one after the other (Box2D's
/// bound on the condition number, 1000).
const CONDITION: f64 = 1000.0;

/// `W` of contacts `i` and `i + 1`'s normal rows, `[W11, W12, W22]`, where they are twins:
/// the same two shapes (consecutive in the keys' order), on two bodies (or one and static
/// geometry), no row locked in either (see `locks`) and the two rows independent enough
/// ([`CONDITION`]); else `None`.
fn twin_w<T: Real, const N: usize>(a: &Contact<T, N>, b: &Contact<T, N>) -> Option<[T; 3]> {
    let same = a.key.0 != OWN_ROWS
        && (a.key.0, a.key.1) == (b.key.0, b.key.1)
        && a.bodies == b.bodies
        && a.bodies[0] != a.bodies[1];
    let free = ![a.normal.held, a.tangent.held, b.normal.held, b.tangent.held]
        .iter()
        .any(|&h| h);
    if !same || !free || a.normal.inverse <= T::zero() || b.normal.inverse <= T::zero() {
        return None;
    }
    let cross = |x: &Contact<T, N>, y: &Contact<T, N>| {
        x.normal.j[0].dot(&y.normal.b[0]) + x.normal.j[1].dot(&y.normal.b[1])
    };
    let (w11, w12, w22) = (cross(a, a), cross(a, b), cross(b, b));
    let det = w11 * w22 - w12 * w12;
    (det * T::from_f64(CONDITION) > w11 * w22 && det.is_finite()).then_some([w11, w12, w22])
}

/// Whether contact `c` is the only support of each of its bodies along its normal: no
/// other contact of the body, of another pair of shapes, pushes it within 60 degrees of
/// the way `c` does. Two supports of one body solved each as twins (a box of a pyramid on
/// the two below it) each ask the body to turn with their other body, at odds with each
/// other, and the sweeps settled slower than point by point: a pyramid of 20 rows that
/// stands with 12 sweeps point by point sank 0.12 m and fell apart with every pair as
/// twins (16 sweeps held it). A body with one support each way (a box of a column) has
/// nothing to be at odds with.
fn alone<T: Real, const N: usize, const B: usize, const K: usize>(
    contacts: &[Contact<T, N>],
    lists: &BodyLists<B, K>,
    c: &Contact<T, N>,
) -> bool {
    let push = |c: &Contact<T, N>, body: usize| {
        if c.bodies[1] == Some(body) {
            c.direction
        } else {
            scale(c.direction, -T::one())
        }
    };
    c.bodies.iter().flatten().all(|&body| {
        let along = push(c, body);
        lists.contacts_of(contacts, body).all(|o| {
            (o.key.0, o.key.1) == (c.key.0, c.key.1)
                || o.key.0 == OWN_ROWS
                || dot(push(o, body), along) <= T::HALF
        })
    })
}

/// Each contact's [`Contact::twin`] set: `Some(W)` on the first of two twins ([`twin_w`])
/// that are their bodies' only support along their normal ([`alone`]), taken in the keys'
/// order, a contact at most one twin's.
pub(crate) fn mark<T: Real, const N: usize, const B: usize, const K: usize>(
    contacts: &mut [Contact<T, N>],
) {
    for c in contacts.iter_mut() {
        c.twin = None;
    }
    // Most scenes have none (balls, ragdolls whose rows are locked): no lists to make.
    let candidate =
        |contacts: &[Contact<T, N>], i: usize| match (contacts.get(i), contacts.get(i + 1)) {
            (Some(a), Some(b)) => twin_w(a, b),
            _ => None,
        };
    if !(0..contacts.len()).any(|i| candidate(contacts, i).is_some()) {
        return;
    }
    let lists = BodyLists::<B, K>::of(contacts);
    let mut i = 0;
    while let Some(c) = contacts.get(i) {
        let w = candidate(contacts, i).filter(|_| alone(contacts, &lists, c));
        if let Some(c) = contacts.get_mut(i) {
            c.twin = w;
        }
        i += if w.is_some() { 2 } else { 1 };
    }
}

/// The impulses `x >= 0` of two normal rows with `W = [w11, w12, w22]` that leave their
/// speeds `r + W x` (`r`: the speeds over their targets with no impulse) at or above zero,
/// and zero where an impulse pushes (the complementarity problem of the pair, whose
/// solution is the minimum of its program over `x >= 0`): of the four ways the rows can
/// push, the first that holds. Where rounding leaves none (a solution on the border of two
/// ways, where they meet), both rows' solution with its negative part dropped: within
/// rounding of either.
fn pair_lcp<T: Real>([w11, w12, w22]: [T; 3], [r1, r2]: [T; 2]) -> [T; 2] {
    let zero = T::zero();
    if r1 >= zero && r2 >= zero {
        return [zero, zero];
    }
    let det = w11 * w22 - w12 * w12;
    let both = [(w12 * r2 - w22 * r1) / det, (w12 * r1 - w11 * r2) / det];
    if both[0] >= zero && both[1] >= zero {
        return both;
    }
    let first = -r1 / w11;
    if first >= zero && w12 * first + r2 >= zero {
        return [first, zero];
    }
    let second = -r2 / w22;
    if second >= zero && w12 * second + r1 >= zero {
        return [zero, second];
    }
    both.map(|x| x.max(zero))
}

/// Twins `i` and `i + 1` (contact `i`'s [`Contact::twin`] is their `W`) in the phase
/// `DRIFT` says: both normal rows at once ([`pair_lcp`]), then each tangent within
/// `friction` times its normal's new impulse (so that the cone holds as the update leaves
/// it; the caller passes zero in the drift, which moves along the normals alone), on a copy of the two bodies' velocities written back once. Whether they were
/// twins.
#[inline(always)]
pub(crate) fn twins<T: Real, const N: usize, const DRIFT: bool>(
    v: &mut [SVector<T, N>],
    contacts: &mut [Contact<T, N>],
    i: usize,
    friction: T,
) -> bool {
    let Some((a, rest)) = contacts.get_mut(i..).and_then(|c| c.split_first_mut()) else {
        return false;
    };
    let (Some(w), Some(b)) = (a.twin, rest.first_mut()) else {
        return false;
    };
    let bodies = a.bodies;
    let mut near = bodies.map(|k| k.and_then(|k| v.get(k)).copied());
    let phase = if DRIFT { Phase::Drift } else { Phase::Velocity };
    let [w11, w12, w22] = w;
    let speeds = [&*a, &*b].map(|c| {
        c.normal.speed([near[0].as_ref(), near[1].as_ref()]) - phase.target(c, Part::Normal)
    });
    let old = [&*a, &*b].map(|c| phase.impulse_of(c, Part::Normal));
    let r = [
        speeds[0] - (w11 * old[0] + w12 * old[1]),
        speeds[1] - (w12 * old[0] + w22 * old[1]),
    ];
    let x = pair_lcp(w, r);
    for ((c, old), next) in [&mut *a, &mut *b].into_iter().zip(old).zip(x) {
        for (v, b) in near.iter_mut().zip(&c.normal.b) {
            if let Some(v) = v {
                *v += b * (next - old);
            }
        }
        *phase.impulse(c, Part::Normal) = next;
    }
    if friction > T::zero() {
        for c in [&mut *a, &mut *b] {
            if c.tangent.inverse > T::zero() {
                let bound = friction * c.normal.lambda;
                let row = &mut c.tangent;
                let residual = row.speed([near[0].as_ref(), near[1].as_ref()]);
                let next = (row.lambda - residual * row.inverse).max(-bound).min(bound);
                for (x, b) in near.iter_mut().zip(&row.b) {
                    if let Some(x) = x {
                        *x += b * (next - row.lambda);
                    }
                }
                row.lambda = next;
            }
        }
    }
    for (body, x) in bodies.iter().zip(near) {
        if let (Some(slot), Some(x)) = (body.and_then(|k| v.get_mut(k)), x) {
            *slot = x;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::{mark, pair_lcp, twin_w};
    use crate::world::locks::Locks;
    use crate::world::rows::{Contact, Part, Phase, Row};
    use crate::world::solve::{sweep, tests::draws};
    use lagrange_core::nalgebra::SVector;

    /// A contact point of shapes `shapes` between `bodies` (of 2 coordinates, mass matrix
    /// `2 I`), pushing the second along `direction`, its rows' Jacobians drawn from `draw`.
    fn point(
        shapes: (u32, u32),
        id: u32,
        bodies: [Option<usize>; 2],
        direction: [f64; 2],
        draw: &mut impl FnMut() -> f64,
    ) -> Contact<f64, 2> {
        let mut row = || {
            let j = [0, 1].map(|_| SVector::<f64, 2>::new(draw(), draw()));
            let j = [0, 1].map(|s| {
                if bodies[s].is_some() {
                    j[s]
                } else {
                    SVector::zeros()
                }
            });
            Row::new(j, j.map(|j| j * 0.5))
        };
        Contact {
            key: (shapes.0, shapes.1, id),
            bodies,
            normal: row(),
            tangent: row(),
            gap: 0.0,
            lower: 0.0,
            approach: 0.0,
            drift: 0.0,
            reach: 0.0,
            point: [0.0; 2],
            direction,
            twin: None,
        }
    }

    /// `count` pairs of points, each pair of one pair of shapes, between two of 4 bodies
    /// (or one and static geometry), pushing up, their rows drawn from `draw`.
    fn random_pairs(
        count: u32,
        draw: &mut impl FnMut() -> f64,
    ) -> heapless::Vec<Contact<f64, 2>, 32> {
        let mut contacts = heapless::Vec::new();
        for pair in 0..count {
            let body = |x: f64| ((x + 0.5) * 4.0) as usize;
            let (a, b) = (body(draw()), body(draw()));
            let bodies = if a == b {
                [None, Some(b)]
            } else {
                [Some(a), Some(b)]
            };
            for id in 0..2 {
                let c = point((pair, 100 + pair), id, bodies, [0.0, 1.0], draw);
                assert!(contacts.push(c).is_ok());
            }
        }
        contacts
    }

    /// The pair's complementarity problem solved: over 10,000 random positive definite `W`
    /// (condition below 1000) and speeds `r` (half of them on a border between two ways the
    /// rows can push, where rounding can fail the tests of both), the impulses push only
    /// (`x >= 0`), leave no
    /// row closing (`r + W x >= 0`) and no row pushing that opens (`x_i (r + W x)_i = 0`),
    /// to the rounding of the sums (1e-12 of their terms).
    #[test]
    fn the_pair_is_solved_exactly() {
        let mut draw = draws(0x0bad_5eed_1234_5678);
        let mut tried = 0;
        while tried < 10_000 {
            let (a, b, c) = (draw() + 1.0, 2.0 * draw(), draw() + 1.0);
            let w = [a * a, a * b, b * b + c * c];
            let det = w[0] * w[2] - w[1] * w[1];
            if det * 1000.0 <= w[0] * w[2] {
                continue;
            }
            tried += 1;
            // Every other draw on a border of two ways (`r = -W x`, one of `x` zero: both
            // ways' tests meet at zero there, and rounding may fail both).
            let r = if tried % 2 == 0 {
                [4.0 * draw(), 4.0 * draw()]
            } else {
                let x = [draw() + 0.5, draw() + 0.5];
                let x = if tried % 4 == 1 {
                    [x[0], 0.0]
                } else {
                    [0.0, x[1]]
                };
                // Off the border by an ulp or two either way.
                [
                    -(w[0] * x[0] + w[1] * x[1]) * (1.0 + 4e-16 * draw()),
                    -(w[1] * x[0] + w[2] * x[1]) * (1.0 + 4e-16 * draw()),
                ]
            };
            let x = pair_lcp(w, r);
            let s = [
                r[0] + w[0] * x[0] + w[1] * x[1],
                r[1] + w[1] * x[0] + w[2] * x[1],
            ];
            let tol = 1e-12 * (1.0 + r[0].abs() + r[1].abs()) * (1.0 + x[0] + x[1]);
            for k in 0..2 {
                assert!(x[k] >= 0.0 && s[k] >= -tol, "{w:?} {r:?}: {x:?} {s:?}");
                assert!((x[k] * s[k]).abs() <= tol, "{w:?} {r:?}: {x:?} {s:?}");
            }
        }
    }

    /// Two points are twins only as two points of one pair of shapes, on the same two
    /// bodies, no row of either held, each moved by an impulse, and their rows far enough
    /// from dependent: `W11 W22 / det W` below 1000, asserted at the bound itself with a
    /// `W` whose products are exact (999 x 1000 = 1000 x det, det = 999000 - 999^2).
    #[test]
    fn twins_are_one_pair_free_and_independent() {
        let mut draw = draws(0x7a1e_0002_2026_1202);
        let (a, b) = (Some(0), Some(1));
        let up = [0.0, 1.0];
        let pair = [
            point((3, 4), 0, [a, b], up, &mut draw),
            point((3, 4), 1, [a, b], up, &mut draw),
        ];
        let twins = |[x, y]: &[Contact<f64, 2>; 2]| twin_w(x, y).is_some();
        assert!(twins(&pair));
        let mut other = pair;
        other[1].key = (3, 5, 1);
        assert!(!twins(&other), "two pairs of shapes");
        other = pair;
        other[1].bodies = [a, Some(2)];
        assert!(!twins(&other), "other bodies");
        for (i, normal) in [(0, true), (0, false), (1, true), (1, false)] {
            other = pair;
            let c = &mut other[i];
            let row = if normal {
                &mut c.normal
            } else {
                &mut c.tangent
            };
            row.held = true;
            assert!(!twins(&other), "point {i} held, normal {normal}");
        }
        for i in 0..2 {
            // A row that moves its bodies by less than the rounding: no impulse moves it.
            other = pair;
            let normal = &mut other[i].normal;
            *normal = Row::new(normal.j.map(|j| j * 1e-9), normal.b.map(|b| b * 1e-9));
            assert!(!twins(&other), "row {i} moves nothing");
        }
        // Two points at one place: the same rows.
        other = pair;
        other[1].normal = other[0].normal;
        assert!(!twins(&other), "one point");
        // `W = [999, 999, 1000]` at the bound, `[999, 999, 1001]` within it.
        let e = |x: f64, y: f64| SVector::<f64, 2>::new(x, y);
        let zero = SVector::zeros();
        for (w22, twin) in [(1000.0, false), (1001.0, true)] {
            other = pair;
            other[0].normal = Row::new([e(1.0, 0.0), zero], [e(999.0, 0.0), zero]);
            other[1].normal = Row::new([e(1.0, 1.0), zero], [e(999.0, w22 - 999.0), zero]);
            let w = twin_w(&other[0], &other[1]);
            assert_eq!(w.is_some(), twin, "{w22}: {w:?}");
        }
    }

    /// A column (body 1 on body 0 on static ground, each on one pair of shapes, two points
    /// each) is twins throughout; a body on two others (body 2 of a pyramid's, on bodies 0
    /// and 1, pushed up by both) has neither of its supports as twins, while theirs on the
    /// ground (their one support each way up) are; a single point is nobody's twin.
    #[test]
    fn twins_are_their_bodies_only_support() {
        let mut draw = draws(0x1234_abcd_8765_4321);
        let up = [0.0, 1.0];
        let mut column = [
            point((1, 10), 0, [None, Some(0)], up, &mut draw),
            point((1, 10), 1, [None, Some(0)], up, &mut draw),
            point((10, 11), 0, [Some(0), Some(1)], up, &mut draw),
            point((10, 11), 1, [Some(0), Some(1)], up, &mut draw),
        ];
        mark::<f64, 2, 4, 8>(&mut column);
        let marked = |c: &[Contact<f64, 2>]| -> heapless::Vec<bool, 16> {
            c.iter().map(|c| c.twin.is_some()).collect()
        };
        assert_eq!(marked(&column), [true, false, true, false]);
        let mut pyramid = [
            point((1, 10), 0, [None, Some(0)], up, &mut draw),
            point((1, 10), 1, [None, Some(0)], up, &mut draw),
            point((1, 11), 0, [None, Some(1)], up, &mut draw),
            point((1, 11), 1, [None, Some(1)], up, &mut draw),
            point((10, 12), 0, [Some(0), Some(2)], up, &mut draw),
            point((10, 12), 1, [Some(0), Some(2)], up, &mut draw),
            point((11, 12), 0, [Some(1), Some(2)], up, &mut draw),
            point((11, 12), 1, [Some(1), Some(2)], up, &mut draw),
            point((12, 13), 0, [Some(2), Some(3)], [1.0, 0.0], &mut draw),
        ];
        mark::<f64, 2, 4, 16>(&mut pyramid);
        assert_eq!(
            marked(&pyramid),
            [true, false, true, false, false, false, false, false, false]
        );
    }

    /// Sweeps over random twins (pairs of points of one pair of shapes, among 4 bodies and
    /// static geometry), from rest impulses and targets of zero: the kinetic energy never
    /// rises from one sweep to the next (to 1e-12 of it: each twin's update is the exact
    /// minimum of its program over its two impulses, each tangent's along its row), and
    /// every twin's tangent ends within `mu` times its normal's impulse (a twin's tangents
    /// are updated after its normals).
    #[test]
    fn twins_lower_the_energy_and_keep_the_cone() {
        let mut draw = draws(0x5eed_0000_2026_1201);
        let mut twins = 0;
        for round in 0..400 {
            let friction = if round % 2 == 0 { 0.0 } else { 0.4 };
            let mut contacts = random_pairs(1 + round % 12, &mut draw);
            mark::<f64, 2, 4, 32>(&mut contacts);
            let order: heapless::Vec<u32, 32> = (0..contacts.len() as u32).collect();
            let mut v = [0; 4].map(|_| SVector::<f64, 2>::new(4.0 * draw(), 4.0 * draw()));
            let energy = |v: &[SVector<f64, 2>; 4]| v.iter().map(|v| v.dot(v)).sum::<f64>();
            let locks = Locks::<f64, 4>::new();
            let mut before = energy(&v);
            for _ in 0..6 {
                let velocity = Phase::Velocity;
                sweep(
                    &mut v,
                    &mut contacts,
                    &locks,
                    &order,
                    friction,
                    1,
                    velocity,
                    true,
                );
                let after = energy(&v);
                let rose = friction == 0.0 && after > before * (1.0 + 1e-12);
                assert!(!rose, "round {round}: {before} -> {after}");
                before = after;
            }
            for (i, c) in contacts.iter().enumerate() {
                let head = |i: usize| contacts.get(i).is_some_and(|c| c.twin.is_some());
                if head(i) || (i > 0 && head(i - 1)) {
                    twins += 1;
                    let bound = friction * c.normal.lambda * (1.0 + 1e-12);
                    assert!(c.tangent.lambda.abs() <= bound, "round {round}: {c:?}");
                }
            }
        }
        // Most random pairs share a body another pushes the same way (no twins): 592 of
        // the 5,200 points are twins'.
        assert!(twins > 400, "{twins}");
    }

    /// The drift's sweeps move the bodies along the normals alone: over random twins (as
    /// above, friction 0.4, tangent impulses drawn within the cone, pseudo-velocities drawn
    /// closing), no tangent impulse changes, bit for bit, and some normal's drift impulse
    /// does (the sweeps ran).
    #[test]
    fn twins_in_the_drift_keep_their_tangents() {
        let mut draw = draws(0x0d71_f700_2026_1202);
        let mut moved = 0;
        for round in 0..100 {
            let mut contacts = random_pairs(1 + round % 12, &mut draw);
            for c in contacts.iter_mut() {
                c.normal.lambda = draw() + 0.5;
                c.tangent.lambda = 0.8 * draw() * c.normal.lambda;
            }
            mark::<f64, 2, 4, 32>(&mut contacts);
            let tangents: heapless::Vec<u64, 32> = contacts
                .iter()
                .map(|c| c.tangent.lambda.to_bits())
                .collect();
            let order: heapless::Vec<u32, 32> = (0..contacts.len() as u32).collect();
            let mut pseudo = [0; 4].map(|_| SVector::<f64, 2>::new(draw(), -4.0 * draw().abs()));
            let locks = Locks::<f64, 4>::new();
            sweep(
                &mut pseudo,
                &mut contacts,
                &locks,
                &order,
                0.4,
                4,
                Phase::Drift,
                true,
            );
            let after: heapless::Vec<u64, 32> = contacts
                .iter()
                .map(|c| c.tangent.lambda.to_bits())
                .collect();
            assert_eq!(tangents, after, "round {round}");
            moved += contacts
                .iter()
                .filter(|c| Phase::Drift.impulse_of(c, Part::Normal) != 0.0)
                .count();
        }
        assert!(moved > 100, "{moved}");
    }
}
