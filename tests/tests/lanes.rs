//! Lanes: `L` instances stepped side by side give, bit for bit, what each gives alone, for
//! every mechanism that gathers and every method that steps lanes, in `f32` and `f64`; a law
//! that branches differently in different lanes is caught (a divergence) and a bank then steps
//! its instances one by one. (The lane sine and cosine are checked against the scalar ones in
//! `lagrange-core/tests/fast_trig.rs`.)

use lagrange_core::nalgebra::SVector;
use lagrange_core::{check_finite, divergences, Error, Gather, Lanes, Real, Scalar, State};
use lagrange_integrators::scene::{Bank, InLanes, NeverSleeps, Scene, LANES};
use lagrange_integrators::{
    ExplicitEuler, FixedTimestep, Integrator, Rk4, SemiImplicitEuler, VelocityVerlet,
};
use lagrange_systems::{
    Acrobot, CartPole, DoublePendulum, FallingParticle, RigidBody, SimplePendulum, SpringMassDamper,
};
use lagrange_tests::{for_f32_and_f64, Rng};

/// Lanes per group in the tests of lanes alone (a scene's bank steps [`LANES`] at a time).
const L: usize = 8;

/// Steps per comparison: long enough for a chaotic double pendulum to amplify any bit.
const STEPS: usize = 400;

/// `L` instances built by `make`, started from `start`, stepped by `integrator` in lanes
/// and alone for [`STEPS`] steps of `dt`: every lane equal to its instance alone, bit for bit,
/// and no divergence. The lanes are gathered twice, from the instances at once and by putting
/// each into a group gathered from the first alone (as a bank does as instances join), and
/// both step alike.
fn lanes_equal_alone<T, const N: usize, M, I>(
    integrator: I,
    dt: f64,
    make: impl Fn(&mut Rng) -> Result<(M, State<T, N>), Error>,
    seed: u64,
) -> Result<(), Error>
where
    T: Real,
    M: Gather<T, N>,
    I: Integrator<T, N, M> + Clone,
{
    let mut rng = Rng::new(seed);
    let built: Vec<(M, State<T, N>)> = (0..L).map(|_| make(&mut rng)).collect::<Result<_, _>>()?;
    let instances: [&M; L] = core::array::from_fn(|i| &built[i].0);
    let lanes = M::gather(instances);
    let mut put = M::gather([instances[0]; L]);
    for (lane, m) in instances.iter().enumerate() {
        m.put(&mut put, lane);
    }
    let dt = T::from_f64(dt);
    let mut alone: Vec<State<T, N>> = built.iter().map(|(_, s)| *s).collect();
    let states: [&State<T, N>; L] = core::array::from_fn(|i| &built[i].1);
    let mut side = State {
        t: Lanes::gather(&states, |s| s.t),
        q: SVector::from_fn(|j, _| Lanes::gather(&states, |s| s.q[j])),
        qd: SVector::from_fn(|j, _| Lanes::gather(&states, |s| s.qd[j])),
    };
    let before = divergences();
    for step in 0..STEPS {
        let by_put = integrator
            .step_lanes(&put, &side, dt)
            .ok_or(Error::InvalidParameter {
                name: "integrator",
                reason: "steps no lanes",
            })??;
        side = integrator
            .step_lanes(&lanes, &side, dt)
            .ok_or(Error::InvalidParameter {
                name: "integrator",
                reason: "steps no lanes",
            })??;
        let bits = |s: &State<Lanes<T, L>, N>| {
            (0..L)
                .map(|i| (s.q.map(|x| x.0[i]), s.qd.map(|x| x.0[i])))
                .collect::<Vec<_>>()
        };
        assert!(bits(&by_put) == bits(&side), "{} step {step}: put", I::NAME);
        for (i, (s, (m, _))) in alone.iter_mut().zip(&built).enumerate() {
            *s = integrator.clone().run_step(m, s, dt)?;
            let lane = (side.t.0[i], side.q.map(|x| x.0[i]), side.qd.map(|x| x.0[i]));
            assert!(
                lane.0 == s.t && lane.1 == s.q && lane.2 == s.qd,
                "{} step {step}, lane {i}: {lane:?} alone {s:?}",
                I::NAME
            );
        }
    }
    assert_eq!(divergences(), before, "{}", I::NAME);
    Ok(())
}

