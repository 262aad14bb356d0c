//! [`ShapePairs`]: contact rows between shapes on two links of one mechanism (two mechanisms
//! made one by [`Pair`](crate::Pair), or a mechanism's own links), from the narrow phase.

use crate::collide::collide;
use crate::shape::Shape;
use crate::vec2::{rotate, sub, Vec2};
use lagrange_core::constraints::contact::Contacts;
use lagrange_core::links::{Links, Pose};
use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{Constraints, Dual, Error, Real};

/// A shape on a link: the link's number and the shape in the link's frame.
pub type OnLink<T> = (usize, Shape<T>);

/// A shape on a link and a shape on another.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct ShapePair<T> {
    a: OnLink<T>,
    b: OnLink<T>,
}

/// A row's contact: the normal from the first shape to the second, and the point midway
/// between the surfaces in each link's frame.
struct Touch<T> {
    normal: Vec2<T>,
    gap: T,
    local: [Vec2<T>; 2],
}

/// Contact rows between pairs of shapes on a mechanism's links, two rows a pair (a
/// [`collide`] manifold's two points, in its order; a manifold of one point leaves its second
/// row far open, its Jacobian zero):
///
/// ```text
/// g = the point's gap (collide, at q)
/// J = n . (dp_b/dq - dp_a/dq)          p_a, p_b the contact point fixed in each link
/// T = t . (dp_b/dq - dp_a/dq)          t = n turned a quarter turn (friction)
/// ```
///
/// An impulse on a row pushes the two links apart along the normal, equal and opposite:
/// linear and angular momentum of the two kept. For [`ImpulseStepper`], which asks the rows
/// at one configuration a step; `J'q'` holds the normal fixed (its turning is neglected).
///
/// [`ImpulseStepper`]: https://docs.rs/lagrange-integrators/latest/lagrange_integrators/struct.ImpulseStepper.html
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapePairs<T, L, const N: usize, const C: usize> {
    links: L,
    /// Row `i`'s pair (rows `2k` and `2k + 1` share one).
    pairs: [ShapePair<T>; C],
}

/// The gap of a row whose manifold has no such point: far open, never in contact.
fn far<T: Real>() -> T {
    T::MAX.sqrt()
}

impl<T: Real, L: Links<T, N>, const N: usize, const C: usize> ShapePairs<T, L, N, C> {
    /// Rows between each pair `((link_a, shape_a), (link_b, shape_b))` of `pairs` (shapes in
    /// their links' frames); `C` must be twice the number of pairs.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `pairs` when a link is not one of `links`' or `C` is not
    /// twice their number.
    pub fn new(links: L, pairs: &[(OnLink<T>, OnLink<T>)]) -> Result<Self, Error> {
        if pairs
            .iter()
            .any(|(a, b)| a.0 >= L::LINKS || b.0 >= L::LINKS)
        {
            return Err(Error::InvalidParameter {
                name: "pairs",
                reason: "a shape's link is not one of the mechanism's",
            });
        }
        if 2 * pairs.len() != C {
            return Err(Error::InvalidParameter {
                name: "pairs",
                reason: "C must be twice the number of pairs",
            });
        }
        let Some(&(a, b)) = pairs.first() else {
            return Err(Error::InvalidParameter {
                name: "pairs",
                reason: "at least one pair",
            });
        };
        let mut rows = [ShapePair { a, b }; C];
        for (k, &(a, b)) in pairs.iter().enumerate() {
            for slot in 0..2 {
                if let Some(row) = rows.get_mut(2 * k + slot) {
                    *row = ShapePair { a, b };
                }
            }
        }
        Ok(Self { links, pairs: rows })
    }

    /// The mechanism's links.
    #[must_use]
    pub fn links(&self) -> &L {
        &self.links
    }

    /// Row `i`'s contact at `q`, if its manifold has that point.
    fn touch(&self, q: &SVector<T, N>, i: usize) -> Option<Touch<T>> {
        let pair = &self.pairs[i];
        let poses: [Pose<T>; 2] = [pair.a.0, pair.b.0].map(|link| self.links.pose(q, link));
        let a = pair.a.1.placed(&poses[0]);
        let b = pair.b.1.placed(&poses[1]);
        let m = collide(&a, &b, far());
        let p = *m.points().get(i % 2)?;
        let local = poses.map(|pose| {
            let (s, c) = pose.angle.sin_cos();
            rotate(sub(p.point, pose.origin), (-s, c))
        });
        Some(Touch {
            normal: m.normal,
            gap: p.gap,
            local,
        })
    }

    /// `d/dq` of the point `local[1]` of link b less the point `local[0]` of link a, along
    /// `direction`.
    fn row(
        &self,
        q: &SVector<T, N>,
        i: usize,
        local: [Vec2<T>; 2],
        direction: Vec2<T>,
    ) -> SMatrix<T, 1, N> {
        let pair = &self.pairs[i];
        let ja = self.links.point(q, pair.a.0, local[0]).jacobian;
        let jb = self.links.point(q, pair.b.0, local[1]).jacobian;
        let d = jb - ja;
        d.row(0) * direction[0] + d.row(1) * direction[1]
    }
}

impl<T: Real, L: Links<T, N>, const N: usize, const C: usize> Constraints<T, N, C>
    for ShapePairs<T, L, N, C>
{
    fn position_residual(&self, q: &SVector<T, N>) -> SVector<T, C> {
        SVector::from_fn(|i, _| self.touch(q, i).map_or_else(far, |t| t.gap))
    }

    fn jacobian(&self, q: &SVector<T, N>) -> SMatrix<T, C, N> {
        let mut j = SMatrix::<T, C, N>::zeros();
        for i in 0..C {
            if let Some(t) = self.touch(q, i) {
                j.set_row(i, &self.row(q, i, t.local, t.normal));
            }
        }
        j
    }

    fn velocity_product(&self, q: &SVector<T, N>, qd: &SVector<T, N>) -> SVector<T, C> {
        // Each contact point's acceleration at q' with q'' = 0 (d2/ds2 of the point at
        // q + s q'), the normal held.
        let line = SVector::<Dual<Dual<T, 1>, 1>, N>::from_fn(|k, _| {
            Dual::new(Dual::new(q[k], [qd[k]]), [Dual::constant(qd[k])])
        });
        SVector::from_fn(|i, _| {
            let Some(t) = self.touch(q, i) else {
                return T::zero();
            };
            let pair = &self.pairs[i];
            let accel = |link: usize, local: Vec2<T>| {
                self.links
                    .pose(&line, link)
                    .point(local)
                    .map(|x| x.eps[0].eps[0])
            };
            let (a, b) = (accel(pair.a.0, t.local[0]), accel(pair.b.0, t.local[1]));
            (b[0] - a[0]) * t.normal[0] + (b[1] - a[1]) * t.normal[1]
        })
    }
}

impl<T: Real, L: Links<T, N>, const N: usize, const C: usize> Contacts<T, N, C>
    for ShapePairs<T, L, N, C>
{
    fn tangent_jacobian(&self, q: &SVector<T, N>) -> Option<SMatrix<T, C, N>> {
        let mut j = SMatrix::<T, C, N>::zeros();
        for i in 0..C {
            if let Some(t) = self.touch(q, i) {
                let tangent = [-t.normal[1], t.normal[0]];
                j.set_row(i, &self.row(q, i, t.local, tangent));
            }
        }
        Some(j)
    }
}
