//! [`RigidBody`]: a free rigid body in the plane (the crate, the ball and the plank of a game).

use crate::small_solve::finite;
use lagrange_core::links::{LinkPoint, Links, Pose};
use lagrange_core::nalgebra::{SMatrix, SVector, Vector3};
use lagrange_core::{
    free_law_force, validate, Error, Gather, GeneralizedForce, Lagrangian, Lanes, Mechanism, Real,
    Scalar, State,
};

/// A rigid body of mass `m` and moment of inertia `I` about its centre of mass, free in the
/// plane, in uniform gravity `g` along -y.
///
/// ```text
/// q = [x, y, th]     centre of mass, m; angle of the body's frame, rad, counter-clockwise
/// L = m (x'^2 + y'^2) / 2 + I th'^2 / 2 - m g y
/// x'' = 0,  y'' = -g,  th'' = 0
/// ```
///
/// The mass matrix is constant (`diag(m, m, I)`): no singular configurations, and RK4 and
/// velocity Verlet are exact to rounding in free flight. One link ([`Links`]), its frame at
/// the centre of mass turned by `th`: a point `(px, py)` of the body is at
/// `(x + px cos th - py sin th, y + px sin th + py cos th)`.
///
/// ```
/// use lagrange_core::{links::Links, Mechanism, State};
/// use lagrange_systems::RigidBody;
/// // A 2 kg crate, 0.5 m by 0.3 m, turning at 1 rad/s.
/// let crate_ = RigidBody::rectangle(2.0_f64, 0.5, 0.3, 9.81)?;
/// let s = State::new(0.0, [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
/// assert_eq!(crate_.acceleration(&s)?.as_slice(), &[0.0, -9.81, 0.0]);
/// // Its corner (0.25, 0.15) moves at (-0.15, 0.25) m/s.
/// let corner = crate_.point(&s.q, 0, [0.25, 0.15]);
/// let v = corner.jacobian * s.qd;
/// assert!((v[0] + 0.15).abs() < 1e-15 && (v[1] - 0.25).abs() < 1e-15);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RigidBody<T: Real> {
    mass: T,
    inertia: T,
    gravity: T,
}

impl<T: Real> RigidBody<T> {
    /// A body of `mass` (kg, > 0) and moment of `inertia` about its centre of mass (kg m^2,
    /// > 0) in `gravity` (m/s^2, >= 0).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `mass`, `inertia` or `gravity` when out of range or
    /// not finite, or the one most responsible when the weight `m g`, `1 / m` or `1 / I`
    /// overflows.
    pub fn new(mass: T, inertia: T, gravity: T) -> Result<Self, Error> {
        let mass = validate::positive("mass", mass)?;
        let inertia = validate::positive("inertia", inertia)?;
        let gravity = validate::non_negative("gravity", gravity)?;
        validate::divisor(mass, &[("mass", mass, 1)])?;
        validate::divisor(inertia, &[("inertia", inertia, 1)])?;
        validate::derived(
            mass * gravity,
            &[("mass", mass, 1), ("gravity", gravity, 1)],
        )?;
        Ok(Self {
            mass,
            inertia,
            gravity,
        })
    }

    /// A uniform rectangle (a crate, a plank) of `mass`, `width` by `height` (m, > 0):
    /// `I = m (w^2 + h^2) / 12`.
    ///
    /// # Errors
    /// As [`RigidBody::new`], and `width` or `height` when not positive and finite (or the
    /// inertia they give overflows or is zero).
    pub fn rectangle(mass: T, width: T, height: T, gravity: T) -> Result<Self, Error> {
        let mass = validate::positive("mass", mass)?;
        let width = validate::positive("width", width)?;
        let height = validate::positive("height", height)?;
        let inertia = mass * (width * width + height * height) / T::from_f64(12.0);
        let inertia = validate::derived(
            inertia,
            &[
                ("mass", mass, 1),
                ("width", width, 2),
                ("height", height, 2),
            ],
        )?;
        Self::new(mass, inertia, gravity)
            .map_err(|e| blame_inertia(e, if width >= height { "width" } else { "height" }))
    }

    /// A uniform disk (a ball, a wheel) of `mass` and `radius` (m, > 0): `I = m r^2 / 2`.
    ///
    /// # Errors
    /// As [`RigidBody::new`], and `radius` when not positive and finite (or the inertia it
    /// gives overflows or is zero).
    pub fn disk(mass: T, radius: T, gravity: T) -> Result<Self, Error> {
        let mass = validate::positive("mass", mass)?;
        let radius = validate::positive("radius", radius)?;
        let inertia = validate::derived(
            mass * radius * radius * T::HALF,
            &[("mass", mass, 1), ("radius", radius, 2)],
        )?;
        Self::new(mass, inertia, gravity).map_err(|e| blame_inertia(e, "radius"))
    }

