//! Dormand-Prince 5(4): the pair of `ode45` and DOPRI5, with Shampine's dense output.

use super::embedded::{EmbeddedPair, EmbeddedRungeKutta};

/// The Dormand-Prince 5(4) pair (Dormand and Prince 1980; dense output as in Hairer's
/// DOPRI5). The seventh stage is at `(t0 + h, y1)`: its row is `b`, and its derivative is the
/// first stage of the next step.
///
/// ```text
///   0  |
///  1/5 | 1/5
/// 3/10 | 3/40        9/40
///  4/5 | 44/45      -56/15       32/9
///  8/9 | 19372/6561 -25360/2187  64448/6561 -212/729
///   1  | 9017/3168  -355/33      46732/5247  49/176  -5103/18656
///   1  | 35/384      0           500/1113    125/192 -2187/6784    11/84
/// -----+---------------------------------------------------------------------------
///  b   | 35/384      0           500/1113    125/192 -2187/6784    11/84     0
///  e   | 71/57600    0          -71/16695    71/1920 -17253/339200 22/525   -1/40
///  d   | -12715105075/11282082432  0  87487479700/32700410799
///      | -10690763975/1880347072  701980252875/199316789632
///      | -1453857185/822651844  69997945/29380423
/// ```
///
/// `e = b - b^` (`b^` the fourth-order weights), `d` the dense row (Shampine 1986).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Dopri5Pair;

/// The rows of `A`; the last is `b`.
const A: [[f64; 7]; 7] = [
    [0.0; 7],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
        0.0,
    ],
];

impl EmbeddedPair<7, 1> for Dopri5Pair {
    const NAME: &'static str = "Dormand-Prince 5(4)";
    const ORDER: u32 = 5;
    const ERROR_EXPONENT: u32 = 5;
    const DENSE_ORDER: u32 = 4;
    const C: [f64; 7] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
    const A: [[f64; 7]; 7] = A;
    const FSAL: usize = 6;
    const E: [f64; 7] = [
        71.0 / 57600.0,
        0.0,
        -71.0 / 16695.0,
        71.0 / 1920.0,
        -17253.0 / 339200.0,
        22.0 / 525.0,
        -1.0 / 40.0,
    ];
    const E3: Option<[f64; 7]> = None;
    const DENSE: [[f64; 7]; 1] = [[
        -12715105075.0 / 11282082432.0,
        0.0,
        87487479700.0 / 32700410799.0,
        -10690763975.0 / 1880347072.0,
        701980252875.0 / 199316789632.0,
        -1453857185.0 / 822651844.0,
        69997945.0 / 29380423.0,
    ]];
}

/// Adaptive Dormand-Prince 5(4) with PI step-size control, dense output and events.
///
/// Order 5 (local extrapolation: the fifth-order solution is propagated, the fourth-order one
/// only estimates the error), explicit, adaptive; 6 acceleration evaluations per accepted step
/// (7 stages, the last reused as the next step's first), plus 6 per rejected attempt. Dense
/// output of order 4 at no extra evaluation. Not symplectic: over long conservative runs the
/// energy error drifts, in proportion to the tolerance. The general-purpose choice for
/// tolerances from about `1e-3` to `1e-8`; tighter, use
/// [`DormandPrince853`](crate::DormandPrince853).
///
/// ```
/// use lagrange_integrators::prelude::*;
/// use lagrange_systems::SimplePendulum;
/// let p = SimplePendulum::new(1.0_f64, 1.0, 9.81, 0.0)?;
/// let mut dp = DormandPrince54::new(AdaptiveSettings::new(1e-8, 1e-10)?);
/// let end = dp.integrate_to(&p, &State::at_rest([0.5]), 10.0)?;
/// assert_eq!(end.t, 10.0);
/// // One more step of the controller's choosing, and a sample inside it.
/// let next = dp.next_step(&p, &end, 20.0)?;
/// let midway = dp.dense_output(0.5 * (end.t + next.t))?;
/// assert!(midway.t > end.t && midway.t < next.t);
/// // As an integrator, it lands on a frame's time through its dense output.
/// let frame = dp.step(&p, &next, 1.0 / 60.0)?;
/// assert_eq!(frame.t, next.t + 1.0 / 60.0);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
pub type DormandPrince54<T, const N: usize> = EmbeddedRungeKutta<T, N, 7, 1, Dopri5Pair>;