/// Every lane-stepping method on one mechanism.
fn every_method<T, const N: usize, M>(
    dt: f64,
    make: impl Fn(&mut Rng) -> Result<(M, State<T, N>), Error> + Copy,
) -> Result<(), Error>
where
    T: Real,
    M: Gather<T, N>,
{
    lanes_equal_alone(Rk4, dt, make, 1)?;
    lanes_equal_alone(ExplicitEuler, dt, make, 2)?;
    lanes_equal_alone(SemiImplicitEuler, dt, make, 3)?;
    lanes_equal_alone(VelocityVerlet, dt, make, 4)?;
    Ok(())
}

/// A value of `T` uniform in `[lo, hi)`.
fn u<T: Real>(rng: &mut Rng, lo: f64, hi: f64) -> T {
    rng.uniform(lo, hi)
}

/// Pendulums of different lengths and damping, from small and from large angles (some beyond
/// the lane trig's fast range), and the standard mechanisms with parameters of their own.
fn every_gathering_mechanism<T: Real>() -> Result<(), Error> {
    every_method(1e-2, |r| {
        let p = SimplePendulum::new(
            u(r, 0.5, 2.0),
            u(r, 0.3, 3.0),
            T::from_f64(9.81),
            u(r, 0.0, 1.0),
        )?;
        let th = if r.unit() < 0.5 {
            u(r, -0.7, 0.7)
        } else {
            u(r, -700.0, 700.0)
        };
        Ok((p, State::new(T::zero(), [th], [u(r, -2.0, 2.0)])))
    })?;
    every_method(1e-2, |r| {
        let p = DoublePendulum::new(
            u(r, 0.5, 2.0),
            u(r, 0.5, 2.0),
            u(r, 0.5, 2.0),
            u(r, 0.5, 2.0),
            T::from_f64(9.81),
        )?;
        Ok((p, State::at_rest([u(r, -3.0, 3.0), u(r, -3.0, 3.0)])))
    })?;
    every_method(1e-2, |r| {
        let mut p = CartPole::new(
            u(r, 0.5, 2.0),
            u(r, 0.05, 0.5),
            u(r, 0.2, 1.0),
            T::from_f64(9.8),
        )?;
        p.set_force(u(r, -5.0, 5.0))?;
        Ok((p, State::at_rest([u(r, -1.0, 1.0), u(r, -3.0, 3.0)])))
    })?;
    every_method(1e-2, |r| {
        let mut p = Acrobot::<T>::spong();
        p.set_torque(u(r, -2.0, 2.0))?;
        Ok((p, State::at_rest([u(r, -2.0, 2.0), u(r, -2.0, 2.0)])))
    })?;
    every_method(1e-2, |r| {
        let p = SpringMassDamper::new(u(r, 0.5, 2.0), u(r, 1.0, 50.0), u(r, 0.0, 1.0))?;
        Ok((
            p,
            State::new(T::zero(), [u(r, -1.0, 1.0)], [u(r, -1.0, 1.0)]),
        ))
    })?;
    every_method(1e-2, |r| {
        let p = FallingParticle::new(u(r, 0.5, 2.0), T::from_f64(9.81))?;
        Ok((
            p,
            State::new(T::zero(), [u(r, 0.0, 10.0)], [u(r, -1.0, 1.0)]),
        ))
    })?;
    every_method(1e-2, |r| {
        let p = RigidBody::new(u(r, 0.5, 2.0), u(r, 0.1, 1.0), T::from_f64(9.81))?;
        let q = [u(r, -1.0, 1.0), u(r, 0.0, 10.0), u(r, -3.0, 3.0)];
        let qd = [u(r, -1.0, 1.0), u(r, -1.0, 1.0), u(r, -5.0, 5.0)];
        Ok((p, State::new(T::zero(), q, qd)))
    })?;
    Ok(())
}

