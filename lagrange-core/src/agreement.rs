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
    use crate::{GeneralizedForce, Lagrangian, Scalar};
    use nalgebra::SMatrix;

    extern crate std;
    use std::string::ToString;

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

    /// `tolerance` is the single-precision one for `f32` and the double-precision one for
    /// `f64`, and the two are what their documentation says.
    #[test]
    fn tolerance_follows_the_scalar() {
        assert_eq!(tolerance::<f32>(), F32_TOLERANCE);
        assert_eq!(tolerance::<f64>(), F64_TOLERANCE);
        assert_eq!((F32_TOLERANCE, F64_TOLERANCE), (1e-4, 1e-12));
    }

    /// `Agreement::max` takes the worse entry from either side, entry by entry, whichever
    /// side it is called on.
    #[test]
    fn agreement_max_is_entry_by_entry() {
        let a = Agreement {
            acceleration: 1.0,
            mass_matrix: 0.5,
            energy: 3.0,
        };
        let b = Agreement {
            acceleration: 2.0,
            mass_matrix: 0.25,
            energy: 4.0,
        };
        let worst = Agreement {
            acceleration: 2.0,
            mass_matrix: 0.5,
            energy: 4.0,
        };
        assert_eq!(a.max(b), worst);
        assert_eq!(b.max(a), worst);
        assert_eq!(a.max(a), a);
    }

    /// An `Agreement` prints each of its three figures, named, to two significant digits.
    #[test]
    fn agreement_prints_its_figures() {
        let a = Agreement {
            acceleration: 1.5e-13,
            mass_matrix: 0.0,
            energy: 2.5e-5,
        };
        assert_eq!(
            a.to_string(),
            "acceleration 1.5e-13, mass matrix 0.0e0, energy 2.5e-5"
        );
    }

    /// A `Disagreement` says what differed, by how much against what limit, and where; or
    /// what failed, where, and the error itself.
    fn disagreement_prints_what_and_where<T: Real>() {
        let state = State::<T, 1>::new(T::from_f64(0.5), [T::from_f64(1.25)], [T::TWO]);
        let differs = Disagreement::Differs {
            what: "M",
            state,
            relative: 2.5e-3,
            tolerance: 1e-12,
        };
        let text = differs.to_string();
        let head = "M differs from the automatic path by 2.5e-3 (relative; at most 1e-12) at ";
        assert!(text.starts_with(head), "{text}");
        // Where: the whole state (its time 0.5, coordinate 1.25 and velocity 2 among it).
        let place = std::format!("{state:?}");
        assert!(place.contains("0.5") && place.contains("1.25"), "{place}");
        assert_eq!(&text[head.len()..], place);
        let error = Error::SingularMassMatrix { pivot: 1 };
        let failed: Disagreement<T, 1> = Disagreement::Failed {
            what: "the mechanism's solve_mass",
            state,
            error,
        };
        assert!(!error.to_string().is_empty());
        assert_eq!(
            failed.to_string(),
            std::format!("the mechanism's solve_mass failed at {place}: {error}")
        );
    }

    #[test]
    fn disagreement_prints_what_and_where_f32() {
        disagreement_prints_what_and_where::<f32>();
    }

    #[test]
    fn disagreement_prints_what_and_where_f64() {
        disagreement_prints_what_and_where::<f64>();
    }

    /// Gravity of [`Bob`], m/s^2.
    const G: f64 = 9.81;

    /// A unit point mass in the plane, in gravity `G` along -y, with the row
    /// `phi = (x^2 + y^2 - 1) / 2` (a rod of length 1 from the origin): every form written in
    /// closed form, each multiplied by `1 + error` with the error its field (all zero: every
    /// form right). Its law is its own closed form `q'' = f + extra` (`M` is the identity), which
    /// reads neither `mass_matrix` nor `solve_mass`, so that each wrong form shows alone.
    #[derive(Clone, Copy, Default)]
    struct Bob<T> {
        rhs: T,
        mass: T,
        solve: T,
        energy: T,
        phi: T,
        jacobian: T,
        product: T,
        /// The law drops the extra force.
        drops_force: bool,
    }

    impl<T: Real> Lagrangian<T, 2> for Bob<T> {
        fn kinetic<S: Scalar<Real = T>>(&self, _: S, _: &SVector<S, 2>, qd: &SVector<S, 2>) -> S {
            (qd[0] * qd[0] + qd[1] * qd[1]) * T::HALF
        }
        fn potential<S: Scalar<Real = T>>(&self, _: S, q: &SVector<S, 2>) -> S {
            q[1] * T::from_f64(G)
        }
        fn energy(&self, s: &State<T, 2>) -> T {
            (self.kinetic_energy(s) + self.potential_energy(s)) * (T::one() + self.energy)
        }
    }

    impl<T: Real> Mechanism<T, 2> for Bob<T> {
        fn mass_matrix(&self, _: &State<T, 2>) -> SMatrix<T, 2, 2> {
            SMatrix::identity() * (T::one() + self.mass)
        }
        fn rhs(&self, _: &State<T, 2>) -> SVector<T, 2> {
            SVector::from([T::zero(), -T::from_f64(G) * (T::one() + self.rhs)])
        }
        fn solve_mass(&self, _: &State<T, 2>, b: &SVector<T, 2>) -> Result<SVector<T, 2>, Error> {
            Ok(b * (T::one() + self.solve))
        }
        fn law<F: GeneralizedForce<T, 2>>(
            &self,
            s: &State<T, 2>,
            extra: &F,
        ) -> Result<SVector<T, 2>, Error> {
            let f = self.rhs(s);
            Ok(if self.drops_force {
                f
            } else {
                extra.added_to(s, f)
            })
        }
    }

    impl<T: Real> Constraints<T, 2, 1> for Bob<T> {
        fn position_residual(&self, q: &SVector<T, 2>) -> SVector<T, 1> {
            let phi = (q[0] * q[0] + q[1] * q[1] - T::one()) * T::HALF;
            SVector::from([phi * (T::one() + self.phi)])
        }
        fn jacobian(&self, q: &SVector<T, 2>) -> SMatrix<T, 1, 2> {
            SMatrix::from([[q[0]], [q[1]]]) * (T::one() + self.jacobian)
        }
        fn velocity_product(&self, _: &SVector<T, 2>, qd: &SVector<T, 2>) -> SVector<T, 1> {
            SVector::from([(qd[0] * qd[0] + qd[1] * qd[1]) * (T::one() + self.product)])
        }
    }

    impl<T: Real> HolonomicConstraints<T, 2, 1> for Bob<T> {
        fn phi<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 2>) -> SVector<S, 1> {
            SVector::from([(q[0] * q[0] + q[1] * q[1] - T::one()) * T::HALF])
        }
    }

    /// Where [`Bob`] is sampled: away from the origin, where its row's gradient vanishes.
    const BOB_RANGES: [(f64, f64); 2] = [(0.5, 1.5), (-1.5, -0.5)];

    /// The relative error put into a wrong form: a hundred times what [`check`] accepts in
    /// `T` (1e-10 in f64, 1e-2 in f32), small against the form, far outside the tolerance.
    fn small_error<T: Real>() -> T {
        T::from_f64(100.0 * tolerance::<T>())
    }

    /// `found` is a [`Disagreement::Differs`] naming `named`, at the tolerance of `T`, with a
    /// relative difference above it and at most `most`.
    fn assert_names<T: Real, const N: usize>(
        found: Result<(), Disagreement<T, N>>,
        named: &str,
        most: f64,
    ) {
        assert!(
            matches!(
                found,
                Err(Disagreement::Differs { what, relative, tolerance: accepted, .. })
                    if what == named
                        && accepted == tolerance::<T>()
                        && relative > accepted
                        && relative <= most
            ),
            "{named}: {found:?}"
        );
    }

    /// The check detects a mechanism whose rhs, mass matrix, `M^-1`, energy or constraint
    /// rows are wrong by a small relative amount, and names which; the right one passes.
    fn wrong_forms_are_named<T: Real>() {
        let bob = Bob::<T>::default();
        assert_eq!(check(&bob, &BOB_RANGES), Ok(()));
        assert_eq!(check_held(&bob, &BOB_RANGES), Ok(()));
        let e = small_error::<T>();
        // A form `a (1 + e)` against `a` differs by `e |a| / (|a| (1 + e) + scale)`, at most
        // `e`, give or take the rounding of forms of order one (4 EPSILON: each side rounded
        // once or twice).
        let most = e.to_f64() + 4.0 * T::EPSILON.to_f64();
        for (wrong, named) in [
            (Bob { rhs: e, ..bob }, "q''"),
            (Bob { solve: e, ..bob }, "M^-1 f"),
            (Bob { mass: e, ..bob }, "M"),
            (Bob { energy: e, ..bob }, "energy"),
            (Bob { phi: e, ..bob }, "phi"),
            (Bob { jacobian: e, ..bob }, "J"),
            (Bob { product: e, ..bob }, "J'q'"),
        ] {
            assert_names(check_held(&wrong, &BOB_RANGES), named, most);
        }
        // The rows alone, with the free law wrong: the constrained motion differs, by at most
        // the error in `f`, `G e`, over the constrained `|q''| + 1`, at least 1.
        let mut random = RandomStates::new(BOB_RANGES, SEED);
        let states = (0..RANDOM_STATES).map(|_| random.state::<T>());
        let found = compare_rows(&Bob { rhs: e, ..bob }, states, tolerance::<T>());
        assert_names(found.map(|_| ()), "constrained q''", G * most);
    }

    #[test]
    fn wrong_forms_are_named_f32() {
        wrong_forms_are_named::<f32>();
    }

    #[test]
    fn wrong_forms_are_named_f64() {
        wrong_forms_are_named::<f64>();
    }

    /// The extra force of the comparison is `0.7 q' + 1/2`, and a law that drops it is caught:
    /// at `q' = (1, -2)` the force is `(1.2, -0.9)`, the automatic path's `q''` is
    /// `(0, -G) + (1.2, -0.9)` and the law's `(0, -G)`, so the relative difference is
    /// `1.2 / (G + 1)` (the largest difference over the law's largest entry plus 1).
    fn a_dropped_force_is_measured<T: Real>() {
        let state = State::new(
            T::one(),
            [T::from_f64(0.75), T::from_f64(-0.5)],
            [T::one(), -T::TWO],
        );
        let bob = Bob::<T> {
            drops_force: true,
            ..Bob::default()
        };
        let expected = 1.2 / (G + 1.0);
        let found = compare(&bob, [state], Scales::UNIT, tolerance::<T>());
        // 1.2 and G rounded to T, and one division: a few EPSILON.
        let close = 4.0 * T::EPSILON.to_f64() * expected;
        assert!(
            matches!(
                found,
                Err(Disagreement::Differs { what: "q'' with an extra force", relative, .. })
                    if (relative - expected).abs() <= close
            ),
            "{found:?} against {expected:e}"
        );
    }

    #[test]
    fn a_dropped_force_is_measured_f32() {
        a_dropped_force_is_measured::<f32>();
    }

    #[test]
    fn a_dropped_force_is_measured_f64() {
        a_dropped_force_is_measured::<f64>();
    }

    /// `compare_rows` returns the largest relative difference it saw: rows right to rounding
    /// give a figure within the tolerance, and a `phi` 10% too large at `q = (0, -2)` (where
    /// `phi = 3/2` exactly) gives `(0.15) / (1.65 + 1)`, the difference over the closed
    /// form's size plus 1, when the tolerance lets it through.
    fn compare_rows_reports_the_worst<T: Real>() {
        let mut random = RandomStates::new(BOB_RANGES, SEED);
        let states = (0..RANDOM_STATES).map(|_| random.state::<T>());
        let right = compare_rows(&Bob::<T>::default(), states, tolerance::<T>());
        assert!(
            right.is_ok_and(|e| (0.0..=tolerance::<T>()).contains(&e)),
            "{right:?}"
        );
        let state = State::new(T::zero(), [T::zero(), -T::TWO], [T::one(), T::HALF]);
        let wrong = Bob::<T> {
            phi: T::from_f64(0.1),
            ..Bob::default()
        };
        let expected = (1.5 * 0.1) / (1.5 * 1.1 + 1.0);
        let found = compare_rows(&wrong, [state], 1.0);
        // The difference 1.65 - 1.5 in T magnifies the rounding of 1.65 (at most 1.3 EPSILON,
        // from 1.1 and the product) by 1.65 / 0.15 = 11: 16 EPSILON covers it.
        let close = 16.0 * T::EPSILON.to_f64() * expected;
        assert!(
            found.is_ok_and(|e| (e - expected).abs() <= close),
            "{found:?} against {expected:e}"
        );
    }

    #[test]
    fn compare_rows_reports_the_worst_f32() {
        compare_rows_reports_the_worst::<f32>();
    }

    #[test]
    fn compare_rows_reports_the_worst_f64() {
        compare_rows_reports_the_worst::<f64>();
    }

    /// SplitMix64 (Steele, Lea and Flood, 2014) written from its definition, as in Vigna's
    /// reference `splitmix64.c`: the state advances by the golden-ratio increment
    /// `0x9E3779B97F4A7C15`, and the output is the new state through Stafford's "Mix13"
    /// finaliser (xor with itself shifted right 30, times `0xBF58476D1CE4E5B9`, xor-shift
    /// 27, times `0x94D049BB133111EB`, xor-shift 31).
    fn splitmix64(state: &mut u64) -> u64 {
        *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A 64-bit output as a float in `[0, 1)`: its top 53 bits over 2^53.
    fn top_53(x: u64) -> f64 {
        (x >> 11) as f64 / (1u64 << 53) as f64
    }

    /// The generator is SplitMix64: the reimplementation above reproduces the published first
    /// outputs from seed 0 (those of `splitmix64.c`, also the seeds of xoshiro's examples), and
    /// `unit` gives their top 53 bits, for those and for 1,000 more draws from three seeds.
    #[test]
    fn random_states_are_splitmix64() {
        let published: [u64; 4] = [
            0xE220_A839_7B1D_CDAF,
            0x6E78_9E6A_A1B9_65F4,
            0x06C4_5D18_8009_454F,
            0xF88B_B8A8_724C_81EC,
        ];
        let mut reference = 0;
        for x in published {
            assert_eq!(splitmix64(&mut reference), x);
        }
        let mut random = RandomStates::new([(0.0, 1.0)], 0);
        for x in published {
            assert_eq!(random.unit(), top_53(x));
        }
        for seed in [0, SEED, u64::MAX] {
            let (mut random, mut reference) = (RandomStates::new([], seed), seed);
            for _ in 0..1000 {
                assert_eq!(random.unit(), top_53(splitmix64(&mut reference)));
            }
        }
    }

    /// A state is drawn coordinates first, then velocities in `[-3, 3)`, then the time in
    /// `[0, 10)`, each from the next output, the same in `f32` (rounded) as in `f64`.
    fn a_state_takes_outputs_in_order<T: Real>() {
        let mut reference = 0;
        let u: [f64; 5] = core::array::from_fn(|_| top_53(splitmix64(&mut reference)));
        let s = RandomStates::new([(1.0, 2.0), (-4.0, 0.0)], 0).state::<T>();
        let expected = State::<T, 2>::new(
            T::from_f64(10.0 * u[4]),
            [T::from_f64(1.0 + u[0]), T::from_f64(-4.0 + 4.0 * u[1])],
            [
                T::from_f64(-3.0 + 6.0 * u[2]),
                T::from_f64(-3.0 + 6.0 * u[3]),
            ],
        );
        assert_eq!(s, expected);
    }

    #[test]
    fn a_state_takes_outputs_in_order_f32() {
        a_state_takes_outputs_in_order::<f32>();
    }

    #[test]
    fn a_state_takes_outputs_in_order_f64() {
        a_state_takes_outputs_in_order::<f64>();
    }

    /// 10,000 draws from the check's seed are in `[0, 1)`, all different, with a mean and a
    /// variance near those of the uniform distribution (1/2 and 1/12).
    #[test]
    fn random_units_look_uniform() {
        const DRAWS: usize = 10_000;
        let mut random = RandomStates::new([], SEED);
        let mut u = [0.0f64; DRAWS];
        for x in &mut u {
            *x = random.unit();
        }
        assert!(u.iter().all(|x| (0.0..1.0).contains(x)));
        let mean = u.iter().sum::<f64>() / DRAWS as f64;
        let variance = u.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / DRAWS as f64;
        // The mean of n uniform draws has standard deviation sqrt(1/12 / n) = 0.0029 at
        // n = 10^4, the sample variance about sqrt(1/180 / n) = 0.00075: five of each, which
        // a uniform generator misses with probability below 1e-6.
        let sd_mean = Scalar::sqrt(1.0 / 12.0 / DRAWS as f64);
        let sd_variance = Scalar::sqrt(1.0 / 180.0 / DRAWS as f64);
        assert!((mean - 0.5).abs() < 5.0 * sd_mean, "{mean}");
        assert!(
            (variance - 1.0 / 12.0).abs() < 5.0 * sd_variance,
            "{variance}"
        );
        u.sort_unstable_by(f64::total_cmp);
        assert!(u.windows(2).all(|w| w[0] < w[1]));
    }
}
