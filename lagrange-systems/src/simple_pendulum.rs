//! [`SimplePendulum`]: a point mass on a massless rod, with optional viscous damping.

use crate::small_solve::finite;
use lagrange_core::nalgebra::{Matrix1, SMatrix, SVector, Vector1};
use lagrange_core::{
    free_law_force, validate, Error, Gather, GeneralizedForce, Lagrangian, Lanes, Mechanism, Real,
    Scalar, State,
};

/// A point mass `m` on a massless rod of length `l` about a fixed pivot, in gravity `g`, with
/// viscous damping `b` at the pivot.
///
/// ```text
/// q = [th]     angle from the downward vertical, rad; the bob is at (l sin th, -l cos th)
/// L = m l^2 th'^2 / 2 + m g l cos th
/// Q = -b th'
/// m l^2 th'' = -m g l sin th - b th'
/// ```
///
/// No singular configurations. Energy `T + V` is conserved when `b = 0` and never increases
/// otherwise.
///
/// ```
/// use lagrange_core::{Mechanism, State};
/// use lagrange_systems::SimplePendulum;
/// let p = SimplePendulum::new(1.0, 1.0, 9.81, 0.0)?;
/// let a = p.acceleration(&State::new(0.0, [0.1], [0.0]))?;
/// assert!((a[0] + 9.81 * 0.1f64.sin()).abs() < 1e-15);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SimplePendulum<T: Real> {
    mass: T,
    length: T,
    gravity: T,
    damping: T,
    /// `g / l`, `b / (m l^2)` and `1 / (m l^2)`, formed once: `th'' = -w2 sin th - rate th'`
    /// costs one sine and no division.
    w2: T,
    rate: T,
    inv_inertia: T,
}

impl<T: Real> SimplePendulum<T> {
    /// A pendulum of `mass` (kg, > 0), `length` (m, > 0), `gravity` (m/s^2, >= 0) and
    /// `damping` (N m s/rad, >= 0).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first parameter out of range or not finite, or
    /// the one most responsible when a quantity formed from them leaves the range of `T`
    /// (`m l^2` and its inverse, `m g l`, `g / l`, `b / (m l^2)`).
    pub fn new(mass: T, length: T, gravity: T, damping: T) -> Result<Self, Error> {
        let mass = validate::positive("mass", mass)?;
        let length = validate::positive("length", length)?;
        let gravity = validate::non_negative("gravity", gravity)?;
        let damping = validate::non_negative("damping", damping)?;
        let (m, l, g, b) = (
            ("mass", mass, 1),
            ("length", length, 2),
            ("gravity", gravity, 1),
            ("damping", damping, 1),
        );
        let inertia = validate::divisor(mass * length * length, &[m, l])?;
        let inv_inertia = T::one() / inertia;
        validate::derived(mass * gravity * length, &[m, g, ("length", length, 1)])?;
        let w2 = validate::derived(gravity / length, &[g, ("length", length, -1)])?;
        let rate = validate::derived(
            damping * inv_inertia,
            &[b, ("mass", mass, -1), ("length", length, -2)],
        )?;
        Ok(Self {
            mass,
            length,
            gravity,
            damping,
            w2,
            rate,
            inv_inertia,
        })
    }
    /// Mass, kg.
    #[must_use]
    pub fn mass(&self) -> T {
        self.mass
    }
    /// Length, m.
    #[must_use]
    pub fn length(&self) -> T {
        self.length
    }
    /// Gravity, m/s^2.
    #[must_use]
    pub fn gravity(&self) -> T {
        self.gravity
    }
    /// Damping, N m s/rad.
    #[must_use]
    pub fn damping(&self) -> T {
        self.damping
    }
    /// Moment of inertia about the pivot, `m l^2`.
    fn inertia(&self) -> T {
        self.mass * self.length * self.length
    }
}

