//! Dormand, El-Mikkawy and Prince's Runge-Kutta-Nyström 12(10): a Nyström pair for laws
//! `q'' = f(t, q)` at tight tolerances.

use super::embedded::{EmbeddedPair, EmbeddedRungeKutta};
use super::nystrom::{lower_triangular, Nystrom};

/// The Runge-Kutta-Nyström 12(10) pair of Dormand, El-Mikkawy and Prince ("High-order
/// embedded Runge-Kutta-Nyström formulae", IMA J. Numer. Anal. 7, 1987), for laws that do
/// not read `q'` ([`Nystrom`]). Seventeen stages make a step of order 12 and a tenth-order
/// embedded solution; an eighteenth, at `(t0 + h, y1)` (its position row is `b`, its
/// velocity row `b'`), is the first stage of the next step, so a step costs 17 evaluations.
/// The coefficients are the published rationals (of up to 67 digits) rounded to the nearest
/// `f64`.
///
/// The nodes: `c = 0, 1/50, 1/25, 1/10, 2/15, 4/25, 1/20, 1/5, 1/4, 1/3, 1/2, 5/9, 3/4,
/// 6/7, 8437/8926, 1, 1` and `1` (the stage that starts the next step).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Nystrom1210Pair;

const C: [f64; 18] = [
    0.0,
    0.02,
    0.04,
    0.1,
    0.13333333333333333,
    0.16,
    0.05,
    0.2,
    0.25,
    0.3333333333333333,
    0.5,
    0.5555555555555556,
    0.75,
    0.8571428571428571,
    0.9452162222720143,
    1.0,
    1.0,
    1.0,
];
const ABAR: [[f64; 18]; 18] = lower_triangular([
    &[],
    &[0.0002],
    &[0.0002666666666666667, 0.0005333333333333334],
    &[0.002916666666666667, -0.004166666666666667, 0.00625],
    &[
        0.0016460905349794238,
        0.0,
        0.0054869684499314125,
        0.0017558299039780521,
    ],
    &[
        0.0019456,
        0.0,
        0.007151746031746032,
        0.0029127111111111113,
        0.0007899428571428571,
    ],
    &[
        0.00056640625,
        0.0,
        0.0008809730489417989,
        -0.0004369212962962963,
        0.00033900669642857143,
        -9.946469907407407e-05,
    ],
    &[
        0.0030833333333333333,
        0.0,
        0.0,
        0.0017777777777777779,
        0.0027,
        0.0015782828282828283,
        0.01086060606060606,
    ],
    &[
        0.00365183937480113,
        0.0,
        0.003965171714072343,
        0.0031972582629306284,
        0.008221467306855435,
        -0.0013130926959572379,
        0.009771586968064868,
        0.003755769069232834,
    ],
    &[
        0.003707241068718501,
        0.0,
        0.005082045854555286,
        0.001174708002175412,
        -0.021147629915126993,
        0.06010463698107881,
        0.02010573476850619,
        -0.02835075012293358,
        0.014879568918581932,
    ],
    &[
        0.03512537656073344,
        0.0,
        -0.008615749195138479,
        -0.005791448051007917,
        1.945554823782616,
        -3.4351238674565137,
        -0.10930701107475221,
        2.3496383118995166,
        -0.7560094086870229,
        0.10952897222156927,
    ],
    &[
        0.020527792537482496,
        0.0,
        -0.00728644676448018,
        -0.0021153556079618403,
        0.9275807968723522,
        -1.6522824844257367,
        -0.02107956300568657,
        1.2065364326207872,
        -0.4137144770010661,
        0.09079873982809654,
        0.005355552600533985,
    ],
    &[
        -0.14324078875545515,
        0.0,
        0.012528703773091817,
        0.006826019163969827,
        -4.799555395574387,
        5.6986250439519415,
        0.7553430369523645,
        -0.12755487858281084,
        -1.9605926051117384,
        0.9185609056635262,
        -0.23880085505284432,
        0.15911081357234216,
    ],
    &[
        0.8045019205520489,
        0.0,
        -0.016658527067011247,
        -0.021415834042629735,
        16.827235928962466,
        -11.172835357176098,
        -3.377159297226324,
        -15.243326655360846,
        17.179835738215417,
        -5.437719239823995,
        1.3878671618364655,
        -0.5925827732652812,
        0.029603873171297354,
    ],
    &[
        -0.913296766697358,
        0.0,
        0.0024112725757805178,
        0.01765812269386174,
        -14.851649779720384,
        2.1589708670045757,
        3.99791558311788,
        28.434151800232232,
        -25.2593643549416,
        7.733878542362238,
        -1.8913028948478674,
        1.0014845070224718,
        0.004641199599109052,
        0.011218755022148957,
    ],
    &[
        -0.27519629720559396,
        0.0,
        0.03661188877915492,
        0.009789519688231562,
        -12.293062345886211,
        14.207226453937903,
        1.5866476906789537,
        2.4577735327595946,
        -8.935193694403273,
        4.373672731613407,
        -1.8347181765449492,
        1.1592085289061491,
        -0.017290253165383924,
        0.019325977904460768,
        0.005204442937554993,
    ],
    &[
        1.3076391847404059,
        0.0,
        0.017364109189745843,
        -0.018544456454265796,
        14.811522032867726,
        9.38317630848247,
        -5.2284261999445425,
        -48.95128052584765,
        38.297096034337926,
        -10.58738133697598,
        2.4332304376226275,
        -1.0453406042575444,
        0.0717732095086726,
        0.0021622109708082783,
        0.007009595759602514,
        0.0,
    ],
    &[
        0.012127868517185414,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.08629746251568875,
        0.2525469581187147,
        -0.1974186799326823,
        0.2031869190789726,
        -0.020775808077714918,
        0.10967804874502014,
        0.038065132526466504,
        0.01163406880432423,
        0.0046580297040248785,
        0.0,
        0.0,
    ],
]);
/// `A`: only the row of the stage at `(t0 + h, y1)`, the velocity weights `b'`.
const A: [[f64; 18]; 18] = {
    let mut a = [[0.0; 18]; 18];
    a[17] = [
        0.012127868517185414,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.09083943422704079,
        0.3156836976483934,
        -0.2632249065769097,
        0.3047803786184589,
        -0.041551616155429835,
        0.2467756096762953,
        0.15226053010586602,
        0.08143848163026961,
        0.08502571193890811,
        -0.009155189630077963,
        0.025,
        0.0,
    ];
    a
};
const E_Q: [f64; 18] = [
    -0.004880833389821577,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.014038126584857338,
    -0.11947921920803832,
    0.20440246507662121,
    -0.1322681492223791,
    0.11053069299761689,
    -0.07975385787102851,
    0.011224330486437457,
    -0.004671596801593694,
    0.0008580413473282841,
    0.0,
    0.0,
    0.0,
];
const E_V: [f64; 18] = [
    -0.004880833389821577,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.014776975352481408,
    -0.1493490240100479,
    0.2725366201021616,
    -0.19840222383356862,
    0.22106138599523378,
    -0.17944618020981415,
    0.04489732194574983,
    -0.03270117761115586,
    0.015662325288859434,
    -0.029155189630077964,
    0.025,
    0.0,
];