/// A bank of pendulums that is not a multiple of the lane width, stepped by a scene, equals
/// a `FixedTimestep` per pendulum, bit for bit (interpolated states too).
fn a_bank_in_lanes_equals_its_instances_alone<T: Real>() -> Result<(), Error> {
    const K: usize = 3 * LANES + 5;
    let mut rng = Rng::new(11);
    let dt = T::from_f64(1.0 / 120.0);
    let mut bank: Bank<T, 2, K, DoublePendulum<T>, Rk4, NeverSleeps, InLanes> =
        Bank::new(Rk4, NeverSleeps)?;
    let mut alone = Vec::new();
    for _ in 0..K {
        let p = DoublePendulum::new(
            u(&mut rng, 0.5, 2.0),
            T::one(),
            T::one(),
            u(&mut rng, 0.5, 2.0),
            T::from_f64(9.81),
        )?;
        let s = State::at_rest([u(&mut rng, -3.0, 3.0), u(&mut rng, -3.0, 3.0)]);
        let id = bank.add(p, s)?;
        alone.push((id, p, FixedTimestep::new(Rk4, dt, 4, s)?));
    }
    let mut scene = Scene::new(bank, dt, 4)?;
    for frame in 0..600 {
        let frame_time = T::from_f64([1.0 / 60.0, 1.0 / 144.0, 0.03][frame % 3]);
        scene.advance(frame_time)?;
        for (id, p, clock) in &mut alone {
            clock.advance(p, frame_time)?;
            let (mine, theirs) = (scene.banks().state(*id)?, clock.current());
            assert!(mine.q == theirs.q && mine.qd == theirs.qd, "frame {frame}");
            let drawn = scene.banks().interpolated(*id, scene.alpha())?;
            assert!(drawn.q == clock.interpolated().q);
        }
    }
    Ok(())
}

/// The tests of results over lanes ([`check_finite`], [`Real::every_lane_finite`],
/// [`Real::every_lane_positive`]) hold exactly when they hold in every lane, and count no
/// divergence where the lanes disagree (their failure is an error for the whole group).
fn result_tests_hold_in_every_lane_and_count_nothing<T: Real>() -> Result<(), Error> {
    let mut rng = Rng::new(21);
    let specials = [
        0.0,
        -0.0,
        1.0,
        -2.5,
        1e-30,
        f64::NAN,
        f64::INFINITY,
        -f64::INFINITY,
    ];
    let value = |rng: &mut Rng| -> Lanes<T, L> {
        Lanes::from_fn(|_| {
            // Mostly finite and positive, so that every answer comes up.
            if rng.unit() < 0.9 {
                rng.uniform(0.5, 2.0)
            } else {
                T::from_f64(specials[(rng.unit() * specials.len() as f64) as usize % 8])
            }
        })
    };
    let before = divergences();
    let (mut failed, mut passed) = (0, 0);
    for _ in 0..4000 {
        let values = [value(&mut rng), value(&mut rng)];
        let every = |test: fn(T) -> bool| values.iter().all(|v| v.0.iter().all(|&x| test(x)));
        let finite = every(|x| x.is_finite());
        assert_eq!(Lanes::every_lane_finite(&values), finite, "{values:?}");
        assert_eq!(
            Lanes::every_lane_positive(&values),
            every(|x| x > T::zero()),
            "{values:?}"
        );
        let checked = check_finite(&values, Error::NonFiniteState);
        assert_eq!(checked.is_ok(), finite);
        if finite {
            passed += 1;
        } else {
            failed += 1;
        }
    }
    assert!(
        failed > 500 && passed > 500,
        "{failed} failed, {passed} passed"
    );
    assert_eq!(divergences(), before);
    Ok(())
}

