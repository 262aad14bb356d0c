//! One physical check per mechanism, independent of its own Lagrangian: equilibria and rates
//! from Newton's laws, small-oscillation frequencies measured from an integration, a conserved
//! momentum, Kepler's third law. A consistent error in a system's `T`, `V` and equations (which
//! its test against the automatic path cannot see) fails here. f32 and f64.

use lagrange_core::{Error, Mechanism, Real, State};
use lagrange_integrators::{Integrator, Rk4};
use lagrange_systems::{
    BeadOnRotatingHoop, DoublePendulum, ElasticPendulum, Kepler, SphericalPendulum, SwingingAtwood,
};
use lagrange_tests::{for_f32_and_f64, pick};

const G: f64 = 9.81;

/// `x` in precision `T`.
fn t<T: Real>(x: f64) -> T {
    T::from_f64(x)
}

/// The state `(q, q')` at `t = 0` in precision `T`.
fn state<T: Real, const N: usize>(q: [f64; N], qd: [f64; N]) -> State<T, N> {
    State::new(T::zero(), q.map(t::<T>), qd.map(t::<T>))
}

/// `max_i |q''_i|` at `s`, in f64.
fn largest_acceleration<T: Real, M: Mechanism<T, N>, const N: usize>(
    m: &M,
    s: &State<T, N>,
) -> Result<f64, Error> {
    Ok(m.acceleration(s)?
        .iter()
        .map(|a| a.to_f64().abs())
        .fold(0.0, f64::max))
}

/// The period of `signal` along an RK4 run of `m` from `start` (`steps` steps of `dt`): the
/// mean time between its upward zero crossings, each located by linear interpolation between
/// steps. (Upward crossings only: where the oscillation's centre is offset from zero by a
/// nonlinearity, up- and down-crossings shift in opposite directions.) Time is counted in steps,
/// not read from the state, so that f32's rounding of `t` does not enter.
fn period<T: Real, M: Mechanism<T, N>, const N: usize>(
    m: &M,
    start: &State<T, N>,
    dt: f64,
    steps: u64,
    signal: impl Fn(&State<T, N>) -> f64,
) -> Result<f64, Error> {
    let h = t::<T>(dt).to_f64();
    let (mut last, mut n) = (signal(start), 0u64);
    let mut crossings = Vec::new();
    Rk4.integrate_with(m, start, t::<T>(dt), steps, |s| {
        n += 1;
        let now = signal(s);
        if last < 0.0 && now >= 0.0 {
            crossings.push(h * (n as f64 - now / (now - last)));
        }
        last = now;
    })?;
    assert!(crossings.len() >= 3, "{} upward crossings", crossings.len());
    let (first, final_) = (crossings[0], crossings[crossings.len() - 1]);
    Ok((final_ - first) / (crossings.len() - 1) as f64)
}

/// `|measured / expected - 1|`, printed and asserted below `bound`.
fn frequency_agrees(what: &str, measured: f64, expected: f64, bound: f64) {
    let err = (measured / expected - 1.0).abs();
    println!("{what}: {measured:.9} against {expected:.9}, relative {err:.2e} (bound {bound:.0e})");
    assert!(
        err < bound,
        "{what}: {measured} against {expected}: {err:e}"
    );
}

