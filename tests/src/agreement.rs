//! Hand-derived against automatic: one check, shared by every system's test, that a mechanism's
//! closed-form equations agree with the automatic Euler-Lagrange path of its own Lagrangian.

use crate::Rng;
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, EulerLagrange, Lagrangian, Mechanism, Real, State};

/// The largest relative disagreements found by [`agrees_with_automatic`].
#[derive(Debug, Clone, Copy, Default)]
pub struct Agreement {
    /// Accelerations `q''`.
    pub acceleration: f64,
    /// Mass matrices.
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

impl core::fmt::Display for Agreement {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "acceleration {:.1e}, mass matrix {:.1e}, energy {:.1e}",
            self.acceleration, self.mass_matrix, self.energy
        )
    }
}

/// The natural sizes of a system's accelerations and energies (e.g. `g / l` and `m g l`), which
/// [`agrees_with_automatic`] adds to the size of a compared value, so that a state where the
/// value happens to vanish, or its terms cancel, is not judged on rounding alone.
#[derive(Debug, Clone, Copy)]
pub struct Scales {
    /// A natural acceleration.
    pub acceleration: f64,
    /// A natural energy.
    pub energy: f64,
}

/// `|a - b|_inf / (|a|_inf + scale)`: relative, with `scale` the system's natural size of the
/// quantity so that a state where it happens to vanish is not judged on rounding alone.
pub fn relative<T: Real>(
    a: impl IntoIterator<Item = T>,
    b: impl IntoIterator<Item = T>,
    scale: f64,
) -> f64 {
    let (mut diff, mut size) = (0.0f64, 0.0f64);
    for (x, y) in a.into_iter().zip(b) {
        diff = diff.max((x - y).abs().to_f64());
        size = size.max(x.abs().to_f64());
    }
    diff / (size + scale)
}

/// A state with every coordinate uniform in `q`, every velocity uniform in `qd` and the time
/// uniform in `[0, 10)`, drawn in that order.
pub fn random_state<T: Real, const N: usize>(
    rng: &mut Rng,
    q: (f64, f64),
    qd: (f64, f64),
) -> State<T, N> {
    let q: [T; N] = core::array::from_fn(|_| rng.uniform(q.0, q.1));
    let qd: [T; N] = core::array::from_fn(|_| rng.uniform(qd.0, qd.1));
    State::new(rng.uniform(0.0, 10.0), q, qd)
}

/// Compares `hand` with `EulerLagrange::new(hand)` at `states` states drawn by `sample`:
/// accelerations (relative to `|q''| + scale.acceleration`), mass matrices (relative to their
/// largest entry) and energies (relative to `|E| + scale.energy`) must each agree to
/// `tolerance`. Returns the largest
/// disagreements seen, for the test to report.
///
/// # Errors
/// Either path's error at a sampled state (a sampler must avoid singular configurations).
pub fn agrees_with_automatic<T, S, const N: usize>(
    hand: &S,
    scale: Scales,
    tolerance: f64,
    states: usize,
    rng: &mut Rng,
    mut sample: impl FnMut(&mut Rng) -> State<T, N>,
) -> Result<Agreement, Error>
where
    T: Real,
    S: Mechanism<T, N> + Lagrangian<T, N> + Clone,
{
    let auto = EulerLagrange::new(hand.clone());
    let mut worst = Agreement::default();
    for _ in 0..states {
        let s = sample(rng);
        let (a, b) = (hand.acceleration(&s)?, auto.acceleration(&s)?);
        let e = relative(a.iter().copied(), b.iter().copied(), scale.acceleration);
        assert!(
            e < tolerance,
            "acceleration at {s:?}: hand {a:?} auto {b:?} ({e:e})"
        );
        worst.acceleration = worst.acceleration.max(e);
        // The same law with an extra force that reads the state (an input, a drive), and
        // the split form: M^-1 f from each one's own `rhs` and `solve_mass`.
        let push = |x: &State<T, N>| {
            SVector::<T, N>::from_fn(|i, _| x.qd[i] * T::from_f64(0.7) + T::from_f64(1.3))
        };
        let (a, b) = (
            hand.acceleration_with(&s, &push)?,
            auto.acceleration_with(&s, &push)?,
        );
        let e = relative(a.iter().copied(), b.iter().copied(), scale.acceleration);
        assert!(
            e < tolerance,
            "acceleration with a force at {s:?}: hand {a:?} auto {b:?} ({e:e})"
        );
        worst.acceleration = worst.acceleration.max(e);
        let (a, b) = (
            hand.solve_mass(&s, &hand.rhs(&s))?,
            auto.solve_mass(&s, &auto.rhs(&s))?,
        );
        let e = relative(a.iter().copied(), b.iter().copied(), scale.acceleration);
        assert!(
            e < tolerance,
            "M^-1 rhs at {s:?}: hand {a:?} auto {b:?} ({e:e})"
        );
        worst.acceleration = worst.acceleration.max(e);
        let (ma, mb) = (hand.mass_matrix(&s), auto.mass_matrix(&s));
        let e = relative(ma.iter().copied(), mb.iter().copied(), 0.0);
        assert!(
            e < tolerance,
            "mass matrix at {s:?}: hand {ma:?} auto {mb:?} ({e:e})"
        );
        worst.mass_matrix = worst.mass_matrix.max(e);
        let e = relative([hand.energy(&s)], [auto.energy(&s)], scale.energy);
        assert!(e < tolerance, "energy at {s:?} ({e:e})");
        worst.energy = worst.energy.max(e);
        // A Lagrangian that says it does not read the time gives the same `T` and `V`, bit
        // for bit, at another time (an impulse stepper's guard takes its `dL/dt` as zero).
        if !S::READS_TIME {
            let later = s.t + T::from_f64(1234.5);
            assert!(
                hand.kinetic(later, &s.q, &s.qd) == hand.kinetic(s.t, &s.q, &s.qd)
                    && hand.potential(later, &s.q) == hand.potential(s.t, &s.q),
                "READS_TIME is false, but L changes with t at {s:?}"
            );
        }
    }
    Ok(worst)
}
