//! The standard mechanisms of issue 4 refuse bad parameters by name, and answer singular and
//! non-finite states with specific errors, never a panic or a NaN.

use lagrange_core::nalgebra::SVector;
use lagrange_core::{Controlled, Error, Mechanism, Real, State};
use lagrange_integrators::{Integrator, Rk4};
use lagrange_systems::exact::{damped_oscillator, eccentric_anomaly, kepler_orbit};
use lagrange_systems::{
    Acrobot, CartPole, ElasticPendulum, Kepler, NLinkPendulum, SphericalPendulum, SpringMassDamper,
    SwingingAtwood,
};
use lagrange_tests::for_f32_and_f64;

/// The values no positive parameter may take.
fn not_positive<T: Real>() -> [T; 5] {
    [
        T::zero(),
        -T::one(),
        T::from_f64(f64::NAN),
        T::INFINITY,
        -T::INFINITY,
    ]
}

/// The values no non-negative parameter may take.
fn negative_or_not_finite<T: Real>() -> [T; 4] {
    [-T::one(), T::from_f64(f64::NAN), T::INFINITY, -T::INFINITY]
}

/// `Err(InvalidParameter { name, .. })` with exactly this name.
fn refuses<V: core::fmt::Debug>(result: Result<V, Error>, expected: &str) {
    assert!(
        matches!(result, Err(Error::InvalidParameter { name, .. }) if name == expected),
        "expected InvalidParameter {{ name: {expected} }}, got {result:?}"
    );
}

/// Every positive parameter of every new system.
fn positive_parameters_are_named<T: Real>() -> Result<(), Error> {
    let (one, g) = (T::one(), T::from_f64(9.81));
    for bad in not_positive::<T>() {
        refuses(
            NLinkPendulum::new([one, bad, one], [one; 3], g),
            "masses[1]",
        );
        refuses(
            NLinkPendulum::new([one; 3], [one, one, bad], g),
            "lengths[2]",
        );
        refuses(SpringMassDamper::new(bad, one, one), "mass");
        refuses(ElasticPendulum::new(bad, one, one, g), "mass");
        refuses(ElasticPendulum::new(one, bad, one, g), "stiffness");
        refuses(SphericalPendulum::new(bad, one, g), "mass");
        refuses(SphericalPendulum::new(one, bad, g), "length");
        refuses(CartPole::new(bad, one, one, g), "cart_mass");
        refuses(CartPole::new(one, bad, one, g), "pole_mass");
        refuses(CartPole::new(one, one, bad, g), "pole_half_length");
        let h = T::HALF;
        refuses(Acrobot::new(bad, one, one, one, h, h, one, one, g), "m1");
        refuses(Acrobot::new(one, bad, one, one, h, h, one, one, g), "m2");
        refuses(Acrobot::new(one, one, bad, one, h, h, one, one, g), "l1");
        refuses(Acrobot::new(one, one, one, bad, h, h, one, one, g), "l2");
        refuses(SwingingAtwood::new(bad, one, g), "big_mass");
        refuses(SwingingAtwood::new(one, bad, g), "small_mass");
        refuses(Kepler::new(bad), "mu");
    }
    Ok(())
}

/// Every non-negative parameter: zero is valid, negative or non-finite is not.
fn non_negative_parameters_are_named<T: Real>() -> Result<(), Error> {
    let (zero, one, g) = (T::zero(), T::one(), T::from_f64(9.81));
    let h = T::HALF;
    for bad in negative_or_not_finite::<T>() {
        refuses(NLinkPendulum::new([one; 2], [one; 2], bad), "gravity");
        refuses(SpringMassDamper::new(one, bad, one), "stiffness");
        refuses(SpringMassDamper::new(one, one, bad), "damping");
        refuses(ElasticPendulum::new(one, one, bad, g), "rest_length");
        refuses(ElasticPendulum::new(one, one, one, bad), "gravity");
        refuses(SphericalPendulum::new(one, one, bad), "gravity");
        refuses(CartPole::new(one, one, one, bad), "gravity");
        refuses(Acrobot::new(one, one, one, one, bad, h, one, one, g), "lc1");
        refuses(Acrobot::new(one, one, one, one, h, bad, one, one, g), "lc2");
        refuses(Acrobot::new(one, one, one, one, h, h, bad, one, g), "i1");
        refuses(Acrobot::new(one, one, one, one, h, h, one, bad, g), "i2");
        refuses(
            Acrobot::new(one, one, one, one, h, h, one, one, bad),
            "gravity",
        );
        refuses(SwingingAtwood::new(one, one, bad), "gravity");
    }
    NLinkPendulum::new([one; 2], [one; 2], zero)?;
    SpringMassDamper::new(one, zero, zero)?;
    ElasticPendulum::new(one, one, zero, zero)?;
    // Point-mass links (no inertia about the centre of mass) are valid...
    Acrobot::new(one, one, one, one, one, one, zero, zero, g)?;
    // ...a link with no inertia about its hinge is not.
    refuses(
        Acrobot::new(one, one, one, one, zero, h, zero, one, g),
        "i1",
    );
    refuses(
        Acrobot::new(one, one, one, one, h, zero, one, zero, g),
        "i2",
    );
    Ok(())
}

