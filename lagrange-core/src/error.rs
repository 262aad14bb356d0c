//! The error type shared by every lagrange crate.

use core::fmt;

/// Everything that can go wrong in building or stepping a mechanism.
///
/// Small and `Copy`, so that it costs nothing to return from a hot loop; no variant allocates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum Error {
    /// A constructor or method was given a parameter it cannot use.
    InvalidParameter {
        /// The parameter's name as it appears in the signature.
        name: &'static str,
        /// Why it was refused, e.g. "must be positive and finite".
        reason: &'static str,
    },
    /// A state (time, coordinate or velocity) holds NaN or an infinity.
    NonFiniteState,
    /// The mass matrix is singular or not positive definite: the Cholesky pivot at this index
    /// was not positive.
    SingularMassMatrix {
        /// Index of the first pivot that was zero, negative or NaN.
        pivot: usize,
    },
    /// The coordinates are at a singular configuration of the mechanism, where its equations
    /// of motion are undefined (e.g. a spherical pendulum exactly at a pole).
    Singularity {
        /// Which configuration, e.g. "sin(th) = 0".
        what: &'static str,
    },
    /// An iterative solve did not converge.
    NoConvergence {
        /// How many iterations were spent.
        iterations: u32,
    },
    /// An adaptive integrator needed a step smaller than its minimum.
    StepSizeUnderflow,
    /// Constraint row `row` is, to within `sqrt(EPSILON)` of its own size, a combination of the
    /// rows before it (in the mass-weighted sense of `J M^-1 J^T`), or (row 0, or any row whose
    /// gradient vanishes) singular on its own: the constraints are redundant, or the
    /// configuration is one where they are singular (their Jacobian loses rank, or a row's
    /// gradient vanishes).
    RedundantConstraints {
        /// Index of the first dependent constraint row.
        row: usize,
    },
    /// A state violates constraint `row` beyond the tolerance it was checked against: its
    /// position residual `phi`, its velocity residual `J q'`, or (for a contact) its
    /// penetration. Typically an inconsistent initial state.
    ConstraintViolated {
        /// Index of the first violated constraint row.
        row: usize,
    },
    /// An adaptive integrator took its maximum number of steps without reaching the end time.
    TooManySteps {
        /// How many steps were taken.
        steps: u64,
    },
    /// The Newton matrix of an implicit step is singular: a pivot of its LU factorisation
    /// was zero (the step is too large for the mechanism's Jacobian, or the Jacobian is
    /// degenerate).
    SingularJacobian,
    /// An instance handle that names no instance of a scene's bank: never issued by it, or
    /// of an instance removed since.
    NoSuchInstance,
    /// A scene's bank already holds as many instances as it has room for.
    BankFull {
        /// The bank's capacity.
        capacity: usize,
    },
    /// Constraint or contact row `row` gave a value that is NaN or infinite at this state: its
    /// gap or position residual, its Jacobian row or its tangent row.
    NonFiniteRow {
        /// Index of the first such row.
        row: usize,
    },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidParameter { name, reason } => {
                write!(f, "invalid parameter `{name}`: {reason}")
            }
            Self::NonFiniteState => f.write_str("state is not finite (NaN or infinity)"),
            Self::SingularMassMatrix { pivot } => write!(
                f,
                "mass matrix is singular or not positive definite (pivot {pivot})"
            ),
            Self::Singularity { what } => write!(f, "singular configuration: {what}"),
            Self::NoConvergence { iterations } => {
                write!(f, "no convergence after {iterations} iterations")
            }
            Self::StepSizeUnderflow => f.write_str("step size fell below its minimum"),
            // Row 0 has no rows before it: it is singular on its own (its gradient vanishes in
            // the mass metric, as for a pendulum's bob at its pivot).
            Self::RedundantConstraints { row: 0 } => f.write_str(
                "constraint 0 is singular here (its gradient vanishes in the mass metric)",
            ),
            Self::RedundantConstraints { row } => write!(
                f,
                "constraint {row} is singular here or depends on the ones before it (redundant or singular constraints)"
            ),
            Self::ConstraintViolated { row } => {
                write!(f, "state violates constraint {row} beyond the tolerance")
            }
            Self::TooManySteps { steps } => {
                write!(f, "end time not reached within the limit of {steps} steps")
            }
            Self::SingularJacobian => {
                f.write_str("the Newton matrix of an implicit step is singular")
            }
            Self::NoSuchInstance => f.write_str("no such instance in this bank"),
            Self::BankFull { capacity } => {
                write!(f, "the bank is full ({capacity} instances)")
            }
            Self::NonFiniteRow { row } => write!(
                f,
                "row {row} is not finite here (its gap, Jacobian or tangent is NaN or infinite)"
            ),
        }
    }
}

impl core::error::Error for Error {}
