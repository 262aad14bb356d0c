//! P4, a Kepler orbit: mu = 1, e = 0.5, a = 1 from periapsis over 100 periods (T = 200 pi);
//! exact reference from Kepler's equation.

use crate::bench::problem::{Problem, Reference};
use crate::bench::real::BenchReal;
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, EulerLagrange, Lagrangian, Real, Scalar, State};
use std::f64::consts::PI;

/// Gravitational parameter.
const MU: f64 = 1.0;
/// Eccentricity.
const E: f64 = 0.5;
/// Semi-major axis.
const A: f64 = 1.0;
/// The published final angle 200 pi, to check the exact solution.
#[allow(clippy::excessive_precision)]
const PUBLISHED_PHI: f64 = 628.318_530_717_958_647_69;

/// Unit mass in the plane about a centre of attraction `mu`, polar coordinates `[r, phi]`:
///
/// ```text
/// T = (r'^2 + r^2 phi'^2) / 2,   V = -mu / r
/// ```
///
/// Until a hand-derived `Kepler` lands, P4 runs through `EulerLagrange` on this (automatic
/// path: provisional timings).
#[derive(Debug, Clone, Copy)]
pub struct KeplerLagrangian<T> {
    mu: T,
}

impl<T: Real> Lagrangian<T, 2> for KeplerLagrangian<T> {
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 2>, qd: &SVector<S, 2>) -> S {
        S::from_f64(0.5) * (qd[0] * qd[0] + q[0] * q[0] * qd[1] * qd[1])
    }
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 2>) -> S {
        -S::from_real(self.mu) / q[0]
    }
}

/// The Kepler mechanism the bench runs.
pub type KeplerMechanism<T> = EulerLagrange<KeplerLagrangian<T>>;

/// The exact state at time `t` of the orbit that is at periapsis at `t = 0`: solve Kepler's
/// equation `E - e sin E = M` (mean anomaly `M = n t` reduced to `[-pi, pi]`, whole turns
/// kept) by Newton's method, then
///
/// ```text
/// r    = a (1 - e cos E),        nu = 2 atan2(sqrt(1+e) sin(E/2), sqrt(1-e) cos(E/2))
/// phi  = nu + 2 pi turns,        r' = sqrt(mu a) e sin E / r,   phi' = sqrt(mu a (1-e^2)) / r^2
/// ```
pub fn kepler_state(t: f64) -> State<f64, 2> {
    let n = (MU / (A * A * A)).sqrt();
    let mean = n * t;
    let turns = (mean / (2.0 * PI)).round();
    let m = mean - 2.0 * PI * turns;
    let mut ecc = if E < 0.8 { m } else { PI.copysign(m) };
    for _ in 0..50 {
        let step = (ecc - E * ecc.sin() - m) / (1.0 - E * ecc.cos());
        ecc -= step;
        if step.abs() < 1e-17 {
            break;
        }
    }
    let r = A * (1.0 - E * ecc.cos());
    let nu =
        2.0 * ((1.0 + E).sqrt() * (0.5 * ecc).sin()).atan2((1.0 - E).sqrt() * (0.5 * ecc).cos());
    State::new(
        t,
        [r, nu + 2.0 * PI * turns],
        [
            (MU * A).sqrt() * E * ecc.sin() / r,
            (MU * A * (1.0 - E * E)).sqrt() / (r * r),
        ],
    )
}

/// P4.
pub struct KeplerOrbit;

impl Problem<2, 4> for KeplerOrbit {
    type Mech<T: BenchReal> = KeplerMechanism<T>;

    fn id(&self) -> &'static str {
        "P4"
    }
    fn title(&self) -> &'static str {
        "Kepler orbit: mu = 1, e = 0.5, a = 1, from periapsis, 100 periods (T = 200 pi)"
    }
    fn mechanism_note(&self) -> &'static str {
        "EulerLagrange on a bench-local Kepler Lagrangian (automatic path; provisional \
         timings until Kepler lands)"
    }
    fn mechanism<T: BenchReal>(&self) -> Result<KeplerMechanism<T>, Error> {
        Ok(EulerLagrange::new(KeplerLagrangian { mu: T::real(MU) }))
    }
    fn start(&self) -> State<f64, 2> {
        kepler_state(0.0)
    }
    fn t_end(&self) -> f64 {
        200.0 * PI
    }
    fn energy_datum(&self) -> Option<State<f64, 2>> {
        None
    }
    fn reference(&self) -> Result<Reference<2>, String> {
        let state = kepler_state(self.t_end());
        let start = self.start();
        // At 100 whole periods the exact state is the start with phi advanced by 200 pi.
        let error = (state.q[1] - PUBLISHED_PHI)
            .abs()
            .max((state.q[0] - start.q[0]).abs())
            .max((state.qd[0] - start.qd[0]).abs())
            .max((state.qd[1] - start.qd[1]).abs());
        Ok(Reference {
            state,
            source: "exact: Kepler's equation by Newton (error = distance to the published \
                     state)"
                .into(),
            error,
        })
    }
    fn coarsest_dt(&self) -> f64 {
        0.1
    }
    fn fastest_frequency(&self) -> f64 {
        // The angular rate at periapsis, sqrt(mu a (1 - e^2)) / r_p^2.
        (MU * A * (1.0 - E * E)).sqrt() / (A * (1.0 - E)).powi(2)
    }
}
