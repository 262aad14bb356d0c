//! [`CartesianPendulum`]: the simple pendulum in Cartesian coordinates, held by a constraint.

use lagrange_core::constraints::{Constraints, HolonomicConstraints};
use lagrange_core::nalgebra::{Matrix1x2, Matrix2, SMatrix, SVector, Vector1, Vector2};
use lagrange_core::{check_finite, validate, Error, Lagrangian, Mechanism, Real, Scalar, State};

/// A point mass `m` at `(x, y)` from a fixed pivot, in gravity `g`, held at distance `l` by a
/// massless rod: the same pendulum as [`SimplePendulum`](crate::SimplePendulum), written in two
/// coordinates and one holonomic constraint instead of one angle.
///
/// ```text
/// q      = [x, y]                 the bob relative to the pivot, m; y up
/// L      = m (x'^2 + y'^2) / 2 - m g y            (a free particle)
/// phi    = (x^2 + y^2 - l^2) / (2 l) = 0          ~ r - l near the circle: a length, m
/// J      = [x, y] / l,   J'q' = (x'^2 + y'^2) / l
/// m q''  = [0, -m g] + J^T lambda
/// lambda = m l (g y - |q'|^2) / (x^2 + y^2)       the rod's tension is -lambda (pulls inward)
/// ```
///
/// On the constraint, `x = l sin th`, `y = -l cos th` with `th` the simple pendulum's angle
/// from the downward vertical ([`CartesianPendulum::state_from_angle`],
/// [`CartesianPendulum::angle`]). Singular configuration: the bob at the pivot (`x = y = 0`,
/// where `J = 0`), reported as [`Error::RedundantConstraints`]. Energy `T + V` is conserved
/// by the exact motion.
///
/// This type is the two parts of the pendulum: as a [`Mechanism`] it is the free particle
/// (mass matrix, `f`, closed-form mass solve), and as [`Constraints`] it is the rod. The
/// pendulum itself, whose acceleration includes the rod's force, is
/// [`Constrained::new`](lagrange_core::Constrained::new) of it; drift control and the
/// multiplier come from there.
///
/// ```
/// use lagrange_core::prelude::*;
/// use lagrange_systems::CartesianPendulum;
/// let p = Constrained::new(CartesianPendulum::new(1.0_f64, 1.0, 9.81)?);
/// // Horizontal at rest: the rod carries nothing, the bob falls freely.
/// let a = p.acceleration(&State::new(0.0, [1.0, 0.0], [0.0, 0.0]))?;
/// assert!(a[0].abs() < 1e-15 && (a[1] + 9.81).abs() < 1e-15);
/// // Hanging at rest: the rod's tension, -lambda, carries the weight.
/// let hanging = p.parts().state_from_angle(0.0, 0.0, 0.0);
/// assert!((p.solve(&hanging)?.multipliers[0] + 9.81).abs() < 1e-14);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CartesianPendulum<T: Real> {
    mass: T,
    length: T,
    gravity: T,
}

impl<T: Real> CartesianPendulum<T> {
    /// A bob of `mass` (kg, > 0) on a rod of `length` (m, > 0) in `gravity` (m/s^2, >= 0).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first parameter out of range or not finite, or
    /// the one most responsible when `1 / m`, the weight `m g`, `l^2` or `1 / (2 l)` leaves the
    /// range of `T`.
    pub fn new(mass: T, length: T, gravity: T) -> Result<Self, Error> {
        let mass = validate::positive("mass", mass)?;
        let length = validate::positive("length", length)?;
        let gravity = validate::non_negative("gravity", gravity)?;
        validate::divisor(mass, &[("mass", mass, 1)])?;
        validate::derived(
            mass * gravity,
            &[("mass", mass, 1), ("gravity", gravity, 1)],
        )?;
        // The rows divide by l and 2 l, and phi holds l^2.
        let l = ("length", length, 1);
        validate::divisor(length, &[l])?;
        validate::divisor(T::TWO * length, &[l])?;
        validate::derived(length * length, &[("length", length, 2)])?;
        Ok(Self {
            mass,
            length,
            gravity,
        })
    }

    /// Mass, kg.
    #[must_use]
    pub fn mass(&self) -> T {
        self.mass
    }
    /// Rod length, m.
    #[must_use]
    pub fn length(&self) -> T {
        self.length
    }
    /// Gravity, m/s^2.
    #[must_use]
    pub fn gravity(&self) -> T {
        self.gravity
    }

    /// The consistent state at time `t` of angle `th` from the downward vertical and angular
    /// rate `thd`. (No error channel: not finite where an argument is not, or where `l thd`
    /// overflows; check it with [`State::is_finite`].)
    #[must_use]
    pub fn state_from_angle(&self, t: T, th: T, thd: T) -> State<T, 2> {
        let (s, c) = th.sin_cos();
        let l = self.length;
        State::new(t, [l * s, -l * c], [l * c * thd, l * s * thd])
    }

    /// The angle from the downward vertical and its rate, `(atan2(x, -y), (x y' - y x') / r^2)`.
    /// (No error channel: the rate is NaN at the pivot, `r = 0`, and both are NaN or infinite
    /// for a state that is not finite.)
    #[must_use]
    pub fn angle(&self, state: &State<T, 2>) -> (T, T) {
        let (x, y) = (state.q[0], state.q[1]);
        let r2 = x * x + y * y;
        (x.atan2(-y), (x * state.qd[1] - y * state.qd[0]) / r2)
    }
}

impl<T: Real> Mechanism<T, 2> for CartesianPendulum<T> {
    fn mass_matrix(&self, _s: &State<T, 2>) -> Matrix2<T> {
        Matrix2::identity() * self.mass
    }
    fn rhs(&self, _s: &State<T, 2>) -> Vector2<T> {
        Vector2::new(T::zero(), -self.mass * self.gravity)
    }
    fn solve_mass(&self, _s: &State<T, 2>, b: &Vector2<T>) -> Result<Vector2<T>, Error> {
        let x = b / self.mass;
        check_finite(x.as_slice(), Error::NonFiniteState).map(|()| x)
    }
}

impl<T: Real> Constraints<T, 2, 1> for CartesianPendulum<T> {
    fn position_residual(&self, q: &Vector2<T>) -> Vector1<T> {
        let l = self.length;
        Vector1::new((q[0] * q[0] + q[1] * q[1] - l * l) / (T::TWO * l))
    }
    fn jacobian(&self, q: &Vector2<T>) -> SMatrix<T, 1, 2> {
        Matrix1x2::new(q[0], q[1]) / self.length
    }
    fn velocity_product(&self, _q: &Vector2<T>, qd: &Vector2<T>) -> Vector1<T> {
        Vector1::new((qd[0] * qd[0] + qd[1] * qd[1]) / self.length)
    }
}

impl<T: Real> HolonomicConstraints<T, 2, 1> for CartesianPendulum<T> {
    fn phi<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 2>) -> SVector<S, 1> {
        let l = S::from_real(self.length);
        Vector1::new((q[0] * q[0] + q[1] * q[1] - l * l) / (l + l))
    }
}

/// The free particle, for the automatic Euler-Lagrange check.
impl<T: Real> Lagrangian<T, 2> for CartesianPendulum<T> {
    const READS_TIME: bool = false;
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, _q: &SVector<S, 2>, qd: &SVector<S, 2>) -> S {
        S::from_real(T::HALF * self.mass) * (qd[0] * qd[0] + qd[1] * qd[1])
    }
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 2>) -> S {
        S::from_real(self.mass * self.gravity) * q[1]
    }
}
