//! The [`Mechanism`] contract: what an integrator needs to know about a system, with its
//! acceleration law stated once ([`Mechanism::law`]).

use crate::constraints::{Constrained, Constraints, Held};
use crate::forces::{Forced, NoForce};
use crate::{
    central_difference_jacobian, check_finite, solve_spd, Error, GeneralizedForce, Jacobian,
    Lagrangian, Real, State,
};
use nalgebra::{SMatrix, SVector};

/// A mechanical system with `N` generalized coordinates, in the form
///
/// ```text
/// M(t, q, q') q'' = f(t, q, q') + Q(t, q, q') + extra
/// ```
///
/// where `M` is the mass matrix, `f` ([`Mechanism::rhs`]) everything else the Euler-Lagrange
/// equations give (`dL/dq` less the velocity-product terms of `d/dt dL/dq'`), `Q`
/// ([`Lagrangian::non_conservative_force`]) the mechanism's own non-conservative forces, and
/// `extra` any generalized force added from outside ([`GeneralizedForce`]: a drive, an input,
/// a wrapper's force).
///
/// **Physics written once.** A mechanism is a [`Lagrangian`]: its energies are `T` and `V`
/// evaluated at real scalars ([`Lagrangian::energy`]), never written a second time. It adds
/// `M`, `f` and, for speed, a closed-form solve ([`Mechanism::solve_mass`]) or a closed-form
/// law.
///
/// **One law.** How the mechanism moves is stated in one place, [`Mechanism::law`]: `q''` under
/// an extra force. Everything an integrator asks derives from it, so a wrapper cannot be right
/// for explicit methods and wrong for implicit ones:
///
/// - [`Mechanism::acceleration`] and [`Mechanism::acceleration_with`] call it (and refuse a
///   non-finite result);
/// - its Jacobian ([`Mechanism::law_jacobian`], what Newton's method in the implicit
///   integrators needs) is by default central differences of the law itself, correct for any
///   law; a type overrides it only for its own law (exact dual-number Jacobians of
///   [`EulerLagrange`](crate::EulerLagrange));
/// - the force the law applies besides `f` ([`Mechanism::law_force`], what a variational
///   integrator discretises) is by default `M q'' - f`, again correct for any law.
///
/// A wrapper ([`Forced`], [`Constrained`]) passes its own force on to the inner law with the
/// caller's, or states a new law (constraint forces); it never has to keep several hooks in
/// step. Energies are computed only when asked, never inside a step.
pub trait Mechanism<T: Real, const N: usize>: Lagrangian<T, N> {
    /// The mass matrix `M = d2L/dq'2`, symmetric positive definite away from singular
    /// configurations.
    ///
    /// No error channel: for a state that is not finite or so extreme that an entry
    /// overflows, entries are NaN or infinite (never a panic); the solves that use `M` refuse
    /// them ([`Error::NonFiniteState`]).
    fn mass_matrix(&self, state: &State<T, N>) -> SMatrix<T, N, N>;

    /// The right-hand side `f` of `M q'' = f + Q`, without the generalized forces `Q`.
    ///
    /// No error channel: for a state that is not finite or so extreme that a term overflows,
    /// components are NaN or infinite (never a panic); the law refuses them.
    fn rhs(&self, state: &State<T, N>) -> SVector<T, N>;

    /// Solves `M x = b` at `state`: a fixed-size Cholesky solve by default
    /// ([`solve_spd`]); a hand-derived mechanism overrides it with its closed-form inverse.
    ///
    /// # Errors
    /// [`Error::SingularMassMatrix`] where `M` is singular or indefinite, or a system's own
    /// [`Error::Singularity`] at a singular configuration.
    fn solve_mass(&self, state: &State<T, N>, b: &SVector<T, N>) -> Result<SVector<T, N>, Error> {
        solve_spd(&self.mass_matrix(state), b)
    }

    /// **The acceleration law**: `q''` at `state` under the mechanism's own forces and `extra`.
    ///
    /// The default is the unconstrained law `M^-1 (f + Q + extra)` (one [`solve_mass`]); a
    /// hand-derived mechanism overrides it with its closed form, a constrained one adds its
    /// constraint forces. Call it through [`Mechanism::acceleration`] or
    /// [`Mechanism::acceleration_with`], which check the result.
    ///
    /// **Finite or an error.** Like every function of the library that returns a `Result`,
    /// the library's laws (the default, every system's, every wrapper's) return `Ok` only
    /// with finite accelerations, and [`Error::NonFiniteState`] where they would not be. A
    /// law of your own should do the same; if it does not, [`Mechanism::acceleration`] still
    /// refuses its non-finite result.
    ///
    /// [`solve_mass`]: Mechanism::solve_mass
    ///
    /// # Errors
    /// As [`Mechanism::solve_mass`]; a system's own [`Error::Singularity`].
    fn law<F: GeneralizedForce<T, N>>(
        &self,
        state: &State<T, N>,
        extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        let b = self.rhs(state) + self.non_conservative_force(state);
        self.solve_mass(state, &extra.added_to(state, b))
    }

