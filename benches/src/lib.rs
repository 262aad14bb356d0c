//! Wall-clock timing shared by the bench binaries ([`timing`]), and fixtures of the criterion micro-benchmarks (`cargo bench -p lagrange-benches`): each
//! standard system with the parameters of the bench's problems and a moving state at which
//! every term of its equations is non-zero.

pub mod timing;

use lagrange_core::{Error, EulerLagrange, Real, State};
use lagrange_systems::{
    Acrobot, BeadOnRotatingHoop, CartPole, DoublePendulum, ElasticPendulum, FallingParticle,
    Kepler, NLinkPendulum, SimplePendulum, SphericalPendulum, SpringMassDamper, SwingingAtwood,
};

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
) -> Result<Fixture<EulerLagrange<T, 2, DoublePendulum<T>>, T, 2>, Error> {
    let f = double_pendulum::<T>()?;
    Ok(Fixture {
        name: "double pendulum (automatic)",
        mechanism: EulerLagrange::new(f.mechanism),
        state: f.state,
    })
}

/// A state of `N` coordinates and rates from two arrays.
fn state<T: Real, const N: usize>(q: [f64; N], qd: [f64; N]) -> State<T, N> {
    State::new(T::zero(), q.map(T::from_f64), qd.map(T::from_f64))
}

/// The chain of P3 with `N` unit links, moving.
///
/// # Errors
/// Never, for these parameters.
pub fn chain<T: Real, const N: usize>() -> Result<Fixture<NLinkPendulum<T, N>, T, N>, Error> {
    Ok(Fixture {
        name: if N == 5 { "chain N=5" } else { "chain N=20" },
        mechanism: NLinkPendulum::new([T::one(); N], [T::one(); N], T::from_f64(G))?,
        state: state([core::f64::consts::FRAC_PI_4; N], [0.3; N]),
    })
}

/// A unit mass on a spring of stiffness 100, lightly damped.
///
/// # Errors
/// Never, for these parameters.
pub fn spring<T: Real>() -> Result<Fixture<SpringMassDamper<T>, T, 1>, Error> {
    Ok(Fixture {
        name: "spring-mass-damper",
        mechanism: SpringMassDamper::new(T::one(), T::from_f64(100.0), T::from_f64(0.1))?,
        state: state([0.1], [0.5]),
    })
}

/// The elastic pendulum of P5.
///
/// # Errors
/// Never, for these parameters.
pub fn elastic<T: Real>() -> Result<Fixture<ElasticPendulum<T>, T, 2>, Error> {
    Ok(Fixture {
        name: "elastic pendulum",
        mechanism: ElasticPendulum::new(T::one(), T::from_f64(1e6), T::one(), T::from_f64(G))?,
        state: state([1.001, 0.3], [0.01, 0.2]),
    })
}

/// A spherical pendulum away from its axis.
///
/// # Errors
/// Never, for these parameters.
pub fn spherical<T: Real>() -> Result<Fixture<SphericalPendulum<T>, T, 2>, Error> {
    Ok(Fixture {
        name: "spherical pendulum",
        mechanism: SphericalPendulum::new(T::one(), T::one(), T::from_f64(G))?,
        state: state([1.0, 0.2], [0.3, 1.5]),
    })
}

/// The classic cart-pole, pole tilted.
///
/// # Errors
/// Never, for these parameters.
pub fn cart_pole<T: Real>() -> Result<Fixture<CartPole<T>, T, 2>, Error> {
    Ok(Fixture {
        name: "cart-pole",
        mechanism: CartPole::new(T::one(), T::from_f64(0.1), T::from_f64(0.5), T::from_f64(G))?,
        state: state([0.1, 0.2], [0.3, -0.4]),
    })
}

/// Spong's acrobot.
///
/// # Errors
/// Never.
pub fn acrobot<T: Real>() -> Result<Fixture<Acrobot<T>, T, 2>, Error> {
    Ok(Fixture {
        name: "acrobot",
        mechanism: Acrobot::spong(),
        state: state([0.5, 0.7], [0.3, -0.4]),
    })
}

/// A swinging Atwood machine with mass ratio 3.
///
/// # Errors
/// Never, for these parameters.
pub fn atwood<T: Real>() -> Result<Fixture<SwingingAtwood<T>, T, 2>, Error> {
    Ok(Fixture {
        name: "swinging Atwood",
        mechanism: SwingingAtwood::new(T::from_f64(3.0), T::one(), T::from_f64(G))?,
        state: state([1.0, 0.5], [0.1, 0.3]),
    })
}

/// The Kepler orbit of P4 at periapsis.
///
/// # Errors
/// Never, for these parameters.
pub fn kepler<T: Real>() -> Result<Fixture<Kepler<T>, T, 2>, Error> {
    Ok(Fixture {
        name: "Kepler",
        mechanism: Kepler::new(T::one())?,
        state: state([0.5, 0.0], [0.0, 12f64.sqrt()]),
    })
}
