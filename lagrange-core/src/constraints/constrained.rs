//! Accelerations with Lagrange multipliers: [`constrained_acceleration`], the [`Constrained`]
//! mechanism wrapper, and [`Stabilization`] (Baumgarte) against drift.

use super::{Constraints, Schur};
use crate::mechanism::{finite, finite_jacobian};
use crate::{
    validate, Error, GeneralizedForce, Jacobian, Lagrangian, Mechanism, NoForce, Real, Scalar,
    State,
};
use nalgebra::{SMatrix, SVector};

/// Drift control folded into the acceleration-level constraint equation.
///
/// Integrating `J q'' + J'q' = 0` keeps `phi'' = 0` only: rounding and truncation errors in
/// `phi` and `phi'` then grow (linearly in `phi'`, quadratically in `phi`). Baumgarte replaces
/// the equation by
///
/// ```text
/// J q'' + J'q' = -2 alpha (J q') - beta^2 phi      i.e.  e'' + 2 alpha e' + beta^2 e = 0
/// ```
///
/// so that a constraint error `e` decays instead of drifting (for a Pfaffian row `phi = 0`
/// and only `-2 alpha (J q')` acts). The residual is then bounded, not zero. It settles where
/// two errors balance: the integrator's own drift, which the feedback suppresses more the
/// larger the rate, and the integrator's error on the stabilising term itself, which grows
/// with `rate dt` (the stages of a step sit off the constraint, where the feedback is large).
/// Measured on the Cartesian pendulum (l = 1 m, 0.5 rad, dt = 1e-3 s, 100 s; largest `|phi|`,
/// m; tests/tests/cartesian_pendulum.rs):
///
/// ```text
/// rate dt              none     0.001    0.003    0.01     0.03     0.1      0.3      1
/// RK4                  7e-9     1.3e-12  5e-13    4e-12    3e-11    3e-10    3e-9     6e-8
/// velocity Verlet      2e-2     4e-6     6e-7     2e-7     6e-8     2e-8     6e-9     4e-9
/// semi-implicit Euler  6e-2     1e-3     5e-4     2e-4     8e-5     2e-5     8e-6     unstable
/// ```
///
/// So, the documented choice of gains against `dt`:
///
/// - first- and second-order methods: drift dominates, take the largest rate that stays
///   stable, `rate dt = 0.3`, critically damped: [`Stabilization::for_step`];
/// - fourth order (RK4): the feedback's own error dominates early; take a rate of the order of
///   the mechanism's own frequency, independent of `dt` (here `sqrt(g/l) ~ 3/s`, best at
///   1-10/s for dt from 1e-2 to 1e-4): [`Stabilization::critical`].
///
/// For residuals at rounding level use projection
/// ([`Projection`](crate::constraints::Projection)) instead.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Stabilization<T> {
    /// No drift control: `J q'' + J'q' = 0` exactly.
    #[default]
    None,
    /// Baumgarte stabilisation with gains `alpha` (1/s, on `phi'`) and `beta` (1/s, on `phi`).
    Baumgarte {
        /// Damping rate on the velocity residual, 1/s.
        alpha: T,
        /// Natural frequency on the position residual, 1/s.
        beta: T,
    },
}

/// `alpha dt` of [`Stabilization::for_step`].
const RATE_TIMES_STEP: f64 = 0.3;

impl<T: Real> Stabilization<T> {
    /// Baumgarte stabilisation with gains `alpha` and `beta` (1/s, each >= 0).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `alpha` or `beta` when negative or not finite, or so large
    /// that the gains the equation uses, `2 alpha` and `beta^2`, overflow.
    pub fn baumgarte(alpha: T, beta: T) -> Result<Self, Error> {
        let alpha = validate::non_negative("alpha", alpha)?;
        let beta = validate::non_negative("beta", beta)?;
        validate::derived(T::TWO * alpha, &[("alpha", alpha, 1)])?;
        validate::derived(beta * beta, &[("beta", beta, 2)])?;
        Ok(Self::Baumgarte { alpha, beta })
    }

    /// Critically damped Baumgarte stabilisation, `alpha = beta = rate` (1/s, > 0): a
    /// constraint error decays like `(1 + rate t) exp(-rate t)`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `rate` when not positive and finite, or so large that
    /// `rate^2` overflows.
    pub fn critical(rate: T) -> Result<Self, Error> {
        let rate = validate::positive("rate", rate)?;
        validate::derived(rate * rate, &[("rate", rate, 2)])?;
        Ok(Self::Baumgarte {
            alpha: rate,
            beta: rate,
        })
    }