/// A group of pendulums one of which is thrown so fast that its step overflows: the lane step
/// is an error, never `Ok` with an infinity, and counts no divergence; the others alone step
/// as before.
fn a_lane_that_blows_up_fails_the_group<T: Real>() -> Result<(), Error> {
    let fast = T::MAX / T::from_f64(4.0);
    let built: Vec<(SimplePendulum<T>, State<T, 1>)> = (0..L)
        .map(|i| {
            let v = if i == 5 {
                fast
            } else {
                T::from_f64(0.1 * i as f64)
            };
            Ok((
                SimplePendulum::new(T::one(), T::one(), T::from_f64(9.81), T::zero())?,
                State::new(T::zero(), [T::from_f64(0.3)], [v]),
            ))
        })
        .collect::<Result<_, Error>>()?;
    let lanes = SimplePendulum::gather(core::array::from_fn(|i| &built[i].0));
    let states: [&State<T, 1>; L] = core::array::from_fn(|i| &built[i].1);
    let side = State {
        t: Lanes::gather(&states, |s| s.t),
        q: SVector::from_fn(|j, _| Lanes::gather(&states, |s| s.q[j])),
        qd: SVector::from_fn(|j, _| Lanes::gather(&states, |s| s.qd[j])),
    };
    let dt = T::from_f64(0.01);
    let before = divergences();
    let stepped = Integrator::<T, 1, SimplePendulum<T>>::step_lanes(&Rk4, &lanes, &side, dt);
    assert!(
        matches!(stepped, Some(Err(Error::NonFiniteState))),
        "{stepped:?}"
    );
    assert_eq!(divergences(), before);
    for (i, (m, s)) in built.iter().enumerate() {
        assert_eq!(Rk4.run_step(m, s, dt).is_ok(), i != 5, "lane {i}");
    }
    Ok(())
}

/// Zero and one, and whether a number is zero, through the bound (`Scalar` asks for
/// `num_traits`' `Zero` and `One`).
fn zero<S: Scalar>() -> S {
    S::zero()
}
fn one<S: Scalar>() -> S {
    S::one()
}
fn is_zero<S: Scalar>(x: &S) -> bool {
    x.is_zero()
}

/// Every lane of `got` is `f` of its index, bit for bit (the operands are finite and so are
/// the results: `==` is bitwise there, but for the sign of zero, which none has).
fn lane_by_lane<T: Real>(got: Lanes<T, L>, f: impl Fn(usize) -> T, what: &str) {
    for i in 0..L {
        assert!(got.0[i] == f(i), "{what}, lane {i}: {got:?}");
    }
}

