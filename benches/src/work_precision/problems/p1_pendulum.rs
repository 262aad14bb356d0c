//! P1, the origin's pendulum: L = 1 m, g = 9.81 m/s^2, 30 degrees at rest, 10 s; exact
//! reference from the Jacobi elliptic solution.

use crate::problem::{HandRhs, Problem, Reference};
use crate::real::BenchReal;
use lagrange_core::{Error, Real, Scalar, State};
use lagrange_systems::exact::pendulum_from_rest;
use lagrange_systems::SimplePendulum;

/// Gravity, m/s^2.
const G: f64 = 9.81;
/// Release angle, rad.
const TH0: f64 = std::f64::consts::FRAC_PI_6;
/// The published state at T = 10 s (shared/BENCH_PROBLEMS.md), to check the exact solution.
#[allow(clippy::excessive_precision)]
const PUBLISHED: [f64; 2] = [
    0.423_644_515_500_648_239_467_574_017_94,
    0.945_574_218_564_063_669_918_578_389_53,
];

/// P1.
pub struct OriginPendulum;

/// P1's equation by hand: `th'' = -(g / l) sin th`.
pub struct PendulumRhs<T> {
    /// `g / l`, 1/s^2.
    w2: T,
}

impl<T: Real> HandRhs<T, 1> for PendulumRhs<T> {
    #[inline]
    fn accelerations(&self, _t: T, q: &[T; 1], _qd: &[T; 1], qdd: &mut [T; 1]) {
        qdd[0] = -self.w2 * Scalar::sin(q[0]);
    }
}

impl Problem<1, 2> for OriginPendulum {
    type Mech<T: BenchReal> = SimplePendulum<T>;
    type Hand<T: BenchReal> = PendulumRhs<T>;

    fn id(&self) -> &'static str {
        "P1"
    }
    fn title(&self) -> &'static str {
        "origin's pendulum: L = 1, g = 9.81, 30 deg at rest, T = 10 s"
    }
    fn mechanism_note(&self) -> &'static str {
        "SimplePendulum (hand-derived)"
    }
    fn mechanism<T: BenchReal>(&self) -> Result<SimplePendulum<T>, Error> {
        SimplePendulum::new(T::one(), T::one(), T::real(G), T::zero())
    }
    fn hand<T: BenchReal>(&self) -> PendulumRhs<T> {
        PendulumRhs { w2: T::real(G) }
    }
    fn start(&self) -> State<f64, 1> {
        State::at_rest([TH0])
    }
    fn t_end(&self) -> f64 {
        10.0
    }
    fn energy_datum(&self) -> Option<State<f64, 1>> {
        Some(State::at_rest([0.0]))
    }
    fn reference(&self) -> Result<Reference<1>, String> {
        let (th, thd) =
            pendulum_from_rest(TH0, G.sqrt(), self.t_end()).map_err(|e| e.to_string())?;
        // The Jacobi solution evaluates sn at u = K - w T ~ -29, so its own error is about
        // |u| eps; the published 1e-27 digits measure it.
        let error = (th - PUBLISHED[0]).abs().max((thd - PUBLISHED[1]).abs());
        Ok(Reference {
            state: State::new(self.t_end(), [th], [thd]),
            source: "exact: Jacobi elliptic sn/cn (error = distance to the published 1e-27 digits)"
                .into(),
            error,
        })
    }
    fn coarsest_dt(&self) -> f64 {
        0.1
    }
    fn fastest_frequency(&self) -> f64 {
        G.sqrt()
    }
    fn python_rhs(&self) -> Option<&'static str> {
        // G and L = 1 as above.
        Some("def rhs(t, y):\n    return [y[1], -9.81 * math.sin(y[0])]\n")
    }
    fn hand_rk4<T: BenchReal>(&self, s: &State<T, 1>, dt: T, steps: u64) -> Option<State<T, 1>> {
        let [th, thd] = T::hand_rk4_pendulum(G, [s.q[0], s.qd[0]], dt, steps);
        Some(State::new(s.t + dt * T::real(steps as f64), [th], [thd]))
    }
}
