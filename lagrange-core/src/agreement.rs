//! A mechanism's own equations against the automatic path of its own Lagrangian: the check
//! every hand-derived and generated mechanism is tested with, written once.
//!
//! [`compare`] takes any [`Mechanism`] (which is a [`Lagrangian`]) and compares it, state by
//! state, with [`EulerLagrange`] of the same `T`, `V` and `Q`: accelerations (alone, and with an
//! extra force that reads the state), `M^-1 f` from each one's own `rhs` and `solve_mass`, mass
//! matrices and energies. [`compare_rows`] does the same for constraint rows written in closed
//! form against their dual-number derivatives ([`Holonomic`]) and for the constrained motion.
//! [`check`] and [`check_held`] are what a generated test module calls: both at
//! [`RANDOM_STATES`] states drawn from [`RandomStates`], within [`tolerance`].
//!
//! No allocation, no panic: a disagreement is returned as a [`Disagreement`] that names what
//! differed and where, so a test that returns it fails with that message.
//!
//! ```
//! use lagrange_core::agreement::{check, Disagreement};
//! use lagrange_core::prelude::*;
//!
//! /// A unit mass on a spring, with its own (correct) closed-form law.
//! #[derive(Clone, Copy)]
//! struct Spring { k: f64 }
//! impl Lagrangian<f64, 1> for Spring {
//!     fn kinetic<S: Scalar<Real = f64>>(&self, _t: S, _q: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
//!         qd[0] * qd[0] * 0.5
//!     }
//!     fn potential<S: Scalar<Real = f64>>(&self, _t: S, q: &SVector<S, 1>) -> S {
//!         q[0] * q[0] * (0.5 * self.k)
//!     }
//! }
//! impl Mechanism<f64, 1> for Spring {
//!     fn mass_matrix(&self, _s: &State<f64, 1>) -> lagrange_core::nalgebra::SMatrix<f64, 1, 1> {
//!         lagrange_core::nalgebra::SMatrix::from([[1.0]])
//!     }
//!     fn rhs(&self, s: &State<f64, 1>) -> SVector<f64, 1> {
//!         SVector::from([-self.k * s.q[0]])
//!     }
//! }
//!
//! check(&Spring { k: 3.0 }, &[(-2.0, 2.0)])?;
//! # Ok::<(), Disagreement<f64, 1>>(())
//! ```

use crate::constraints::{Constrained, Constraints, Holonomic, HolonomicConstraints};
use crate::{Error, EulerLagrange, Lagrangian, Mechanism, Real, State};
use core::fmt;
use nalgebra::SVector;

/// How many random states [`check`] and [`check_held`] compare.
pub const RANDOM_STATES: usize = 1000;

/// The largest relative disagreement [`check`] accepts in `f64`.
pub const F64_TOLERANCE: f64 = 1e-12;

/// The largest relative disagreement [`check`] accepts in `f32` (its `fast_trig` sines and
/// cosines, within 2 ulp, and rounding through a solve).
pub const F32_TOLERANCE: f64 = 1e-4;

/// [`F32_TOLERANCE`] for a single-precision `T`, [`F64_TOLERANCE`] otherwise.
#[must_use]
pub fn tolerance<T: Real>() -> f64 {
    if T::EPSILON.to_f64() > 1e-10 {
        F32_TOLERANCE
    } else {
        F64_TOLERANCE
    }
}

/// The natural sizes of a mechanism's accelerations and energies (e.g. `g / l` and `m g l`),
/// added to the size of a compared value, so that a state where the value happens to vanish,
/// or its terms cancel, is not judged on rounding alone.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Scales {
    /// A natural acceleration.
    pub acceleration: f64,
    /// A natural energy.
    pub energy: f64,
}

impl Scales {
    /// Both sizes 1: what [`check`] uses, for a mechanism in units where its accelerations and
    /// energies are of order one.
    pub const UNIT: Self = Self {
        acceleration: 1.0,
        energy: 1.0,
    };
}

