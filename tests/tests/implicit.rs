//! The implicit machinery: exact and finite-difference Jacobians, Newton's failures as
//! specific errors, and the implicit and variational methods in f32 and f64.

use lagrange_core::nalgebra::{SVector, Vector1};
use lagrange_core::{
    central_difference_jacobian, Error, EulerLagrange, Input, Lagrangian, Mechanism, Real, Scalar,
    State, ViscousDamping,
};
use lagrange_integrators::{
    BackwardEuler, GaussLegendre2, ImplicitMidpoint, Integrator, Method, NewtonSettings,
    PhaseState, RadauIIA2, Rk4, StormerVerlet, VariationalMidpoint, Yoshida4,
};
use lagrange_systems::exact::pendulum_from_rest;
use lagrange_systems::{DoublePendulum, Kepler, NLinkPendulum, SimplePendulum};
use lagrange_tests::{fitted_order, for_f32_and_f64, kepler_periapsis, pick, state_error, Rng};

/// The automatic path's Jacobian is exact: for the pendulum, `dq''/dth = -(g/l) cos th`
/// and, with damping added by wrapping, `dq''/dth' = -b` to rounding, where the
/// central-difference default (what a hand-derived system gets) is good to ~1e-10 relative
/// in f64 and ~1e-4 in f32 (`EPSILON^(2/3)` and the rounding of the residual it
/// differentiates).
fn pendulum_jacobian_exact_and_approximate<T: Real>() -> Result<(), Error> {
    let g = T::from_f64(9.81);
    let hand = SimplePendulum::new(T::one(), T::one(), g, T::from_f64(0.3))?;
    let undamped = SimplePendulum::new(T::one(), T::one(), g, T::zero())?;
    let auto = EulerLagrange::new(undamped).with_force(ViscousDamping::uniform(T::from_f64(0.3))?);
    let mut rng = Rng::new(7);
    let (exact_tol, fd_tol) = (pick::<T>(4e-6, 1e-14), pick::<T>(2e-3, 1e-9));
    for _ in 0..100 {
        let s = State::new(
            T::zero(),
            [rng.uniform(-3.0, 3.0)],
            [rng.uniform(-5.0, 5.0)],
        );
        let exact = (-g * s.q[0].cos()).to_f64();
        let (_, ja) = auto.acceleration_jacobian(&s)?;
        let (_, jh) = hand.acceleration_jacobian(&s)?;
        assert!((ja.wrt_q[(0, 0)].to_f64() - exact).abs() <= exact_tol * 10.0);
        assert!((jh.wrt_q[(0, 0)].to_f64() - exact).abs() <= fd_tol * 10.0);
        // d q''/d th' = -b / (m l^2) = -0.3
        assert!((ja.wrt_qd[(0, 0)].to_f64() + 0.3).abs() <= exact_tol);
        assert!((jh.wrt_qd[(0, 0)].to_f64() + 0.3).abs() <= fd_tol);
    }
    Ok(())
}