impl<T: Real> Gather<T, 1> for SimplePendulum<T> {
    type Gathered<const L: usize> = SimplePendulum<Lanes<T, L>>;
    /// Lane by lane: every parameter gathered.
    fn gather<const L: usize>(instances: [&Self; L]) -> Self::Gathered<L> {
        let lanes = |field: fn(&Self) -> T| Lanes::gather(&instances, field);
        SimplePendulum {
            mass: lanes(|m| m.mass),
            length: lanes(|m| m.length),
            gravity: lanes(|m| m.gravity),
            damping: lanes(|m| m.damping),
            w2: lanes(|m| m.w2),
            rate: lanes(|m| m.rate),
            inv_inertia: lanes(|m| m.inv_inertia),
        }
    }
    #[inline(always)] // see `Gather::window`
    fn window<const W: usize, const L: usize>(
        wide: &Self::Gathered<W>,
        at: usize,
    ) -> Self::Gathered<L> {
        SimplePendulum {
            mass: wide.mass.window(at),
            length: wide.length.window(at),
            gravity: wide.gravity.window(at),
            damping: wide.damping.window(at),
            w2: wide.w2.window(at),
            rate: wide.rate.window(at),
            inv_inertia: wide.inv_inertia.window(at),
        }
    }
    fn put<const L: usize>(&self, lanes: &mut Self::Gathered<L>, lane: usize) {
        lanes.mass.set(lane, self.mass);
        lanes.length.set(lane, self.length);
        lanes.gravity.set(lane, self.gravity);
        lanes.damping.set(lane, self.damping);
        lanes.w2.set(lane, self.w2);
        lanes.rate.set(lane, self.rate);
        lanes.inv_inertia.set(lane, self.inv_inertia);
    }
}

impl<T: Real> Mechanism<T, 1> for SimplePendulum<T> {
    fn mass_matrix(&self, _s: &State<T, 1>) -> SMatrix<T, 1, 1> {
        Matrix1::new(self.inertia())
    }
    fn rhs(&self, s: &State<T, 1>) -> SVector<T, 1> {
        Vector1::new(-self.mass * self.gravity * self.length * s.q[0].sin())
    }
    fn solve_mass(&self, _s: &State<T, 1>, b: &SVector<T, 1>) -> Result<SVector<T, 1>, Error> {
        finite(b * self.inv_inertia, Error::NonFiniteState)
    }
    /// The closed form.
    // Inlined into the integrators' stages: returned through memory, the accelerations of
    // pendulums stepped in lanes stall the loads that read them back.
    #[inline(always)]
    fn law<F: GeneralizedForce<T, 1>>(
        &self,
        s: &State<T, 1>,
        extra: &F,
    ) -> Result<SVector<T, 1>, Error> {
        let free = Vector1::new(-self.w2 * s.q[0].sin() - self.rate * s.qd[0]);
        let qdd = if F::IS_ZERO {
            free
        } else {
            free + extra.force(s) * self.inv_inertia
        };
        finite(qdd, Error::NonFiniteState)
    }
    fn law_force<F: GeneralizedForce<T, 1>>(
        &self,
        s: &State<T, 1>,
        extra: &F,
    ) -> Result<SVector<T, 1>, Error> {
        free_law_force(self, s, extra)
    }
    /// Only through the damping: an undamped pendulum's law is `q'' = -(g/L) sin q`.
    fn reads_velocities(&self) -> bool {
        self.damping != T::zero()
    }
}

impl<T: Real> Lagrangian<T, 1> for SimplePendulum<T> {
    const READS_TIME: bool = false;
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, _q: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
        S::from_real(T::HALF * self.inertia()) * qd[0] * qd[0]
    }
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 1>) -> S {
        -S::from_real(self.mass * self.gravity * self.length) * q[0].cos()
    }
    fn non_conservative_force(&self, s: &State<T, 1>) -> SVector<T, 1> {
        Vector1::new(-self.damping * s.qd[0])
    }
}
