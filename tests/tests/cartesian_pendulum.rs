//! The origin's two ways of writing the same pendulum side by side: one angle, or Cartesian
//! coordinates held by a constraint with a Lagrange multiplier; and the constraint residual
//! with projection, with Baumgarte stabilisation, and without drift control.

use lagrange_core::constraints::Stabilization;
use lagrange_core::{Constrained, Constraints, Error, Projection, Real, State};
use lagrange_integrators::{Integrator, Method, Projected, Rk4, VelocityVerlet};
use lagrange_systems::{CartesianPendulum, SimplePendulum};
use lagrange_tests::{for_f32_and_f64, pick};

const G: f64 = 9.81;
const TH0: f64 = core::f64::consts::FRAC_PI_6;
const DT: f64 = 1e-3;

/// Projection tolerance on `phi ~ r - l` (m): f64 well above rounding of `x^2 + y^2 - l^2`
/// (~2e-16), f32 above its rounding (~1.2e-7).
fn projection<T: Real>() -> Result<Projection<T>, Error> {
    Projection::new(T::from_f64(pick::<T>(1e-6, 1e-13)), 4)
}

/// RK4 + projection on the Cartesian pendulum against RK4 on the angle, both from the origin's
/// 30 degrees at rest, dt = 1e-3, 10 s. Both carry RK4's truncation error (~1e-11 rad here);
/// their difference is the projection's effect plus the two error patterns, measured 2.8e-12
/// rad in f64, bound 1.4e-11 (the issue asked for 1e-8). In f32 each run's rounding
/// walk is ~1e-6 rad (see origin_pendulum.rs); measured difference 2.3e-6 rad, bound 1e-5.
fn tracks_simple_pendulum<T: Real>() -> Result<(), Error> {
    let (one, g, dt) = (T::one(), T::from_f64(G), T::from_f64(DT));
    let simple = SimplePendulum::new(one, one, g, T::zero())?;
    let cartesian = Constrained::new(CartesianPendulum::new(one, one, g)?);
    let mut stepper = Projected::new(Rk4, projection::<T>()?);
    let mut s = State::at_rest([T::from_f64(TH0)]);
    let mut c = cartesian
        .parts()
        .state_from_angle(T::zero(), s.q[0], T::zero());
    let mut worst: f64 = 0.0;
    for _ in 0..10_000 {
        s = Rk4.step(&simple, &s, dt)?;
        c = stepper.step(&cartesian, &c, dt)?;
        let (th, thd) = cartesian.parts().angle(&c);
        worst = worst.max((th - s.q[0]).abs().to_f64());
        worst = worst.max(((thd - s.qd[0]) * T::from_f64(0.1)).abs().to_f64());
    }
    println!("Cartesian vs angle pendulum, 10 s: max |dth| {worst:.3e} rad");
    assert!(worst < pick::<T>(1e-5, 1.4e-11), "{worst:e}");
    Ok(())
}

/// The multiplier is the rod's force: tension `-lambda = m (v^2 / l + g cos th)` at any state
/// on the circle, to rounding (8 ulps of the largest term).
fn multiplier_is_rod_tension<T: Real>() -> Result<(), Error> {
    let (m, l, g) = (T::from_f64(2.0), T::from_f64(0.7), T::from_f64(G));
    let p = Constrained::new(CartesianPendulum::new(m, l, g)?);
    for i in 0..40 {
        let th = T::from_f64(-3.0 + 0.15 * f64::from(i));
        let thd = T::from_f64(4.0 - 0.2 * f64::from(i));
        let s = p.parts().state_from_angle(T::zero(), th, thd);
        let lambda = p.solve(&s)?.multipliers[0];
        let tension = m * (l * thd * thd + g * th.cos());
        let scale = m * (l * thd * thd + g);
        assert!(
            (tension + lambda).abs() <= T::from_f64(8.0) * T::EPSILON * scale,
            "th {th}: tension {tension}, lambda {lambda}"
        );
    }
    Ok(())
}