/// At random states of the double pendulum, damped by wrapping and driven by an input, the
/// exact Jacobian of the automatic path and the central differences of the hand-derived
/// system's law agree to the differences' accuracy (measured worst 8.8e-10 relative in f64,
/// 5.8e-4 in f32, differencing the acceleration itself; bounds 4.4e-9 and 2.9e-3); the wrapper
/// composes: the damping's exact `-c` appears in `dq''/dq'` through `M^-1`.
fn double_pendulum_jacobians_agree<T: Real>() -> Result<(), Error> {
    let one = T::one();
    let dp = DoublePendulum::new(
        one,
        T::from_f64(0.7),
        one,
        T::from_f64(1.3),
        T::from_f64(9.81),
    )?;
    let damping = ViscousDamping::new([T::from_f64(0.2), T::from_f64(0.4)])?;
    let input = Input::new([T::from_f64(0.5), -T::from_f64(0.25)]);
    let hand = dp.with_force(damping).with_force(input);
    let auto = EulerLagrange::new(dp).with_force(damping).with_force(input);
    let mut rng = Rng::new(11);
    let tol = pick::<T>(2.9e-3, 4.4e-9);
    let mut worst = 0.0f64;
    for _ in 0..200 {
        let s = State::new(
            T::zero(),
            [rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0)],
            [rng.uniform(-4.0, 4.0), rng.uniform(-4.0, 4.0)],
        );
        let (_, ja) = auto.acceleration_jacobian(&s)?;
        let (_, jh) = hand.acceleration_jacobian(&s)?;
        let scale = ja
            .wrt_q
            .iter()
            .chain(ja.wrt_qd.iter())
            .fold(1.0f64, |m, x| m.max(x.to_f64().abs()));
        for (a, h) in ja
            .wrt_q
            .iter()
            .chain(ja.wrt_qd.iter())
            .zip(jh.wrt_q.iter().chain(jh.wrt_qd.iter()))
        {
            worst = worst.max((a.to_f64() - h.to_f64()).abs() / scale);
        }
        // Damping only: dq''/dq' of the damping term alone is -M^-1 diag(c).
        let m = auto.mass_matrix(&s);
        let damped_only = EulerLagrange::new(dp).with_force(damping);
        let undamped = EulerLagrange::new(dp);
        let diff = damped_only.acceleration_jacobian(&s)?.1.wrt_qd
            - undamped.acceleration_jacobian(&s)?.1.wrt_qd;
        let expected =
            -lagrange_core::solve_spd(&m, &SVector::from([T::from_f64(0.2), T::zero()]))?;
        assert!((diff[(0, 0)] - expected[0]).abs().to_f64() < pick::<T>(1e-4, 1e-12) * scale);
        assert!((diff[(1, 0)] - expected[1]).abs().to_f64() < pick::<T>(1e-4, 1e-12) * scale);
    }
    println!("worst relative difference, exact vs central differences: {worst:.2e}");
    assert!(worst < tol, "{worst}");
    Ok(())
}

/// The central-difference helper is exact for a function linear in the state.
#[test]
fn central_differences_are_exact_for_linear_functions() {
    let s = State::new(0.3, [1e3, -2.0], [0.5, -1e-3]);
    let j = central_difference_jacobian(&s, |s: &State<f64, 2>| {
        SVector::from([2.0 * s.q[0] - 3.0 * s.qd[1], 0.5 * s.q[1] + 7.0 * s.qd[0]])
    });
    let expected_q = [[2.0, 0.0], [0.0, 0.5]];
    let expected_qd = [[0.0, -3.0], [7.0, 0.0]];
    for i in 0..2 {
        for k in 0..2 {
            assert!((j.wrt_q[(i, k)] - expected_q[i][k]).abs() < 1e-9);
            assert!((j.wrt_qd[(i, k)] - expected_qd[i][k]).abs() < 1e-9);
        }
    }
}

/// One Newton iteration is never enough for a nonlinear step: each implicit method reports
/// `NoConvergence { iterations: 1 }` and the caller keeps the start state.
fn newton_failure_is_reported<T: Real>() -> Result<(), Error> {
    let one = T::one();
    let dp = DoublePendulum::new(one, one, one, one, T::from_f64(9.81))?;
    let auto = EulerLagrange::new(dp);
    let s = State::new(T::zero(), [T::HALF, -T::HALF], [one, T::from_f64(2.0)]);
    let once = NewtonSettings::new(T::from_f64(8.0) * T::EPSILON, 1)?;
    let dt = T::from_f64(0.05);
    let failed = Err(Error::NoConvergence { iterations: 1 });
    assert_eq!(ImplicitMidpoint::new(once).step(&dp, &s, dt), failed);
    assert_eq!(GaussLegendre2::new(once).step(&dp, &s, dt), failed);
    assert_eq!(BackwardEuler::new(once).step(&dp, &s, dt), failed);
    assert_eq!(RadauIIA2::new(once).step(&dp, &s, dt), failed);
    assert_eq!(StormerVerlet::new(once).step(&dp, &s, dt), failed);
    assert_eq!(VariationalMidpoint::new(once).step(&auto, &s, dt), failed);
    // With the default settings the same steps succeed.
    GaussLegendre2::default().step(&dp, &s, dt)?;
    VariationalMidpoint::default().step(&auto, &s, dt)?;
    Ok(())
}