/// The elastic pendulum (m = 1.5 kg, k = 150 N/m, l0 = 1 m) hanging at rest at the static
/// stretch `m g / k` (Hooke against the weight) is in equilibrium: largest `|q''|` measured
/// 7.1e-15 m/s^2 in f64 (bound 3.5e-14), 5.1e-6 in f32 (bound 2.5e-5). Pulled straight down it
/// oscillates at `sqrt(k / m)`, exactly for any amplitude (the motion stays on the vertical,
/// where the spring is linear); a small swing (1e-3 rad) at `r_eq` oscillates at
/// `sqrt(g / r_eq)` up to the amplitude's shift `O(th0^2)`. Measured over 10 s of RK4 at
/// dt = 1e-3, relative frequency errors (f64 / f32) and bounds:
///
/// ```text
/// radial   5.6e-11 (RK4's phase error, (w dt)^4 / 120) / 9.0e-7     bounds 2.8e-10 / 1.5e-6
/// swing    1.5e-7 (the amplitude's shift)               / 2.3e-7     bounds 7.5e-7  / 1.2e-6
/// ```
///
/// The radial motion is measured at amplitudes of 3 to 7 cm. In f32 its error is the state's
/// rounding (`r` near 1.1 m carries 1.2e-7 m, which moves each crossing), and it scatters with
/// the amplitude: from 8.8e-8 to 9.0e-7 with the law's closed form in `k / m`, and from 4.7e-9
/// to 9.9e-7 with the earlier `M^-1 f` (a single amplitude, 5 cm, gave 7.3e-8 there, which
/// the earlier bound of 3.7e-7 was set from).
fn elastic_pendulum<T: Real>() -> Result<(), Error> {
    let (m, k, l0) = (1.5, 150.0, 1.0);
    let p = ElasticPendulum::new(t::<T>(m), t(k), t(l0), t(G))?;
    let r_eq = l0 + m * G / k;
    let a = largest_acceleration(&p, &state::<T, 2>([r_eq, 0.0], [0.0, 0.0]))?;
    println!("elastic pendulum at the static stretch: |q''| {a:.2e}");
    assert!(a < pick::<T>(2.5e-5, 3.5e-14), "{a:e}");

    let expected = (k / m).sqrt();
    let bound = pick::<T>(1.5e-6, 2.8e-10);
    for amplitude in [0.03, 0.04, 0.045, 0.05, 0.06, 0.07] {
        let radial = period(
            &p,
            &state([r_eq + amplitude, 0.0], [0.0, 0.0]),
            1e-3,
            10_000,
            |s| s.q[0].to_f64() - r_eq,
        )?;
        frequency_agrees(
            "elastic, radial",
            2.0 * core::f64::consts::PI / radial,
            expected,
            bound,
        );
    }

    let swing = period(&p, &state([r_eq, 1e-3], [0.0, 0.0]), 1e-3, 10_000, |s| {
        s.q[1].to_f64()
    })?;
    let expected = (G / r_eq).sqrt();
    let bound = pick::<T>(1.2e-6, 7.5e-7);
    frequency_agrees(
        "elastic, swing",
        2.0 * core::f64::consts::PI / swing,
        expected,
        bound,
    );
    Ok(())
}

/// The conical pendulum: a bob circling at polar angle `th` keeps it when the rod's tension
/// `S` balances weight and centripetal force, `S cos th = m g`, `S sin th = m l sin th phi'^2`,
/// so `phi'^2 = g / (l cos th)`; there `th'' = phi'' = 0` at four angles from 0.2 to 1.4 rad
/// (largest `|q''|` measured 2.3e-15 in f64, 8.1e-7 in f32; bounds 1.1e-14 and 4e-6 rad/s^2).
/// Away from it the azimuthal momentum `m l^2 sin^2 th phi'` (computed here) is conserved:
/// over 10 s of RK4 at dt = 1e-3 from a nutating start, relative drift measured 8.9e-12 (f64)
/// and 7.3e-6 (f32); bounds 4.5e-11 and 3.7e-5.
fn spherical_pendulum<T: Real>() -> Result<(), Error> {
    let (m, l) = (0.7, 1.3);
    let p = SphericalPendulum::new(t::<T>(m), t(l), t(G))?;
    let mut worst: f64 = 0.0;
    for th in [0.2f64, 0.5, 1.0, 1.4] {
        let rate = (G / (l * th.cos())).sqrt();
        worst = worst.max(largest_acceleration(&p, &state([th, 0.3], [0.0, rate]))?);
    }
    println!("conical pendulum: largest |q''| {worst:.2e}");
    assert!(worst < pick::<T>(4e-6, 1.1e-14), "{worst:e}");

    let momentum = |s: &State<T, 2>| {
        let sin = s.q[0].to_f64().sin();
        m * l * l * sin * sin * s.qd[1].to_f64()
    };
    let start = state([0.8, 0.0], [0.5, 2.0]);
    let p0 = momentum(&start);
    let mut drift: f64 = 0.0;
    Rk4.integrate_with(&p, &start, t::<T>(1e-3), 10_000, |s| {
        drift = drift.max((momentum(s) / p0 - 1.0).abs());
    })?;
    println!("spherical pendulum: azimuthal momentum drift {drift:.2e}");
    assert!(drift < pick::<T>(3.7e-5, 4.5e-11), "{drift:e}");
    Ok(())
}