    /// Mass, kg.
    #[must_use]
    pub fn mass(&self) -> T {
        self.mass
    }
    /// Moment of inertia about the centre of mass, kg m^2.
    #[must_use]
    pub fn inertia(&self) -> T {
        self.inertia
    }
    /// Gravity, m/s^2.
    #[must_use]
    pub fn gravity(&self) -> T {
        self.gravity
    }
}

/// `e`, with an inertia refused named as the dimension `name` that gave it.
fn blame_inertia(e: Error, name: &'static str) -> Error {
    match e {
        Error::InvalidParameter {
            name: "inertia",
            reason,
        } => Error::InvalidParameter { name, reason },
        e => e,
    }
}

impl<T: Real> Gather<T, 3> for RigidBody<T> {
    type Gathered<const L: usize> = RigidBody<Lanes<T, L>>;
    /// Lane by lane: every parameter gathered.
    fn gather<const L: usize>(instances: [&Self; L]) -> Self::Gathered<L> {
        let lanes = |field: fn(&Self) -> T| Lanes::gather(&instances, field);
        RigidBody {
            mass: lanes(|b| b.mass),
            inertia: lanes(|b| b.inertia),
            gravity: lanes(|b| b.gravity),
        }
    }
    #[inline(always)] // see `Gather::window`
    fn window<const W: usize, const L: usize>(
        wide: &Self::Gathered<W>,
        at: usize,
    ) -> Self::Gathered<L> {
        RigidBody {
            mass: wide.mass.window(at),
            inertia: wide.inertia.window(at),
            gravity: wide.gravity.window(at),
        }
    }
    fn put<const L: usize>(&self, lanes: &mut Self::Gathered<L>, lane: usize) {
        lanes.mass.set(lane, self.mass);
        lanes.inertia.set(lane, self.inertia);
        lanes.gravity.set(lane, self.gravity);
    }
}

impl<T: Real> Mechanism<T, 3> for RigidBody<T> {
    fn mass_matrix(&self, _s: &State<T, 3>) -> SMatrix<T, 3, 3> {
        SMatrix::from_diagonal(&Vector3::new(self.mass, self.mass, self.inertia))
    }
    fn rhs(&self, _s: &State<T, 3>) -> SVector<T, 3> {
        Vector3::new(T::zero(), -self.mass * self.gravity, T::zero())
    }
    fn solve_mass(&self, _s: &State<T, 3>, b: &SVector<T, 3>) -> Result<SVector<T, 3>, Error> {
        let x = Vector3::new(b[0] / self.mass, b[1] / self.mass, b[2] / self.inertia);
        finite(x, Error::NonFiniteState)
    }
    fn law_force<F: GeneralizedForce<T, 3>>(
        &self,
        s: &State<T, 3>,
        extra: &F,
    ) -> Result<SVector<T, 3>, Error> {
        free_law_force(self, s, extra)
    }
    /// Never: the acceleration is `(0, -g, 0)`.
    fn reads_velocities(&self) -> bool {
        false
    }
}

impl<T: Real> Lagrangian<T, 3> for RigidBody<T> {
    const READS_TIME: bool = false;
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, _q: &SVector<S, 3>, qd: &SVector<S, 3>) -> S {
        S::from_real(T::HALF * self.mass) * (qd[0] * qd[0] + qd[1] * qd[1])
            + S::from_real(T::HALF * self.inertia) * qd[2] * qd[2]
    }
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 3>) -> S {
        S::from_real(self.mass * self.gravity) * q[1]
    }
}

impl<T: Real> Links<T, 3> for RigidBody<T> {
    /// The body itself.
    const LINKS: usize = 1;

    /// The body's frame: at the centre of mass `(x, y)`, turned by `th`.
    fn pose<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 3>, _link: usize) -> Pose<S> {
        Pose {
            origin: [q[0], q[1]],
            angle: q[2],
        }
    }

    /// `d/dth` of the point's offset from the centre of mass is that offset turned a
    /// quarter turn: no trigonometry.
    fn jacobian_at(
        &self,
        q: &SVector<T, 3>,
        _link: usize,
        _pose: &Pose<T>,
        at: [T; 2],
    ) -> SMatrix<T, 2, 3> {
        let (dx, dy) = (at[0] - q[0], at[1] - q[1]);
        SMatrix::<T, 2, 3>::new(T::one(), T::zero(), -dy, T::zero(), T::one(), dx)
    }

    /// By hand: `d/dth` of the turned offset is the offset turned a further quarter turn.
    fn point(&self, q: &SVector<T, 3>, _link: usize, local: [T; 2]) -> LinkPoint<T, 3> {
        let (s, c) = q[2].sin_cos();
        let (dx, dy) = (c * local[0] - s * local[1], s * local[0] + c * local[1]);
        LinkPoint {
            position: [q[0] + dx, q[1] + dy],
            jacobian: SMatrix::<T, 2, 3>::new(T::one(), T::zero(), -dy, T::zero(), T::one(), dx),
        }
    }
}