    /// Critically damped Baumgarte stabilisation for a first- or second-order integrator at a
    /// fixed step `dt` (s, > 0): `rate = 0.3 / dt`, so a constraint error decays over a few
    /// steps while `rate dt` stays inside the stability limit of semi-implicit Euler (which
    /// fails at `rate dt = 1`). For RK4 prefer [`Stabilization::critical`] at the mechanism's
    /// own frequency (see the table above).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `dt` when not positive and finite, or so small that the
    /// rate (or its square) overflows.
    pub fn for_step(dt: T) -> Result<Self, Error> {
        let dt = validate::positive("dt", dt)?;
        let rate = T::from_f64(RATE_TIMES_STEP) / dt;
        validate::derived(rate * rate, &[("dt", dt, -2)])?;
        Ok(Self::Baumgarte {
            alpha: rate,
            beta: rate,
        })
    }
}

impl<T: Real> Stabilization<T> {
    /// The right-hand side of the acceleration-level constraint equation `J q'' = target`:
    /// `-J'q'` without stabilisation, `-J'q' - 2 alpha (J q') - beta^2 phi` with Baumgarte.
    /// `phi` is called only when `beta` is not zero.
    pub(crate) fn target<const C: usize>(
        &self,
        velocity_product: &SVector<T, C>,
        velocity_residual: &SVector<T, C>,
        phi: impl FnOnce() -> SVector<T, C>,
    ) -> SVector<T, C> {
        let mut target = -velocity_product;
        if let Self::Baumgarte { alpha, beta } = *self {
            target -= velocity_residual * (T::TWO * alpha);
            if beta != T::zero() {
                target -= phi() * (beta * beta);
            }
        }
        target
    }
}

/// The constrained accelerations and the multipliers that produce them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConstrainedAcceleration<T: Real, const N: usize, const C: usize> {
    /// `q''`.
    pub acceleration: SVector<T, N>,
    /// `lambda`: the constraint forces are `J^T lambda` (generalized forces), and each
    /// `lambda_i` is the force along row `i`'s gradient (for a contact row, the normal force;
    /// it pushes when positive). Zero on inactive rows.
    pub multipliers: SVector<T, C>,
}

/// Solves the KKT system of `mechanism` under the `constraints` rows marked `active`:
///
/// ```text
/// [ M  J^T ] [  q''    ]   [ f + Q + extra                 ]
/// [ J   0  ] [ -lambda ] = [ -J'q' - 2 alpha J q' - beta^2 phi ]     (Baumgarte terms when chosen)
/// ```
///
/// by its Schur complement: `a0 = M^-1 (f + Q + extra)` (the mechanism's own law, so a closed
/// form is used where it has one), `S lambda = r - J a0`, `q'' = a0 + M^-1 J^T lambda`. Cost:
/// one law and `C` calls of [`Mechanism::solve_mass`], one Jacobian and one velocity-product
/// evaluation (plus `phi` for Baumgarte), a `C x C` Cholesky.
///
/// `mechanism` must be unconstrained: its law is `M^-1 (f + Q + extra)`. Put every constraint
/// in one set.
///
/// # Errors
/// [`Error::RedundantConstraints`] for dependent or singular active rows;
/// [`Error::NonFiniteState`]; whatever the mechanism's law returns.
pub(crate) fn constrained_acceleration<T, M, K, F, const N: usize, const C: usize>(
    mechanism: &M,
    constraints: &K,
    stabilization: &Stabilization<T>,
    state: &State<T, N>,
    extra: &F,
    active: &[bool; C],
) -> Result<ConstrainedAcceleration<T, N, C>, Error>
where
    T: Real,
    M: Mechanism<T, N>,
    K: Constraints<T, N, C>,
    F: GeneralizedForce<T, N>,
{
    let a0 = mechanism.law(state, extra)?;
    if !active.iter().any(|&on| on) {
        // No row in force (a contact set in free flight): the unconstrained motion.
        return Ok(ConstrainedAcceleration {
            acceleration: a0,
            multipliers: SVector::zeros(),
        });
    }
    let schur = Schur::new(mechanism, constraints, state, active)?;
    let j = schur.jacobian();
    let target = stabilization.target(
        &constraints.velocity_product(&state.q, &state.qd),
        &(j * state.qd),
        || constraints.position_residual(&state.q),
    );
    solve_kkt(&schur, &a0, &target)
}

