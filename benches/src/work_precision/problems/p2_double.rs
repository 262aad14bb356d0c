//! P2, the chaotic double pendulum: m = l = 1, both angles pi/2 at rest, 10 s; reference from
//! the published 1e-27 solve.

use crate::problem::{HandRhs, Problem, Reference};
use crate::real::BenchReal;
use lagrange_core::{Error, Real, Scalar, State};
use lagrange_systems::DoublePendulum;

/// Gravity, m/s^2.
const G: f64 = 9.81;

/// The published state at T = 10 s (th1, th2, th1', th2'), error about 1e-27.
#[allow(clippy::excessive_precision)]
const PUBLISHED: [f64; 4] = [
    -0.568_474_664_015_950_188_776_113_708_02,
    -0.526_393_727_932_404_698_329_554_193_32,
    6.078_384_885_761_964_854_824_997_286_8,
    -9.681_360_681_708_878_758_076_838_527_3,
];

/// P2.
pub struct ChaoticDouble;

/// P2's equations by hand, for unit masses and rods, as the hand-written RK4 loop writes them:
/// `M = [[2, c], [c, 1]]`, `f = [-s w2^2 - 2 g sin th1, s w1^2 - g sin th2]`, `q'' = M^-1 f` with
/// `s, c` the sine and cosine of `th1 - th2`.
pub struct DoubleRhs<T> {
    /// Gravity, m/s^2.
    g: T,
}

impl<T: Real> HandRhs<T, 2> for DoubleRhs<T> {
    #[inline]
    fn accelerations(&self, _t: T, q: &[T; 2], qd: &[T; 2], qdd: &mut [T; 2]) {
        let [a, b] = *q;
        let [wa, wb] = *qd;
        let (s, c) = Scalar::sin_cos(a - b);
        let f1 = -s * wb * wb - T::TWO * self.g * Scalar::sin(a);
        let f2 = s * wa * wa - self.g * Scalar::sin(b);
        let det = T::TWO - c * c;
        *qdd = [(f1 - c * f2) / det, (T::TWO * f2 - c * f1) / det];
    }
}

impl Problem<2, 4> for ChaoticDouble {
    type Mech<T: BenchReal> = DoublePendulum<T>;
    type Hand<T: BenchReal> = DoubleRhs<T>;

    fn id(&self) -> &'static str {
        "P2"
    }
    fn title(&self) -> &'static str {
        "chaotic double pendulum: m = l = 1, both angles pi/2 at rest, T = 10 s"
    }
    fn mechanism_note(&self) -> &'static str {
        "DoublePendulum (hand-derived)"
    }
    fn mechanism<T: BenchReal>(&self) -> Result<DoublePendulum<T>, Error> {
        let one = T::one();
        DoublePendulum::new(one, one, one, one, T::real(G))
    }
    fn hand<T: BenchReal>(&self) -> DoubleRhs<T> {
        DoubleRhs { g: T::real(G) }
    }
    fn start(&self) -> State<f64, 2> {
        State::at_rest([std::f64::consts::FRAC_PI_2; 2])
    }
    fn t_end(&self) -> f64 {
        10.0
    }
    fn energy_datum(&self) -> Option<State<f64, 2>> {
        Some(State::at_rest([0.0; 2]))
    }
    fn reference(&self) -> Result<Reference<2>, String> {
        let [a, b, c, d] = PUBLISHED;
        Ok(Reference {
            state: State::new(self.t_end(), [a, b], [c, d]),
            source: "published high-precision solve (shared/BENCH_PROBLEMS.md)".into(),
            error: 1e-27,
        })
    }
    fn coarsest_dt(&self) -> f64 {
        0.05
    }
    fn fastest_frequency(&self) -> f64 {
        // The faster normal mode of the unit double pendulum: w^2 = (2 + sqrt 2) g / l.
        ((2.0 + std::f64::consts::SQRT_2) * G).sqrt()
    }
    fn python_rhs(&self) -> Option<&'static str> {
        // Unit masses and rods, G as above: M = [[2, c], [c, 1]], the same closed-form
        // inverse as the hand-written loop.
        Some(
            "def rhs(t, y):\n\
             \x20   a, b, wa, wb = y\n\
             \x20   s, c = math.sin(a - b), math.cos(a - b)\n\
             \x20   f1 = -s * wb * wb - 2.0 * 9.81 * math.sin(a)\n\
             \x20   f2 = s * wa * wa - 9.81 * math.sin(b)\n\
             \x20   det = 2.0 - c * c\n\
             \x20   return [wa, wb, (f1 - c * f2) / det, (2.0 * f2 - c * f1) / det]\n",
        )
    }
    fn hand_rk4<T: BenchReal>(&self, s: &State<T, 2>, dt: T, steps: u64) -> Option<State<T, 2>> {
        let [a, b, c, d] = T::hand_rk4_double(G, [s.q[0], s.q[1], s.qd[0], s.qd[1]], dt, steps);
        Some(State::new(s.t + dt * T::real(steps as f64), [a, b], [c, d]))
    }
}
