//! [`PlaneContacts`]: the contact rows of a mechanism's shapes against static half-planes (a
//! floor, walls), for the contact steppers: a crate on the floor, a wheel rolling down a slope,
//! a pendulum's bob against a wall, from a mechanism's [`Links`] and shapes alone.

use crate::collide::HalfPlane;
use crate::shape::Shape;
use crate::vec2::{rotate, scale, Vec2};
use lagrange_core::constraints::contact::Contacts;
use lagrange_core::links::Links;
use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{Constraints, Dual, Error, Real, Scalar};

/// One row: a vertex of a shape's core on a link, against a half-plane.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct PlaneRow<T> {
    link: usize,
    /// The vertex, in the link's frame.
    local: Vec2<T>,
    radius: T,
    plane: HalfPlane<T>,
}

/// The contacts of shapes on a mechanism's links with static half-planes: a row for every
/// vertex of every shape's core against every plane (`C` of them: a box's four corners on a
/// floor are four rows, a circle's centre one), its gap the distance of the rounded shape's
/// surface at that vertex from the plane:
///
/// ```text
/// g = n . v(q) - offset - radius          v the vertex in the world, (n, offset) the plane
/// J = n . dv/dq                            (Links::point)
/// T = t . dp/dq                            p the material point touching: v - radius n,
///                                          t = n turned a quarter turn (friction; a ball
///                                          that rolls turns as it slides)
/// ```
///
/// A row is a [`Contacts`] row for [`ImpulseStepper`] and [`ContactStepper`] alike; its rows
/// keep their order from step to step, so that impulses warm-start by row. `J'q'` comes from
/// the pose in nested dual numbers.
///
/// [`ImpulseStepper`]: https://docs.rs/lagrange-integrators/latest/lagrange_integrators/struct.ImpulseStepper.html
/// [`ContactStepper`]: https://docs.rs/lagrange-integrators/latest/lagrange_integrators/struct.ContactStepper.html
///
/// ```
/// use lagrange_core::{Constraints, nalgebra::SVector};
/// use lagrange_systems::RigidBody;
/// use lagrange_world::{HalfPlane, PlaneContacts, Shape};
///
/// let body = RigidBody::rectangle(2.0_f64, 0.5, 0.3, 9.81)?;
/// let floor = HalfPlane::new([0.0, 1.0], 0.0)?;
/// let rows = PlaneContacts::<_, _, 3, 4>::new(body, &[(0, Shape::rectangle(0.5, 0.3)?)], &[floor])?;
/// // Level, its centre 0.2 m up: its lower corners 0.05 m above the floor, its upper 0.35.
/// let gaps = rows.position_residual(&SVector::from([0.0_f64, 0.2, 0.0]));
/// let near = |g: f64, h: f64| (g - h).abs() < 1e-15;
/// assert!(near(gaps[0], 0.05) && near(gaps[1], 0.05) && near(gaps[2], 0.35) && near(gaps[3], 0.35));
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneContacts<T, L, const N: usize, const C: usize> {
    links: L,
    rows: [PlaneRow<T>; C],
}

impl<T: Real, L: Links<T, N>, const N: usize, const C: usize> PlaneContacts<T, L, N, C> {
    /// The rows of `shapes` (each on a link of `links`, in the link's frame) against
    /// `planes`: `C` must be the number of their core vertices times the number of planes.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `shapes` when a link is not one of `links`' or `C` is not
    /// that count.
    pub fn new(
        links: L,
        shapes: &[(usize, Shape<T>)],
        planes: &[HalfPlane<T>],
    ) -> Result<Self, Error> {
        if shapes.iter().any(|&(link, _)| link >= L::LINKS) {
            return Err(Error::InvalidParameter {
                name: "shapes",
                reason: "a shape's link is not one of the mechanism's",
            });
        }
        let vertices: usize = shapes.iter().map(|(_, s)| s.vertices().len()).sum();
        if vertices * planes.len() != C {
            return Err(Error::InvalidParameter {
                name: "shapes",
                reason: "C must be the shapes' core vertices times the planes",
            });
        }
        let floor = planes.first().copied().unwrap_or_else(HalfPlane::floor);
        let mut rows = [PlaneRow {
            link: 0,
            local: [T::zero(); 2],
            radius: T::zero(),
            plane: floor,
        }; C];
        let mut k = 0;
        for (link, shape) in shapes {
            for &local in shape.vertices() {
                for (p, &plane) in planes.iter().enumerate() {
                    if let Some(row) = rows.get_mut(p * vertices + k) {
                        *row = PlaneRow {
                            link: *link,
                            local,
                            radius: shape.radius(),
                            plane,
                        };
                    }
                }
                k += 1;
            }
        }
        Ok(Self { links, rows })
    }

    /// The mechanism's links.
    #[must_use]
    pub fn links(&self) -> &L {
        &self.links
    }

    /// Row `i`'s gap at coordinates `q` of any scalar.
    fn gap<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, N>, i: usize) -> S {
        let row = &self.rows[i];
        let v = self.links.pose(q, row.link).point(row.local);
        let n = row.plane.normal();
        v[0] * S::from_real(n[0]) + v[1] * S::from_real(n[1])
            - S::from_real(row.plane.offset() + row.radius)
    }
}

impl<T: Real, L: Links<T, N>, const N: usize, const C: usize> Constraints<T, N, C>
    for PlaneContacts<T, L, N, C>
{
    fn position_residual(&self, q: &SVector<T, N>) -> SVector<T, C> {
        SVector::from_fn(|i, _| self.gap(q, i))
    }

    fn jacobian(&self, q: &SVector<T, N>) -> SMatrix<T, C, N> {
        let mut j = SMatrix::<T, C, N>::zeros();
        for (i, row) in self.rows.iter().enumerate() {
            let point = self.links.point(q, row.link, row.local).jacobian;
            let n = row.plane.normal();
            j.set_row(i, &(point.row(0) * n[0] + point.row(1) * n[1]));
        }
        j
    }

    fn velocity_product(&self, q: &SVector<T, N>, qd: &SVector<T, N>) -> SVector<T, C> {
        // q + s q' seeded in the outer and the inner direction: d2/ds2 of the gap.
        let line = SVector::<Dual<Dual<T, 1>, 1>, N>::from_fn(|k, _| {
            Dual::new(Dual::new(q[k], [qd[k]]), [Dual::constant(qd[k])])
        });
        SVector::from_fn(|i, _| self.gap(&line, i).eps[0].eps[0])
    }
}

impl<T: Real, L: Links<T, N>, const N: usize, const C: usize> Contacts<T, N, C>
    for PlaneContacts<T, L, N, C>
{
    fn tangent_jacobian(&self, q: &SVector<T, N>) -> Option<SMatrix<T, C, N>> {
        let mut j = SMatrix::<T, C, N>::zeros();
        for (i, row) in self.rows.iter().enumerate() {
            let n = row.plane.normal();
            // The material point touching, `v - radius n`, in the link's frame.
            let angle = self.links.pose(q, row.link).angle;
            let (s, c) = angle.sin_cos();
            let back = rotate(scale(n, -row.radius), (-s, c));
            let local = [row.local[0] + back[0], row.local[1] + back[1]];
            let point = self.links.point(q, row.link, local).jacobian;
            let t = [-n[1], n[0]];
            j.set_row(i, &(point.row(0) * t[0] + point.row(1) * t[1]));
        }
        Some(j)
    }
}