/// A spring pushing outwards, `V = -8 x^2` (`q'' = 16 x`): at `h = 0.5` the implicit
/// midpoint's Newton matrix `1 - (h/2)^2 16` is exactly zero.
#[test]
fn singular_newton_matrix_is_reported() -> Result<(), Error> {
    struct Repeller;
    impl Lagrangian<f64, 1> for Repeller {
        fn kinetic<S: Scalar<Real = f64>>(&self, _: S, _: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
            S::from_f64(0.5) * qd[0] * qd[0]
        }
        fn potential<S: Scalar<Real = f64>>(&self, _: S, q: &SVector<S, 1>) -> S {
            S::from_f64(-8.0) * q[0] * q[0]
        }
    }
    let repeller = EulerLagrange::new(Repeller);
    let s = State::new(0.0, [1.0], [0.0]);
    assert_eq!(
        ImplicitMidpoint::default().step(&repeller, &s, 0.5),
        Err(Error::SingularJacobian)
    );
    // A different step is fine.
    ImplicitMidpoint::default().step(&repeller, &s, 0.25)?;
    Ok(())
}

/// A mechanism whose accelerations become NaN inside the step (a square root of a negative
/// number beyond `x = 1`): the implicit step reports `NonFiniteState`, never a NaN state.
#[test]
fn nan_inside_a_step_is_reported() -> Result<(), Error> {
    struct Wall;
    impl Lagrangian<f64, 1> for Wall {
        fn kinetic<S: Scalar<Real = f64>>(&self, _: S, _: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
            S::from_f64(0.5) * qd[0] * qd[0]
        }
        fn potential<S: Scalar<Real = f64>>(&self, _: S, q: &SVector<S, 1>) -> S {
            -(S::one() - q[0]).sqrt()
        }
    }
    let m = EulerLagrange::new(Wall);
    let s = State::new(0.0, [0.9], [10.0]);
    for result in [
        ImplicitMidpoint::default().step(&m, &s, 0.1),
        GaussLegendre2::default().step(&m, &s, 0.1),
        RadauIIA2::default().step(&m, &s, 0.1),
        StormerVerlet::default().step(&m, &s, 0.1),
        VariationalMidpoint::default().step(&m, &s, 0.1),
    ] {
        assert_eq!(result, Err(Error::NonFiniteState));
    }
    Ok(())
}

/// Every new fixed-step method in f32 and f64 on the origin's pendulum, 10 s at dt = 1e-2,
/// against the exact solution: the f64 errors are the methods' own (measured 0.51 for
/// backward Euler, which has damped most of the swing, down to 4.6e-8 for Gauss-Legendre);
/// f32 adds rounding of a few 1e-6 over 1000 steps.
fn implicit_methods_in_both_precisions<T: Real>() -> Result<(), Error> {
    let (th0, g) = (T::from_f64(core::f64::consts::FRAC_PI_6), T::from_f64(9.81));
    let p = SimplePendulum::new(T::one(), T::one(), g, T::zero())?;
    let auto = EulerLagrange::new(p);
    let start = State::at_rest([th0]);
    let (th, thd) = pendulum_from_rest(th0.to_f64(), g.to_f64().sqrt(), 10.0)?;
    let dt = T::from_f64(1e-2);
    // Bounds: the measured f64 errors and a third again.
    let runs: [(&str, State<T, 1>, f64); 7] = [
        (
            "implicit midpoint",
            ImplicitMidpoint::default().integrate(&p, &start, dt, 1000)?,
            4e-3,
        ),
        (
            "Gauss-Legendre 2",
            GaussLegendre2::default().integrate(&p, &start, dt, 1000)?,
            7e-8,
        ),
        (
            "backward Euler",
            BackwardEuler::default().integrate(&p, &start, dt, 1000)?,
            0.6,
        ),
        (
            "Radau IIA 2",
            RadauIIA2::default().integrate(&p, &start, dt, 1000)?,
            3e-5,
        ),
        (
            "Stormer-Verlet",
            StormerVerlet::default().integrate(&p, &start, dt, 1000)?,
            2.5e-3,
        ),
        (
            "Yoshida 4",
            Yoshida4::<StormerVerlet<T, 1>>::default().integrate(&p, &start, dt, 1000)?,
            3.5e-6,
        ),
        (
            "variational midpoint",
            VariationalMidpoint::default().integrate(&auto, &start, dt, 1000)?,
            4e-3,
        ),
    ];
    // f32 rounding over 1000 steps: measured 2.5e-6.
    let rounding = pick::<T>(1e-5, 0.0);
    for (name, end, bound) in runs {
        let err = state_error(&end, &[th, thd]);
        println!("{name:<22} error at 10 s: {err:.3e}");
        assert!(err < bound + rounding, "{name}: {err}");
    }
    Ok(())
}

