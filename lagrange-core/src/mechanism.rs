//! The [`Mechanism`] contract: what an integrator needs to know about a system.

use crate::forces::Forced;
use crate::{central_difference_jacobian, solve_spd, Error, Jacobian, Real, State};
use nalgebra::{SMatrix, SVector};

/// A mechanical system with `N` generalized coordinates, in the form
///
/// ```text
/// M(t, q, q') q'' = f(t, q, q') + Q(t, q, q')
/// ```
///
/// where `M` is the mass matrix, `f` ([`Mechanism::rhs`]) everything else the Euler-Lagrange
/// equations give (`dL/dq` less the velocity-product terms of `d/dt dL/dq'`) and `Q`
/// ([`Mechanism::generalized_force`]) the non-conservative generalized forces.
///
/// Implementors give `M`, `f` and the energies; [`Mechanism::acceleration`] solves for `q''`
/// through [`Mechanism::solve_mass`], whose default is a fixed-size Cholesky solve. A
/// hand-derived system overrides `solve_mass` with its closed-form inverse; wrappers such as
/// [`Forced`] add to `Q` and keep that fast path.
///
/// Energies are computed only when asked, never inside a step.
pub trait Mechanism<T: Real, const N: usize> {
    /// The mass matrix `M = d2L/dq'2`, symmetric positive definite away from singular
    /// configurations.
    fn mass_matrix(&self, state: &State<T, N>) -> SMatrix<T, N, N>;

    /// The right-hand side `f` of `M q'' = f + Q`, without the generalized forces `Q`.
    fn rhs(&self, state: &State<T, N>) -> SVector<T, N>;

    /// The non-conservative generalized forces `Q` (damping, drives, inputs); zero by default.
    fn generalized_force(&self, state: &State<T, N>) -> SVector<T, N> {
        let _ = state;
        SVector::zeros()
    }

    /// Kinetic energy `T`.
    fn kinetic_energy(&self, state: &State<T, N>) -> T;

    /// Potential energy `V`.
    fn potential_energy(&self, state: &State<T, N>) -> T;

    /// Total energy `T + V`.
    fn energy(&self, state: &State<T, N>) -> T {
        self.kinetic_energy(state) + self.potential_energy(state)
    }

    /// Solves `M x = b` at `state`.
    ///
    /// # Errors
    /// [`Error::SingularMassMatrix`] where `M` is singular or indefinite, or a system's own
    /// [`Error::Singularity`] at a singular configuration.
    fn solve_mass(&self, state: &State<T, N>, b: &SVector<T, N>) -> Result<SVector<T, N>, Error> {
        solve_spd(&self.mass_matrix(state), b)
    }

    /// The generalized accelerations `q''`.
    ///
    /// # Errors
    /// As [`Mechanism::solve_mass`].
    fn acceleration(&self, state: &State<T, N>) -> Result<SVector<T, N>, Error> {
        self.solve_mass(state, &(self.rhs(state) + self.generalized_force(state)))
    }

    /// The generalized accelerations with the extra generalized force `extra` acting besides
    /// `Q`: `M^-1 (f + Q + extra)` by default.
    ///
    /// [`Forced`] calls this, so that a mechanism whose acceleration law is more than
    /// `M^-1 (f + Q)` keeps that law when a force is added by wrapping: a constrained mechanism
    /// (see [`constraints`](crate::constraints)) overrides both this method and
    /// [`Mechanism::acceleration`] to add its constraint forces.
    ///
    /// # Errors
    /// As [`Mechanism::solve_mass`].
    fn acceleration_with(
        &self,
        state: &State<T, N>,
        extra: &SVector<T, N>,
    ) -> Result<SVector<T, N>, Error> {
        self.solve_mass(
            state,
            &(self.rhs(state) + self.generalized_force(state) + extra),
        )
    }

