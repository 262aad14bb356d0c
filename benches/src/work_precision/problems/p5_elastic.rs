//! P5, a stiff elastic pendulum: m = 1, l0 = 1, k = 1e6, g = 9.81, stretched 1e-3 beyond its
//! static stretch, 0.3 rad from the vertical, at rest, T = 2 s; reference from the tightest run
//! of the library's A-stable Gauss-Legendre 2, with its estimated error.

use crate::problem::{state_error, HandRhs, Problem, Reference};
use crate::real::BenchReal;
use lagrange_core::{Error, Real, Scalar, State};
use lagrange_integrators::{GaussLegendre2, Integrator, Rk4};
use lagrange_systems::ElasticPendulum;

/// Mass, kg.
const M: f64 = 1.0;
/// Rest length, m.
const L0: f64 = 1.0;
/// Stiffness, N/m.
const K: f64 = 1e6;
/// Gravity, m/s^2.
const G: f64 = 9.81;
/// Steps of the finer reference run (the coarser takes half as many).
const REFERENCE_STEPS: u64 = 1 << 19;

/// P5.
pub struct StiffElastic;

/// P5's equations by hand: `r'' = r th'^2 + g cos th - (k / m) (r - l0)`,
/// `th'' = -(2 r' th' + g sin th) / r`.
pub struct ElasticRhs<T> {
    /// `k / m`, 1/s^2.
    k_over_m: T,
    /// Rest length, m.
    l0: T,
    /// Gravity, m/s^2.
    g: T,
}

impl<T: Real> HandRhs<T, 2> for ElasticRhs<T> {
    #[inline]
    fn accelerations(&self, _t: T, q: &[T; 2], qd: &[T; 2], qdd: &mut [T; 2]) {
        let [r, th] = *q;
        let [rd, thd] = *qd;
        let (sin, cos) = Scalar::sin_cos(th);
        *qdd = [
            r * thd * thd + self.g * cos - self.k_over_m * (r - self.l0),
            -(T::TWO * rd * thd + self.g * sin) / r,
        ];
    }
}

impl Problem<2, 4> for StiffElastic {
    type Mech<T: BenchReal> = ElasticPendulum<T>;
    type Hand<T: BenchReal> = ElasticRhs<T>;

    fn id(&self) -> &'static str {
        "P5"
    }
    fn title(&self) -> &'static str {
        "stiff elastic pendulum: m = 1, l0 = 1, k = 1e6, g = 9.81, r0 = 1 + mg/k + 1e-3, \
         th0 = 0.3 at rest, T = 2 s"
    }
    fn mechanism_note(&self) -> &'static str {
        "ElasticPendulum (hand-derived)"
    }
    fn mechanism<T: BenchReal>(&self) -> Result<ElasticPendulum<T>, Error> {
        ElasticPendulum::new(T::real(M), T::real(K), T::real(L0), T::real(G))
    }
    fn hand<T: BenchReal>(&self) -> ElasticRhs<T> {
        ElasticRhs {
            k_over_m: T::real(K / M),
            l0: T::real(L0),
            g: T::real(G),
        }
    }
    fn start(&self) -> State<f64, 2> {
        State::at_rest([L0 + M * G / K + 1e-3, 0.3])
    }
    fn t_end(&self) -> f64 {
        2.0
    }
    fn energy_datum(&self) -> Option<State<f64, 2>> {
        Some(State::at_rest([L0 + M * G / K, 0.0]))
    }
    fn reference(&self) -> Result<Reference<2>, String> {
        // The tightest run of the library's A-stable, fourth-order implicit method (Gauss-
        // Legendre 2, h w = 3.8e-3), its error estimated by Richardson from the run with half
        // as many steps, and checked against RK4 with twice as many.
        let m = self.mechanism::<f64>().map_err(|e| e.to_string())?;
        let (start, t) = (self.start(), self.t_end());
        let gl = |steps: u64| {
            GaussLegendre2::<f64>::default()
                .integrate(&m, &start, t / steps as f64, steps)
                .map_err(|e| e.to_string())
        };
        let coarse = gl(REFERENCE_STEPS / 2)?;
        let fine = gl(REFERENCE_STEPS)?;
        let rk4 = Rk4
            .integrate(
                &m,
                &start,
                t / (2 * REFERENCE_STEPS) as f64,
                2 * REFERENCE_STEPS,
            )
            .map_err(|e| e.to_string())?;
        let estimate = state_error(&coarse, &fine) / 15.0;
        Ok(Reference {
            state: fine,
            source: format!(
                "tightest run of the library's Gauss-Legendre 2 (A-stable implicit, order 4): \
                 {REFERENCE_STEPS} steps, h w = {:.1e}; error estimated by Richardson from \
                 the run with half as many; RK4 with twice as many steps differs by {:.1e}",
                t / REFERENCE_STEPS as f64 * self.fastest_frequency(),
                state_error(&rk4, &fine)
            ),
            error: estimate,
        })
    }
    fn coarsest_dt(&self) -> f64 {
        2e-3
    }
    fn fastest_frequency(&self) -> f64 {
        (K / M).sqrt()
    }
}
