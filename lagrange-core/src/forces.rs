//! Composable generalized forces: damping, inputs and user forces added by wrapping a
//! mechanism, never by editing it.

use crate::constraints::Constraints;
use crate::mechanism::{finite, finite_jacobian};
use crate::{
    central_difference_jacobian, validate, Error, Jacobian, Lagrangian, Mechanism, Real, Scalar,
    State,
};
use nalgebra::{SMatrix, SVector};

/// A generalized force `Q(t, q, q')` that can be added to any mechanism with
/// [`Mechanism::with_force`], or passed as the extra force of
/// [`Mechanism::acceleration_with`].
///
/// Closures `Fn(&State<T, N>) -> SVector<T, N>` are generalized forces, and so is a pair of
/// them, `(a, b)`, acting together.
pub trait GeneralizedForce<T: Real, const N: usize> {
    /// True for a force that is zero everywhere ([`NoForce`]): a law may skip adding it, so
    /// that a mechanism stepped without extra forces pays nothing for them.
    const IS_ZERO: bool = false;

    /// The force at `state`. No error channel: a force of the library is NaN or infinite
    /// only for a state that is or for one so extreme that it overflows; the laws refuse a
    /// non-finite force, yours included ([`Error::NonFiniteState`]).
    fn force(&self, state: &State<T, N>) -> SVector<T, N>;

    /// `(dQ/dq, dQ/dq')` at `state`, for the Newton matrices of implicit integrators. The
    /// default takes central differences ([`central_difference_jacobian`], `4 N` evaluations
    /// of [`GeneralizedForce::force`]); [`ViscousDamping`] and [`Input`] give theirs exactly.
    fn jacobian(&self, state: &State<T, N>) -> Jacobian<T, N> {
        central_difference_jacobian(state, |s| self.force(s))
    }

    /// `b` plus this force at `state`; `b` itself, at no cost, for a zero force.
    #[inline]
    fn added_to(&self, state: &State<T, N>, b: SVector<T, N>) -> SVector<T, N> {
        if Self::IS_ZERO {
            b
        } else {
            b + self.force(state)
        }
    }
}

impl<T: Real, const N: usize, F: Fn(&State<T, N>) -> SVector<T, N>> GeneralizedForce<T, N> for F {
    fn force(&self, state: &State<T, N>) -> SVector<T, N> {
        self(state)
    }
}

/// No force: the extra force of [`Mechanism::acceleration`]. Adding it costs nothing.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct NoForce;

impl<T: Real, const N: usize> GeneralizedForce<T, N> for NoForce {
    const IS_ZERO: bool = true;
    fn force(&self, _state: &State<T, N>) -> SVector<T, N> {
        SVector::zeros()
    }
    fn jacobian(&self, _state: &State<T, N>) -> Jacobian<T, N> {
        Jacobian::zeros()
    }
}

/// Two forces acting together (their sum); a zero one costs nothing.
impl<T, const N: usize, A, B> GeneralizedForce<T, N> for (A, B)
where
    T: Real,
    A: GeneralizedForce<T, N>,
    B: GeneralizedForce<T, N>,
{
    const IS_ZERO: bool = A::IS_ZERO && B::IS_ZERO;
    fn force(&self, state: &State<T, N>) -> SVector<T, N> {
        match (A::IS_ZERO, B::IS_ZERO) {
            (true, _) => self.1.force(state),
            (_, true) => self.0.force(state),
            _ => self.0.force(state) + self.1.force(state),
        }
    }
    fn jacobian(&self, state: &State<T, N>) -> Jacobian<T, N> {
        match (A::IS_ZERO, B::IS_ZERO) {
            (true, _) => self.1.jacobian(state),
            (_, true) => self.0.jacobian(state),
            _ => self.0.jacobian(state) + self.1.jacobian(state),
        }
    }
}

