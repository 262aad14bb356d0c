//! Dormand, El-Mikkawy and Prince's Runge-Kutta-Nyström 8(6): a Nyström pair for laws
//! `q'' = f(t, q)` between the 6(4) and the 12(10) pairs.

use super::embedded::{EmbeddedPair, EmbeddedRungeKutta};
use super::nystrom::{lower_triangular, Nystrom};

/// The Runge-Kutta-Nyström 8(6) pair of Dormand, El-Mikkawy and Prince ("High-order embedded
/// Runge-Kutta-Nyström formulae", IMA J. Numer. Anal. 7, 1987), for laws that do not read
/// `q'` ([`Nystrom`]). Nine stages make a step of order 8, the ninth at `(t0 + h, y1)` (its
/// position row is `b`) starting the next step, so a step costs 8 evaluations; a sixth-order
/// embedded solution estimates the error (its velocity weights use the ninth stage). The
/// coefficients are the published rationals rounded to the nearest `f64`.
///
/// The nodes: `c = 0, 1/20, 1/10, 3/10, 1/2, 7/10, 9/10, 1` and `1` (the stage that starts the
/// next step).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Nystrom86Pair;

const C: [f64; 9] = [0.0, 0.05, 0.1, 0.3, 0.5, 0.7, 0.9, 1.0, 1.0];
const ABAR: [[f64; 9]; 9] = lower_triangular([
    &[],
    &[0.00125],
    &[0.0016666666666666668, 0.0033333333333333335],
    &[0.045, -0.09, 0.09],
    &[
        -0.3379798532571243,
        0.8611516478170984,
        -0.48613644655235316,
        0.0879646519923791,
    ],
    &[
        0.7461462641043086,
        -1.804347430246737,
        1.2761518285888953,
        -0.031220932716737166,
        0.05827027027027027,
    ],
    &[
        -1.2551623461807584,
        3.257463187064823,
        -2.068866619575089,
        0.4206478455603251,
        -0.018382978723404254,
        0.06930091185410335,
    ],
    &[
        3.772901830095941,
        -9.669613121677195,
        6.7991544547851674,
        -0.8490343907823893,
        0.4671734865470852,
        -0.04939742152466368,
        0.028815162556053812,
    ],
    &[
        0.028092718568909044,
        0.0,
        0.1457093253968254,
        0.1529431216931217,
        0.09151785714285714,
        0.06554705215419501,
        0.01618992504409171,
        0.0,
    ],
]);
/// `A`: only the row of the stage at `(t0 + h, y1)`, the velocity weights `b'`.
const A: [[f64; 9]; 9] = {
    let mut a = [[0.0; 9]; 9];
    a[8] = [
        0.028092718568909044,
        0.0,
        0.1618992504409171,
        0.2184901738473167,
        0.18303571428571427,
        0.2184901738473167,
        0.1618992504409171,
        0.028092718568909044,
        0.0,
    ];
    a
};
const E_Q: [f64; 9] = [
    -0.044557986852984274,
    0.0,
    0.10965442077101599,
    -0.14620589436135464,
    0.1315853049252192,
    -0.06265966901200913,
    0.012183824530112887,
    0.0,
    0.0,
];
const E_V: [f64; 9] = [
    -0.044557986852984274,
    0.0,
    0.12183824530112887,
    -0.2088655633733638,
    0.2631706098504384,
    -0.2088655633733638,
    0.12183824530112887,
    0.10544201314701572,
    -0.15,
];

impl EmbeddedPair<9, 2> for Nystrom86Pair {
    const NAME: &'static str = "Dormand-Prince Nystrom 8(6)";
    const ORDER: u32 = 8;
    const ERROR_EXPONENT: u32 = 7;
    const DENSE_ORDER: u32 = 4;
    const C: [f64; 9] = C;
    const A: [[f64; 9]; 9] = A;
    const FSAL: usize = 8;
    const E: [f64; 9] = E_V;
    const E3: Option<[f64; 9]> = None;
    const DENSE: [[f64; 9]; 2] = [[0.0; 9]; 2];
    const NYSTROM: Option<Nystrom<9>> = Some(Nystrom { abar: ABAR, e: E_Q });
}

/// Adaptive Runge-Kutta-Nyström 8(6) with PI step-size control, dense output and events, for
/// mechanisms whose law does not read the velocities ([`Mechanism::reads_velocities`]
/// `false`); it refuses any other mechanism with [`Error::InvalidParameter`] `mechanism`.
///
/// Order 8, explicit, adaptive; 8 acceleration evaluations per accepted step (9 stages, the
/// last reused as the next step's first), plus 8 per rejected attempt. Dense output of order
/// 4 at no extra evaluation (the quintic Hermite interpolant); an event is located on it and
/// then again on steps of the pair; [`Integrator::step`] lands by a last step shortened to
/// the frame's end. Not symplectic. Between
/// [`DormandPrinceNystrom64`](crate::DormandPrinceNystrom64) and
/// [`DormandPrinceNystrom1210`](crate::DormandPrinceNystrom1210): tolerances of about `1e-6`
/// to `1e-10`.
///
/// [`Mechanism::reads_velocities`]: lagrange_core::Mechanism::reads_velocities
/// [`Error::InvalidParameter`]: lagrange_core::Error::InvalidParameter
/// [`Integrator::step`]: crate::Integrator::step
///
/// ```
/// use lagrange_integrators::prelude::*;
/// use lagrange_systems::exact::pendulum_from_rest;
/// use lagrange_systems::SimplePendulum;
/// let p = SimplePendulum::new(1.0, 1.0, 9.81, 0.0)?;
/// let mut rkn = DormandPrinceNystrom86::new(AdaptiveSettings::new(1e-10, 1e-12)?);
/// let end = rkn.integrate_to(&p, &State::at_rest([0.5]), 10.0)?;
/// let (th, _) = pendulum_from_rest(0.5, 9.81f64.sqrt(), 10.0)?;
/// assert!((end.q[0] - th).abs() < 1e-9);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
pub type DormandPrinceNystrom86<T, const N: usize> = EmbeddedRungeKutta<T, N, 9, 2, Nystrom86Pair>;