/// The discrete momentum of a cyclic coordinate is conserved exactly: Kepler's `phi` over
/// 2000 steps (2 orbits), free and with damping on `r` only (a discrete force with no `phi`
/// component leaves `p_phi` alone): `p_phi` never changes by a single bit, while `r^2 phi'`
/// of Gauss-Legendre (order 4, symmetric but not variational in polar coordinates) changes by
/// ~5e-11 relative in f64 and ~3e-6 in f32 at this step.
fn variational_conserves_cyclic_momentum<T: Real>() -> Result<(), Error> {
    const STEPS_CYCLIC: u32 = 2000;
    let free = EulerLagrange::new(Kepler::new(T::one())?);
    let damped = free.with_force(ViscousDamping::new([T::from_f64(0.05), T::zero()])?);
    let start = kepler_periapsis::<T>();
    let dt = T::from_f64(2.0 * core::f64::consts::PI / 1000.0);
    let mut vi = VariationalMidpoint::default();
    for (name, z0) in [
        ("free", vi.phase_state(&free, &start)),
        ("damped r", vi.phase_state(&damped, &start)),
    ] {
        let mut z = z0;
        let mut worst = 0.0f64;
        for _ in 0..STEPS_CYCLIC {
            z = if name == "free" {
                vi.step_phase(&free, &z, dt)?
            } else {
                vi.step_phase(&damped, &z, dt)?
            };
            worst = worst.max((z.p[1] - z0.p[1]).abs().to_f64());
        }
        println!(
            "{name}: p_phi {:.17} -> {:.17}, worst change {worst:e}",
            z0.p[1].to_f64(),
            z.p[1].to_f64()
        );
        assert!(worst == 0.0, "{name}: p_phi changed by {worst}");
    }
    // For comparison, a symmetric non-variational method's angular momentum.
    let mut s = start;
    let l0 = (s.q[0] * s.q[0] * s.qd[1]).to_f64();
    let mut worst = 0.0f64;
    let mut gl = lagrange_integrators::GaussLegendre2::default();
    for _ in 0..STEPS_CYCLIC {
        s = gl.step(&free, &s, dt)?;
        worst = worst.max(((s.q[0] * s.q[0] * s.qd[1]).to_f64() - l0).abs() / l0);
    }
    println!("Gauss-Legendre 2: worst relative change of r^2 phi' {worst:.2e}");
    assert!(worst > 0.0);
    Ok(())
}

/// A chain falling from rest, observed step by step: each observation converts the momenta
/// back to velocities, where the upper links barely move while the lower ones already swing.
/// Each velocity converges relative to the largest (not to its own size, which left nothing to
/// converge to and made every such run fail with `NoConvergence`). The observed run ends in
/// the unobserved run's state: the conversions do not feed back.
fn variational_observes_a_chain_falling_from_rest<T: Real>() -> Result<(), Error> {
    let chain = EulerLagrange::new(NLinkPendulum::new(
        [T::one(); 8],
        [T::one(); 8],
        T::from_f64(9.81),
    )?);
    let start = State::new(
        T::zero(),
        [T::from_f64(core::f64::consts::FRAC_PI_4); 8],
        [T::zero(); 8],
    );
    let dt = T::from_f64(1e-3);
    let mut observed = 0;
    let end = VariationalMidpoint::default().integrate_with(&chain, &start, dt, 500, |s| {
        assert!(s.is_finite());
        observed += 1;
    })?;
    let unobserved = VariationalMidpoint::default().integrate(&chain, &start, dt, 500)?;
    assert_eq!(observed, 500);
    assert_eq!(end.q, unobserved.q);
    Ok(())
}

