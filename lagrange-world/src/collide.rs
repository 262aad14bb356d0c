//! The narrow phase: [`collide`] two shapes, [`collide_half_plane`] a shape with the static
//! half-plane of a floor or a wall.
//!
//! Both shapes are cores rounded by radii ([`Shape`]), so one method serves every pair:
//!
//! ```text
//! cores apart      the closest points of the cores (segment against segment, every pair of
//!                  edges: at most 8 x 8); further than the radii and the margin: no point.
//!                  Where a face of one core is the closest feature (the separating axis of
//!                  the largest separation is as far as the closest points), the other's
//!                  nearest edge is clipped to that face: one or two points; else one point
//!                  along the line of the closest points (a corner, a circle)
//! cores overlap    the separating axis of the least penetration among the cores' edge
//!                  normals (Gottschalk's theorem: in the plane, the edge normals suffice),
//!                  and the same clipping; cores are known to overlap by their axes alone
//!                  (each edge normal's separation negative), before any closest points
//!                  are looked for
//! ```
//!
//! A margin above zero keeps the points of shapes still apart but closing (speculative
//! contacts: a fast ball does not pass through a thin plank in one step); their gaps are
//! positive.

use crate::manifold::{ContactPoint, Manifold};
use crate::shape::{Shape, MAX_VERTICES};
use crate::vec2::{add, closest_on_segments, dot, length, scale, sub, Vec2};
use lagrange_core::{Error, Real};

/// The largest separation of the cores along an edge normal of one of them: which shape's
/// edge (the second's when `flip`), and how far.
#[derive(Debug, Clone, Copy)]
struct Axis<T> {
    flip: bool,
    edge: usize,
    separation: T,
}

/// Where `a` and `b` touch or are within `margin` (>= 0) of touching; the normal from `a` to
/// `b`. Swapping them swaps the normal's sign and nothing else.
///
/// ```
/// use lagrange_world::{collide, Shape};
/// use lagrange_core::links::Pose;
/// // A 1 m box resting on another, 1 mm into it, turned by nothing.
/// let (floor, top) = (Shape::rectangle(4.0_f64, 1.0)?, Shape::rectangle(1.0, 1.0)?);
/// let top = top.placed(&Pose { origin: [0.0, 0.999], angle: 0.0 });
/// let m = collide(&floor, &top, 0.0);
/// assert_eq!(m.points().len(), 2);
/// assert!((m.normal[1] - 1.0).abs() < 1e-15);
/// assert!(m.points().iter().all(|p| (p.gap + 0.001).abs() < 1e-12));
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[must_use]
pub fn collide<T: Real>(a: &Shape<T>, b: &Shape<T>, margin: T) -> Manifold<T> {
    let radii = a.radius() + b.radius();
    let axis = best_axis(a, b);
    // Cores that overlap along every edge normal overlap (the separating axis theorem; a
    // circle's core, a point, is inside a polygon exactly when it is inside along each of
    // the polygon's normals): no closest points to look for. Two circles have no axis.
    if let Some(axis) = axis.filter(|x| x.separation < T::zero()) {
        return clip(a, b, axis, margin);
    }
    let Some((pa, pb, d)) = core_distance(a, b) else {
        // The cores overlap: the axis of least penetration (two circles at one centre have
        // none: straight up, by convention).
        return match axis {
            Some(axis) => clip(a, b, axis, margin),
            None => one_point(
                a,
                b,
                [T::zero(), T::one()],
                [pa_of(a), pa_of(b)],
                -radii,
                margin,
            ),
        };
    };
    if d - radii > margin {
        return Manifold::along(scale(sub(pb, pa), T::one() / d));
    }
    let scale_of = |p: Vec2<T>| p[0].abs() + p[1].abs();
    let rounding =
        T::from_f64(64.0) * T::EPSILON * (T::one() + d + radii + scale_of(pa) + scale_of(pb));
    if let Some(axis) = axis.filter(|axis| axis.separation >= d - rounding) {
        let m = clip(a, b, axis, margin);
        if !m.points().is_empty() {
            return m;
        }
    }
    let normal = scale(sub(pb, pa), T::one() / d);
    one_point(a, b, normal, [pa, pb], d - radii, margin)
}