/// Newton on the swinging Atwood machine (big mass `M` on one side, rising as the other side's
/// length `r` grows; small mass `m` swinging at angle `th`): string tension `S`,
///
/// ```text
/// big mass:            M r''                 = S - M g
/// small, along string: m (r'' - r th'^2)     = m g cos th - S
/// small, across it:    m (r th'' + 2 r' th') = -m g sin th
/// => r''  = (m r th'^2 - g (M - m cos th)) / (M + m),   th'' = -(g sin th + 2 r' th') / r
/// ```
///
/// At `th = 0` at rest this is Atwood's `r'' = (m - M) g / (M + m)`; a swing rate adds the
/// centripetal `m r th'^2 / (M + m)`. Checked at those two states, and at states with `th` and
/// `r'` too: worst difference measured 4.5e-17 (f64) and 1.1e-7 (f32) relative to `g`;
/// bounds 2.3e-16 and 5.4e-7. Turning gravity's sign in `T`, `V` and the equations alike
/// (which the test against the automatic path passes) misses them by 3.2 g.
fn swinging_atwood<T: Real>() -> Result<(), Error> {
    let (big, small) = (3.0, 1.2);
    let a = SwingingAtwood::new(t::<T>(big), t(small), t(G))?;
    let newton = |r: f64, th: f64, rd: f64, thd: f64| {
        [
            (small * r * thd * thd - G * (big - small * th.cos())) / (big + small),
            -(G * th.sin() + 2.0 * rd * thd) / r,
        ]
    };
    // Atwood's machine proper, and with the swing rate's centripetal term.
    let atwood = (small - big) * G / (big + small);
    let (r, thd) = (1.5, 2.0);
    let cases = [
        ([r, 0.0, 0.0, 0.0], [atwood, 0.0]),
        (
            [r, 0.0, 0.0, thd],
            [atwood + small * r * thd * thd / (big + small), 0.0],
        ),
        ([r, 0.7, 0.4, -1.1], newton(r, 0.7, 0.4, -1.1)),
        ([0.6, -1.9, -0.8, 2.5], newton(0.6, -1.9, -0.8, 2.5)),
    ];
    assert!((newton(r, 0.0, 0.0, 0.0)[0] - atwood).abs() < 1e-15);
    let mut worst: f64 = 0.0;
    for ([r, th, rd, thd], expected) in cases {
        let q = a.acceleration(&state([r, th], [rd, thd]))?;
        for i in 0..2 {
            worst = worst.max((q[i].to_f64() - expected[i]).abs() / G);
        }
    }
    println!("swinging Atwood against Newton: worst {worst:.2e} of g");
    assert!(worst < pick::<T>(5.4e-7, 2.3e-16), "{worst:e}");
    Ok(())
}

/// The bead on a hoop of radius `R` spinning at `w` with `R w^2 > g` (R = 0.5 m, w = 10 rad/s):
/// in the rotating frame the centrifugal force `m w^2 R sin th` has the component
/// `m w^2 R sin th cos th` along the hoop, which balances gravity's `m g sin th` where
/// `cos th = g / (R w^2)`: zero acceleration there (measured 6.7e-15 rad/s^2 in f64, 2.4e-6 in
/// f32; bounds 3.3e-14 and 1.2e-5). Linearising `th'' = w^2 sin th cos th - (g / R) sin th`
/// about it gives the frequency `w sin th_eq`. Measured over 10 s of RK4 at dt = 1e-3 from
/// `th_eq + A`: relative error 2.8e-7 in f64 at A = 1e-3 rad and 3.5e-5 in f32 at A = 1e-2
/// (f32 resolves `th` near 1.37 rad to 1e-7, too coarse for a smaller amplitude), both the
/// amplitude's shift `-0.28 A^2` of the Lindstedt series; bounds 1.4e-6 and 1.7e-4.
fn bead_on_rotating_hoop<T: Real>() -> Result<(), Error> {
    let (r, w) = (0.5, 10.0);
    let b = BeadOnRotatingHoop::new(t::<T>(0.1), t(r), t(w), t(G))?;
    let th_eq = (G / (r * w * w)).acos();
    let a = largest_acceleration(&b, &state([th_eq], [0.0]))?;
    println!("bead at the off-axis equilibrium: |th''| {a:.2e}");
    assert!(a < pick::<T>(1.2e-5, 3.3e-14), "{a:e}");
    let amplitude = pick::<T>(1e-2, 1e-3);
    let measured = period(&b, &state([th_eq + amplitude], [0.0]), 1e-3, 10_000, |s| {
        s.q[0].to_f64() - th_eq
    })?;
    let bound = pick::<T>(1.7e-4, 1.4e-6);
    frequency_agrees(
        "bead about the off-axis equilibrium",
        2.0 * core::f64::consts::PI / measured,
        w * th_eq.sin(),
        bound,
    );
    Ok(())
}