for_f32_and_f64!(
    variational_observes_a_chain_falling_from_rest,
    pendulum_jacobian_exact_and_approximate,
    double_pendulum_jacobians_agree,
    newton_failure_is_reported,
    implicit_methods_in_both_precisions,
    variational_conserves_cyclic_momentum
);

/// With damping and a drive torque (discrete Lagrange-d'Alembert forces), the variational
/// integrator converges at order 2 to the forced motion (reference: RK4 at 1e-4), and the
/// damped energy falls as the continuous one does.
#[test]
fn variational_forces_converge_at_order_two() -> Result<(), Error> {
    let p = SimplePendulum::new(1.0, 1.0, 9.81, 0.0)?;
    let forced = EulerLagrange::new(p)
        .with_force(ViscousDamping::uniform(0.3)?)
        .with_force(Input::new([0.8]));
    let start = State::new(0.0, [0.4], [1.0]);
    let reference = Rk4.integrate(&forced, &start, 1e-4, 20_000)?;
    let dts = [2e-2, 1e-2, 5e-3, 2.5e-3];
    let mut errs = Vec::new();
    for dt in dts {
        let end =
            VariationalMidpoint::default().integrate(&forced, &start, dt, (2.0 / dt) as u64)?;
        errs.push(state_error(&end, &[reference.q[0], reference.qd[0]]));
    }
    let order = fitted_order(&dts, &errs);
    println!("forced variational midpoint: errors {errs:?}, order {order:.3}");
    assert!((order - 2.0).abs() < 0.2);

    // Damping alone removes energy at every step.
    let damped = EulerLagrange::new(p).with_force(ViscousDamping::uniform(0.3)?);
    let mut e = damped.energy(&start);
    VariationalMidpoint::default().integrate_with(&damped, &start, 1e-2, 500, |s| {
        let next = damped.energy(s);
        assert!(next <= e + 1e-12, "energy rose {e} -> {next}");
        e = next;
    })?;
    Ok(())
}

/// `max_i |v_i|`.
fn max_abs(v: &SVector<f64, 2>) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// The variational integrator's momenta are the Legendre transform `p = dL/dq'`, and the
/// conversion back to velocities inverts it.
#[test]
fn legendre_transform_round_trip() -> Result<(), Error> {
    let dp = EulerLagrange::new(DoublePendulum::new(1.0, 2.0, 0.5, 1.5, 9.81)?);
    let vi = VariationalMidpoint::default();
    let mut rng = Rng::new(3);
    for _ in 0..100 {
        let s: State<f64, 2> = State::new(
            0.0,
            [rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0)],
            [rng.uniform(-4.0, 4.0), rng.uniform(-4.0, 4.0)],
        );
        let z = vi.phase_state(&dp, &s);
        // p = M q' for a kinetic energy quadratic in q'.
        let p = dp.mass_matrix(&s) * s.qd;
        assert!(max_abs(&(z.p - p)) < 1e-13 * (1.0 + max_abs(&p)));
        let back = vi.velocity_state(&dp, &z, &SVector::zeros())?;
        assert!(max_abs(&(back.qd - s.qd)) < 1e-13 * (1.0 + max_abs(&s.qd)));
    }
    Ok(())
}

/// The pendulum's Lagrangian has no cyclic coordinate, but a pendulum at the bottom at rest
/// is a fixed point of every method: zero stays exactly zero.
#[test]
fn equilibrium_is_a_fixed_point() -> Result<(), Error> {
    let p = SimplePendulum::new(1.0, 1.0, 9.81, 0.0)?;
    let rest = State::at_rest([0.0]);
    for end in [
        ImplicitMidpoint::default().integrate(&p, &rest, 0.1, 100)?,
        GaussLegendre2::default().integrate(&p, &rest, 0.1, 100)?,
        RadauIIA2::default().integrate(&p, &rest, 0.1, 100)?,
        StormerVerlet::default().integrate(&p, &rest, 0.1, 100)?,
        VariationalMidpoint::default().integrate(&EulerLagrange::new(p), &rest, 0.1, 100)?,
    ] {
        assert_eq!((end.q, end.qd), (Vector1::new(0.0), Vector1::new(0.0)));
    }
    Ok(())
}