/// A force borrowed: how a wrapper passes its own force on with the caller's.
#[derive(Debug, Clone, Copy)]
pub struct Borrowed<'a, F>(pub &'a F);

impl<T: Real, const N: usize, F: GeneralizedForce<T, N>> GeneralizedForce<T, N>
    for Borrowed<'_, F>
{
    const IS_ZERO: bool = F::IS_ZERO;
    fn force(&self, state: &State<T, N>) -> SVector<T, N> {
        self.0.force(state)
    }
    fn jacobian(&self, state: &State<T, N>) -> Jacobian<T, N> {
        self.0.jacobian(state)
    }
}

/// Linear viscous damping `Q_i = -c_i q'_i`. It never adds energy.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViscousDamping<T: Real, const N: usize> {
    coefficients: SVector<T, N>,
}

impl<T: Real, const N: usize> ViscousDamping<T, N> {
    /// Damping with one coefficient per coordinate (units: force per unit generalized velocity).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first entry (`coefficients[i]`) that is negative
    /// or not finite.
    pub fn new(coefficients: [T; N]) -> Result<Self, Error> {
        const NAMES: [&str; 32] = crate::entry_names!("coefficients");
        for (i, c) in coefficients.into_iter().enumerate() {
            validate::non_negative(validate::entry(&NAMES, i, "coefficients"), c)?;
        }
        Ok(Self {
            coefficients: SVector::from(coefficients),
        })
    }

    /// The same coefficient on every coordinate.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `coefficient` when negative or not finite.
    pub fn uniform(coefficient: T) -> Result<Self, Error> {
        let c = validate::non_negative("coefficient", coefficient)?;
        Ok(Self {
            coefficients: SVector::repeat(c),
        })
    }

    /// The coefficients.
    #[must_use]
    pub fn coefficients(&self) -> &SVector<T, N> {
        &self.coefficients
    }
}

impl<T: Real, const N: usize> GeneralizedForce<T, N> for ViscousDamping<T, N> {
    fn force(&self, state: &State<T, N>) -> SVector<T, N> {
        -self.coefficients.component_mul(&state.qd)
    }
    fn jacobian(&self, _state: &State<T, N>) -> Jacobian<T, N> {
        Jacobian {
            wrt_q: SMatrix::zeros(),
            wrt_qd: SMatrix::from_diagonal(&-self.coefficients),
        }
    }
}

/// A drive or control input: a generalized force held constant over a step, which the caller
/// sets between steps (a motor torque, a cart force).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Input<T: Real, const N: usize> {
    /// The force on each coordinate.
    pub value: SVector<T, N>,
}

impl<T: Real, const N: usize> Input<T, N> {
    /// An input initially equal to `value`.
    #[must_use]
    pub fn new(value: [T; N]) -> Self {
        Self {
            value: SVector::from(value),
        }
    }
}

impl<T: Real, const N: usize> GeneralizedForce<T, N> for Input<T, N> {
    fn force(&self, _state: &State<T, N>) -> SVector<T, N> {
        self.value
    }
    fn jacobian(&self, _state: &State<T, N>) -> Jacobian<T, N> {
        Jacobian::zeros()
    }
}

/// A mechanism with an extra generalized force: `M q'' = f + Q + force`.
///
/// Made by [`Mechanism::with_force`]; wrap again to add more forces. Its acceleration law is
/// the inner mechanism's with the force added ([`Mechanism::law`] with the force beside the
/// caller's), so a closed-form law, a constrained one and their Jacobians all keep working.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Forced<M, F> {
    mechanism: M,
    force: F,
}

impl<M, F> Forced<M, F> {
    /// `mechanism` with `force` added.
    pub fn new(mechanism: M, force: F) -> Self {
        Self { mechanism, force }
    }
    /// The wrapped mechanism.
    #[must_use]
    pub fn mechanism(&self) -> &M {
        &self.mechanism
    }
    /// The added force.
    #[must_use]
    pub fn force(&self) -> &F {
        &self.force
    }
    /// The added force, to change between steps (e.g. an [`Input`]'s value).
    pub fn force_mut(&mut self) -> &mut F {
        &mut self.force
    }
}

