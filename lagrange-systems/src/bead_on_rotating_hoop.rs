//! [`BeadOnRotatingHoop`]: a bead sliding on a vertical hoop driven to spin about the vertical.

use crate::small_solve::finite;
use lagrange_core::nalgebra::{Matrix1, SMatrix, SVector, Vector1};
use lagrange_core::{
    free_law_force, validate, Error, GeneralizedForce, Lagrangian, Mechanism, Real, Scalar, State,
};

/// A bead of mass `m` sliding without friction on a vertical hoop of radius `R` that is driven
/// at constant angular speed `omega` about the vertical axis through its centre.
///
/// ```text
/// q = [th]     angle of the bead from the bottom of the hoop, rad
/// T = m R^2 (th'^2 + omega^2 sin^2 th) / 2
/// V = -m g R cos th
/// m R^2 th'' = m R^2 omega^2 sin th cos th - m g R sin th
/// ```
///
/// The drive does work, so `T + V` is not conserved; the Jacobi integral
/// ([`BeadOnRotatingHoop::jacobi_integral`]) `m R^2 (th'^2 - omega^2 sin^2 th)/2 + V` is. The
/// bottom is stable while `omega^2 < g / R`; above that the bead settles off-axis at
/// `cos th = g / (R omega^2)`. No singular configurations.
///
/// ```
/// use lagrange_core::prelude::*;
/// use lagrange_systems::BeadOnRotatingHoop;
/// let hoop = BeadOnRotatingHoop::new(0.1, 0.5, 10.0, 9.81)?;
/// // At the off-axis equilibrium the bead does not move.
/// let th = (9.81f64 / (0.5 * 100.0)).acos();
/// let a = hoop.acceleration(&State::new(0.0, [th], [0.0]))?;
/// assert!(a[0].abs() < 1e-13);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BeadOnRotatingHoop<T: Real> {
    mass: T,
    radius: T,
    omega: T,
    gravity: T,
}

impl<T: Real> BeadOnRotatingHoop<T> {
    /// A bead of `mass` (kg, > 0) on a hoop of `radius` (m, > 0) spinning at `omega` (rad/s,
    /// any finite sign) in `gravity` (m/s^2, >= 0).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first parameter out of range or not finite, or
    /// the one most responsible when a quantity formed from them leaves the range of `T`
    /// (`m R^2`, which the motion divides by, `m R^2 omega^2`, `m g R`).
    pub fn new(mass: T, radius: T, omega: T, gravity: T) -> Result<Self, Error> {
        let mass = validate::positive("mass", mass)?;
        let radius = validate::positive("radius", radius)?;
        let omega = validate::finite("omega", omega)?;
        let gravity = validate::non_negative("gravity", gravity)?;
        let (m, r2, w2) = (
            ("mass", mass, 1),
            ("radius", radius, 2),
            ("omega", omega, 2),
        );
        let inertia = validate::divisor(mass * radius * radius, &[m, r2])?;
        validate::derived(inertia * (omega * omega), &[m, r2, w2])?;
        validate::derived(
            mass * gravity * radius,
            &[m, ("gravity", gravity, 1), ("radius", radius, 1)],
        )?;
        Ok(Self {
            mass,
            radius,
            omega,
            gravity,
        })
    }
    /// Mass, kg.
    #[must_use]
    pub fn mass(&self) -> T {
        self.mass
    }
    /// Radius, m.
    #[must_use]
    pub fn radius(&self) -> T {
        self.radius
    }
    /// Spin rate, rad/s.
    #[must_use]
    pub fn omega(&self) -> T {
        self.omega
    }
    /// Gravity, m/s^2.
    #[must_use]
    pub fn gravity(&self) -> T {
        self.gravity
    }
    /// The conserved Jacobi integral `m R^2 (th'^2 - omega^2 sin^2 th)/2 - m g R cos th`.
    /// (No error channel: NaN or infinite for a state that is not finite or so extreme that
    /// it overflows.)
    #[must_use]
    pub fn jacobi_integral(&self, s: &State<T, 1>) -> T {
        let sin = s.q[0].sin();
        let w = self.omega;
        T::HALF * self.inertia() * (s.qd[0] * s.qd[0] - w * w * sin * sin)
            + self.potential_energy(s)
    }
    /// `m R^2`.
    fn inertia(&self) -> T {
        self.mass * self.radius * self.radius
    }
}

impl<T: Real> Mechanism<T, 1> for BeadOnRotatingHoop<T> {
    fn mass_matrix(&self, _s: &State<T, 1>) -> SMatrix<T, 1, 1> {
        Matrix1::new(self.inertia())
    }
    fn rhs(&self, s: &State<T, 1>) -> SVector<T, 1> {
        let (sin, cos) = s.q[0].sin_cos();
        let w2 = self.omega * self.omega;
        Vector1::new(self.inertia() * w2 * sin * cos - self.mass * self.gravity * self.radius * sin)
    }
    fn solve_mass(&self, _s: &State<T, 1>, b: &SVector<T, 1>) -> Result<SVector<T, 1>, Error> {
        finite(b / self.inertia(), Error::NonFiniteState)
    }
    fn law_force<F: GeneralizedForce<T, 1>>(
        &self,
        s: &State<T, 1>,
        extra: &F,
    ) -> Result<SVector<T, 1>, Error> {
        free_law_force(self, s, extra)
    }
}

impl<T: Real> Lagrangian<T, 1> for BeadOnRotatingHoop<T> {
    const READS_TIME: bool = false;
    /// The hoop is kept spinning: `T + V` is not conserved (the Jacobi integral is).
    const DRIVEN: bool = true;
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
        let sin = q[0].sin();
        let w = S::from_real(self.omega);
        S::from_real(T::HALF * self.inertia()) * (qd[0] * qd[0] + w * w * sin * sin)
    }
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 1>) -> S {
        -S::from_real(self.mass * self.gravity * self.radius) * q[0].cos()
    }
}