/// Newton converges as fast as its matrix lets it: the implicit Runge-Kutta methods on the
/// double pendulum (two coordinates, so that every block of the Newton matrix and every pivot
/// of its LU factors is used), 50 steps from a swinging state, at most the measured
/// iterations in all (f64, measured 238 to 310); steps of 0.02 s, and of 0.1 s where Newton
/// refreshes its matrix when it slows down; and Stormer-Verlet's kick on a heavily damped
/// pendulum, where the fixed-point start hands over to Newton (223). A matrix factored wrong, refreshed late or
/// handed over late still converges, slowly: more iterations.
#[test]
fn newton_iterations_are_few() -> Result<(), Error> {
    fn total<I: Integrator<f64, 2, DoublePendulum<f64>>>(
        mut method: I,
        dt: f64,
    ) -> Result<u32, Error> {
        let dp = DoublePendulum::new(1.0, 1.3, 0.9, 1.1, 9.81)?;
        let mut s = State::new(0.0, [0.6, -0.4], [0.3, 0.5]);
        let mut total = 0;
        for _ in 0..50 {
            s = method.step(&dp, &s, dt)?;
            total += method.last_step().iterations;
        }
        Ok(total)
    }
    let damped = SimplePendulum::new(1.0, 1.0, 9.81, 40.0)?;
    let mut sv = StormerVerlet::default();
    let mut s = State::new(0.0, [0.9], [-0.4]);
    let mut kicks = 0;
    for _ in 0..50 {
        s = sv.step(&damped, &s, 0.05)?;
        kicks += sv.last_step().iterations;
    }
    for (name, iterations, measured) in [
        (
            "implicit midpoint, 0.02 s",
            total(ImplicitMidpoint::default(), 0.02)?,
            287,
        ),
        (
            "Gauss-Legendre 2, 0.02 s",
            total(GaussLegendre2::default(), 0.02)?,
            274,
        ),
        (
            "Radau IIA 2, 0.02 s",
            total(RadauIIA2::default(), 0.02)?,
            238,
        ),
        (
            "backward Euler, 0.02 s",
            total(BackwardEuler::default(), 0.02)?,
            245,
        ),
        (
            "implicit midpoint, 0.1 s",
            total(ImplicitMidpoint::default(), 0.1)?,
            301,
        ),
        (
            "Gauss-Legendre 2, 0.1 s",
            total(GaussLegendre2::default(), 0.1)?,
            295,
        ),
        ("Radau IIA 2, 0.1 s", total(RadauIIA2::default(), 0.1)?, 310),
        (
            "backward Euler, 0.1 s",
            total(BackwardEuler::default(), 0.1)?,
            278,
        ),
        ("Stormer-Verlet, damped", kicks, 223),
    ] {
        println!("{name}: {iterations} Newton iterations in 50 steps");
        assert!(
            iterations <= measured,
            "{name}: {iterations} iterations, measured {measured}"
        );
    }
    Ok(())
}

/// The Newton settings read back what they were given.
#[test]
fn newton_settings_read_back() -> Result<(), Error> {
    let s = NewtonSettings::new(1e-9, 7)?;
    assert_eq!((s.tolerance(), s.max_iterations()), (1e-9, 7));
    Ok(())
}