/// The elastic pendulum's law takes `k / m`: a pair whose ratio overflows is refused, naming
/// the parameter that pushes it furthest (f32: 1e30 / 1e-10; f64: 1e300 / 1e-10 and
/// 1e10 / 1e-300).
#[test]
fn elastic_pendulum_refuses_a_spring_rate_that_overflows() {
    refuses(ElasticPendulum::new(1e-10f32, 1e30, 1.0, 9.81), "stiffness");
    refuses(
        ElasticPendulum::new(1e-10f64, 1e300, 1.0, 9.81),
        "stiffness",
    );
    refuses(ElasticPendulum::new(1e-300f64, 1e10, 1.0, 0.0), "mass");
    assert!(ElasticPendulum::new(1e-10f64, 1e290, 1.0, 9.81).is_ok());
}

/// A mass whose inverse overflows is refused (f32: 1e-45 is a positive subnormal).
#[test]
fn chain_refuses_a_mass_it_cannot_invert() {
    refuses(
        NLinkPendulum::new([1.0f32, 1e-45], [1.0; 2], 9.81),
        "masses[1]",
    );
    // A total that overflows names the heaviest mass (the first of equals)...
    refuses(
        NLinkPendulum::new([1e308f64, 1e308], [1.0; 2], 0.0),
        "masses[0]",
    );
    // ...and in gravity the last link's weight g m l overflows first.
    refuses(
        NLinkPendulum::new([1e308f64, 1e308], [1.0; 2], 9.81),
        "masses[1]",
    );
}

/// Inputs refuse non-finite values by name and keep their last good value; through
/// `Controlled::set_input` the name is `input`, that method's own parameter (issue 15).
fn inputs_refuse_non_finite<T: Real>() -> Result<(), Error> {
    let g = T::from_f64(9.81);
    let mut cp = CartPole::new(T::one(), T::one(), T::one(), g)?;
    let mut acrobot = Acrobot::<T>::spong();
    cp.set_force(T::from_f64(3.0))?;
    acrobot.set_torque(-T::from_f64(2.0))?;
    for bad in [T::from_f64(f64::NAN), T::INFINITY, -T::INFINITY] {
        refuses(cp.set_force(bad), "force");
        refuses(acrobot.set_torque(bad), "torque");
        refuses(Controlled::set_input(&mut cp, bad), "input");
        refuses(Controlled::set_input(&mut acrobot, bad), "input");
    }
    assert_eq!(cp.force(), T::from_f64(3.0));
    assert_eq!(acrobot.torque(), -T::from_f64(2.0));
    Ok(())
}

/// `Err(Singularity)` at `s`, from the law and from the split form's `solve_mass`.
fn singular<T: Real, const N: usize>(m: &impl Mechanism<T, N>, s: &State<T, N>) {
    let a = m.acceleration(s);
    assert!(
        matches!(a, Err(Error::Singularity { .. })),
        "at {s:?}: {a:?}"
    );
    let x = m.solve_mass(s, &lagrange_core::nalgebra::SVector::from_element(T::one()));
    assert!(
        matches!(x, Err(Error::Singularity { .. })),
        "solve_mass at {s:?}: {x:?}"
    );
}