    /// The law's accelerations and their Jacobian `(dq''/dq, dq''/dq')` at `state`, `extra`
    /// included (a force that depends on the state enters through its own Jacobian).
    ///
    /// The default takes central differences of [`Mechanism::law`] itself
    /// ([`central_difference_jacobian`], `4 N` more evaluations, relative accuracy about
    /// `EPSILON^(2/3)`): correct for any law. Override it only with the Jacobian of the law
    /// this type states.
    ///
    /// # Errors
    /// The first error of any evaluation of the law; [`Error::NonFiniteState`] when the
    /// accelerations or the Jacobian are not finite.
    fn law_jacobian<F: GeneralizedForce<T, N>>(
        &self,
        state: &State<T, N>,
        extra: &F,
    ) -> Result<(SVector<T, N>, Jacobian<T, N>), Error> {
        jacobian_by_differences(self, state, extra)
    }

    /// The generalized force the law applies besides `f`: `M q'' - f`, that is `Q + extra`
    /// for an unconstrained law, plus the constraint forces for a constrained one. The
    /// default evaluates exactly that (one law, one mass matrix, one `f`); a type may
    /// override it with the same force in closed form ([`free_law_force`] for a free law).
    ///
    /// [`free_law_force`]: crate::free_law_force
    ///
    /// # Errors
    /// As [`Mechanism::law`]; [`Error::NonFiniteState`] when the force is not finite.
    fn law_force<F: GeneralizedForce<T, N>>(
        &self,
        state: &State<T, N>,
        extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        let qdd = self.law(state, extra)?;
        finite(self.mass_matrix(state) * qdd - self.rhs(state))
    }

    /// Whether the law reads the velocities `q'`: `true` unless the type says otherwise (the
    /// safe answer). A Runge-Kutta-Nyström pair (`lagrange-integrators`'
    /// `DormandPrinceNystrom64`, say) steps only laws `q'' = f(t, q)`, and refuses a mechanism
    /// that answers `true`.
    /// Answer `false` only when [`Mechanism::law`] with no extra force gives the same
    /// accelerations whatever `q'` is (no damping, no Coriolis or centrifugal terms, no
    /// velocity-dependent force).
    ///
    /// ```
    /// use lagrange_core::prelude::*;
    /// # struct Spring;
    /// # impl Lagrangian<f64, 1> for Spring {
    /// #     fn kinetic<S: Scalar<Real = f64>>(&self, _: S, _: &SVector<S, 1>, qd: &SVector<S, 1>) -> S { qd[0] * qd[0] * 0.5 }
    /// #     fn potential<S: Scalar<Real = f64>>(&self, _: S, q: &SVector<S, 1>) -> S { q[0] * q[0] * 0.5 }
    /// # }
    /// // The automatic law cannot know: it says it reads them.
    /// assert!(EulerLagrange::new(Spring).reads_velocities());
    /// ```
    fn reads_velocities(&self) -> bool {
        true
    }

    /// The generalized accelerations `q''` (the law with no extra force).
    ///
    /// # Errors
    /// As [`Mechanism::law`]; [`Error::NonFiniteState`] when they are not finite.
    // Inlined into the integrators' stages: returned through memory, the accelerations of a
    // mechanism stepped in lanes stall every load that reads them back.
    #[inline(always)]
    fn acceleration(&self, state: &State<T, N>) -> Result<SVector<T, N>, Error> {
        self.acceleration_with(state, &NoForce)
    }

    /// The generalized accelerations with the extra generalized force `extra` acting besides
    /// the mechanism's own (an input, a drive, an impulse spread over time).
    ///
    /// ```
    /// use lagrange_core::prelude::*;
    /// use lagrange_core::nalgebra::Vector1;
    /// # struct Spring;
    /// # impl Lagrangian<f64, 1> for Spring {
    /// #     fn kinetic<S: Scalar<Real = f64>>(&self, _: S, _: &SVector<S, 1>, qd: &SVector<S, 1>) -> S { qd[0] * qd[0] * 0.5 }
    /// #     fn potential<S: Scalar<Real = f64>>(&self, _: S, q: &SVector<S, 1>) -> S { q[0] * q[0] * 0.5 }
    /// # }
    /// let spring = EulerLagrange::new(Spring);
    /// let push = |_: &State<f64, 1>| Vector1::new(3.0);
    /// let a = spring.acceleration_with(&State::new(0.0, [1.0], [0.0]), &push)?;
    /// assert!((a[0] - (-1.0 + 3.0)).abs() < 1e-15);
    /// # Ok::<(), lagrange_core::Error>(())
    /// ```
    ///
    /// # Errors
    /// As [`Mechanism::acceleration`].
    #[inline(always)]
    fn acceleration_with<F: GeneralizedForce<T, N>>(
        &self,
        state: &State<T, N>,
        extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        finite(self.law(state, extra)?)
    }