/// The largest relative disagreements [`compare`] found.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Agreement {
    /// Accelerations `q''` (alone, with an extra force, and `M^-1 f`).
    pub acceleration: f64,
    /// Mass matrices (relative to their largest entry).
    pub mass_matrix: f64,
    /// Energies `T + V`.
    pub energy: f64,
}

impl Agreement {
    /// The worse of `self` and `other`, entry by entry.
    #[must_use]
    pub fn max(self, other: Self) -> Self {
        Self {
            acceleration: self.acceleration.max(other.acceleration),
            mass_matrix: self.mass_matrix.max(other.mass_matrix),
            energy: self.energy.max(other.energy),
        }
    }
}

impl fmt::Display for Agreement {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "acceleration {:.1e}, mass matrix {:.1e}, energy {:.1e}",
            self.acceleration, self.mass_matrix, self.energy
        )
    }
}

/// Where a mechanism and the automatic path disagreed.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum Disagreement<T: Real, const N: usize> {
    /// The two differ by more than the tolerance.
    Differs {
        /// What was compared: `"q''"`, `"M"`, `"energy"`, `"phi"`, ...
        what: &'static str,
        /// Where.
        state: State<T, N>,
        /// `|a - b|_inf / (|a|_inf + scale)`.
        relative: f64,
        /// The largest accepted.
        tolerance: f64,
    },
    /// One of the two returned an error (a sampled state must avoid singular configurations).
    Failed {
        /// Which: `"the mechanism"` or `"the automatic path"`, and what it was asked.
        what: &'static str,
        /// Where.
        state: State<T, N>,
        /// Its error.
        error: Error,
    },
}

impl<T: Real, const N: usize> fmt::Display for Disagreement<T, N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Differs {
                what,
                state,
                relative,
                tolerance,
            } => write!(
                f,
                "{what} differs from the automatic path by {relative:e} (relative; at most \
                 {tolerance:e}) at {state:?}"
            ),
            Self::Failed { what, state, error } => {
                write!(f, "{what} failed at {state:?}: {error}")
            }
        }
    }
}

impl<T: Real, const N: usize> core::error::Error for Disagreement<T, N> {}

/// `|a - b|_inf / (|a|_inf + scale)`: relative, with `scale` the quantity's natural size so
/// that a value that happens to vanish is not judged on rounding alone.
#[must_use]
pub fn relative<T: Real>(
    a: impl IntoIterator<Item = T>,
    b: impl IntoIterator<Item = T>,
    scale: f64,
) -> f64 {
    let (mut diff, mut size) = (0.0f64, 0.0f64);
    for (x, y) in a.into_iter().zip(b) {
        let d = (x - y).abs().to_f64();
        // A NaN on either side is a disagreement, not a zero difference.
        diff = if d.is_nan() {
            f64::INFINITY
        } else {
            diff.max(d)
        };
        size = size.max(x.abs().to_f64());
    }
    diff / (size + scale)
}

/// A state compared: `Ok(e)` within `tolerance`, else the [`Disagreement`].
fn within<T: Real, const N: usize>(
    what: &'static str,
    state: &State<T, N>,
    relative: f64,
    tolerance: f64,
) -> Result<f64, Disagreement<T, N>> {
    if relative <= tolerance {
        Ok(relative)
    } else {
        Err(Disagreement::Differs {
            what,
            state: *state,
            relative,
            tolerance,
        })
    }
}

/// `result`, or the [`Disagreement::Failed`] naming `what`.
fn ok<T: Real, const N: usize, R>(
    what: &'static str,
    state: &State<T, N>,
    result: Result<R, Error>,
) -> Result<R, Disagreement<T, N>> {
    result.map_err(|error| Disagreement::Failed {
        what,
        state: *state,
        error,
    })
}

