//! [`RollingDisk`]: a vertical disk rolling without slipping on a plane, two nonholonomic
//! constraints.

use lagrange_core::constraints::{Constraints, PfaffianConstraints};
use lagrange_core::nalgebra::{Matrix2x4, SMatrix, SVector, Vector2, Vector4};
use lagrange_core::{all_finite, validate, Error, Lagrangian, Mechanism, Real, Scalar, State};

/// A uniform thin disk of mass `m` and radius `R` held upright (no tilt) and rolling without
/// slipping on a horizontal plane: free to turn about the vertical and to roll, but its
/// contact point may move only along its heading. The textbook nonholonomic system: the two
/// rolling constraints restrict velocities, not positions, so no choice of coordinates
/// absorbs them and every position stays reachable.
///
/// ```text
/// q   = [x, y, psi, phi]   x, y: the contact point in the plane, m (horizontal coordinates:
///                          here y is not height); psi: heading, the rolling direction
///                          (cos psi, sin psi), rad; phi: rolling angle about the axle, rad
/// T   = m (x'^2 + y'^2) / 2 + I_t psi'^2 / 2 + I_s phi'^2 / 2,   I_t = m R^2/4, I_s = m R^2/2
/// V   = 0                  the centre stays at height R
/// A q' = [ x' - R cos psi phi',
///          y' - R sin psi phi' ] = 0                           (Pfaffian, nonholonomic)
/// J'q' = [ R sin psi psi' phi', -R cos psi psi' phi' ]
/// M q'' = J^T lambda,      lambda = the horizontal contact force (N)
/// ```
///
/// The exact motion: `psi'` and `phi'` constant, the contact point on a circle of radius
/// `R phi' / psi'` (a straight line when `psi' = 0`), energy constant. No singular
/// configurations (`A` always has rank 2).
///
/// This type is the two parts of the disk: as a [`Mechanism`] the free disk, as
/// [`Constraints`] the rolling rows. The rolling disk, whose acceleration includes the contact
/// force, is [`Constrained::new`](lagrange_core::Constrained::new) of it. Add a drive or
/// steering torque with [`Mechanism::with_force`]: it acts through the constraints.
///
/// ```
/// use lagrange_core::prelude::*;
/// use lagrange_systems::RollingDisk;
/// let disk = Constrained::new(RollingDisk::new(1.0_f64, 0.5)?);
/// let s = disk.parts().rolling(0.0, [0.0, 0.0, 0.3, 0.0], 1.0, 4.0)?;
/// assert!(disk.residual(&s).velocity < 1e-15);
/// // Turning at a steady rate: the contact force is centripetal, the rates do not change.
/// let a = disk.acceleration(&s)?;
/// assert!(a[2].abs() < 1e-15 && a[3].abs() < 1e-14);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RollingDisk<T: Real> {
    mass: T,
    radius: T,
}

impl<T: Real> RollingDisk<T> {
    /// A disk of `mass` (kg, > 0) and `radius` (m, > 0).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first parameter out of range or not finite, or
    /// the one most responsible when an inertia the motion divides by (`m`, `m r^2 / 4`,
    /// `m r^2 / 2`) leaves the range of `T`.
    pub fn new(mass: T, radius: T) -> Result<Self, Error> {
        let mass = validate::positive("mass", mass)?;
        let radius = validate::positive("radius", radius)?;
        let disk = Self { mass, radius };
        // The motion divides by every inertia; the smallest is m r^2 / 4.
        let (m, r2) = (("mass", mass, 1), ("radius", radius, 2));
        validate::divisor(mass, &[m])?;
        validate::divisor(disk.inertias()[2], &[m, r2])?;
        validate::divisor(disk.inertias()[3], &[m, r2])?;
        Ok(disk)
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

    /// The consistent state at time `t` at `q = [x, y, psi, phi]`, turning at `turn_rate`
    /// (`psi'`, rad/s) and rolling at `roll_rate` (`phi'`, rad/s): `x' = R cos psi phi'`,
    /// `y' = R sin psi phi'`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `t`, an entry `q[i]`, `turn_rate` or `roll_rate` when
    /// not finite, or `roll_rate` when the rolling speed `R roll_rate` overflows.
    pub fn rolling(
        &self,
        t: T,
        q: [T; 4],
        turn_rate: T,
        roll_rate: T,
    ) -> Result<State<T, 4>, Error> {
        const Q: [&str; 32] = lagrange_core::entry_names!("q");
        validate::finite("t", t)?;
        for (i, x) in q.into_iter().enumerate() {
            validate::finite(validate::entry(&Q, i, "q"), x)?;
        }
        let turn_rate = validate::finite("turn_rate", turn_rate)?;
        let roll_rate = validate::finite("roll_rate", roll_rate)?;
        let (s, c) = q[2].sin_cos();
        let v = validate::derived(self.radius * roll_rate, &[("roll_rate", roll_rate, 1)])?;
        Ok(State::new(t, q, [v * c, v * s, turn_rate, roll_rate]))
    }

    /// The diagonal of the mass matrix, `[m, m, m R^2/4, m R^2/2]`.
    fn inertias(&self) -> Vector4<T> {
        let mr2 = self.mass * self.radius * self.radius;
        Vector4::new(self.mass, self.mass, T::HALF * T::HALF * mr2, T::HALF * mr2)
    }
}

impl<T: Real> Mechanism<T, 4> for RollingDisk<T> {
    fn mass_matrix(&self, _s: &State<T, 4>) -> SMatrix<T, 4, 4> {
        SMatrix::from_diagonal(&self.inertias())
    }
    fn rhs(&self, _s: &State<T, 4>) -> Vector4<T> {
        Vector4::zeros()
    }
    fn solve_mass(&self, _s: &State<T, 4>, b: &Vector4<T>) -> Result<Vector4<T>, Error> {
        let x = b.component_div(&self.inertias());
        if all_finite(x.as_slice()) {
            Ok(x)
        } else {
            Err(Error::NonFiniteState)
        }
    }
}

impl<T: Real> Constraints<T, 4, 2> for RollingDisk<T> {
    fn jacobian(&self, q: &Vector4<T>) -> Matrix2x4<T> {
        self.matrix(q)
    }
    fn velocity_product(&self, q: &Vector4<T>, qd: &Vector4<T>) -> Vector2<T> {
        let (s, c) = q[2].sin_cos();
        let r = self.radius * qd[2] * qd[3];
        Vector2::new(r * s, -r * c)
    }
}

impl<T: Real> PfaffianConstraints<T, 4, 2> for RollingDisk<T> {
    fn matrix<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 4>) -> SMatrix<S, 2, 4> {
        let (s, c) = q[2].sin_cos();
        let r = S::from_real(self.radius);
        let (zero, one) = (S::zero(), S::one());
        SMatrix::<S, 2, 4>::from_row_slice(&[one, zero, zero, -r * c, zero, one, zero, -r * s])
    }
}

/// The free disk, for the automatic Euler-Lagrange check.
impl<T: Real> Lagrangian<T, 4> for RollingDisk<T> {
    const READS_TIME: bool = false;
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, _q: &SVector<S, 4>, qd: &SVector<S, 4>) -> S {
        let i = self.inertias();
        let mut t = S::zero();
        for k in 0..4 {
            t += S::from_real(T::HALF * i[k]) * qd[k] * qd[k];
        }
        t
    }
    fn potential<S: Scalar<Real = T>>(&self, _t: S, _q: &SVector<S, 4>) -> S {
        S::zero()
    }
}
