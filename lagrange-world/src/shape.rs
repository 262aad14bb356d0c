//! [`Shape`]: a convex shape of the plane, a core (a point, a segment or a convex polygon)
//! rounded by a radius: circles, capsules, boxes and polygons in one form, so that one
//! narrow phase serves every pair.

use crate::vec2::{add, cross, dot, length, right, rotate, scale, sub, Vec2};
use lagrange_core::links::Pose;
use lagrange_core::validate::positive;
use lagrange_core::{Error, Real};

/// Most vertices of a shape's core.
pub const MAX_VERTICES: usize = 8;

/// A convex shape: the points within `radius` of its core, the convex hull of its vertices
/// (one vertex: a circle; two: a capsule; three to [`MAX_VERTICES`], wound counter-clockwise:
/// a polygon, rounded when the radius is not zero).
///
/// Made in a body's own frame ([`Shape::circle`], [`Shape::capsule`], [`Shape::rectangle`],
/// [`Shape::polygon`], moved on it by [`Shape::offset`]) and put in the world by
/// [`Shape::placed`] at the body's [`Pose`].
///
/// ```
/// use lagrange_world::Shape;
/// let crate_ = Shape::rectangle(0.5, 0.3)?;
/// assert_eq!(crate_.vertices().len(), 4);
/// let ball = Shape::circle(0.1)?;
/// assert_eq!((ball.vertices().len(), ball.radius()), (1, 0.1));
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Shape<T> {
    vertices: [Vec2<T>; MAX_VERTICES],
    /// The outward unit normal of edge `i`, from vertex `i` to vertex `i + 1` (for a capsule,
    /// edge 0 and edge 1 are the core's two sides).
    normals: [Vec2<T>; MAX_VERTICES],
    count: usize,
    radius: T,
}

impl<T: Real> Shape<T> {
    /// A circle of `radius` (> 0, finite) about the origin.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `radius`.
    pub fn circle(radius: T) -> Result<Self, Error> {
        let radius = positive("radius", radius)?;
        Ok(Self::from_core(&[[T::zero(); 2]], radius))
    }

    /// A capsule: the points within `radius` (> 0) of the segment from `(-half_length, 0)` to
    /// `(half_length, 0)` (`half_length` > 0).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `half_length` or `radius`.
    pub fn capsule(half_length: T, radius: T) -> Result<Self, Error> {
        let h = positive("half_length", half_length)?;
        let radius = positive("radius", radius)?;
        Ok(Self::from_core(&[[-h, T::zero()], [h, T::zero()]], radius))
    }

    /// A `width` by `height` rectangle (both > 0) centred on the origin.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `width` or `height`.
    pub fn rectangle(width: T, height: T) -> Result<Self, Error> {
        let w = positive("width", width)? * T::HALF;
        let h = positive("height", height)? * T::HALF;
        Ok(Self::from_core(
            &[[-w, -h], [w, -h], [w, h], [-w, h]],
            T::zero(),
        ))
    }

    /// The convex polygon of `vertices` (3 to [`MAX_VERTICES`], finite, wound
    /// counter-clockwise, every vertex strictly to the left of every edge it is not on: no
    /// two vertices alike, none on the line of an edge, and once round, not a star whose
    /// every turn is to the left).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `vertices` otherwise, and for edges whose products
    /// overflow or vanish in `T` (coordinates near its largest or smallest).
    pub fn polygon(vertices: &[Vec2<T>]) -> Result<Self, Error> {
        let n = vertices.len();
        let refuse = |reason| {
            Err(Error::InvalidParameter {
                name: "vertices",
                reason,
            })
        };
        if !(3..=MAX_VERTICES).contains(&n) {
            return refuse("a polygon has 3 to 8 vertices");
        }
        if vertices.iter().flatten().any(|x| !x.is_finite()) {
            return refuse("must be finite");
        }
        // Each edge `a -> b` against every other vertex `v`: strictly left, beyond the
        // rounding of the cross product's terms. (Each turn to the left alone lets a star
        // through: the pentagram turns left at every vertex, twice round.)
        // Two vertices alike are refused below (a zero cross product); others whose lengths'
        // product overflows or vanishes are at the scalar's limits.
        let apart = |x: Vec2<T>| x[0] != T::zero() || x[1] != T::zero();
        for (i, &a) in vertices.iter().enumerate() {
            let b = vertices[(i + 1) % n];
            let e = sub(b, a);
            for v in (2..n).map(|k| vertices[(i + k) % n]) {
                let f = sub(v, a);
                let size = length(e) * length(f);
                if apart(e) && apart(f) && !(size.is_finite() && size > T::zero()) {
                    return refuse("edges too long or too short for the scalar: their products overflow or vanish");
                }
                // (Compared so that a NaN refuses.)
                let threshold = T::from_f64(64.0) * T::EPSILON * size;
                if cross(e, f).partial_cmp(&threshold) != Some(core::cmp::Ordering::Greater) {
                    return refuse("must be convex and wound counter-clockwise, each vertex strictly left of every edge it is not on");
                }
            }
        }
        Ok(Self::from_core(vertices, T::zero()))
    }

