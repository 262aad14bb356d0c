//! Composable generalized forces: damping, inputs and user forces added by wrapping a
//! mechanism, never by editing it.

use crate::{central_difference_jacobian, validate, Error, Jacobian, Mechanism, Real, State};
use nalgebra::{SMatrix, SVector};

/// A generalized force `Q(t, q, q')` that can be added to any mechanism with
/// [`Mechanism::with_force`].
///
/// Closures `Fn(&State<T, N>) -> SVector<T, N>` are generalized forces.
pub trait GeneralizedForce<T: Real, const N: usize> {
    /// The force at `state`.
    fn force(&self, state: &State<T, N>) -> SVector<T, N>;

    /// `(dQ/dq, dQ/dq')` at `state`, for the Newton matrices of implicit integrators. The
    /// default takes central differences ([`central_difference_jacobian`], `4 N` evaluations
    /// of [`GeneralizedForce::force`]); [`ViscousDamping`] and [`Input`] give theirs exactly.
    fn jacobian(&self, state: &State<T, N>) -> Jacobian<T, N> {
        central_difference_jacobian(state, |s| self.force(s))
    }
}

impl<T: Real, const N: usize, F: Fn(&State<T, N>) -> SVector<T, N>> GeneralizedForce<T, N> for F {
    fn force(&self, state: &State<T, N>) -> SVector<T, N> {
        self(state)
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
    /// [`Error::InvalidParameter`] `coefficients` when any is negative or not finite.
    pub fn new(coefficients: [T; N]) -> Result<Self, Error> {
        for c in coefficients {
            validate::non_negative("coefficients", c)?;
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
/// Made by [`Mechanism::with_force`]; wrap again to add more forces. The inner mechanism's
/// closed-form mass solve is kept.
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
    fn generalized_force(&self, state: &State<T, N>) -> SVector<T, N> {
        self.mechanism.generalized_force(state) + self.force.force(state)
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
    /// The inner mechanism's acceleration law with this force added, so that a constrained
    /// mechanism keeps its constraint forces when wrapped.
    fn acceleration(&self, state: &State<T, N>) -> Result<SVector<T, N>, Error> {
        self.mechanism
            .acceleration_with(state, &self.force.force(state))
    }
    fn acceleration_with(
        &self,
        state: &State<T, N>,
        extra: &SVector<T, N>,
    ) -> Result<SVector<T, N>, Error> {
        self.mechanism
            .acceleration_with(state, &(self.force.force(state) + extra))
    }
    fn equation_jacobian(&self, state: &State<T, N>, qdd: &SVector<T, N>) -> Jacobian<T, N> {
        self.mechanism.equation_jacobian(state, qdd) - self.force.jacobian(state)
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