/// Compares `mechanism` with `EulerLagrange::new(mechanism.clone())` (the automatic path of its
/// own `T`, `V` and `Q`) at every state of `states`: accelerations relative to
/// `|q''| + scales.acceleration` (alone; with an extra force that reads the state; and
/// `M^-1 f` from each one's own `rhs` and `solve_mass`), mass matrices relative to their
/// largest entry, energies relative to `|E| + scales.energy`. Returns the largest
/// disagreements seen.
///
/// # Errors
/// The first comparison beyond `tolerance` ([`Disagreement::Differs`]), or the first error of
/// either path ([`Disagreement::Failed`]).
pub fn compare<T, const N: usize, X>(
    mechanism: &X,
    states: impl IntoIterator<Item = State<T, N>>,
    scales: Scales,
    tolerance: f64,
) -> Result<Agreement, Disagreement<T, N>>
where
    T: Real,
    X: Mechanism<T, N> + Clone,
{
    let auto = EulerLagrange::new(mechanism.clone());
    let mut worst = Agreement::default();
    let push =
        |x: &State<T, N>| SVector::<T, N>::from_fn(|i, _| x.qd[i] * T::from_f64(0.7) + T::HALF);
    for s in states {
        let pairs = [
            (
                "q''",
                ok(
                    "the mechanism's acceleration",
                    &s,
                    mechanism.acceleration(&s),
                )?,
                ok("the automatic acceleration", &s, auto.acceleration(&s))?,
            ),
            (
                "q'' with an extra force",
                ok(
                    "the mechanism's acceleration with a force",
                    &s,
                    mechanism.acceleration_with(&s, &push),
                )?,
                ok(
                    "the automatic acceleration with a force",
                    &s,
                    auto.acceleration_with(&s, &push),
                )?,
            ),
            (
                "M^-1 f",
                ok(
                    "the mechanism's solve_mass",
                    &s,
                    mechanism.solve_mass(&s, &mechanism.rhs(&s)),
                )?,
                ok(
                    "the automatic solve_mass",
                    &s,
                    auto.solve_mass(&s, &auto.rhs(&s)),
                )?,
            ),
        ];
        for (what, a, b) in pairs {
            let e = relative(a.iter().copied(), b.iter().copied(), scales.acceleration);
            worst.acceleration = worst.acceleration.max(within(what, &s, e, tolerance)?);
        }
        let (ma, mb) = (mechanism.mass_matrix(&s), auto.mass_matrix(&s));
        let e = relative(ma.iter().copied(), mb.iter().copied(), 0.0);
        worst.mass_matrix = worst.mass_matrix.max(within("M", &s, e, tolerance)?);
        let e = relative([mechanism.energy(&s)], [auto.energy(&s)], scales.energy);
        worst.energy = worst.energy.max(within("energy", &s, e, tolerance)?);
    }
    Ok(worst)
}