/// The radial coordinates at and past zero, the spherical pendulum on its axis, and states so
/// near them that a square underflows or `q''` overflows: `Error::Singularity`, never NaN or
/// infinity.
fn singular_states_are_reported<T: Real>() -> Result<(), Error> {
    let (one, g) = (T::one(), T::from_f64(9.81));
    let elastic = ElasticPendulum::new(one, one, one, g)?;
    let atwood = SwingingAtwood::new(T::from_f64(2.0), one, g)?;
    let kepler = Kepler::new(one)?;
    // A radius whose square underflows to zero (f64 1e-200, f32 1e-30).
    let tiny = if T::EPSILON.to_f64() > 1e-10 {
        1e-30
    } else {
        1e-200
    };
    for r in [0.0, -0.0, -0.5, tiny] {
        let s = State::new(T::zero(), [T::from_f64(r), T::from_f64(0.3)], [one, one]);
        singular(&elastic, &s);
        singular(&atwood, &s);
        singular(&kepler, &s);
        singular(&elastic.with_force(|_: &State<T, 2>| SVector::zeros()), &s);
    }
    // Kepler's r'' = -mu / r^2 overflows while r^2 is still positive (f64 1e-160, f32 1e-20).
    let near = if T::EPSILON.to_f64() > 1e-10 {
        1e-20
    } else {
        1e-160
    };
    singular(
        &kepler,
        &State::new(T::zero(), [T::from_f64(near), T::zero()], [one, one]),
    );
    // The elastic pendulum's th'' overflows there too at r' = 1 / r (2 / r^2: f64 2e320,
    // f32 2e40), and at r = 1 both accelerations overflow at rates of 1e200 (f32 1e20):
    // finite states, refused all the same.
    let fast = T::from_f64(1.0 / near);
    singular(
        &elastic,
        &State::new(T::zero(), [T::from_f64(near), T::zero()], [fast, one]),
    );
    let faster = T::from_f64(if T::EPSILON.to_f64() > 1e-10 {
        1e20
    } else {
        1e200
    });
    let both = elastic.acceleration(&State::new(T::zero(), [one, T::zero()], [faster, faster]));
    assert!(matches!(both, Err(Error::Singularity { .. })), "{both:?}");
    let spherical = SphericalPendulum::new(one, one, g)?;
    for th in [0.0, -0.0, tiny] {
        singular(
            &spherical,
            &State::new(T::zero(), [T::from_f64(th), T::zero()], [one, one]),
        );
    }
    // Not on the axis in floating point: sin(pi) is about 1.2e-16 (f64), -8.7e-8 (f32), and
    // the equations there are correct, if steep.
    let steep = spherical.acceleration(&State::new(T::zero(), [T::PI, T::zero()], [one, one]))?;
    assert!(steep.iter().all(|x| x.is_finite()), "{steep:?}");
    Ok(())
}

/// At a state holding NaN or infinity, every new system's acceleration is either an error
/// (`NonFiniteState`, or `Singularity` where the bad value sits in a radius it checks first) or
/// finite (a cyclic coordinate such as the cart's `x` or the time does not enter the
/// equations): never a NaN.
fn non_finite_states_never_give_nan<T: Real>() -> Result<(), Error> {
    let (one, g) = (T::one(), T::from_f64(9.81));
    let bads = [T::from_f64(f64::NAN), T::INFINITY, -T::INFINITY];
    fn check<T: Real, const N: usize>(
        m: &impl Mechanism<T, N>,
        good: State<T, N>,
        bads: [T; 3],
    ) -> Result<(), Error> {
        m.acceleration(&good)?;
        for bad in bads {
            for k in 0..2 * N + 1 {
                let mut s = good;
                match k {
                    0 => s.t = bad,
                    k if k <= N => s.q[k - 1] = bad,
                    k => s.qd[k - N - 1] = bad,
                }
                match m.acceleration(&s) {
                    Ok(a) => assert!(a.iter().all(|x| x.is_finite()), "{s:?}: {a:?}"),
                    Err(e) => assert!(
                        matches!(e, Error::NonFiniteState | Error::Singularity { .. }),
                        "{s:?}: {e:?}"
                    ),
                }
            }
        }
        Ok(())
    }
    let two = |a: f64, b: f64| State::new(T::zero(), [T::from_f64(a), T::from_f64(b)], [one, one]);
    check(
        &NLinkPendulum::new([one; 4], [one; 4], g)?,
        State::new(T::zero(), [T::HALF; 4], [one; 4]),
        bads,
    )?;
    check(
        &SpringMassDamper::new(one, one, one)?,
        State::new(T::zero(), [one], [one]),
        bads,
    )?;
    check(
        &ElasticPendulum::new(one, one, one, g)?,
        two(1.0, 0.3),
        bads,
    )?;
    check(&SphericalPendulum::new(one, one, g)?, two(0.5, 0.3), bads)?;
    check(&CartPole::new(one, one, one, g)?, two(0.5, 0.3), bads)?;
    check(&Acrobot::<T>::spong(), two(0.5, 0.3), bads)?;
    check(
        &SwingingAtwood::new(T::from_f64(2.0), one, g)?,
        two(1.0, 0.3),
        bads,
    )?;
    check(&Kepler::new(one)?, two(1.0, 0.3), bads)
}

for_f32_and_f64!(
    positive_parameters_are_named,
    non_negative_parameters_are_named,
    inputs_refuse_non_finite,
    singular_states_are_reported,
    non_finite_states_never_give_nan
);