/// A static half-plane: the points `x` with `normal . x >= offset` are free; the others are
/// inside it (the floor: normal `(0, 1)`, offset 0).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HalfPlane<T> {
    normal: Vec2<T>,
    offset: T,
}

impl<T: Real> HalfPlane<T> {
    /// The half-plane whose boundary passes `offset` along `normal` (not zero, finite; made
    /// unit) from the origin.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `normal` or `offset`.
    pub fn new(normal: Vec2<T>, offset: T) -> Result<Self, Error> {
        let size = length(normal);
        if !(size.is_finite() && size > T::zero() && (T::one() / size).is_finite()) {
            return Err(Error::InvalidParameter {
                name: "normal",
                reason: "must be finite and not zero",
            });
        }
        if !offset.is_finite() {
            return Err(Error::InvalidParameter {
                name: "offset",
                reason: "must be finite",
            });
        }
        Ok(Self {
            normal: scale(normal, T::one() / size),
            offset,
        })
    }

    /// The floor `y >= 0`.
    #[must_use]
    pub fn floor() -> Self {
        Self {
            normal: [T::zero(), T::one()],
            offset: T::zero(),
        }
    }

    /// The unit normal, out of the half-plane.
    #[must_use]
    pub fn normal(&self) -> Vec2<T> {
        self.normal
    }

    /// How far the boundary is from the origin along the normal.
    #[must_use]
    pub fn offset(&self) -> T {
        self.offset
    }
}

/// Where `shape` touches the half-plane `plane` or is within `margin` of it: the normal is
/// the plane's (from the plane to the shape), a point per vertex of the core within the
/// margin, the two deepest (a box resting flat: its two lower corners). Each point's id is
/// its vertex.
#[must_use]
pub fn collide_half_plane<T: Real>(
    plane: &HalfPlane<T>,
    shape: &Shape<T>,
    margin: T,
) -> Manifold<T> {
    let mut deepest: [Option<&ContactPoint<T>>; 2] = [None, None];
    let points = half_plane_points(plane, shape, margin);
    for p in &points {
        if deepest[0].is_none_or(|d| p.gap < d.gap) {
            deepest = [Some(p), deepest[0]];
        } else if deepest[1].is_none_or(|d| p.gap < d.gap) {
            deepest[1] = Some(p);
        }
    }
    let mut m = Manifold::along(plane.normal);
    for p in deepest.into_iter().flatten() {
        m.push(*p);
    }
    m
}

/// Every vertex of `shape`'s core within `margin` of the half-plane `plane` as a contact
/// point (its id the vertex, its gap and point at the start; see [`collide_half_plane`]). A
/// world keeps them all, within the margin and how far the shape may move, not the two
/// deepest: a shape turning fast brings a vertex that is not among the deepest at the start
/// into the plane (a plank spun about one end sweeps its far corner 20 cm down in a step),
/// and the impulses may turn it the other way than its velocities at the start (a box struck
/// on a corner).
pub(crate) fn half_plane_points<T: Real>(
    plane: &HalfPlane<T>,
    shape: &Shape<T>,
    margin: T,
) -> heapless::Vec<ContactPoint<T>, MAX_VERTICES> {
    let n = plane.normal;
    let gap_of = |v: Vec2<T>| dot(v, n) - plane.offset - shape.radius();
    let mut points = heapless::Vec::new();
    for (i, &v) in shape.vertices().iter().enumerate() {
        let gap = gap_of(v);
        if gap > margin {
            continue;
        }
        // Midway between the shape's surface and the plane's boundary, below the vertex.
        let on_shape = sub(v, scale(n, shape.radius()));
        let point = ContactPoint {
            point: sub(on_shape, scale(n, gap * T::HALF)),
            gap,
            id: u32::try_from(i).unwrap_or(0),
        };
        // A core has at most MAX_VERTICES vertices.
        let _ = points.push(point);
    }
    points
}