/// Compares the constraint rows of `mechanism`, written in closed form ([`Constraints`]), with
/// the dual-number derivatives of the same rows written generic over the scalar
/// ([`HolonomicConstraints`] through [`Holonomic`]), and the constrained motion
/// ([`Constrained`]) with the automatic path held by those rows, at every state of `states`:
/// `phi`, `J`, `J'q'` and `q''`, each relative to its size plus 1. Returns the largest
/// disagreement seen.
///
/// # Errors
/// As [`compare`].
pub fn compare_rows<T, const N: usize, const C: usize, X>(
    mechanism: &X,
    states: impl IntoIterator<Item = State<T, N>>,
    tolerance: f64,
) -> Result<f64, Disagreement<T, N>>
where
    T: Real,
    X: Mechanism<T, N> + Constraints<T, N, C> + HolonomicConstraints<T, N, C> + Clone,
{
    let rows = Holonomic::new(mechanism.clone());
    let constrained = Constrained::new(mechanism.clone());
    let automatic = EulerLagrange::new(mechanism.clone()).held_by(rows.clone());
    let mut worst = 0.0f64;
    for s in states {
        let checks = [
            (
                "phi",
                relative(
                    mechanism.position_residual(&s.q).iter().copied(),
                    rows.position_residual(&s.q).iter().copied(),
                    1.0,
                ),
            ),
            (
                "J",
                relative(
                    mechanism.jacobian(&s.q).iter().copied(),
                    rows.jacobian(&s.q).iter().copied(),
                    1.0,
                ),
            ),
            (
                "J'q'",
                relative(
                    mechanism.velocity_product(&s.q, &s.qd).iter().copied(),
                    rows.velocity_product(&s.q, &s.qd).iter().copied(),
                    1.0,
                ),
            ),
            (
                "constrained q''",
                relative(
                    ok(
                        "the constrained acceleration",
                        &s,
                        constrained.acceleration(&s),
                    )?
                    .iter()
                    .copied(),
                    ok(
                        "the automatic constrained acceleration",
                        &s,
                        automatic.acceleration(&s),
                    )?
                    .iter()
                    .copied(),
                    1.0,
                ),
            ),
        ];
        for (what, e) in checks {
            worst = worst.max(within(what, &s, e, tolerance)?);
        }
    }
    Ok(worst)
}

/// Reproducible random states (SplitMix64 from a fixed seed, the same on every machine): each
/// coordinate uniform in its range, each velocity uniform in `[-3, 3)`, the time uniform in
/// `[0, 10)`, drawn in that order. An endless iterator: `take` what is needed.
///
/// ```
/// use lagrange_core::agreement::RandomStates;
/// let s: lagrange_core::State<f64, 2> = RandomStates::new([(0.5, 1.0), (-1.0, 0.0)], 7)
///     .next()
///     .unwrap_or(lagrange_core::State::at_rest([0.0; 2]));
/// assert!((0.5..1.0).contains(&s.q[0]) && (-1.0..0.0).contains(&s.q[1]));
/// ```
#[derive(Debug, Clone)]
pub struct RandomStates<const N: usize> {
    ranges: [(f64, f64); N],
    seed: u64,
}

impl<const N: usize> RandomStates<N> {
    /// States with coordinate `i` in `ranges[i]`, from `seed`.
    #[must_use]
    pub fn new(ranges: [(f64, f64); N], seed: u64) -> Self {
        Self { ranges, seed }
    }

    /// Uniform in `[0, 1)`.
    fn unit(&mut self) -> f64 {
        self.seed = self.seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.seed;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `[lo, hi)`.
    fn uniform(&mut self, (lo, hi): (f64, f64)) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// The next state, in `T`.
    pub fn state<T: Real>(&mut self) -> State<T, N> {
        let mut q = [T::zero(); N];
        for (x, range) in q.iter_mut().zip(self.ranges) {
            *x = T::from_f64(self.uniform(range));
        }
        let mut qd = [T::zero(); N];
        for x in &mut qd {
            *x = T::from_f64(self.uniform((-3.0, 3.0)));
        }
        let t = T::from_f64(self.uniform((0.0, 10.0)));
        State::new(t, q, qd)
    }
}

impl<const N: usize> Iterator for RandomStates<N> {
    type Item = State<f64, N>;
    fn next(&mut self) -> Option<State<f64, N>> {
        Some(self.state())
    }
}

/// The seed of [`check`] and [`check_held`].
const SEED: u64 = 16;

/// `mechanism` against the automatic path of its own Lagrangian ([`compare`]) at
/// [`RANDOM_STATES`] states of [`RandomStates`] (coordinates in `ranges`), with
/// [`Scales::UNIT`], within [`tolerance`] for `T`: the test of a generated mechanism.
///
/// # Errors
/// As [`compare`].
pub fn check<T, const N: usize, X>(
    mechanism: &X,
    ranges: &[(f64, f64); N],
) -> Result<(), Disagreement<T, N>>
where
    T: Real,
    X: Mechanism<T, N> + Clone,
{
    let mut random = RandomStates::new(*ranges, SEED);
    let states = (0..RANDOM_STATES).map(|_| random.state::<T>());
    compare(mechanism, states, Scales::UNIT, tolerance::<T>()).map(|_| ())
}

/// [`check`], then the constraint rows and the constrained motion ([`compare_rows`]) at as many
/// further states: the test of a generated mechanism with rows `phi`.
///
/// # Errors
/// As [`compare`].
pub fn check_held<T, const N: usize, const C: usize, X>(
    mechanism: &X,
    ranges: &[(f64, f64); N],
) -> Result<(), Disagreement<T, N>>
where
    T: Real,
    X: Mechanism<T, N> + Constraints<T, N, C> + HolonomicConstraints<T, N, C> + Clone,
{
    let mut random = RandomStates::new(*ranges, SEED);
    let states = (0..RANDOM_STATES).map(|_| random.state::<T>());
    compare(mechanism, states, Scales::UNIT, tolerance::<T>())?;
    let states = (0..RANDOM_STATES).map(|_| random.state::<T>());
    compare_rows(mechanism, states, tolerance::<T>()).map(|_| ())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Lagrangian, Scalar};
    use nalgebra::SMatrix;