impl EmbeddedPair<18, 2> for Nystrom1210Pair {
    const NAME: &'static str = "Dormand-Prince Nystrom 12(10)";
    const ORDER: u32 = 12;
    const ERROR_EXPONENT: u32 = 11;
    const DENSE_ORDER: u32 = 4;
    const C: [f64; 18] = C;
    const A: [[f64; 18]; 18] = A;
    const FSAL: usize = 17;
    const E: [f64; 18] = E_V;
    const E3: Option<[f64; 18]> = None;
    const DENSE: [[f64; 18]; 2] = [[0.0; 18]; 2];
    const NYSTROM: Option<Nystrom<18>> = Some(Nystrom { abar: ABAR, e: E_Q });
}

/// Adaptive Runge-Kutta-Nyström 12(10) with PI step-size control, dense output and events,
/// for mechanisms whose law does not read the velocities ([`Mechanism::reads_velocities`]
/// `false`); it refuses any other mechanism with [`Error::InvalidParameter`] `mechanism`.
///
/// Order 12 (the slope of the global error against a fixed step measures 12.6 on the
/// pendulum released at 2 rad), explicit, adaptive; 17 acceleration evaluations per accepted
/// step, plus 17 per rejected attempt. Dense output of order 4 at no extra evaluation (the
/// quintic Hermite interpolant: far below the steps' order, for plots); an event is located
/// on it and then again on steps of the pair (a few steps' evaluations), so that its time and
/// state are as accurate as a step; [`Integrator::step`] lands by a last step shortened to
/// the frame's end. Not symplectic.
/// The long-step choice at tolerances of about `1e-9` down to `1e-14` in `f64`: its steps are
/// several times Dormand-Prince 8(5,3)'s for the same error.
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
/// let mut rkn = DormandPrinceNystrom1210::new(AdaptiveSettings::new(1e-12, 1e-14)?);
/// let end = rkn.integrate_to(&p, &State::at_rest([0.5]), 10.0)?;
/// let (th, _) = pendulum_from_rest(0.5, 9.81f64.sqrt(), 10.0)?;
/// assert!((end.q[0] - th).abs() < 1e-11);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
pub type DormandPrinceNystrom1210<T, const N: usize> =
    EmbeddedRungeKutta<T, N, 18, 2, Nystrom1210Pair>;