/// The last stage of every constrained solve: with `S` factored in `schur`, the free
/// acceleration `a0 = M^-1 (f + Q)` and the constraint equation `J q'' = target`,
///
/// ```text
/// lambda = S^-1 (target - J a0),    q'' = a0 + M^-1 J^T lambda
/// ```
///
/// # Errors
/// [`Error::NonFiniteState`] when the result is not finite.
pub(crate) fn solve_kkt<T: Real, const N: usize, const C: usize>(
    schur: &Schur<T, N, C>,
    free_acceleration: &SVector<T, N>,
    target: &SVector<T, C>,
) -> Result<ConstrainedAcceleration<T, N, C>, Error> {
    let multipliers = schur.multipliers(&(target - schur.jacobian() * free_acceleration));
    let acceleration = free_acceleration + schur.response(&multipliers);
    if T::every_lane_finite(acceleration.as_slice()) & T::every_lane_finite(multipliers.as_slice())
    {
        Ok(ConstrainedAcceleration {
            acceleration,
            multipliers,
        })
    } else {
        Err(Error::NonFiniteState)
    }
}

/// A mechanism under `C` constraints, from one value `P` that is both the unconstrained
/// mechanism and its constraint rows (a standard constrained mechanism of `lagrange-systems`,
/// or [`Held`]: any mechanism with rows of your own, made by
/// [`Mechanism::held_by`]). It moves as its KKT system says, so every integrator steps it
/// unchanged:
///
/// ```text
/// [ M  J^T ] [  q''    ]   [ f + Q + extra                     ]
/// [ J   0  ] [ -lambda ] = [ -J'q' - 2 alpha J q' - beta^2 phi ]     (Baumgarte terms when chosen)
/// ```
///
/// solved by its Schur complement: `a0 = M^-1 (f + Q + extra)` (the unconstrained law, a
/// closed form where there is one), `(J M^-1 J^T) lambda = target - J a0`,
/// `q'' = a0 + M^-1 J^T lambda`: one law, `C` mass solves, one Jacobian and one
/// velocity-product evaluation (plus `phi` for Baumgarte) and a `C x C` Cholesky, on the stack.
///
/// Its law ([`Mechanism::law`]) is the constrained one; mass matrix, `f`, `Q`, energies and
/// `solve_mass` are the unconstrained mechanism's. Forces added by
/// [`Mechanism::with_force`], inside or outside this wrapper, act through the constraints.
/// Its Jacobian for implicit methods and the force its law applies (constraint forces
/// included) derive from the constrained law. Drift control: [`Stabilization`] here, or
/// projection after each step (`Projected` in lagrange-integrators), which reads the rows from
/// this mechanism ([`Constraints`]).
///
/// ```
/// use lagrange_core::prelude::*;
/// use lagrange_core::constraints::{Holonomic, HolonomicConstraints};
/// use lagrange_core::nalgebra::Vector1;
///
/// /// A unit point mass in the plane in gravity 9.81 along -y.
/// struct Particle;
/// impl Lagrangian<f64, 2> for Particle {
///     fn kinetic<S: Scalar<Real = f64>>(&self, _t: S, _q: &SVector<S, 2>, v: &SVector<S, 2>) -> S {
///         (v[0] * v[0] + v[1] * v[1]) * 0.5
///     }
///     fn potential<S: Scalar<Real = f64>>(&self, _t: S, q: &SVector<S, 2>) -> S {
///         q[1] * 9.81
///     }
/// }
/// /// On a rod of length 1 from the origin.
/// struct Rod;
/// impl HolonomicConstraints<f64, 2, 1> for Rod {
///     fn phi<S: Scalar<Real = f64> + 'static>(&self, q: &SVector<S, 2>) -> SVector<S, 1> {
///         Vector1::new((q[0] * q[0] + q[1] * q[1] - 1.0) * 0.5)
///     }
/// }
///
/// let pendulum = EulerLagrange::new(Particle).held_by(Holonomic::new(Rod));
/// // Hanging at rest: the rod carries the weight, nothing moves. The force J^T lambda pulls
/// // the bob up, against grad phi = (0, -1): lambda = -m g, the rod's tension with its sign.
/// let hanging = State::new(0.0, [0.0, -1.0], [0.0, 0.0]);
/// let solved = pendulum.solve(&hanging)?;
/// assert!(solved.acceleration.iter().all(|a| a.abs() < 1e-15));
/// assert!((solved.multipliers[0] + 9.81).abs() < 1e-14);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Constrained<T, const C: usize, P> {
    parts: P,
    stabilization: Stabilization<T>,
}

impl<T: Real, const C: usize, P> Constrained<T, C, P> {
    /// The mechanism and rows of `parts` held together, without drift control.
    pub fn new(parts: P) -> Self {
        Self {
            parts,
            stabilization: Stabilization::None,
        }
    }