/// The single vertex of a circle (any vertex of another core).
fn pa_of<T: Real>(s: &Shape<T>) -> Vec2<T> {
    s.vertices()[0]
}

/// One point along `normal` between the cores' closest points `[pa, pb]`, at `gap`, if within
/// `margin`; its id names the cores' vertices furthest along the normal.
fn one_point<T: Real>(
    a: &Shape<T>,
    b: &Shape<T>,
    normal: Vec2<T>,
    [pa, pb]: [Vec2<T>; 2],
    gap: T,
    margin: T,
) -> Manifold<T> {
    let mut m = Manifold::along(normal);
    if gap <= margin {
        let on_a = add(pa, scale(normal, a.radius()));
        let on_b = sub(pb, scale(normal, b.radius()));
        let (ia, ib) = (a.support(normal), b.support([-normal[0], -normal[1]]));
        m.push(ContactPoint {
            point: scale(add(on_a, on_b), T::HALF),
            gap,
            id: (2 << 24) | (index(ia) << 16) | (index(ib) << 8),
        });
    }
    m
}

/// `i` (below 8) as an id field.
fn index(i: usize) -> u32 {
    u32::try_from(i).unwrap_or(0) & 0xff
}

/// The edges of a core, as segments: a circle's one point (as a segment of length zero), a
/// capsule's one segment, a polygon's edges.
fn edges<T: Real>(s: &Shape<T>) -> impl Iterator<Item = (Vec2<T>, Vec2<T>)> + '_ {
    let v = s.vertices();
    let n = v.len();
    let count = match n {
        1 | 2 => 1,
        _ => n,
    };
    (0..count).map(move |i| (v[i], v[(i + 1) % n]))
}

/// The closest points of the cores of `a` and `b` and their distance, or `None` where the
/// cores overlap (they cross, or one holds the other).
pub(crate) fn core_distance<T: Real>(a: &Shape<T>, b: &Shape<T>) -> Option<(Vec2<T>, Vec2<T>, T)> {
    let mut best: Option<(Vec2<T>, Vec2<T>, T)> = None;
    for (p0, p1) in edges(a) {
        for (q0, q1) in edges(b) {
            let (p, q, d) = closest_on_segments(p0, p1, q0, q1);
            if best.is_none_or(|(_, _, e)| d < e) {
                best = Some((p, q, d));
            }
        }
    }
    let inside = |v: Vec2<T>, s: &Shape<T>| {
        s.vertices().len() >= 3
            && s.vertices()
                .iter()
                .zip(s.normals())
                .all(|(&w, &n)| dot(sub(v, w), n) <= T::zero())
    };
    // Closer than the rounding of the coordinates (64 ulps of their size) is touching: the
    // line of two closest points that far apart points anywhere.
    let size = a
        .vertices()
        .iter()
        .chain(b.vertices())
        .fold(T::one(), |m, v| m.max(v[0].abs()).max(v[1].abs()));
    let rounding = T::from_f64(64.0) * T::EPSILON * size;
    match best {
        Some((_, _, d))
            if d > rounding && !inside(a.vertices()[0], b) && !inside(b.vertices()[0], a) =>
        {
            best
        }
        _ => None,
    }
}

/// How much larger the second shape's separation must be than the first's for its edge to
/// be the reference, as a share of the shorter of the two edges: two faces resting flat on
/// each other (a box on a box) are each the axis of the largest separation by turns, as
/// the boxes tip by a few microradians either way, and each turn named the contact's points
/// anew (the reference face is in their ids), so that no impulse was warm-started from
/// the step before; a column of five boxes, cold every other step, crept 0.3 m sideways
/// in 20 s, and one of ten fell. A face kept until the other is better by a thousandth of
/// its length turns over only past a milliradian between the faces (Box2D's tolerance is
/// a tenth of its slop, 0.5 mm, for boxes of half a metre to a few).
const KEEP_FIRST: f64 = 1.0 / 1024.0;

