//! Verner's "most efficient" 7(6) pair: order 7 with a sixth-order estimate, for moderate to
//! tight tolerances on any law.

use super::embedded::{EmbeddedPair, EmbeddedRungeKutta};
use super::nystrom::lower_triangular;

/// The "most efficient" Runge-Kutta 7(6) pair of J. H. Verner ("Numerically optimal
/// Runge-Kutta pairs with interpolants", Numer. Algorithms 53, 2010; the coefficients of his
/// web page). Ten stages make a step of order 7 and a sixth-order embedded solution; an
/// eleventh, at `(t0 + h, y1)` (its row is `b`), is the first stage of the next step, so a
/// step costs 10 evaluations. The coefficients are the exact values rounded to the nearest
/// `f64` (evaluated to 60 digits from the rational forms in OrdinaryDiffEq.jl's
/// `verner_tableaus.jl`).
///
/// The pair's own interpolants need more stages; this one uses none
/// ([`EmbeddedPair::HERMITE_DENSE`]).
///
/// The nodes: `c = 0, 0.005, 0.1089, 0.1633, 0.4555, 0.6095, 0.884, 0.925, 1, 1` and `1`
/// (the stage that starts the next step).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Verner76Pair;

/// The nodes.
const C: [f64; 11] = [
    0.0,
    0.005,
    0.10888888888888888,
    0.16333333333333333,
    0.4555,
    0.6095094489978381,
    0.884,
    0.925,
    1.0,
    1.0,
    1.0,
];
/// The stage coefficients, row by row (row 10 is `b`).
const A: [[f64; 11]; 11] = lower_triangular([
    &[],
    &[0.005],
    &[-1.07679012345679, 1.185679012345679],
    &[0.04083333333333333, 0.0, 0.1225],
    &[
        0.6389139236255726,
        0.0,
        -2.455672638223657,
        2.272258714598084,
    ],
    &[
        -2.6615773750187572,
        0.0,
        10.804513886456137,
        -8.3539146573962,
        0.820487594956657,
    ],
    &[
        6.067741434696771,
        0.0,
        -24.711273635911084,
        20.427517930788895,
        -1.9061579788166472,
        1.006172249242068,
    ],
    &[
        12.054670076253203,
        0.0,
        -49.75478495046899,
        41.142888638604674,
        -4.461760149974004,
        2.042334822239175,
        -0.09834843665406108,
    ],
    &[
        10.138146522881808,
        0.0,
        -42.6411360317175,
        35.76384003992257,
        -4.3480228403929075,
        2.0098622683770357,
        0.3487490460338272,
        -0.27143900510483127,
    ],
    &[
        -45.030072034298676,
        0.0,
        187.3272437654589,
        -154.02882369350186,
        18.56465306347536,
        -7.141809679295079,
        1.3088085781613785,
    ],
    &[
        0.04715561848627222,
        0.0,
        0.0,
        0.25750564298434153,
        0.2621665397741262,
        0.15216092656738558,
        0.49399691700324844,
        -0.29430311714032503,
        0.0813174723249511,
    ],
]);
/// `b - b^`: the seventh-order weights less the sixth-order ones.
const E: [f64; 11] = [
    0.0025470118799310456,
    0.0,
    0.0,
    -0.00965839487279575,
    0.0420647097563969,
    -0.0666822437469301,
    0.26500974646212816,
    -0.29430311714032503,
    0.0813174723249511,
    -0.020295184663356284,
    0.0,
];

impl EmbeddedPair<11, 2> for Verner76Pair {
    const NAME: &'static str = "Verner 7(6)";
    const ORDER: u32 = 7;
    const ERROR_EXPONENT: u32 = 7;
    const DENSE_ORDER: u32 = 4;
    const C: [f64; 11] = C;
    const A: [[f64; 11]; 11] = A;
    const FSAL: usize = 10;
    const E: [f64; 11] = E;
    const E3: Option<[f64; 11]> = None;
    const DENSE: [[f64; 11]; 2] = [[0.0; 11]; 2];
    const HERMITE_DENSE: bool = true;
}

/// Adaptive Verner 7(6) with PI step-size control, dense output and events: order 7 for any
/// law, from moderate to tight tolerances.
///
/// Order 7, explicit, adaptive; 10 acceleration evaluations per accepted step (11 stages, the
/// last reused as the next step's first), plus 10 per rejected attempt. Dense output of order
/// 4 at no extra evaluation (the quintic Hermite interpolant through `q`, `q'` and `q''` at
/// both ends: below the steps' order, for plots); an event is located on it and then again
/// on steps of the pair; [`Integrator::step`] lands by a last step shortened to the frame's
/// end. Not symplectic.
///
/// [`Integrator::step`]: crate::Integrator::step
///
/// ```
/// use lagrange_integrators::prelude::*;
/// use lagrange_systems::exact::pendulum_from_rest;
/// use lagrange_systems::SimplePendulum;
/// let p = SimplePendulum::new(1.0, 1.0, 9.81, 0.0)?;
/// let mut vern = Verner76::new(AdaptiveSettings::new(1e-10, 1e-12)?);
/// let end = vern.integrate_to(&p, &State::at_rest([0.5]), 10.0)?;
/// let (th, _) = pendulum_from_rest(0.5, 9.81f64.sqrt(), 10.0)?;
/// assert!((end.q[0] - th).abs() < 1e-9);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
pub type Verner76<T, const N: usize> = EmbeddedRungeKutta<T, N, 11, 2, Verner76Pair>;