    /// The same with `stabilization`.
    #[must_use]
    pub fn with_stabilization(self, stabilization: Stabilization<T>) -> Self {
        Self {
            stabilization,
            ..self
        }
    }

    /// The unconstrained mechanism and its rows.
    #[must_use]
    pub fn parts(&self) -> &P {
        &self.parts
    }

    /// The drift control in use.
    #[must_use]
    pub fn stabilization(&self) -> Stabilization<T> {
        self.stabilization
    }

    /// Accelerations and multipliers at `state`.
    ///
    /// # Errors
    /// [`Error::RedundantConstraints`] for dependent or singular rows;
    /// [`Error::NonFiniteState`]; whatever the unconstrained mechanism's law returns.
    pub fn solve<const N: usize>(
        &self,
        state: &State<T, N>,
    ) -> Result<ConstrainedAcceleration<T, N, C>, Error>
    where
        P: Mechanism<T, N> + Constraints<T, N, C>,
    {
        self.solve_with(state, &NoForce)
    }

    /// As [`Constrained::solve`] with an extra generalized force.
    ///
    /// # Errors
    /// [`Error::RedundantConstraints`] for dependent or singular rows;
    /// [`Error::NonFiniteState`]; whatever the unconstrained mechanism's law returns.
    pub fn solve_with<F: GeneralizedForce<T, N>, const N: usize>(
        &self,
        state: &State<T, N>,
        extra: &F,
    ) -> Result<ConstrainedAcceleration<T, N, C>, Error>
    where
        P: Mechanism<T, N> + Constraints<T, N, C>,
    {
        constrained_acceleration(
            &self.parts,
            &self.parts,
            &self.stabilization,
            state,
            extra,
            &[true; C],
        )
    }
}

impl<T, P, const N: usize, const C: usize> Lagrangian<T, N> for Constrained<T, C, P>
where
    T: Real,
    P: Lagrangian<T, N>,
{
    const EXPLICIT_TIME: bool = P::EXPLICIT_TIME;
    const CONSTANT_MASS: bool = P::CONSTANT_MASS;
    const DRIVEN: bool = P::DRIVEN;
    const READS_TIME: bool = P::READS_TIME;
    fn kinetic<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>, qd: &SVector<S, N>) -> S {
        self.parts.kinetic(t, q, qd)
    }
    fn potential<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>) -> S {
        self.parts.potential(t, q)
    }
    fn non_conservative_force(&self, state: &State<T, N>) -> SVector<T, N> {
        self.parts.non_conservative_force(state)
    }
}

impl<T, P, const N: usize, const C: usize> Mechanism<T, N> for Constrained<T, C, P>
where
    T: Real,
    P: Mechanism<T, N> + Constraints<T, N, C>,
{
    fn mass_matrix(&self, state: &State<T, N>) -> SMatrix<T, N, N> {
        self.parts.mass_matrix(state)
    }
    fn rhs(&self, state: &State<T, N>) -> SVector<T, N> {
        self.parts.rhs(state)
    }
    fn solve_mass(&self, state: &State<T, N>, b: &SVector<T, N>) -> Result<SVector<T, N>, Error> {
        finite(self.parts.solve_mass(state, b)?)
    }
    fn law<F: GeneralizedForce<T, N>>(
        &self,
        state: &State<T, N>,
        extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        Ok(self.solve_with(state, extra)?.acceleration)
    }
    /// `Q + extra + J^T lambda`: the free law's force and the constraint forces.
    fn law_force<F: GeneralizedForce<T, N>>(
        &self,
        state: &State<T, N>,
        extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        let lambda = self.solve_with(state, extra)?.multipliers;
        let rows = self.parts.jacobian(&state.q);
        finite(self.parts.law_force(state, extra)? + rows.transpose() * lambda)
    }
    /// The free jump `M^-1 p` less what would break the velocity constraints: with
    /// `S mu = -J M^-1 p`, `dq' = M^-1 (p + J^T mu)`, so that `J dq' = 0` (the rows' reaction
    /// impulses `J^T mu`).
    fn velocity_jump(
        &self,
        state: &State<T, N>,
        impulse: &SVector<T, N>,
    ) -> Result<SVector<T, N>, Error> {
        let free = self.parts.velocity_jump(state, impulse)?;
        let schur = Schur::new(&self.parts, &self.parts, state, &[true; C])?;
        let reaction = schur.multipliers(&-(schur.jacobian() * free));
        finite(free + schur.response(&reaction))
    }
}

