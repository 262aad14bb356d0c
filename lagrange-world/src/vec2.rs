//! The few operations on points and directions of the plane the geometry needs, on `[T; 2]`.

use lagrange_core::Real;

/// A point or a direction of the plane.
pub type Vec2<T> = [T; 2];

pub(crate) fn add<T: Real>(a: Vec2<T>, b: Vec2<T>) -> Vec2<T> {
    [a[0] + b[0], a[1] + b[1]]
}

pub(crate) fn sub<T: Real>(a: Vec2<T>, b: Vec2<T>) -> Vec2<T> {
    [a[0] - b[0], a[1] - b[1]]
}

pub(crate) fn scale<T: Real>(a: Vec2<T>, s: T) -> Vec2<T> {
    [a[0] * s, a[1] * s]
}

pub(crate) fn dot<T: Real>(a: Vec2<T>, b: Vec2<T>) -> T {
    a[0] * b[0] + a[1] * b[1]
}

/// The z component of `a x b`.
pub(crate) fn cross<T: Real>(a: Vec2<T>, b: Vec2<T>) -> T {
    a[0] * b[1] - a[1] * b[0]
}

/// `a` turned a quarter turn clockwise: the outward normal of an edge along `a` of a polygon
/// wound counter-clockwise.
pub(crate) fn right<T: Real>(a: Vec2<T>) -> Vec2<T> {
    [a[1], -a[0]]
}

pub(crate) fn length<T: Real>(a: Vec2<T>) -> T {
    dot(a, a).sqrt()
}

/// `a` turned by the angle whose sine and cosine are `(s, c)`.
pub(crate) fn rotate<T: Real>(a: Vec2<T>, (s, c): (T, T)) -> Vec2<T> {
    [c * a[0] - s * a[1], s * a[0] + c * a[1]]
}

/// The closest points of the segments `p0 p1` and `q0 q1` (either may be a point): on each,
/// and their distance. Clamped parameters (Ericson, *Real-Time Collision Detection*, 5.1.9).
pub(crate) fn closest_on_segments<T: Real>(
    p0: Vec2<T>,
    p1: Vec2<T>,
    q0: Vec2<T>,
    q1: Vec2<T>,
) -> (Vec2<T>, Vec2<T>, T) {
    let (d1, d2, r) = (sub(p1, p0), sub(q1, q0), sub(p0, q0));
    let (a, e, f) = (dot(d1, d1), dot(d2, d2), dot(d2, r));
    let unit = |x: T| x.max(T::zero()).min(T::one());
    let (s, t) = if a <= T::zero() && e <= T::zero() {
        (T::zero(), T::zero())
    } else if a <= T::zero() {
        (T::zero(), unit(f / e))
    } else {
        let c = dot(d1, r);
        if e <= T::zero() {
            (unit(-c / a), T::zero())
        } else {
            let b = dot(d1, d2);
            let denominator = a * e - b * b;
            let s = if denominator > T::zero() {
                unit((b * f - c * e) / denominator)
            } else {
                T::zero()
            };
            let t = (b * s + f) / e;
            if t < T::zero() {
                (unit(-c / a), T::zero())
            } else if t > T::one() {
                (unit((b - c) / a), T::one())
            } else {
                (s, t)
            }
        }
    };
    let (p, q) = (add(p0, scale(d1, s)), add(q0, scale(d2, t)));
    (p, q, length(sub(q, p)))
}