    /// The accelerations `q''` and their Jacobian `(dq''/dq, dq''/dq')`, for Newton's method
    /// in the implicit integrators ([`Mechanism::law_jacobian`] with no extra force).
    ///
    /// # Errors
    /// As [`Mechanism::law_jacobian`]; [`Error::NonFiniteState`] when either is not finite.
    fn acceleration_jacobian(
        &self,
        state: &State<T, N>,
    ) -> Result<(SVector<T, N>, Jacobian<T, N>), Error> {
        finite_jacobian(self.law_jacobian(state, &NoForce)?)
    }

    /// The change of velocities `dq'` that a generalized impulse `p` (a force integrated over
    /// an instant: N s, or N m s on an angle) causes at `state`: `M^-1 p` for a free
    /// mechanism (one [`Mechanism::solve_mass`]). A constrained mechanism keeps its velocity
    /// constraints: `J dq' = 0`, its rows' reaction impulses added ([`Constrained`]).
    ///
    /// ```
    /// use lagrange_core::prelude::*;
    /// # use lagrange_core::nalgebra::Vector1;
    /// # struct Wheel;
    /// # impl Lagrangian<f64, 1> for Wheel {
    /// #     fn kinetic<S: Scalar<Real = f64>>(&self, _: S, _: &SVector<S, 1>, qd: &SVector<S, 1>) -> S { qd[0] * qd[0] * 2.0 }
    /// #     fn potential<S: Scalar<Real = f64>>(&self, _: S, _: &SVector<S, 1>) -> S { S::zero() }
    /// # }
    /// // A wheel of inertia 4 kg m^2 given an angular impulse of 2 N m s spins at 0.5 rad/s.
    /// let wheel = EulerLagrange::new(Wheel);
    /// let dqd = wheel.velocity_jump(&State::at_rest([0.0]), &Vector1::new(2.0))?;
    /// assert!((dqd[0] - 0.5).abs() < 1e-15);
    /// # Ok::<(), lagrange_core::Error>(())
    /// ```
    ///
    /// # Errors
    /// As [`Mechanism::solve_mass`]; [`Error::NonFiniteState`] when the result is not finite.
    fn velocity_jump(
        &self,
        state: &State<T, N>,
        impulse: &SVector<T, N>,
    ) -> Result<SVector<T, N>, Error> {
        finite(self.solve_mass(state, impulse)?)
    }

    /// The velocity changes of `K` generalized impulses at once, in place: each column of
    /// `impulses` that is not zero replaced by its [`Mechanism::velocity_jump`] (a zero
    /// column stays zero), by default one at a time. A mechanism whose mass solve can share
    /// work between right-hand sides (its configuration's trigonometry, a factorisation)
    /// overrides it with the same result, faster: what a contact solver builds its rows'
    /// mobilities `M^-1 J^T` with, in storage it keeps from step to step.
    ///
    /// # Errors
    /// As [`Mechanism::velocity_jump`]; after an error the columns are unspecified.
    fn velocity_jumps<const K: usize>(
        &self,
        state: &State<T, N>,
        impulses: &mut SMatrix<T, N, K>,
    ) -> Result<(), Error> {
        if N == 0 {
            return Ok(());
        }
        // Column by column in storage order (nalgebra's column views walk by stride).
        for column in impulses.as_mut_slice().chunks_exact_mut(N) {
            if column.iter().any(|x| *x != T::zero()) {
                let jump = self.velocity_jump(state, &SVector::from_column_slice(column))?;
                column.copy_from_slice(jump.as_slice());
            }
        }
        Ok(())
    }

    /// This mechanism with `force` added to its generalized forces.
    ///
    /// ```
    /// use lagrange_core::prelude::*;
    /// # struct Spring;
    /// # impl Lagrangian<f64, 1> for Spring {
    /// #     fn kinetic<S: Scalar<Real = f64>>(&self, _: S, _: &SVector<S, 1>, qd: &SVector<S, 1>) -> S { qd[0] * qd[0] * 0.5 }
    /// #     fn potential<S: Scalar<Real = f64>>(&self, _: S, q: &SVector<S, 1>) -> S { q[0] * q[0] * 0.5 }
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

