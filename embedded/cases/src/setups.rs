//! [`Setup`]: a mechanism with its parameters, initial state and step size, and the setups of
//! the lockstep cases.

use core::hint::black_box;

use lagrange_core::{Error, EulerLagrange, Mechanism, Real, State};
use lagrange_systems::{CartPole, DoublePendulum, SimplePendulum};

use crate::LibmTrigPendulum;

/// A mechanism, its initial state and step size: the "what" of a lockstep case.
pub trait Setup<T: Real, const N: usize> {
    /// The mechanism built.
    type Mechanism: Mechanism<T, N>;
    /// Name in logs and tables.
    const NAME: &'static str;
    /// Step size, s.
    const DT: f64;
    /// The mechanism and its initial state.
    ///
    /// # Errors
    /// The mechanism constructor's.
    fn build() -> Result<(Self::Mechanism, State<T, N>), Error>;
}

/// The origin's pendulum: L = 1 m, m = 1 kg, g = 9.81 m/s^2, undamped, released at rest from
/// 30 degrees; 1 ms steps.
pub struct PendulumSetup;

/// The pendulum of [`PendulumSetup`] for any scalar.
fn origin_pendulum<T: Real>() -> Result<(SimplePendulum<T>, State<T, 1>), Error> {
    let p = SimplePendulum::new(
        black_box(T::one()),
        black_box(T::one()),
        black_box(T::from_f64(9.81)),
        black_box(T::zero()),
    )?;
    Ok((
        p,
        State::at_rest([T::from_f64(core::f64::consts::FRAC_PI_6)]),
    ))
}

impl<T: Real> Setup<T, 1> for PendulumSetup {
    type Mechanism = SimplePendulum<T>;
    const NAME: &'static str = "pendulum";
    const DT: f64 = 1e-3;
    fn build() -> Result<(SimplePendulum<T>, State<T, 1>), Error> {
        origin_pendulum()
    }
}

/// [`PendulumSetup`] with `libm::sinf` ([`LibmTrigPendulum`]), in `f32` only.
pub struct LibmTrigPendulumSetup;

impl Setup<f32, 1> for LibmTrigPendulumSetup {
    type Mechanism = LibmTrigPendulum;
    const NAME: &'static str = "pendulum (libm sinf)";
    const DT: f64 = 1e-3;
    fn build() -> Result<(LibmTrigPendulum, State<f32, 1>), Error> {
        origin_pendulum().map(|(p, s)| (LibmTrigPendulum(p), s))
    }
}

/// A chaotic double pendulum: unit masses and rods, g = 9.81 m/s^2, both links horizontal
/// (`th1 = th2 = pi/2`) at rest; 1 ms steps.
pub struct DoublePendulumSetup;

impl<T: Real> Setup<T, 2> for DoublePendulumSetup {
    type Mechanism = DoublePendulum<T>;
    const NAME: &'static str = "double pendulum";
    const DT: f64 = 1e-3;
    fn build() -> Result<(DoublePendulum<T>, State<T, 2>), Error> {
        let one = black_box(T::one());
        let dp = DoublePendulum::new(one, one, one, one, black_box(T::from_f64(9.81)))?;
        let half_pi = T::from_f64(core::f64::consts::FRAC_PI_2);
        Ok((dp, State::at_rest([half_pi, half_pi])))
    }
}

/// The classic cart-pole (cart 1 kg, pole 0.1 kg of half-length 0.5 m, g = 9.8 m/s^2) with a
/// constant 1 N push on the cart, released at rest with the pole 0.3 rad from upright: it
/// falls through the bottom and swings; 1 ms steps.
pub struct CartPoleSetup;

/// The cart-pole of [`CartPoleSetup`] for any scalar.
fn cart_pole<T: Real>() -> Result<(CartPole<T>, State<T, 2>), Error> {
    let v = |x: f64| black_box(T::from_f64(x));
    let mut cp = CartPole::new(v(1.0), v(0.1), v(0.5), v(9.8))?;
    cp.set_force(v(1.0))?;
    Ok((cp, State::at_rest([T::zero(), T::from_f64(0.3)])))
}

impl<T: Real> Setup<T, 2> for CartPoleSetup {
    type Mechanism = CartPole<T>;
    const NAME: &'static str = "cart-pole";
    const DT: f64 = 1e-3;
    fn build() -> Result<(CartPole<T>, State<T, 2>), Error> {
        cart_pole()
    }
}

/// [`CartPoleSetup`] through the automatic Euler-Lagrange path ([`EulerLagrange`]), which the
/// variational integrator needs (it works on the Lagrangian, in dual numbers).
pub struct CartPoleLagrangianSetup;

impl<T: Real> Setup<T, 2> for CartPoleLagrangianSetup {
    type Mechanism = EulerLagrange<T, 2, CartPole<T>>;
    const NAME: &'static str = "cart-pole (automatic)";
    const DT: f64 = 1e-3;
    fn build() -> Result<(EulerLagrange<T, 2, CartPole<T>>, State<T, 2>), Error> {
        cart_pole().map(|(cp, s)| (EulerLagrange::new(cp), s))
    }
}