/// Every operation of `Lanes` is the scalar one in each lane, bit for bit, and comparisons
/// that hold in every lane or in none answer as the scalar ones would, counting nothing; the
/// numbers print lane by lane.
fn every_operation_lane_by_lane<T: Real>() -> Result<(), Error> {
    let before = divergences();
    let at = |i: usize, a: f64, b: f64| T::from_f64(a + b * i as f64);
    let x = Lanes::<T, L>::from_fn(|i| at(i, 0.3, 0.25));
    let y = Lanes::<T, L>::from_fn(|i| at(i, -1.1, 0.45));
    let z = Lanes::<T, L>::from_fn(|i| at(i, -0.9, 0.25));
    let c = T::from_f64(1.75);
    let (xs, ys, zs) = (x.0, y.0, z.0);
    lane_by_lane(x + y, |i| xs[i] + ys[i], "+");
    lane_by_lane(x - y, |i| xs[i] - ys[i], "-");
    lane_by_lane(x * y, |i| xs[i] * ys[i], "*");
    lane_by_lane(x / y, |i| xs[i] / ys[i], "/");
    lane_by_lane(x + c, |i| xs[i] + c, "+ c");
    lane_by_lane(x / c, |i| xs[i] / c, "/ c");
    let mut w = x;
    w *= y;
    w -= c;
    lane_by_lane(w, |i| xs[i] * ys[i] - c, "*= -=");
    lane_by_lane(-y, |i| -ys[i], "neg");
    lane_by_lane(x.sin(), |i| xs[i].sin(), "sin");
    lane_by_lane(x.cos(), |i| xs[i].cos(), "cos");
    let (s, co) = y.sin_cos();
    lane_by_lane(s, |i| ys[i].sin(), "sin_cos.0");
    lane_by_lane(co, |i| ys[i].cos(), "sin_cos.1");
    let ([s2], [c2]) = <Lanes<T, L> as Real>::sin_cos_lanes([y]);
    lane_by_lane(s2, |i| ys[i].sin(), "sin_cos_lanes.0");
    lane_by_lane(c2, |i| ys[i].cos(), "sin_cos_lanes.1");
    let ([s3], [c3]) = (
        <Lanes<T, L> as Real>::sin_lanes([y]),
        <Lanes<T, L> as Real>::cos_lanes([y]),
    );
    lane_by_lane(s3, |i| ys[i].sin(), "sin_lanes");
    lane_by_lane(c3, |i| ys[i].cos(), "cos_lanes");
    lane_by_lane(z.tan(), |i| zs[i].tan(), "tan");
    lane_by_lane(x.sqrt(), |i| xs[i].sqrt(), "sqrt");
    lane_by_lane(y.exp(), |i| ys[i].exp(), "exp");
    lane_by_lane(x.ln(), |i| xs[i].ln(), "ln");
    lane_by_lane(y.abs(), |i| ys[i].abs(), "abs");
    lane_by_lane(y.recip(), |i| ys[i].recip(), "recip");
    lane_by_lane(y.powi(3), |i| ys[i].powi(3), "powi 3");
    lane_by_lane(x.powi(-2), |i| xs[i].powi(-2), "powi -2");
    lane_by_lane(y.atan2(x), |i| ys[i].atan2(xs[i]), "atan2");
    lane_by_lane(x.powf(y), |i| xs[i].powf(ys[i]), "powf");
    lane_by_lane(x.max(y), |i| xs[i].max(ys[i]), "max");
    lane_by_lane(x.min(y), |i| xs[i].min(ys[i]), "min");
    lane_by_lane(
        (y * T::from_f64(3.0)).floor(),
        |i| (ys[i] * T::from_f64(3.0)).floor(),
        "floor",
    );
    lane_by_lane(
        (y * T::from_f64(3.0)).round(),
        |i| (ys[i] * T::from_f64(3.0)).round(),
        "round",
    );
    lane_by_lane(z.asin(), |i| zs[i].asin(), "asin");
    lane_by_lane(z.acos(), |i| zs[i].acos(), "acos");
    lane_by_lane(y.atan(), |i| ys[i].atan(), "atan");
    lane_by_lane(Scalar::value(x), |i| xs[i], "value");
    lane_by_lane(
        <Lanes<T, L> as Scalar>::from_real(y),
        |i| ys[i],
        "from_real",
    );
    lane_by_lane(
        Lanes::<T, L>::from_f64(2.5),
        |_| T::from_f64(2.5),
        "from_f64",
    );
    lane_by_lane(
        Lanes::<T, L>::from_f32(2.5),
        |_| T::from_f64(2.5),
        "from_f32",
    );
    lane_by_lane(zero(), |_| T::zero(), "zero");
    lane_by_lane(one(), |_| T::one(), "one");
    assert!(is_zero(&zero::<Lanes<T, L>>()) && !is_zero(&x));
    // A uniform value reads as a plain number.
    assert_eq!(Lanes::<T, L>::splat(c).to_f64(), c.to_f64());
    assert_eq!(Lanes::<T, L>::splat(c).to_f32(), c.to_f32());
    assert!(x.is_finite());
    // Comparisons that hold in every lane or in none.
    let x1 = x + T::one();
    let answers = |a: &Lanes<T, L>, b: &Lanes<T, L>| [a < b, a <= b, a > b, a >= b, a == b, a != b];
    assert_eq!(answers(&x, &x1), [true, true, false, false, false, true]);
    assert_eq!(answers(&x, &x), [false, true, false, true, true, false]);
    assert_eq!(answers(&x1, &x), [false, false, true, true, false, true]);
    assert_eq!(x.partial_cmp(&x1), Some(core::cmp::Ordering::Less));
    assert_eq!(x.partial_cmp(&x), Some(core::cmp::Ordering::Equal));
    assert_eq!(x1.partial_cmp(&x), Some(core::cmp::Ordering::Greater));
    assert_eq!(divergences(), before);
    // Printed lane by lane.
    let two = Lanes([T::from_f64(1.5), T::from_f64(-2.0), T::from_f64(0.25)]);
    assert_eq!(format!("{two}"), "[1.5, -2, 0.25]");
    assert_eq!(format!("{two:e}"), "[1.5e0, -2e0, 2.5e-1]");
    Ok(())
}

for_f32_and_f64!(
    every_operation_lane_by_lane,
    every_gathering_mechanism,
    a_bank_in_lanes_equals_its_instances_alone,
    result_tests_hold_in_every_lane_and_count_nothing,
    a_lane_that_blows_up_fails_the_group
);
