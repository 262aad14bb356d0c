//! Dormand, El-Mikkawy and Prince's Runge-Kutta-Nyström 6(4): a Nyström pair for laws
//! `q'' = f(t, q)` at moderate tolerances.

use super::embedded::{EmbeddedPair, EmbeddedRungeKutta};
use super::nystrom::{lower_triangular, Nystrom};

/// The Runge-Kutta-Nyström 6(4) pair of Dormand, El-Mikkawy and Prince ("Families of
/// Runge-Kutta-Nyström formulae", IMA J. Numer. Anal. 7, 1987, the improved 6(4) "FM"
/// pair), for laws that do not read `q'` ([`Nystrom`]). Six stages make a step of order 6,
/// the sixth at `(t0 + h, y1)` (its position row is `b`) starting the next step; a
/// fourth-order embedded solution estimates the error. The coefficients are the published
/// rationals rounded to the nearest `f64`.
///
/// ```text
///   c   | abar (position rows, h^2 scale)
///  0    |
///  1/10 | 1/200
///  3/10 | -1/2200      1/22
///  7/10 | 637/6600     -7/110        7/33
/// 17/25 | 225437/1968750 -30073/281250 65569/281250 -9367/984375
///  1    | 151/2142     5/116         385/1368      55/168      -6250/28101    <- b
///  b'   | 151/2142     25/522        275/684       275/252     -78125/112404  1/12
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Nystrom64Pair;

const C: [f64; 6] = [0.0, 0.1, 0.3, 0.7, 0.68, 1.0];
const ABAR: [[f64; 6]; 6] = lower_triangular([
    &[],
    &[0.005],
    &[-0.00045454545454545455, 0.045454545454545456],
    &[
        0.09651515151515151,
        -0.06363636363636363,
        0.21212121212121213,
    ],
    &[
        0.11450768253968253,
        -0.10692622222222223,
        0.23313422222222221,
        -0.00951568253968254,
    ],
    &[
        0.07049486461251167,
        0.04310344827586207,
        0.2814327485380117,
        0.3273809523809524,
        -0.22241201380733783,
    ],
]);
/// `A`: only the row of the stage at `(t0 + h, y1)`, the velocity weights `b'`.
const A: [[f64; 6]; 6] = {
    let mut a = [[0.0; 6]; 6];
    a[5] = [
        0.07049486461251167,
        0.04789272030651341,
        0.402046783625731,
        1.0912698412698412,
        -0.6950375431479306,
        0.08333333333333333,
    ];
    a
};
const E_Q: [f64; 6] = [
    0.061929785247432305,
    -0.11435655172413793,
    0.06787830409356725,
    0.07896047619047619,
    -0.09441201380733781,
    0.0,
];
const E_V: [f64; 6] = [
    0.061929785247432305,
    -0.12706283524904213,
    0.09696900584795322,
    0.2632015873015873,
    -0.2950375431479307,
    0.0,
];

impl EmbeddedPair<6, 2> for Nystrom64Pair {
    const NAME: &'static str = "Dormand-Prince Nystrom 6(4)";
    const ORDER: u32 = 6;
    const ERROR_EXPONENT: u32 = 5;
    const DENSE_ORDER: u32 = 4;
    const C: [f64; 6] = C;
    const A: [[f64; 6]; 6] = A;
    const FSAL: usize = 5;
    const E: [f64; 6] = E_V;
    const E3: Option<[f64; 6]> = None;
    const DENSE: [[f64; 6]; 2] = [[0.0; 6]; 2];
    const NYSTROM: Option<Nystrom<6>> = Some(Nystrom { abar: ABAR, e: E_Q });
}

/// Adaptive Runge-Kutta-Nyström 6(4) with PI step-size control, dense output and events, for
/// mechanisms whose law does not read the velocities ([`Mechanism::reads_velocities`]
/// `false`: an undamped pendulum, bodies under gravity, springs); it refuses any other
/// mechanism with [`Error::InvalidParameter`] `mechanism`.
///
/// Order 6 (the slope of the global error against a fixed step measures 6.04 on the
/// pendulum), explicit, adaptive; 5 acceleration evaluations per accepted step (6 stages, the
/// last reused as the next step's first), plus 5 per rejected attempt. Dense output of order
/// 4 at no extra evaluation (the quintic Hermite interpolant); [`Integrator::step`] lands by
/// a last step shortened to the frame's end. Not symplectic. At tolerances of about `1e-4` to
/// `1e-9` it needs fewer evaluations for the same error than the Dormand-Prince pairs, which
/// spend stages on the velocity equation's order that such a law does not need; tighter, use
/// [`DormandPrinceNystrom1210`](crate::DormandPrinceNystrom1210).
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
/// let mut rkn = DormandPrinceNystrom64::new(AdaptiveSettings::new(1e-9, 1e-11)?);
/// let end = rkn.integrate_to(&p, &State::at_rest([0.5]), 10.0)?;
/// let (th, _) = pendulum_from_rest(0.5, 9.81f64.sqrt(), 10.0)?;
/// assert!((end.q[0] - th).abs() < 1e-8);
/// // A damped pendulum's law reads its velocity: refused.
/// let damped = SimplePendulum::new(1.0, 1.0, 9.81, 0.1)?;
/// assert!(rkn.integrate_to(&damped, &State::at_rest([0.5]), 10.0).is_err());
/// # Ok::<(), lagrange_core::Error>(())
/// ```
pub type DormandPrinceNystrom64<T, const N: usize> = EmbeddedRungeKutta<T, N, 6, 2, Nystrom64Pair>;
