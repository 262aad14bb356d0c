//! P4, a Kepler orbit: mu = 1, e = 0.5, a = 1 from periapsis over 100 periods (T = 200 pi);
//! exact reference from Kepler's equation.

use crate::problem::{HandRhs, Problem, Reference};
use crate::real::BenchReal;
use lagrange_core::{Error, Real, State};
use lagrange_systems::exact::kepler_orbit;
use lagrange_systems::Kepler;
use std::f64::consts::PI;

/// Gravitational parameter.
const MU: f64 = 1.0;
/// Eccentricity.
const E: f64 = 0.5;
/// Semi-major axis.
const A: f64 = 1.0;
/// The start's angular rate, `sqrt(mu (1 + e) / (a (1 - e))) / (a (1 - e)) = 2 sqrt 3`.
#[allow(clippy::excessive_precision)]
const PERIAPSIS_RATE: f64 = 3.464_101_615_137_754_587_1;
/// The published final angle 200 pi, to check the exact solution.
#[allow(clippy::excessive_precision)]
const PUBLISHED_PHI: f64 = 628.318_530_717_958_647_69;

/// P4.
pub struct KeplerOrbit;

/// P4's equations by hand, in polar coordinates: `r'' = r phi'^2 - mu / r^2`,
/// `phi'' = -2 r' phi' / r`.
pub struct KeplerRhs<T> {
    /// Gravitational parameter.
    mu: T,
}

impl<T: Real> HandRhs<T, 2> for KeplerRhs<T> {
    #[inline]
    fn accelerations(&self, _t: T, q: &[T; 2], qd: &[T; 2], qdd: &mut [T; 2]) {
        let r = q[0];
        let [rd, phid] = *qd;
        *qdd = [r * phid * phid - self.mu / (r * r), -T::TWO * rd * phid / r];
    }
}

impl Problem<2, 4> for KeplerOrbit {
    type Mech<T: BenchReal> = Kepler<T>;
    type Hand<T: BenchReal> = KeplerRhs<T>;

    fn id(&self) -> &'static str {
        "P4"
    }
    fn title(&self) -> &'static str {
        "Kepler orbit: mu = 1, e = 0.5, a = 1, from periapsis, 100 periods (T = 200 pi)"
    }
    fn mechanism_note(&self) -> &'static str {
        "Kepler (hand-derived)"
    }
    fn mechanism<T: BenchReal>(&self) -> Result<Kepler<T>, Error> {
        Kepler::new(T::real(MU))
    }
    fn hand<T: BenchReal>(&self) -> KeplerRhs<T> {
        KeplerRhs { mu: T::real(MU) }
    }
    fn start(&self) -> State<f64, 2> {
        State::new(0.0, [A * (1.0 - E), 0.0], [0.0, PERIAPSIS_RATE])
    }
    fn t_end(&self) -> f64 {
        200.0 * PI
    }
    fn energy_datum(&self) -> Option<State<f64, 2>> {
        None
    }
    fn reference(&self) -> Result<Reference<2>, String> {
        let state = kepler_orbit(MU, A, E, self.t_end()).map_err(|e| e.to_string())?;
        let start = self.start();
        // At 100 whole periods the exact state is the start with phi advanced by 200 pi.
        let error = (state.q[1] - PUBLISHED_PHI)
            .abs()
            .max((state.q[0] - start.q[0]).abs())
            .max((state.qd[0] - start.qd[0]).abs())
            .max((state.qd[1] - start.qd[1]).abs());
        Ok(Reference {
            state,
            source: "exact: Kepler's equation (lagrange_systems::exact::kepler_orbit; error = \
                     distance to the published state)"
                .into(),
            error,
        })
    }
    fn coarsest_dt(&self) -> f64 {
        0.1
    }
    fn python_rhs(&self) -> Option<&'static str> {
        // Polar coordinates (r, phi) with MU = 1, as `Kepler`:
        // r'' = r phi'^2 - mu / r^2, phi'' = -2 r' phi' / r.
        Some(
            "def rhs(t, y):\n\
             \x20   r, phi, rd, phid = y\n\
             \x20   return [rd, phid, r * phid * phid - 1.0 / (r * r), -2.0 * rd * phid / r]\n",
        )
    }
    fn fastest_frequency(&self) -> f64 {
        // The angular rate at periapsis, sqrt(mu a (1 - e^2)) / r_p^2.
        (MU * A * (1.0 - E * E)).sqrt() / (A * (1.0 - E)).powi(2)
    }
}
