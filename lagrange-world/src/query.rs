//! Queries a game asks of a shape: the signed distance of a point ([`Shape::distance`]) and
//! where a ray first enters it ([`Shape::ray`]).

use crate::shape::Shape;
use crate::vec2::{add, closest_on_segments, dot, length, scale, sub, Vec2};
use lagrange_core::Real;

/// Where a ray first meets a shape.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RayHit<T> {
    /// The ray's parameter at the hit: the point is `origin + t direction`.
    pub t: T,
    /// The point hit, world coordinates.
    pub point: Vec2<T>,
    /// The shape's outward unit normal there (zero for a ray that starts inside, `t = 0`).
    pub normal: Vec2<T>,
}

impl<T: Real> Shape<T> {
    /// The distance from `point` to the shape's surface: positive outside, negative inside
    /// (less the radius: the core's distance, or minus the depth below its nearest edge).
    #[must_use]
    pub fn distance(&self, point: Vec2<T>) -> T {
        let v = self.vertices();
        let n = v.len();
        let inside_core = n >= 3
            && v.iter()
                .zip(self.normals())
                .all(|(&w, &m)| dot(sub(point, w), m) <= T::zero());
        let core = if inside_core {
            // Minus the depth below the nearest edge.
            v.iter()
                .zip(self.normals())
                .map(|(&w, &m)| dot(sub(point, w), m))
                .reduce(T::max)
                .unwrap_or(T::zero())
        } else {
            let edges = if n <= 2 { 1 } else { n };
            (0..edges)
                .map(|i| closest_on_segments(point, point, v[i], v[(i + 1) % n]).2)
                .reduce(T::min)
                .unwrap_or(T::INFINITY)
        };
        core - self.radius()
    }

    /// Where the ray from `origin` along `direction` (not zero) first meets the shape, for
    /// `t` in `[0, t_max]`: `None` where it does not (and for a `t_max` below zero or not a
    /// number: no range). A ray that starts inside meets it at `t = 0`. The shape is the union of its core, the bands of the radius along its edges
    /// and the disks of the radius at its vertices: the ray enters it where it first enters
    /// one of them, through an edge moved out by the radius or a vertex's disk.
    #[must_use]
    pub fn ray(&self, origin: Vec2<T>, direction: Vec2<T>, t_max: T) -> Option<RayHit<T>> {
        if t_max.partial_cmp(&T::zero()).is_none_or(|o| o.is_lt()) {
            return None;
        }
        if self.distance(origin) <= T::zero() {
            return Some(RayHit {
                t: T::zero(),
                point: origin,
                normal: [T::zero(); 2],
            });
        }
        let d2 = dot(direction, direction);
        if !(d2 > T::zero() && d2.is_finite()) {
            return None;
        }
        let r = self.radius();
        let v = self.vertices();
        let n = v.len();
        let mut best: Option<(T, Vec2<T>)> = None;
        let mut consider = |t: T, normal: Vec2<T>| {
            // A hit at an infinite t (a direction so short the ray crawls) is none.
            if t >= T::zero() && t <= t_max && t.is_finite() && best.is_none_or(|(b, _)| t < b) {
                best = Some((t, normal));
            }
        };
        // The edges moved out by the radius, entered from outside, within their extent.
        for (i, &m) in self.normals().iter().enumerate() {
            let along = dot(direction, m);
            if along >= T::zero() {
                continue;
            }
            let start = add(v[i], scale(m, r));
            let t = dot(sub(start, origin), m) / along;
            let hit = add(origin, scale(direction, t));
            let edge = sub(v[(i + 1) % n], v[i]);
            let s = dot(sub(hit, start), edge);
            if s >= T::zero() && s <= dot(edge, edge) {
                consider(t, m);
            }
        }
        // The vertices' disks: the smaller root of |o + t d - v|^2 = r^2.
        if r > T::zero() {
            for &w in v {
                let f = sub(origin, w);
                let b = dot(f, direction);
                let c = dot(f, f) - r * r;
                let disc = b * b - d2 * c;
                if disc >= T::zero() {
                    let t = (-b - disc.sqrt()) / d2;
                    let hit = add(origin, scale(direction, t));
                    let out = sub(hit, w);
                    consider(t, scale(out, T::one() / length(out)));
                }
            }
        }
        best.map(|(t, normal)| RayHit {
            t,
            point: add(origin, scale(direction, t)),
            normal,
        })
    }
}