/// The rows of a constrained mechanism are its parts' rows: what a projection reads.
impl<T, P, const N: usize, const C: usize> Constraints<T, N, C> for Constrained<T, C, P>
where
    T: Real,
    P: Constraints<T, N, C>,
{
    fn position_residual(&self, q: &SVector<T, N>) -> SVector<T, C> {
        self.parts.position_residual(q)
    }
    fn jacobian(&self, q: &SVector<T, N>) -> SMatrix<T, C, N> {
        self.parts.jacobian(q)
    }
    fn velocity_product(&self, q: &SVector<T, N>, qd: &SVector<T, N>) -> SVector<T, C> {
        self.parts.velocity_product(q, qd)
    }
}

/// An unconstrained mechanism `M` and constraint rows `K` that hold it, as one value: what
/// [`Constrained`] is made of when the rows are your own ([`Mechanism::held_by`]). It moves
/// as `M` alone; the rows act only through [`Constrained`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Held<M, K> {
    mechanism: M,
    rows: K,
}

impl<M, K> Held<M, K> {
    /// `mechanism` with its `rows`.
    pub fn new(mechanism: M, rows: K) -> Self {
        Self { mechanism, rows }
    }
    /// The unconstrained mechanism.
    #[must_use]
    pub fn mechanism(&self) -> &M {
        &self.mechanism
    }
    /// The constraint rows.
    #[must_use]
    pub fn rows(&self) -> &K {
        &self.rows
    }
}

impl<T: Real, const N: usize, M: Lagrangian<T, N>, K> Lagrangian<T, N> for Held<M, K> {
    const EXPLICIT_TIME: bool = M::EXPLICIT_TIME;
    const CONSTANT_MASS: bool = M::CONSTANT_MASS;
    const DRIVEN: bool = M::DRIVEN;
    const READS_TIME: bool = M::READS_TIME;
    fn kinetic<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>, qd: &SVector<S, N>) -> S {
        self.mechanism.kinetic(t, q, qd)
    }
    fn potential<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>) -> S {
        self.mechanism.potential(t, q)
    }
    fn non_conservative_force(&self, state: &State<T, N>) -> SVector<T, N> {
        self.mechanism.non_conservative_force(state)
    }
}

impl<T: Real, const N: usize, M: Mechanism<T, N>, K> Mechanism<T, N> for Held<M, K> {
    fn mass_matrix(&self, state: &State<T, N>) -> SMatrix<T, N, N> {
        self.mechanism.mass_matrix(state)
    }
    fn rhs(&self, state: &State<T, N>) -> SVector<T, N> {
        self.mechanism.rhs(state)
    }
    // Each hook checks what it passes on from the (possibly a user's) mechanism.
    fn solve_mass(&self, state: &State<T, N>, b: &SVector<T, N>) -> Result<SVector<T, N>, Error> {
        finite(self.mechanism.solve_mass(state, b)?)
    }
    fn law<F: GeneralizedForce<T, N>>(
        &self,
        state: &State<T, N>,
        extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        finite(self.mechanism.law(state, extra)?)
    }
    fn law_jacobian<F: GeneralizedForce<T, N>>(
        &self,
        state: &State<T, N>,
        extra: &F,
    ) -> Result<(SVector<T, N>, Jacobian<T, N>), Error> {
        finite_jacobian(self.mechanism.law_jacobian(state, extra)?)
    }
    fn law_force<F: GeneralizedForce<T, N>>(
        &self,
        state: &State<T, N>,
        extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        finite(self.mechanism.law_force(state, extra)?)
    }
    fn velocity_jump(
        &self,
        state: &State<T, N>,
        impulse: &SVector<T, N>,
    ) -> Result<SVector<T, N>, Error> {
        self.mechanism.velocity_jump(state, impulse)
    }
}

impl<T, const N: usize, const C: usize, M, K> Constraints<T, N, C> for Held<M, K>
where
    T: Real,
    K: Constraints<T, N, C>,
{
    fn position_residual(&self, q: &SVector<T, N>) -> SVector<T, C> {
        self.rows.position_residual(q)
    }
    fn jacobian(&self, q: &SVector<T, N>) -> SMatrix<T, C, N> {
        self.rows.jacobian(q)
    }
    fn velocity_product(&self, q: &SVector<T, N>, qd: &SVector<T, N>) -> SVector<T, C> {
        self.rows.velocity_product(q, qd)
    }
}

#[cfg(feature = "defmt")]
impl<T: Real, const N: usize, const C: usize> defmt::Format for ConstrainedAcceleration<T, N, C> {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "ConstrainedAcceleration {{ acceleration: ");
        crate::state::format_vector(f, &self.acceleration);
        defmt::write!(f, ", multipliers: ");
        crate::state::format_vector(f, &self.multipliers);
        defmt::write!(f, " }}");
    }
}
