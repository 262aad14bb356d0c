//! Fixtures of the criterion micro-benchmarks (`cargo bench -p lagrange-benches`): each
//! standard system with the parameters of the bench's problems and a moving state at which
//! every term of its equations is non-zero.

use lagrange_core::{Error, EulerLagrange, Real, State};
use lagrange_systems::{BeadOnRotatingHoop, DoublePendulum, FallingParticle, SimplePendulum};

/// A system and a state to evaluate it at.
pub struct Fixture<M, T: Real, const N: usize> {
    /// Name in the benchmark ids.
    pub name: &'static str,
    /// The system.
    pub mechanism: M,
    /// A state with every term of the equations of motion non-zero.
    pub state: State<T, N>,
}

/// `"f32"` or `"f64"`.
#[must_use]
pub fn precision<T: Real>() -> &'static str {
    if T::EPSILON.to_f64() > 1e-10 {
        "f32"
    } else {
        "f64"
    }
}

/// Gravity of every fixture, m/s^2.
const G: f64 = 9.81;

/// The falling particle, 1 kg.
///
/// # Errors
/// Never, for these parameters.
pub fn falling_particle<T: Real>() -> Result<Fixture<FallingParticle<T>, T, 1>, Error> {
    Ok(Fixture {
        name: "falling particle",
        mechanism: FallingParticle::new(T::one(), T::from_f64(G))?,
        state: State::new(T::zero(), [T::from_f64(10.0)], [T::from_f64(-1.0)]),
    })
}

/// The origin's pendulum (P1), lightly damped so that the damping term is evaluated.
///
/// # Errors
/// Never, for these parameters.
pub fn pendulum<T: Real>() -> Result<Fixture<SimplePendulum<T>, T, 1>, Error> {
    Ok(Fixture {
        name: "simple pendulum",
        mechanism: SimplePendulum::new(T::one(), T::one(), T::from_f64(G), T::from_f64(0.1))?,
        state: State::new(T::zero(), [T::from_f64(0.5)], [T::from_f64(0.3)]),
    })
}

/// A bead on a hoop spinning at 5 rad/s.
///
/// # Errors
/// Never, for these parameters.
pub fn bead<T: Real>() -> Result<Fixture<BeadOnRotatingHoop<T>, T, 1>, Error> {
    Ok(Fixture {
        name: "bead on rotating hoop",
        mechanism: BeadOnRotatingHoop::new(T::one(), T::one(), T::from_f64(5.0), T::from_f64(G))?,
        state: State::new(T::zero(), [T::from_f64(0.5)], [T::from_f64(0.3)]),
    })
}

/// The double pendulum of P2.
///
/// # Errors
/// Never, for these parameters.
pub fn double_pendulum<T: Real>() -> Result<Fixture<DoublePendulum<T>, T, 2>, Error> {
    let one = T::one();
    Ok(Fixture {
        name: "double pendulum",
        mechanism: DoublePendulum::new(one, one, one, one, T::from_f64(G))?,
        state: State::new(
            T::zero(),
            [T::from_f64(1.5), T::from_f64(0.7)],
            [T::from_f64(0.3), T::from_f64(-0.8)],
        ),
    })
}

/// The double pendulum of P2 through the automatic Euler-Lagrange path (its `Lagrangian`),
/// to price the automatic path against the hand-derived one.
///
/// # Errors
/// Never, for these parameters.
pub fn double_pendulum_automatic<T: Real>(
) -> Result<Fixture<EulerLagrange<DoublePendulum<T>>, T, 2>, Error> {
    let f = double_pendulum::<T>()?;
    Ok(Fixture {
        name: "double pendulum (automatic)",
        mechanism: EulerLagrange::new(f.mechanism),
        state: f.state,
    })
}