    /// This (unconstrained) mechanism held by the constraint rows `rows`: the generic
    /// constrained mechanism ([`Constrained`]), without drift control.
    fn held_by<K, const C: usize>(self, rows: K) -> Constrained<T, C, Held<Self, K>>
    where
        Self: Sized,
        K: Constraints<T, N, C>,
    {
        Constrained::new(Held::new(self, rows))
    }
}

/// `v` when every component is finite, else [`Error::NonFiniteState`].
///
/// Every component is tested ([`check_finite`]), with one branch for all (the profile of a
/// DOP853 step of a 40-coordinate system showed the test as a scalar loop with a branch per
/// component).
#[inline(always)]
pub(crate) fn finite<T: Real, const N: usize>(v: SVector<T, N>) -> Result<SVector<T, N>, Error> {
    check_finite(v.as_slice(), Error::NonFiniteState).map(|()| v)
}

/// `(qdd, j)` when both are finite, else [`Error::NonFiniteState`]: what a wrapper checks
/// before passing on an inner law's Jacobian.
pub(crate) fn finite_jacobian<T: Real, const N: usize>(
    (qdd, j): (SVector<T, N>, Jacobian<T, N>),
) -> Result<(SVector<T, N>, Jacobian<T, N>), Error> {
    if j.is_finite() {
        Ok((finite(qdd)?, j))
    } else {
        Err(Error::NonFiniteState)
    }
}

/// The law of `mechanism` at `state` with `extra`, and its Jacobian by central differences of
/// the law: the default of [`Mechanism::law_jacobian`].
///
/// # Errors
/// The first error of any evaluation of the law; [`Error::NonFiniteState`] when the
/// accelerations or the Jacobian are not finite.
pub fn jacobian_by_differences<T, const N: usize, M, F>(
    mechanism: &M,
    state: &State<T, N>,
    extra: &F,
) -> Result<(SVector<T, N>, Jacobian<T, N>), Error>
where
    T: Real,
    M: Mechanism<T, N> + ?Sized,
    F: GeneralizedForce<T, N>,
{
    let qdd = finite(mechanism.law(state, extra)?)?;
    let mut failure = None;
    let j = central_difference_jacobian(state, |s| {
        mechanism.law(s, extra).unwrap_or_else(|e| {
            failure = Some(e);
            qdd
        })
    });
    match failure {
        Some(e) => Err(e),
        None if j.is_finite() => Ok((qdd, j)),
        None => Err(Error::NonFiniteState),
    }
}

#[cfg(test)]
mod tests {
    use crate::{EulerLagrange, Lagrangian, Mechanism, Scalar, State};
    use nalgebra::{SMatrix, SVector};

    /// Two coupled coordinates: `M = [[2, 0.5], [0.5, 1]]`, no potential.
    struct Coupled;

    impl Lagrangian<f64, 2> for Coupled {
        fn kinetic<S: Scalar<Real = f64>>(&self, _: S, _: &SVector<S, 2>, qd: &SVector<S, 2>) -> S {
            (qd[0] * qd[0] * S::from_f64(2.0) + qd[0] * qd[1] + qd[1] * qd[1]) * S::from_f64(0.5)
        }
        fn potential<S: Scalar<Real = f64>>(&self, _: S, _: &SVector<S, 2>) -> S {
            S::zero()
        }
    }

    /// The default `velocity_jumps` replaces each column by its `velocity_jump`, bit for bit,
    /// leaves a zero column zero, and refuses a column that is not finite.
    #[test]
    fn jumps_are_each_columns_jump() -> Result<(), crate::Error> {
        let m = EulerLagrange::new(Coupled);
        let s = State::new(0.0, [0.3, -0.2], [1.0, 0.5]);
        let columns = SMatrix::<f64, 2, 3>::from_column_slice(&[1.0, -2.0, 0.0, 0.0, 0.25, 3.0]);
        let mut jumps = columns;
        m.velocity_jumps(&s, &mut jumps)?;
        for k in [0, 2] {
            let one = m.velocity_jump(&s, &columns.column(k).into_owned())?;
            assert_eq!(jumps.column(k), one.column(0), "column {k}");
        }
        assert_eq!(jumps.column(1), SVector::<f64, 2>::zeros().column(0));
        // M times the jump is the column again, to rounding.
        let back = m.mass_matrix(&s) * jumps.column(0);
        assert!((back[0] - 1.0).abs() < 1e-15 && (back[1] + 2.0).abs() < 1e-15);
        let mut bad = columns;
        bad[(1, 2)] = f64::NAN;
        assert!(m.velocity_jumps(&s, &mut bad).is_err());
        Ok(())
    }
}