/// A phase state is finite when its time, coordinates and momenta all are; the variational
/// step refuses one that is not, whichever part holds the NaN or infinity.
#[test]
fn phase_states_that_are_not_finite_are_refused() -> Result<(), Error> {
    let p = SimplePendulum::new(1.0, 1.0, 9.81, 0.0)?;
    let good = PhaseState {
        t: 0.0,
        q: SVector::<f64, 1>::new(0.3),
        p: SVector::<f64, 1>::new(-0.2),
    };
    assert!(good.is_finite());
    let mut method = VariationalMidpoint::default();
    method.step_phase(&p, &good, 0.01)?;
    for bad in [f64::NAN, f64::INFINITY] {
        for broken in [
            PhaseState { t: bad, ..good },
            PhaseState {
                q: SVector::<f64, 1>::new(bad),
                ..good
            },
            PhaseState {
                p: SVector::<f64, 1>::new(bad),
                ..good
            },
        ] {
            assert!(!broken.is_finite(), "{broken:?}");
            assert_eq!(
                method.step_phase(&p, &broken, 0.01),
                Err(Error::NonFiniteState)
            );
        }
    }
    Ok(())
}

/// The variational midpoint's Newton matrix holds the forces' Jacobian, in `q` and in `q'`:
/// a pendulum held by a stiff spring force `-K q` and damped by `-C q'` (K = 800, C = 20: at
/// `h = 0.05` their parts of the matrix, `K h / 4` and `C / 2`, are each half the inertia's
/// `m l^2 / h`), 100 steps of 0.05 s, at most the measured iterations in all (f64: 261; the
/// force's `q` part scaled wrongly: no convergence or more iterations); a run continued
/// from where the last one ended is the one longer run, bit for bit (the momenta are kept,
/// not recomputed from the velocities).
#[test]
fn variational_newton_holds_the_forces_jacobian() -> Result<(), Error> {
    let (k, c) = (800.0, 20.0);
    let held = SimplePendulum::new(1.0, 1.0, 9.81, 0.0)?
        .with_force(move |s: &State<f64, 1>| Vector1::new(-k * s.q[0] - c * s.qd[0]));
    let start = State::new(0.0, [1.2], [0.4]);
    let mut w = VariationalMidpoint::default();
    let (mut s, mut iterations) = (start, 0);
    for _ in 0..100 {
        s = w.step(&held, &s, 0.05)?;
        iterations += w.last_step().iterations;
    }
    println!("variational midpoint, stiff force: {iterations} iterations in 100 steps");
    assert!(iterations <= 261, "{iterations} iterations");
    let mut halves = VariationalMidpoint::default();
    let middle = halves.integrate(&held, &start, 0.05, 50)?;
    let end = halves.integrate(&held, &middle, 0.05, 50)?;
    let whole = VariationalMidpoint::default().integrate(&held, &start, 0.05, 100)?;
    assert_eq!(end, whole, "a continued run is not the whole run");
    Ok(())
}

/// The variational midpoint's Newton starts from good guesses and an exact matrix (the
/// damping's Jacobian included): over 100 steps of 0.05 s of a damped pendulum, at most the
/// measured iterations in all (f64: 393), and over 100 steps alternating 0.05 and 0.02 s
/// (335: the guess scales the last motion to the new step). A run (`integrate`) from a
/// state set from outside starts afresh: bit for bit what a new method gives (it did not:
/// the last run's motion seeded its first guess, a difference of an ulp).
#[test]
fn variational_newton_is_quick_and_restarts() -> Result<(), Error> {
    let p = SimplePendulum::new(1.0, 1.0, 9.81, 0.5)?;
    let start = State::new(0.0, [1.2], [0.4]);
    let mut stepped = 0;
    let mut s = start;
    let mut w = VariationalMidpoint::default();
    for _ in 0..100 {
        s = w.step(&p, &s, 0.05)?;
        stepped += w.last_step().iterations;
    }
    // Steps that alternate in length: the guess scales the last motion to the new step.
    let mut varied = 0;
    for k in 0..100 {
        s = w.step(&p, &s, if k % 2 == 0 { 0.05 } else { 0.02 })?;
        varied += w.last_step().iterations;
    }
    println!("variational midpoint: {stepped} iterations in 100 steps, {varied} alternating");
    assert!(stepped <= 393, "{stepped} iterations");
    assert!(varied <= 335, "{varied} iterations");
    let mut v = VariationalMidpoint::default();
    v.integrate(&p, &start, 0.05, 100)?;
    let outside = State::new(3.0, [-0.7], [1.1]);
    let again = v.integrate(&p, &outside, 0.05, 40)?;
    let fresh = VariationalMidpoint::default().integrate(&p, &outside, 0.05, 40)?;
    assert_eq!(again, fresh, "a run from outside did not start afresh");
    Ok(())
}