/// A body dropped from rest falls straight into the centre, at `t = pi / (2 sqrt 2) = 1.1107` s
/// for mu = 1, r = 1: RK4 at dt = 1e-3 steps towards it and stops with `Singularity` when a
/// stage reaches `r <= 0` (measured: the last good state is at t = 1.110, r = 0.013), never with
/// a NaN state.
#[test]
fn radial_infall_ends_in_singularity() -> Result<(), Error> {
    let kepler = Kepler::new(1.0)?;
    let mut s = State::at_rest([1.0, 0.0]);
    let outcome = loop {
        match Rk4.step(&kepler, &s, 1e-3) {
            Ok(next) => s = next,
            Err(e) => break e,
        }
        assert!(s.t < 2.0, "still falling at {s:?}");
    };
    assert!(matches!(outcome, Error::Singularity { .. }), "{outcome:?}");
    let fall_time = core::f64::consts::PI / (2.0 * 2f64.sqrt());
    assert!(s.is_finite() && s.q[0] > 0.0, "{s:?}");
    assert!((s.t - fall_time).abs() < 2e-3, "stopped at {s:?}");
    println!("infall stopped at t = {}, r = {:e}: {outcome}", s.t, s.q[0]);
    Ok(())
}

#[test]
fn exact_solutions_refuse_bad_arguments() {
    refuses(damped_oscillator(0.0, 1.0, 1.0, 1.0, 0.0, 1.0), "mass");
    refuses(
        damped_oscillator(1.0, -1.0, 1.0, 1.0, 0.0, 1.0),
        "stiffness",
    );
    refuses(
        damped_oscillator(1.0, 1.0, f64::NAN, 1.0, 0.0, 1.0),
        "damping",
    );
    refuses(
        damped_oscillator(1.0, 1.0, 1.0, f64::INFINITY, 0.0, 1.0),
        "x0",
    );
    refuses(damped_oscillator(1.0, 1.0, 1.0, 1.0, f64::NAN, 1.0), "v0");
    refuses(damped_oscillator(1.0, 1.0, 1.0, 1.0, 0.0, f64::NAN), "t");
    for e in [1.0, 1.5, -0.1, f64::NAN] {
        refuses(kepler_orbit(1.0, 1.0, e, 0.0), "eccentricity");
        refuses(eccentric_anomaly(1.0, e), "eccentricity");
    }
    refuses(kepler_orbit(0.0, 1.0, 0.5, 0.0), "mu");
    refuses(kepler_orbit(1.0, -1.0, 0.5, 0.0), "semi_major_axis");
    refuses(kepler_orbit(1.0, 1.0, 0.5, f64::INFINITY), "t");
    refuses(eccentric_anomaly(f64::NAN, 0.5), "mean_anomaly");
}

/// Issue 15: the generated mechanisms (lagrange-generated, `cargo xtask derive`) follow the
/// finiteness rule: a mass so small that the inverse mass overflows, a finite but extreme
/// state, and a non-finite right-hand side give `NonFiniteState`, never `Ok` with an infinity
/// or a NaN, from `solve_mass` and the law.
fn generated_mechanisms_are_finite_or_refuse<T: Real>() -> Result<(), Error> {
    use lagrange_core::NoForce;
    use lagrange_generated::{DoublePendulum, Pendulum};
    let at = State::new(T::zero(), [T::one()], [T::one()]);
    let tiny = Pendulum::new(T::MIN_POSITIVE * T::EPSILON, T::one(), T::one(), T::one())?;
    assert_eq!(tiny.law(&at, &NoForce), Err(Error::NonFiniteState));
    let p = Pendulum::new(T::one(), T::one(), T::one(), T::from_f64(1e6))?;
    let fast = State::new(T::zero(), [T::one()], [T::MAX]);
    assert_eq!(p.law(&fast, &NoForce), Err(Error::NonFiniteState));
    let nan = SVector::from([T::from_f64(f64::NAN)]);
    assert_eq!(p.solve_mass(&at, &nan), Err(Error::NonFiniteState));
    assert!(p.law(&at, &NoForce)?[0].is_finite());
    let d = DoublePendulum::new(T::one(), T::one(), T::one(), T::one(), T::one())?;
    let huge = SVector::from([T::one(), T::MAX]);
    let s2 = State::at_rest([T::one(), T::zero()]);
    assert_eq!(d.solve_mass(&s2, &huge), Err(Error::NonFiniteState));
    Ok(())
}

for_f32_and_f64!(generated_mechanisms_are_finite_or_refuse);