    /// The same shape rounded by `radius` more (>= 0, finite): a box with rounded corners.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `radius`.
    pub fn rounded(mut self, radius: T) -> Result<Self, Error> {
        if !(radius.is_finite() && radius >= T::zero()) {
            return Err(Error::InvalidParameter {
                name: "radius",
                reason: "must be finite and not negative",
            });
        }
        self.radius += radius;
        Ok(self)
    }

    /// The shape moved within its body's frame: turned by `angle` (rad, counter-clockwise),
    /// then shifted by `by`. A shape placed away from a body's origin (a hand on a forearm).
    #[must_use]
    pub fn offset(&self, by: Vec2<T>, angle: T) -> Self {
        self.placed(&Pose { origin: by, angle })
    }

    /// The shape in the world, its body's frame at `pose`.
    #[must_use]
    pub fn placed(&self, pose: &Pose<T>) -> Self {
        let turn = pose.angle.sin_cos();
        let mut out = *self;
        for i in 0..self.count {
            out.vertices[i] = add(pose.origin, rotate(self.vertices[i], turn));
            out.normals[i] = rotate(self.normals[i], turn);
        }
        out
    }

    /// The core's vertices: 1 for a circle, 2 for a capsule, 3 or more for a polygon.
    #[must_use]
    pub fn vertices(&self) -> &[Vec2<T>] {
        &self.vertices[..self.count]
    }

    /// The outward unit normals of the core's edges (`i` from vertex `i` to `i + 1`); none
    /// for a circle, the two sides of a capsule.
    #[must_use]
    pub fn normals(&self) -> &[Vec2<T>] {
        if self.count < 2 {
            &[]
        } else {
            &self.normals[..self.count]
        }
    }

    /// The radius the core is rounded by.
    #[must_use]
    pub fn radius(&self) -> T {
        self.radius
    }

    /// The smallest box holding the shape, `(lower, upper)` corners: what a broad phase
    /// sorts.
    #[must_use]
    pub fn bounds(&self) -> (Vec2<T>, Vec2<T>) {
        let mut lo = self.vertices[0];
        let mut hi = lo;
        for v in self.vertices() {
            lo = [lo[0].min(v[0]), lo[1].min(v[1])];
            hi = [hi[0].max(v[0]), hi[1].max(v[1])];
        }
        let r = [self.radius; 2];
        (sub(lo, r), add(hi, r))
    }

    /// The shape of a valid core (checked by the constructors): its normals computed.
    fn from_core(core: &[Vec2<T>], radius: T) -> Self {
        let count = core.len().min(MAX_VERTICES);
        let mut vertices = [[T::zero(); 2]; MAX_VERTICES];
        vertices[..count].copy_from_slice(&core[..count]);
        let mut normals = [[T::zero(); 2]; MAX_VERTICES];
        if count >= 2 {
            for i in 0..count {
                let e = sub(vertices[(i + 1) % count], vertices[i]);
                normals[i] = scale(right(e), T::one() / length(e));
            }
        }
        Self {
            vertices,
            normals,
            count,
            radius,
        }
    }

    /// The vertex of the core furthest along `direction` (the first of equals).
    pub(crate) fn support(&self, direction: Vec2<T>) -> usize {
        let mut best = 0;
        for i in 1..self.count {
            if dot(self.vertices[i], direction) > dot(self.vertices[best], direction) {
                best = i;
            }
        }
        best
    }
}