/// The separating axis of the largest separation among the edge normals of both cores
/// (the first shape's unless the second's is larger by [`KEEP_FIRST`] of the shorter of
/// their edges), or `None` where neither core has an edge (two circles).
fn best_axis<T: Real>(a: &Shape<T>, b: &Shape<T>) -> Option<Axis<T>> {
    let along = |s: &Shape<T>, o: &Shape<T>, flip: bool| {
        let mut best: Option<Axis<T>> = None;
        for (edge, (&w, &n)) in s.vertices().iter().zip(s.normals()).enumerate() {
            let separation = o
                .vertices()
                .iter()
                .map(|&v| dot(sub(v, w), n))
                .reduce(T::min)
                .unwrap_or(T::INFINITY);
            if best.is_none_or(|x| separation > x.separation) {
                best = Some(Axis {
                    flip,
                    edge,
                    separation,
                });
            }
        }
        best
    };
    match (along(a, b, false), along(b, a, true)) {
        (Some(x), Some(y)) => {
            let edge = |s: &Shape<T>, i: usize| {
                let v = s.vertices();
                length(sub(v[(i + 1) % v.len()], v[i]))
            };
            let keep = T::from_f64(KEEP_FIRST) * edge(a, x.edge).min(edge(b, y.edge));
            Some(if y.separation > x.separation + keep {
                y
            } else {
                x
            })
        }
        (x, y) => x.or(y),
    }
}

/// The incident edge (or vertex) of the other shape clipped to the reference edge `axis` names:
/// up to two points within `margin`.
fn clip<T: Real>(a: &Shape<T>, b: &Shape<T>, axis: Axis<T>, margin: T) -> Manifold<T> {
    let (reference, incident) = if axis.flip { (b, a) } else { (a, b) };
    let rv = reference.vertices();
    let i = axis.edge;
    let n = reference.normals()[i];
    let (v1, v2) = (rv[i], rv[(i + 1) % rv.len()]);
    let normal = if axis.flip { [-n[0], -n[1]] } else { n };
    let mut m = Manifold::along(normal);
    // The incident feature: the other's edge most against the reference normal, or its
    // one vertex.
    let iv = incident.vertices();
    let j = incident
        .normals()
        .iter()
        .enumerate()
        .map(|(j, &m)| (j, dot(m, n)))
        .reduce(|x, y| if y.1 < x.1 { y } else { x })
        .map_or(0, |(j, _)| j);
    let (mut w1, mut w2) = (iv[j], iv[(j + 1) % iv.len()]);
    // Clipped to the reference edge's slab: between the lines through v1 and v2 across it.
    let t = sub(v2, v1);
    let (lo, hi) = (dot(v1, t), dot(v2, t));
    let keep = |w1: &mut Vec2<T>, w2: &mut Vec2<T>, bound: T, below: bool| -> bool {
        let side = |w: Vec2<T>| {
            if below {
                dot(w, t) - bound
            } else {
                bound - dot(w, t)
            }
        };
        let (s1, s2) = (side(*w1), side(*w2));
        if s1 > T::zero() && s2 > T::zero() {
            return false;
        }
        if s1 > T::zero() {
            *w1 = add(*w1, scale(sub(*w2, *w1), s1 / (s1 - s2)));
        } else if s2 > T::zero() {
            *w2 = add(*w2, scale(sub(*w1, *w2), s2 / (s2 - s1)));
        }
        true
    };
    if !keep(&mut w1, &mut w2, hi, true) || !keep(&mut w1, &mut w2, lo, false) {
        return m;
    }
    let points = if iv.len() == 1 { 1 } else { 2 };
    for (k, w) in [w1, w2].into_iter().take(points).enumerate() {
        let depth = dot(sub(w, v1), n);
        let gap = depth - reference.radius() - incident.radius();
        if gap > margin {
            continue;
        }
        let on_reference = add(sub(w, scale(n, depth)), scale(n, reference.radius()));
        let on_incident = sub(w, scale(n, incident.radius()));
        m.push(ContactPoint {
            point: scale(add(on_reference, on_incident), T::HALF),
            gap,
            id: (u32::from(axis.flip) << 24) | (index(i) << 16) | (index(j) << 8) | index(k),
        });
    }
    m
}
