//! [`Manifold`]: where two shapes touch, or are about to: a normal and up to two points, each
//! with its gap and the features it joins.

use crate::vec2::Vec2;
use lagrange_core::Real;

/// One point of a [`Manifold`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ContactPoint<T> {
    /// Midway between the two surfaces, world coordinates.
    pub point: Vec2<T>,
    /// The distance between the surfaces along the manifold's normal: positive apart,
    /// negative overlapping.
    pub gap: T,
    /// The features that meet here (which edge or vertex of each shape), the same for as long
    /// as they keep meeting: what a solver matches its last impulses by.
    pub id: u32,
}

/// Where two shapes touch or are within a margin of touching: the unit normal from the first
/// to the second, and up to two points (two where a face lies on a face: a box resting on the
/// floor).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Manifold<T> {
    /// Unit normal, from the first shape towards the second.
    pub normal: Vec2<T>,
    points: [ContactPoint<T>; 2],
    count: usize,
}

impl<T: Real> Manifold<T> {
    /// No point, along `normal`.
    pub(crate) fn along(normal: Vec2<T>) -> Self {
        let none = ContactPoint {
            point: [T::zero(); 2],
            gap: T::zero(),
            id: 0,
        };
        Self {
            normal,
            points: [none; 2],
            count: 0,
        }
    }

    /// Adds `p` (a third is dropped: callers give at most two).
    pub(crate) fn push(&mut self, p: ContactPoint<T>) {
        if let Some(slot) = self.points.get_mut(self.count) {
            *slot = p;
            self.count += 1;
        }
    }

    /// The points, none where the shapes are further apart than the margin.
    #[must_use]
    pub fn points(&self) -> &[ContactPoint<T>] {
        &self.points[..self.count]
    }

    /// The smallest gap of its points, if it has any.
    #[must_use]
    pub fn gap(&self) -> Option<T> {
        self.points().iter().map(|p| p.gap).reduce(T::min)
    }
}