    /// The Jacobian of the equations of motion written as a residual,
    ///
    /// ```text
    /// r(t, q, q') = M(t, q, q') a - f(t, q, q') - Q(t, q, q')
    /// ```
    ///
    /// with the acceleration `a` held fixed: `(dr/dq, dr/dq')`. It composes: a wrapper that
    /// adds a force subtracts that force's Jacobian. At `a = q''` it gives the Jacobian of the
    /// acceleration ([`Mechanism::acceleration_jacobian`]), which Newton's method in the
    /// implicit integrators needs.
    ///
    /// The default takes central differences of `r` ([`central_difference_jacobian`]):
    /// `4 N` evaluations of `M`, `f` and `Q`, relative accuracy about `EPSILON^(2/3)`.
    /// [`EulerLagrange`](crate::EulerLagrange) overrides it with exact derivatives from dual
    /// numbers; a hand-derived system may override it with its own.
    fn equation_jacobian(&self, state: &State<T, N>, qdd: &SVector<T, N>) -> Jacobian<T, N> {
        central_difference_jacobian(state, |s| {
            self.mass_matrix(s) * qdd - self.rhs(s) - self.generalized_force(s)
        })
    }

    /// The accelerations `q''` and their Jacobian `(dq''/dq, dq''/dq')`.
    ///
    /// Differentiating `M q'' = f + Q` gives `M dq''/dx = -dr/dx` with `r` from
    /// [`Mechanism::equation_jacobian`] at `a = q''`: one acceleration, one equation Jacobian
    /// and `2 N` solves with `M` ([`Mechanism::solve_mass`], so a closed-form inverse is used
    /// where a system has one). Exact where `equation_jacobian` is.
    ///
    /// # Errors
    /// As [`Mechanism::acceleration`]; [`Error::NonFiniteState`] when the Jacobian is not
    /// finite.
    fn acceleration_jacobian(
        &self,
        state: &State<T, N>,
    ) -> Result<(SVector<T, N>, Jacobian<T, N>), Error> {
        let qdd = self.acceleration(state)?;
        let r = self.equation_jacobian(state, &qdd);
        let mut j = Jacobian::<T, N>::zeros();
        for k in 0..N {
            let dq = self.solve_mass(state, &-r.wrt_q.column(k).into_owned())?;
            let dqd = self.solve_mass(state, &-r.wrt_qd.column(k).into_owned())?;
            j.wrt_q.set_column(k, &dq);
            j.wrt_qd.set_column(k, &dqd);
        }
        if j.is_finite() {
            Ok((qdd, j))
        } else {
            Err(Error::NonFiniteState)
        }
    }

    /// This mechanism with `force` added to its generalized forces.
    ///
    /// ```
    /// use lagrange_core::{Mechanism, ViscousDamping};
    /// # use lagrange_core::{EulerLagrange, Lagrangian, Scalar, State};
    /// # use nalgebra::SVector;
    /// # struct Spring;
    /// # impl Lagrangian<f64, 1> for Spring {
    /// #     fn kinetic<S: Scalar<Real = f64>>(&self, _: S, _: &SVector<S, 1>, qd: &SVector<S, 1>) -> S { qd[0] * qd[0] * S::from_f64(0.5) }
    /// #     fn potential<S: Scalar<Real = f64>>(&self, _: S, q: &SVector<S, 1>) -> S { q[0] * q[0] * S::from_f64(0.5) }
    /// # }
    /// let damped = EulerLagrange::new(Spring).with_force(ViscousDamping::uniform(0.5)?);
    /// let a = damped.acceleration(&State::new(0.0, [1.0], [2.0]))?;
    /// assert!((a[0] - (-1.0 - 0.5 * 2.0)).abs() < 1e-15);
    /// # Ok::<(), lagrange_core::Error>(())
    /// ```
    fn with_force<F>(self, force: F) -> Forced<Self, F>
    where
        Self: Sized,
    {
        Forced::new(self, force)
    }
}