for_f32_and_f64!(tracks_simple_pendulum, multiplier_is_rod_tension);

/// The largest position residual over `steps` steps of `integrator` on `p` from 0.5 rad at
/// rest, and the largest over the first tenth of them.
fn residual_run<I: Integrator<f64, 2, Constrained<f64, 1, CartesianPendulum<f64>>>>(
    mut integrator: I,
    p: &Constrained<f64, 1, CartesianPendulum<f64>>,
    steps: u64,
) -> Result<(f64, f64), Error> {
    let start = p.parts().state_from_angle(0.0, 0.5, 0.0);
    let (mut early, mut worst) = (0.0f64, 0.0f64);
    let mut n = 0u64;
    integrator.integrate_with(p, &start, DT, steps, |s| {
        n += 1;
        worst = worst.max(p.residual(s).position);
        if n <= steps / 10 {
            early = worst;
        }
    })?;
    Ok((early, worst))
}

/// `steps` steps at dt = 1e-3 (l = 1 m, 0.5 rad at rest), largest `|phi|` (m) reported for
/// every kind of drift control and asserted:
///
/// - projection (tolerance 1e-13) after each RK4 step: measured 1.0e-13, the tolerance
///   itself; bound 5e-13 (the issue asked for 1e-10);
/// - no drift control: RK4 keeps `phi'' = 0` only, the velocity residual drifts linearly and
///   `phi` quadratically in time: measured 7.1e-11 after 10 s, 7.1e-9 after 100 s. Asserted:
///   at least 20x growth from the first tenth of the run to its end (quadratic growth gives
///   100x), and far above the projected residual;
/// - Baumgarte, RK4 at `critical(3/s)` (the pendulum's own frequency): bounded, measured
///   5.4e-13 at 10 s and at 100 s; asserted: no more than 1.5x growth after the first tenth,
///   and below 2e-12;
/// - Baumgarte, velocity Verlet at `for_step(dt)` (rate dt = 0.3): measured 6.2e-9 against
///   1.7e-2 without control; asserted bounded the same way, below 2e-8, and 1000x below none.
fn residual_figures(steps: u64) -> Result<(), Error> {
    let free = Constrained::new(CartesianPendulum::new(1.0, 1.0, G)?);
    let projected = Projected::new(Rk4, Projection::new(1e-13, 4)?);
    let (_, with_projection) = residual_run(projected, &free, steps)?;
    let (none_early, none) = residual_run(Rk4, &free, steps)?;
    let rk4_baumgarte = free.with_stabilization(Stabilization::critical(3.0)?);
    let (b_early, b_end) = residual_run(Rk4, &rk4_baumgarte, steps)?;
    let (_, verlet_none) = residual_run(VelocityVerlet, &free, steps)?;
    let verlet_baumgarte = free.with_stabilization(Stabilization::for_step(DT)?);
    let (vb_early, vb_end) = residual_run(VelocityVerlet, &verlet_baumgarte, steps)?;
    println!(
        "max |phi| (m) over {steps} steps of dt = 1e-3:\n  RK4 + projection  {with_projection:.2e}\n  \
         RK4, none         {none_early:.2e} (first tenth) -> {none:.2e}\n  \
         RK4, Baumgarte    {b_early:.2e} (first tenth) -> {b_end:.2e}\n  \
         Verlet, none      {verlet_none:.2e}\n  \
         Verlet, Baumgarte {vb_early:.2e} (first tenth) -> {vb_end:.2e}"
    );
    assert!(with_projection < 5e-13, "{with_projection:e}");
    assert!(none > 20.0 * none_early, "{none_early:e} -> {none:e}");
    assert!(none > 10.0 * with_projection, "{none:e}");
    assert!(
        b_end <= 1.5 * b_early && b_end < 2e-12,
        "{b_early:e} {b_end:e}"
    );
    assert!(
        vb_end <= 1.5 * vb_early && vb_end < 2e-8,
        "{vb_early:e} {vb_end:e}"
    );
    assert!(vb_end * 1e3 < verlet_none, "{vb_end:e} {verlet_none:e}");
    Ok(())
}

