//! Verner's "most efficient" 9(8) pair: order 9 with an eighth-order estimate, for tight
//! tolerances on any law.

use super::embedded::{EmbeddedPair, EmbeddedRungeKutta};
use super::nystrom::lower_triangular;

/// The "most efficient" Runge-Kutta 9(8) pair of J. H. Verner ("Numerically optimal
/// Runge-Kutta pairs with interpolants", Numer. Algorithms 53, 2010; the coefficients of his
/// web page, rationals some of which hold `sqrt(6)`). Sixteen stages make a step of order 9 and
/// an eighth-order embedded solution; a seventeenth, at `(t0 + h, y1)` (its row is `b`), is the
/// first stage of the next step, so a step costs 16 evaluations. The coefficients are the
/// exact values rounded to the nearest `f64` (evaluated to 60 digits from the rational forms
/// in OrdinaryDiffEq.jl's `verner_tableaus.jl`).
///
/// The pair's own interpolants need 10 more stages; this one uses none
/// ([`EmbeddedPair::HERMITE_DENSE`]).
///
/// The nodes: `c = 0, 0.03462, 0.0970, 0.1455, 0.561, 0.2290, 0.5450, 0.645, 0.48375,
/// 0.06757, 0.25, 0.6591, 0.8206, 0.9012, 1, 1` and `1` (the stage that starts the next
/// step).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Verner98Pair;

/// The nodes.
const C: [f64; 17] = [
    0.0,
    0.03462,
    0.09702435063878044,
    0.14553652595817068,
    0.561,
    0.229007911590485,
    0.544992088409515,
    0.645,
    0.48375,
    0.06757,
    0.25,
    0.6590650618730999,
    0.8206,
    0.9012,
    1.0,
    1.0,
    1.0,
];
/// The stage coefficients, row by row (row 16 is `b`).
const A: [[f64; 17]; 17] = lower_triangular([
    &[],
    &[0.03462],
    &[-0.038933543885728734, 0.13595789452450918],
    &[0.03638413148954267, 0.0, 0.109152394468628],
    &[2.02576391439397, 0.0, -7.638023836496292, 6.173259922102322],
    &[
        0.05112275589406061,
        0.0,
        0.0,
        0.17708237945550215,
        0.0008027762409222502,
    ],
    &[
        0.13160063579752163,
        0.0,
        0.0,
        -0.29572762526696367,
        0.08781378035642952,
        0.6213052975225275,
    ],
    &[
        0.07166666666666667,
        0.0,
        0.0,
        0.0,
        0.0,
        0.33055335789153195,
        0.24277997544180138,
    ],
    &[
        0.071806640625,
        0.0,
        0.0,
        0.0,
        0.0,
        0.3294380283228177,
        0.11651900292718229,
        -0.034013671875,
    ],
    &[
        0.04836757646340647,
        0.0,
        0.0,
        0.0,
        0.0,
        0.03928989925676164,
        0.10547409458903446,
        -0.021438652846483126,
        -0.10412291746271944,
    ],
    &[
        -0.026645614872014785,
        0.0,
        0.0,
        0.0,
        0.0,
        0.03333333333333333,
        -0.1631072244872467,
        0.033960816841277615,
        0.1572319413814626,
        0.21522674780318796,
    ],
    &[
        0.036890092487086225,
        0.0,
        0.0,
        0.0,
        0.0,
        -0.1465181576725543,
        0.22425777681720244,
        0.022944057170660725,
        -0.003585005290572876,
        0.08669223316444385,
        0.43838406519683376,
    ],
    &[
        -0.48660122151133406,
        0.0,
        0.0,
        0.0,
        0.0,
        -6.304602650282853,
        -0.2812456182894726,
        -2.6790192362198493,
        0.5188156639241576,
        1.3653531876033418,
        5.8850910885039465,
        2.8028087862720628,
    ],
    &[
        0.41853674577534716,
        0.0,
        0.0,
        0.0,
        0.0,
        6.724547581906459,
        -0.4254442801646118,
        3.3432791530012658,
        0.6170816631175378,
        -0.9299661239399328,
        -6.099948804751011,
        -3.002206187889399,
        0.2553202529443446,
    ],
    &[
        -0.7793740861228846,
        0.0,
        0.0,
        0.0,
        0.0,
        -13.937342538107776,
        1.2520488533793572,
        -14.69150040801687,
        -0.4947050585331417,
        2.2429749091462368,
        13.367893803828643,
        14.396650486650687,
        -0.79758133317768,
        0.4409353709534278,
    ],
    &[
        2.0580513374668863,
        0.0,
        0.0,
        0.0,
        0.0,
        22.357937727968032,
        0.9094981099755634,
        35.89110098240264,
        -3.4425150276244536,
        -4.8654813580363685,
        -18.909803813543427,
        -34.26354448030452,
        1.2647565216956427,
    ],
    &[
        0.014611976858423152,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        -0.3915211862331339,
        0.23109325002895065,
        0.12747667699928525,
        0.2246434176204158,
        0.5684352689748513,
        0.058258715572158275,
        0.13643174034822156,
        0.030570139830827976,
    ],
]);
/// `b - b^`: the ninth-order weights less the eighth-order ones.
const E: [f64; 17] = [
    -0.005357988290444578,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    -2.583020491182464,
    0.14252253154686625,
    0.013420653512688676,
    -0.028672962914094935,
    2.624999655215792,
    -0.2825509643291537,
    0.13643174034822156,
    0.030570139830827976,
    -0.048342313738239585,
    0.0,
];

impl EmbeddedPair<17, 2> for Verner98Pair {
    const NAME: &'static str = "Verner 9(8)";
    const ORDER: u32 = 9;
    const ERROR_EXPONENT: u32 = 9;
    const DENSE_ORDER: u32 = 4;
    const C: [f64; 17] = C;
    const A: [[f64; 17]; 17] = A;
    const FSAL: usize = 16;
    const E: [f64; 17] = E;
    const E3: Option<[f64; 17]> = None;
    const DENSE: [[f64; 17]; 2] = [[0.0; 17]; 2];
    const HERMITE_DENSE: bool = true;
}

/// Adaptive Verner 9(8) with PI step-size control, dense output and events: order 9 for any
/// law, at tight tolerances.
///
/// Order 9, explicit, adaptive; 16 acceleration evaluations per accepted step (17 stages, the
/// last reused as the next step's first), plus 16 per rejected attempt. Dense output of order
/// 4 at no extra evaluation (the quintic Hermite interpolant through `q`, `q'` and `q''` at
/// both ends: far below the steps' order, for plots); an event is located on it and then again
/// on steps of the pair, so that its time and state are as accurate as a step;
/// [`Integrator::step`] lands by a last step shortened to the frame's end. Not symplectic.
///
/// [`Integrator::step`]: crate::Integrator::step
///
/// ```
/// use lagrange_integrators::prelude::*;
/// use lagrange_systems::exact::pendulum_from_rest;
/// use lagrange_systems::SimplePendulum;
/// let p = SimplePendulum::new(1.0, 1.0, 9.81, 0.0)?;
/// let mut vern = Verner98::new(AdaptiveSettings::new(1e-12, 1e-14)?);
/// let end = vern.integrate_to(&p, &State::at_rest([0.5]), 10.0)?;
/// let (th, _) = pendulum_from_rest(0.5, 9.81f64.sqrt(), 10.0)?;
/// assert!((end.q[0] - th).abs() < 1e-10);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
pub type Verner98<T, const N: usize> = EmbeddedRungeKutta<T, N, 17, 2, Verner98Pair>;