/// A relativistic oscillator, `T = m c^2 (1 - sqrt(1 - q'^2 / c^2))`, `V = k q^2 / 2`: a
/// kinetic energy that is not quadratic in `q'`, so that the Legendre transform
/// `p = m q' / sqrt(1 - q'^2 / c^2)` is not linear and its inversion by Newton depends on where
/// it starts (for a quadratic `T` one Newton step solves it from anywhere).
struct Relativistic;

impl<T: Real> Lagrangian<T, 1> for Relativistic {
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, _q: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
        S::one() - (S::one() - qd[0] * qd[0]).sqrt()
    }
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 1>) -> S {
        q[0] * q[0] * T::TWO
    }
}

/// The variational midpoint on the relativistic oscillator (`m = c = 1`, `k = 4`) released at
/// `q = 1`: it reaches 0.943 c, a momentum of 2.83 m c, where Newton's inversion of the
/// Legendre transform from a poor start (rest: the first iterate is the Newtonian velocity
/// `p / m`, faster than light) meets the square root of a negative number. The velocities of
/// every run's end are found from the last step's motion `(q1 - q0) / h`, always slower than
/// light: every end state is finite and below c, and the energy `m c^2 (gamma - 1) + k q^2 / 2`
/// stays near its start of 2 over 1,000 steps of 2 ms (measured drift: f64 2.1e-6, the
/// method's own; f32 3.9e-6; bounds about 5 times those). A fresh run's first step starts
/// Newton from `q0 + q0' h`: at most the measured iterations (f64 5, f32 3: its tolerance is
/// looser).
fn variational_inverts_a_legendre_transform_that_is_not_linear<T: Real>() -> Result<(), Error> {
    let m = EulerLagrange::new(Relativistic);
    let start = State::new(T::zero(), [T::one()], [T::zero()]);
    let dt = T::from_f64(2e-3);
    // The conserved energy is the Hamiltonian, not T + V: `p q' - L`.
    let energy = |s: &State<T, 1>| {
        let (q, v) = (s.q[0].to_f64(), s.qd[0].to_f64());
        (1.0 - v * v).sqrt().recip() - 1.0 + 2.0 * q * q
    };
    let mut w = VariationalMidpoint::default();
    let (mut s, mut fastest, mut drift) = (start, 0.0f64, 0.0f64);
    for _ in 0..100 {
        s = w.integrate(&m, &s, dt, 10)?;
        assert!(s.qd[0].abs() < T::one(), "faster than light: {s:?}");
        fastest = fastest.max(s.qd[0].abs().to_f64());
        drift = drift.max((energy(&s) - energy(&start)).abs());
    }
    println!("relativistic oscillator: fastest end {fastest:.3} c, energy drift {drift:.2e}");
    // The premise: some ends are beyond the momentum m c (0.707 c).
    assert!(fastest > 0.9, "fastest {fastest}");
    assert!(drift < pick::<T>(2e-5, 1e-5), "energy drift {drift}");
    // Stepped: each step converts to velocities from its own motion too.
    let mut stepped = VariationalMidpoint::default();
    let mut t = start;
    for _ in 0..300 {
        t = stepped.step(&m, &t, dt)?;
        assert!(t.qd[0].abs() < T::one(), "faster than light: {t:?}");
    }
    let moving = State::new(T::zero(), [T::from_f64(0.3)], [T::from_f64(0.8)]);
    let mut fresh = VariationalMidpoint::default();
    fresh.integrate(&m, &moving, T::from_f64(0.05), 1)?;
    let iterations = fresh.last_step().iterations;
    println!("relativistic oscillator: {iterations} iterations in a fresh first step");
    let measured = pick::<T>(3.0, 5.0) as u32;
    assert!(iterations <= measured, "{iterations} iterations");
    Ok(())
}

for_f32_and_f64!(variational_inverts_a_legendre_transform_that_is_not_linear);