/// The issue's run: 10^5 steps (100 s).
#[test]
#[ignore = "long run: cargo xtask ci runs it in release"]
fn residual_over_100_000_steps() -> Result<(), Error> {
    residual_figures(100_000)
}

/// The same figures over 10^4 steps (10 s), quick enough for the debug test run.
#[test]
fn residual_over_10_000_steps() -> Result<(), Error> {
    residual_figures(10_000)
}

/// An implicit method on a constrained mechanism: Newton needs the Jacobian of the constrained
/// acceleration law (multipliers included), which `CartesianPendulum` gives by differencing its
/// own `acceleration`. Gauss-Legendre 2 + projection against Gauss-Legendre 2 on the angle,
/// dt = 1e-2 over 2 s: both carry the method's `O(dt^4)` error (~1e-8 rad at this step), so
/// they agree far better (measured 7.9e-10 rad; bound 4e-9). The residual Newton drives to zero
/// is exact whatever the Jacobian, so a wrong Jacobian would show in the iteration count.
#[test]
fn implicit_method_on_a_constrained_mechanism() -> Result<(), Error> {
    use lagrange_integrators::GaussLegendre2;
    let simple = SimplePendulum::new(1.0, 1.0, G, 0.0)?;
    let cartesian = Constrained::new(CartesianPendulum::new(1.0, 1.0, G)?);
    let mut angle_form = GaussLegendre2::<f64>::default();
    let mut stepper = Projected::new(GaussLegendre2::<f64>::default(), projection::<f64>()?);
    let mut s = State::at_rest([TH0]);
    let mut c = cartesian.parts().state_from_angle(0.0, TH0, 0.0);
    let (mut worst, mut iterations, mut angle_iterations): (f64, u32, u32) = (0.0, 0, 0);
    for _ in 0..200 {
        s = angle_form.step(&simple, &s, 1e-2)?;
        c = stepper.step(&cartesian, &c, 1e-2)?;
        iterations = iterations.max(stepper.integrator().last_step().iterations);
        angle_iterations = angle_iterations.max(angle_form.last_step().iterations);
        let (th, _) = cartesian.parts().angle(&c);
        worst = worst.max((th - s.q[0]).abs());
    }
    println!(
        "Gauss-Legendre 2, Cartesian vs angle form: {worst:e} rad; Newton iterations per step \
         at most {iterations} (angle form {angle_iterations})"
    );
    assert!(worst < 4e-9, "{worst}");
    // Measured 5 against 3: the Cartesian form has twice the unknowns and a projection after
    // each step. A runaway count would mean Newton is fighting a wrong Jacobian.
    assert!(iterations <= 8, "{iterations} vs {angle_iterations}");
    Ok(())
}

/// The position residual `phi = (x^2 + y^2 - l^2) / (2 l)` of `CartesianPendulum`'s docs,
/// computed here, so that the law below owes nothing to the library's own residual.
fn phi<T: Real>(s: &State<T, 2>, l: f64) -> f64 {
    let (x, y) = (s.q[0].to_f64(), s.q[1].to_f64());
    (x * x + y * y - l * l) / (2.0 * l)
}

/// A state off the circle of radius `l`: the bob at angle `th` from the downward vertical, at
/// rest apart from a radial velocity, with residual `phi = e0` and rate `phi' = J q' = ed0`
/// (`J q' = r r' / l`, so `r' = ed0 l / r`).
fn off_the_circle<T: Real>(l: f64, th: f64, e0: f64, ed0: f64) -> State<T, 2> {
    let r = (l * l + 2.0 * l * e0).sqrt();
    let rd = ed0 * l / r;
    let (s, c) = th.sin_cos();
    State::new(
        T::zero(),
        [T::from_f64(r * s), T::from_f64(-r * c)],
        [T::from_f64(rd * s), T::from_f64(-rd * c)],
    )
}

