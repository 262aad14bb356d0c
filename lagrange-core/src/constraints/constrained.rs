//! Accelerations with Lagrange multipliers: [`constrained_acceleration`], the [`Constrained`]
//! mechanism wrapper, and [`Stabilization`] (Baumgarte) against drift.

use super::{Constraints, Schur};
use crate::{
    acceleration_jacobian_by_differences, validate, Error, Jacobian, Mechanism, Real, State,
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
    /// [`Error::InvalidParameter`] `alpha` or `beta` when negative or not finite.
    pub fn baumgarte(alpha: T, beta: T) -> Result<Self, Error> {
        Ok(Self::Baumgarte {
            alpha: validate::non_negative("alpha", alpha)?,
            beta: validate::non_negative("beta", beta)?,
        })
    }

    /// Critically damped Baumgarte stabilisation, `alpha = beta = rate` (1/s, > 0): a
    /// constraint error decays like `(1 + rate t) exp(-rate t)`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `rate` when not positive and finite.
    pub fn critical(rate: T) -> Result<Self, Error> {
        let rate = validate::positive("rate", rate)?;
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
    /// [`Error::InvalidParameter`] `dt` when not positive and finite.
    pub fn for_step(dt: T) -> Result<Self, Error> {
        let dt = validate::positive("dt", dt)?;
        Self::critical(T::from_f64(RATE_TIMES_STEP) / dt)
    }
}

impl<T: Real> Stabilization<T> {
    /// The right-hand side of the acceleration-level constraint equation `J q'' = target`:
    /// `-J'q'` without stabilisation, `-J'q' - 2 alpha (J q') - beta^2 phi` with Baumgarte.
    /// `phi` is called only when `beta` is not zero.
    pub fn target<const C: usize>(
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
/// by its Schur complement: `a0 = M^-1 (f + Q + extra)`, `S lambda = r - J a0`,
/// `q'' = a0 + M^-1 J^T lambda`. Cost: `C + 1` calls of [`Mechanism::solve_mass`], one
/// Jacobian and one velocity-product evaluation (plus `phi` for Baumgarte), a `C x C` Cholesky.
///
/// `mechanism` supplies `M` (through `solve_mass`), `f` and `Q`; its own
/// [`Mechanism::acceleration`] is never called, so a constrained mechanism may pass itself.
/// It must not hold constraints of its own: put every constraint in one set.
///
/// # Errors
/// [`Error::RedundantConstraints`] for dependent or singular active rows;
/// [`Error::NonFiniteState`]; whatever [`Mechanism::solve_mass`] returns.
pub fn constrained_acceleration<T, M, K, const N: usize, const C: usize>(
    mechanism: &M,
    constraints: &K,
    stabilization: &Stabilization<T>,
    state: &State<T, N>,
    extra: &SVector<T, N>,
    active: &[bool; C],
) -> Result<ConstrainedAcceleration<T, N, C>, Error>
where
    T: Real,
    M: Mechanism<T, N>,
    K: Constraints<T, N, C>,
{
    let force = mechanism.rhs(state) + mechanism.generalized_force(state) + extra;
    let a0 = mechanism.solve_mass(state, &force)?;
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
pub fn solve_kkt<T: Real, const N: usize, const C: usize>(
    schur: &Schur<T, N, C>,
    free_acceleration: &SVector<T, N>,
    target: &SVector<T, C>,
) -> Result<ConstrainedAcceleration<T, N, C>, Error> {
    let multipliers = schur.multipliers(&(target - schur.jacobian() * free_acceleration));
    let acceleration = free_acceleration + schur.response(&multipliers);
    if acceleration
        .iter()
        .chain(multipliers.iter())
        .all(|x| x.is_finite())
    {
        Ok(ConstrainedAcceleration {
            acceleration,
            multipliers,
        })
    } else {
        Err(Error::NonFiniteState)
    }
}

/// A mechanism under `C` constraints: it moves as the KKT system of
/// [`constrained_acceleration`] says, so every integrator steps it unchanged.
///
/// `mechanism` must be unconstrained (its acceleration `M^-1 (f + Q)`); mass matrix, `f`, `Q`,
/// energies and `solve_mass` are its own, and [`Mechanism::acceleration`] adds the constraint
/// forces. Forces added by [`Mechanism::with_force`], inside or outside this wrapper, act
/// through the constraints. Drift control: [`Stabilization`] here, or projection after each
/// step (`Projected` in lagrange-integrators).
///
/// ```
/// use lagrange_core::constraints::{Constrained, Holonomic, HolonomicConstraints};
/// use lagrange_core::{EulerLagrange, Lagrangian, Mechanism, Scalar, State};
/// use nalgebra::{SVector, Vector1};
///
/// /// A unit point mass in the plane in gravity 9.81 along -y.
/// struct Particle;
/// impl Lagrangian<f64, 2> for Particle {
///     fn kinetic<S: Scalar<Real = f64>>(&self, _t: S, _q: &SVector<S, 2>, v: &SVector<S, 2>) -> S {
///         (v[0] * v[0] + v[1] * v[1]) * S::from_f64(0.5)
///     }
///     fn potential<S: Scalar<Real = f64>>(&self, _t: S, q: &SVector<S, 2>) -> S {
///         q[1] * S::from_f64(9.81)
///     }
/// }
/// /// On a rod of length 1 from the origin.
/// struct Rod;
/// impl HolonomicConstraints<f64, 2, 1> for Rod {
///     fn phi<S: Scalar<Real = f64>>(&self, q: &SVector<S, 2>) -> SVector<S, 1> {
///         Vector1::new((q[0] * q[0] + q[1] * q[1] - S::one()) * S::from_f64(0.5))
///     }
/// }
///
/// let pendulum = Constrained::new(EulerLagrange::new(Particle), Holonomic::new(Rod));
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
pub struct Constrained<M, K, T, const C: usize> {
    mechanism: M,
    constraints: K,
    stabilization: Stabilization<T>,
}

impl<M, K, T: Real, const C: usize> Constrained<M, K, T, C> {
    /// `mechanism` held by `constraints`, without drift control.
    pub fn new(mechanism: M, constraints: K) -> Self {
        Self {
            mechanism,
            constraints,
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

    /// The unconstrained mechanism.
    #[must_use]
    pub fn mechanism(&self) -> &M {
        &self.mechanism
    }

    /// The constraints.
    #[must_use]
    pub fn constraints(&self) -> &K {
        &self.constraints
    }

    /// The drift control in use.
    #[must_use]
    pub fn stabilization(&self) -> Stabilization<T> {
        self.stabilization
    }

    /// Accelerations and multipliers at `state`.
    ///
    /// # Errors
    /// As [`constrained_acceleration`].
    pub fn solve<const N: usize>(
        &self,
        state: &State<T, N>,
    ) -> Result<ConstrainedAcceleration<T, N, C>, Error>
    where
        M: Mechanism<T, N>,
        K: Constraints<T, N, C>,
    {
        self.solve_with(state, &SVector::zeros())
    }

    /// As [`Constrained::solve`] with an extra generalized force.
    fn solve_with<const N: usize>(
        &self,
        state: &State<T, N>,
        extra: &SVector<T, N>,
    ) -> Result<ConstrainedAcceleration<T, N, C>, Error>
    where
        M: Mechanism<T, N>,
        K: Constraints<T, N, C>,
    {
        constrained_acceleration(
            &self.mechanism,
            &self.constraints,
            &self.stabilization,
            state,
            extra,
            &[true; C],
        )
    }
}

impl<T, M, K, const N: usize, const C: usize> Mechanism<T, N> for Constrained<M, K, T, C>
where
    T: Real,
    M: Mechanism<T, N>,
    K: Constraints<T, N, C>,
{
    fn mass_matrix(&self, state: &State<T, N>) -> SMatrix<T, N, N> {
        self.mechanism.mass_matrix(state)
    }
    fn rhs(&self, state: &State<T, N>) -> SVector<T, N> {
        self.mechanism.rhs(state)
    }
    fn generalized_force(&self, state: &State<T, N>) -> SVector<T, N> {
        self.mechanism.generalized_force(state)
    }
    fn kinetic_energy(&self, state: &State<T, N>) -> T {
        self.mechanism.kinetic_energy(state)
    }
    fn potential_energy(&self, state: &State<T, N>) -> T {
        self.mechanism.potential_energy(state)
    }
    fn solve_mass(&self, state: &State<T, N>, b: &SVector<T, N>) -> Result<SVector<T, N>, Error> {
        self.mechanism.solve_mass(state, b)
    }
    fn acceleration(&self, state: &State<T, N>) -> Result<SVector<T, N>, Error> {
        Ok(self.solve(state)?.acceleration)
    }
    fn acceleration_with(
        &self,
        state: &State<T, N>,
        extra: &SVector<T, N>,
    ) -> Result<SVector<T, N>, Error> {
        Ok(self.solve_with(state, extra)?.acceleration)
    }
    fn acceleration_jacobian(
        &self,
        state: &State<T, N>,
    ) -> Result<(SVector<T, N>, Jacobian<T, N>), Error> {
        acceleration_jacobian_by_differences(self, state)
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