impl<T, const N: usize, M, F> Lagrangian<T, N> for Forced<M, F>
where
    T: Real,
    M: Lagrangian<T, N>,
    F: GeneralizedForce<T, N>,
{
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
        self.mechanism.non_conservative_force(state) + self.force.force(state)
    }
}

impl<T, const N: usize, M, F> Mechanism<T, N> for Forced<M, F>
where
    T: Real,
    M: Mechanism<T, N>,
    F: GeneralizedForce<T, N>,
{
    fn mass_matrix(&self, state: &State<T, N>) -> SMatrix<T, N, N> {
        self.mechanism.mass_matrix(state)
    }
    fn rhs(&self, state: &State<T, N>) -> SVector<T, N> {
        self.mechanism.rhs(state)
    }
    // Each hook checks what it passes on: the inner mechanism may be a user's whose results
    // are not checked (the library's never return a non-finite `Ok`).
    fn solve_mass(&self, state: &State<T, N>, b: &SVector<T, N>) -> Result<SVector<T, N>, Error> {
        finite(self.mechanism.solve_mass(state, b)?)
    }
    fn law<G: GeneralizedForce<T, N>>(
        &self,
        state: &State<T, N>,
        extra: &G,
    ) -> Result<SVector<T, N>, Error> {
        finite(
            self.mechanism
                .law(state, &(Borrowed(&self.force), Borrowed(extra)))?,
        )
    }
    fn law_jacobian<G: GeneralizedForce<T, N>>(
        &self,
        state: &State<T, N>,
        extra: &G,
    ) -> Result<(SVector<T, N>, Jacobian<T, N>), Error> {
        finite_jacobian(
            self.mechanism
                .law_jacobian(state, &(Borrowed(&self.force), Borrowed(extra)))?,
        )
    }
    fn law_force<G: GeneralizedForce<T, N>>(
        &self,
        state: &State<T, N>,
        extra: &G,
    ) -> Result<SVector<T, N>, Error> {
        finite(
            self.mechanism
                .law_force(state, &(Borrowed(&self.force), Borrowed(extra)))?,
        )
    }
    fn velocity_jump(
        &self,
        state: &State<T, N>,
        impulse: &SVector<T, N>,
    ) -> Result<SVector<T, N>, Error> {
        self.mechanism.velocity_jump(state, impulse)
    }
    fn velocity_jumps<const K: usize>(
        &self,
        state: &State<T, N>,
        impulses: &mut SMatrix<T, N, K>,
    ) -> Result<(), Error> {
        self.mechanism.velocity_jumps(state, impulses)
    }
}

/// A forced constrained mechanism keeps its rows: what a projection reads.
impl<T, const N: usize, const C: usize, M, F> Constraints<T, N, C> for Forced<M, F>
where
    T: Real,
    M: Constraints<T, N, C>,
{
    fn position_residual(&self, q: &SVector<T, N>) -> SVector<T, C> {
        self.mechanism.position_residual(q)
    }
    fn jacobian(&self, q: &SVector<T, N>) -> SMatrix<T, C, N> {
        self.mechanism.jacobian(q)
    }
    fn velocity_product(&self, q: &SVector<T, N>, qd: &SVector<T, N>) -> SVector<T, C> {
        self.mechanism.velocity_product(q, qd)
    }
}

#[cfg(feature = "defmt")]
impl<T: Real, const N: usize> defmt::Format for ViscousDamping<T, N> {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "ViscousDamping ");
        crate::state::format_vector(f, &self.coefficients);
    }
}

#[cfg(feature = "defmt")]
impl<T: Real, const N: usize> defmt::Format for Input<T, N> {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "Input ");
        crate::state::format_vector(f, &self.value);
    }
}