/// Kepler: a circular orbit, gravity supplying the centripetal force, `phi'^2 = mu / r^3`, has
/// `r'' = phi'' = 0` (measured 1.1e-16 in f64 and 6.0e-8 in f32, of terms `mu / r^2` = 0.75;
/// bounds 5.5e-16 and 3e-7). Kepler's third law: the ellipse of semi-major axis `a` (here
/// `mu = 3`, `a = 2`, `e = 0.3`, from periapsis at the vis-viva speed) returns to periapsis
/// after `2 pi a^1.5 / sqrt(mu)`, measured between upward crossings of `r'` over 4.5 periods
/// of RK4 at dt = 1e-3: relative error 1.1e-12 (f64), 1.8e-6 (f32); bounds 5.7e-12 and 9e-6.
fn kepler<T: Real>() -> Result<(), Error> {
    let mu = 3.0;
    let k = Kepler::new(t::<T>(mu))?;
    let r0 = 2.0;
    let a = largest_acceleration(&k, &state([r0, 0.4], [0.0, (mu / (r0 * r0 * r0)).sqrt()]))?;
    println!("circular orbit: |q''| {a:.2e}");
    assert!(a < pick::<T>(3e-7, 5.5e-16), "{a:e}");

    let (sma, e) = (2.0, 0.3);
    let rp = sma * (1.0 - e);
    // Vis-viva at periapsis: v^2 = mu (2 / r - 1 / a).
    let vp = (mu * (2.0 / rp - 1.0 / sma)).sqrt();
    let expected = 2.0 * core::f64::consts::PI * sma.powf(1.5) / mu.sqrt();
    let steps = (4.5 * expected / 1e-3) as u64;
    let measured = period(&k, &state([rp, 0.0], [0.0, vp / rp]), 1e-3, steps, |s| {
        s.qd[0].to_f64()
    })?;
    frequency_agrees(
        "Kepler period",
        measured,
        expected,
        pick::<T>(9e-6, 5.7e-12),
    );
    Ok(())
}

/// The double pendulum of equal masses and lengths, linearised about hanging straight down,
/// has the normal modes `w^2 = (g / l) (2 -+ sqrt 2)` with shapes `th2 = +-sqrt 2 th1`.
/// Started in each shape at 1e-3 rad (l = 0.8 m), it oscillates at the mode's frequency up to
/// the amplitude's shift `O(th^2)`. Measured over 10 s of RK4 at dt = 1e-3, relative errors:
/// slow mode 8.9e-8 (f64) and 5.9e-8 (f32), bound 4.5e-7; fast mode 1.85e-6 in both, bound
/// 9e-6.
fn double_pendulum<T: Real>() -> Result<(), Error> {
    let l = 0.8;
    let dp = DoublePendulum::new(t::<T>(1.3), t(1.3), t(l), t(l), t(G))?;
    let root2 = 2f64.sqrt();
    for (name, shape, w2, bound) in [
        ("slow", root2, 2.0 - root2, 4.5e-7),
        ("fast", -root2, 2.0 + root2, 9e-6),
    ] {
        let start = state([1e-3, shape * 1e-3], [0.0, 0.0]);
        let measured = period(&dp, &start, 1e-3, 10_000, |s| s.q[0].to_f64())?;
        frequency_agrees(
            &format!("double pendulum, {name} mode"),
            2.0 * core::f64::consts::PI / measured,
            (G / l * w2).sqrt(),
            bound,
        );
    }
    Ok(())
}

for_f32_and_f64!(
    elastic_pendulum,
    spherical_pendulum,
    swinging_atwood,
    bead_on_rotating_hoop,
    kepler,
    double_pendulum
);