    /// A pendulum whose closed form is right, or off by `error` in its gravity term.
    #[derive(Clone, Copy)]
    struct Pendulum {
        error: f64,
    }

    impl Lagrangian<f64, 1> for Pendulum {
        fn kinetic<S: Scalar<Real = f64>>(&self, _: S, _: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
            qd[0] * qd[0] * 0.5
        }
        fn potential<S: Scalar<Real = f64>>(&self, _: S, q: &SVector<S, 1>) -> S {
            -q[0].cos() * 9.81
        }
    }

    impl Mechanism<f64, 1> for Pendulum {
        fn mass_matrix(&self, _: &State<f64, 1>) -> SMatrix<f64, 1, 1> {
            SMatrix::from([[1.0]])
        }
        fn rhs(&self, s: &State<f64, 1>) -> SVector<f64, 1> {
            SVector::from([-(9.81 + self.error) * s.q[0].sin()])
        }
    }

    /// A right closed form passes; one that is wrong by a part in 10^9 is caught, by name.
    #[test]
    fn a_wrong_law_is_caught() {
        let ranges = [(-3.0, 3.0)];
        assert_eq!(check(&Pendulum { error: 0.0 }, &ranges), Ok(()));
        let found = check(&Pendulum { error: 1e-8 }, &ranges);
        assert!(
            matches!(found, Err(Disagreement::Differs { what: "q''", .. })),
            "{found:?}"
        );
    }

    /// A NaN on one side is a disagreement.
    #[test]
    fn nan_is_never_agreement() {
        assert!(relative([f64::NAN], [1.0], 1.0) > 1.0);
        assert!(relative([1.0], [f64::NAN], 1.0) > 1.0);
        assert_eq!(relative([2.0], [2.0], 1.0), 0.0);
    }

    /// The states stay in their ranges and are the same from the same seed.
    #[test]
    fn random_states_are_reproducible_and_in_range() {
        let a: [State<f64, 2>; 50] = {
            let mut r = RandomStates::new([(1.0, 2.0), (-5.0, -4.0)], 3);
            core::array::from_fn(|_| r.state())
        };
        let mut r = RandomStates::new([(1.0, 2.0), (-5.0, -4.0)], 3);
        for s in a {
            assert_eq!(r.next(), Some(s));
            assert!((1.0..2.0).contains(&s.q[0]) && (-5.0..-4.0).contains(&s.q[1]));
            assert!((-3.0..3.0).contains(&s.qd[0]) && (0.0..10.0).contains(&s.t));
        }
    }
}