/// Baumgarte's law is exact for this constraint: `phi'' = J q'' + J'q'` identically, and the
/// stabilised acceleration sets `J q'' + J'q' = -2 alpha phi' - beta^2 phi`, so the residual of
/// the exact motion is `e'' + 2 alpha e' + beta^2 e = 0` whatever the pendulum does: the damped
/// oscillator of unit mass, stiffness `beta^2` and damping `2 alpha`. Integrated with RK4 at
/// dt = 1e-3 (error `O(dt^4)`, far below the law's scale) from `e0 = 0.02 m`, the largest
/// `|phi(t) - e(t)| / e0` at t = 0.25, 0.5, 1, 1.5 and 2 s:
///
/// ```text
/// gains                                     start           measured f64 / f32    bound
/// critical(3/s): e0 (1 + 3 t) exp(-3 t)     at rest         1.7e-11 / 2.9e-5      8e-11 / 1.5e-4
/// baumgarte(1/s, 4/s): under-damped         e0' = -0.1 m/s  3.2e-11 / 3.4e-5      1.6e-10 / 1.7e-4
/// ```
///
/// f32 rounds `x^2 + y^2 - l^2` at about 6e-8 m, 3e-6 of a residual of 2e-2 m, and its
/// integration of the bob rounds at the same level each step. The bounds sit far
/// below "a few percent"; a gain off by a factor (`alpha` for `2 alpha`) misses them by orders
/// of magnitude.
fn residual_follows_baumgarte_law<T: Real>() -> Result<(), Error> {
    let (l, e0) = (1.0, 0.02);
    let free = Constrained::new(CartesianPendulum::new(
        T::one(),
        T::from_f64(l),
        T::from_f64(G),
    )?);
    let cases = [
        ("critical(3)", 3.0, 3.0, 0.0, pick::<T>(1.5e-4, 8e-11)),
        (
            "baumgarte(1, 4)",
            1.0,
            4.0,
            -0.1,
            pick::<T>(1.7e-4, 1.6e-10),
        ),
    ];
    for (name, alpha, beta, ed0, bound) in cases {
        let stabilization = if alpha == beta {
            Stabilization::critical(T::from_f64(alpha))?
        } else {
            Stabilization::baumgarte(T::from_f64(alpha), T::from_f64(beta))?
        };
        let p = free.with_stabilization(stabilization);
        let start = off_the_circle::<T>(l, 0.4, e0, ed0);
        assert!((phi(&start, l) - e0).abs() < pick::<T>(1e-7, 1e-16));
        // The law in closed form: the damped oscillator m = 1, k = beta^2, c = 2 alpha.
        let law = |t: f64| {
            lagrange_systems::exact::damped_oscillator(1.0, beta * beta, 2.0 * alpha, e0, ed0, t)
                .map(|(e, _)| e)
        };
        if alpha == beta {
            let t: f64 = 0.7;
            let critical = e0 * (1.0 + beta * t) * (-beta * t).exp();
            assert!((law(t)? - critical).abs() < 1e-15, "critical law");
        }
        let (mut worst, mut n, mut samples) = (0.0f64, 0u64, Vec::new());
        Rk4.integrate_with(&p, &start, T::from_f64(DT), 2000, |s| {
            n += 1;
            if [250, 500, 1000, 1500, 2000].contains(&n) {
                samples.push((n as f64 * DT, phi(s, l)));
            }
        })?;
        for &(t, e) in &samples {
            let expected = law(t)?;
            worst = worst.max((e - expected).abs() / e0);
        }
        println!(
            "{name} ({}): phi(t) / e0 {:?}, worst |phi - e| / e0 {worst:.2e}",
            core::any::type_name::<T>(),
            samples
                .iter()
                .map(|(t, e)| format!("{t}: {:.5}", e / e0))
                .collect::<Vec<_>>()
        );
        assert!(worst < bound, "{name}: {worst:e} > {bound:e}");
    }
    Ok(())
}

for_f32_and_f64!(residual_follows_baumgarte_law);
