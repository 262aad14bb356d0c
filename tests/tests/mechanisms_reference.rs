//! The standard mechanisms against independent references: the chain against the pendulum and
//! the double pendulum, and through a wrapped force against the automatic path; the cart-pole
//! against the Barto-Sutton-Anderson equations (Florian's corrected form); the acrobot against
//! Spong's equations as Sutton and Barto implement them; the f32 chain against the f64 one.

use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, EulerLagrange, Lagrangian, Mechanism, Real, State, ViscousDamping};
use lagrange_systems::{Acrobot, CartPole, DoublePendulum, NLinkPendulum, SimplePendulum};
use lagrange_tests::{for_f32_and_f64, pick, random_state, relative, Rng};

const STATES: usize = 1000;
const G: f64 = 9.81;
const ANGLES: (f64, f64) = (-3.2, 3.2);
const RATES: (f64, f64) = (-5.0, 5.0);

/// Two implementations of the same equations, compared at `STATES` random states; returns the
/// worst relative difference of accelerations (relative to `|q''| + scale`).
fn same_accelerations<T: Real, const N: usize>(
    a: &impl Mechanism<T, N>,
    b: impl Fn(&State<T, N>) -> Result<SVector<T, N>, Error>,
    scale: f64,
    tolerance: f64,
    rng: &mut Rng,
) -> Result<f64, Error> {
    let mut worst = 0.0f64;
    for _ in 0..STATES {
        let s = random_state(rng, ANGLES, RATES);
        let (x, y) = (a.acceleration(&s)?, b(&s)?);
        let e = relative(x.iter().copied(), y.iter().copied(), scale);
        assert!(e < tolerance, "at {s:?}: {x:?} against {y:?} ({e:e})");
        worst = worst.max(e);
    }
    Ok(worst)
}

/// `NLinkPendulum<1>` is the `SimplePendulum` (undamped): the same accelerations, mass matrix
/// and energies to rounding. Measured worst: f64 1.9e-16, f32 5.2e-8 (about one ulp); bound
/// 4 ulps.
fn one_link_is_the_pendulum<T: Real>() -> Result<(), Error> {
    let mut rng = Rng::new(11);
    let (m, l): (T, T) = (rng.uniform(0.2, 5.0), rng.uniform(0.2, 3.0));
    let chain = NLinkPendulum::new([m], [l], T::from_f64(G))?;
    let pendulum = SimplePendulum::new(m, l, T::from_f64(G), T::zero())?;
    let tol = 4.0 * T::EPSILON.to_f64();
    let scale = G / l.to_f64();
    let worst = same_accelerations(&chain, |s| pendulum.acceleration(s), scale, tol, &mut rng)?;
    println!("NLinkPendulum<1> vs SimplePendulum: {worst:.1e}");
    for _ in 0..STATES {
        let s: State<T, 1> = random_state(&mut rng, ANGLES, RATES);
        let e = relative(
            [chain.mass_matrix(&s)[0], chain.energy(&s)],
            [pendulum.mass_matrix(&s)[0], pendulum.energy(&s)],
            G * (m * l).to_f64(),
        );
        assert!(e < tol, "at {s:?}: {e:e}");
    }
    Ok(())
}

/// `NLinkPendulum<2>` is the `DoublePendulum`: accelerations from the tension recursion against
/// the closed-form 2x2 inverse, mass matrices and energies. Measured worst: f64 1.9e-15, f32
/// 1.2e-6 (the 2x2 inverse cancels where the rods are nearly aligned); bounds 1e-14, 5e-6.
fn two_links_are_the_double_pendulum<T: Real>() -> Result<(), Error> {
    let mut rng = Rng::new(12);
    let tol = pick::<T>(5e-6, 1e-14);
    for _ in 0..5 {
        let masses: [T; 2] = [rng.uniform(0.2, 5.0), rng.uniform(0.2, 5.0)];
        let lengths: [T; 2] = [rng.uniform(0.2, 3.0), rng.uniform(0.2, 3.0)];
        let chain = NLinkPendulum::new(masses, lengths, T::from_f64(G))?;
        let [m1, m2] = masses;
        let [l1, l2] = lengths;
        let dp = DoublePendulum::new(m1, m2, l1, l2, T::from_f64(G))?;
        let scale = G / l1.min(l2).to_f64();
        let worst = same_accelerations(&chain, |s| dp.acceleration(s), scale, tol, &mut rng)?;
        println!("NLinkPendulum<2> vs DoublePendulum: {worst:.1e}");
        let energy_scale = G * ((m1 + m2) * l1 + m2 * l2).to_f64();
        for _ in 0..STATES / 5 {
            let s: State<T, 2> = random_state(&mut rng, ANGLES, RATES);
            let e = relative(
                chain.mass_matrix(&s).iter().copied(),
                dp.mass_matrix(&s).iter().copied(),
                0.0,
            );
            assert!(e < tol, "mass matrix at {s:?}: {e:e}");
            let e = relative([chain.energy(&s)], [dp.energy(&s)], energy_scale);
            assert!(e < tol, "energy at {s:?}: {e:e}");
        }
    }
    Ok(())
}

/// A force added by wrapping reaches the chain through `solve_mass`, the tension recursion
/// with a generalized force: it agrees with the automatic path wrapped with the same force.
/// Measured worst: f64 9.2e-15, f32 6.0e-6 (N = 6; the automatic path's f32 Cholesky
/// dominates the difference); bounds 4.6e-14 and 3e-5.
fn wrapped_force_on_the_chain<T: Real>() -> Result<(), Error> {
    let mut rng = Rng::new(13);
    let masses: [T; 6] = core::array::from_fn(|_| rng.uniform(0.2, 5.0));
    let lengths: [T; 6] = core::array::from_fn(|_| rng.uniform(0.2, 3.0));
    let damping: [T; 6] = core::array::from_fn(|_| rng.uniform(0.0, 3.0));
    let chain = NLinkPendulum::new(masses, lengths, T::from_f64(G))?;
    let hand = chain.with_force(ViscousDamping::new(damping)?);
    let auto = EulerLagrange::new(chain).with_force(ViscousDamping::new(damping)?);
    let scale = G / lengths.iter().fold(f64::INFINITY, |a, l| a.min(l.to_f64()));
    let tol = pick::<T>(3e-5, 4.6e-14);
    let worst = same_accelerations(&hand, |s| auto.acceleration(s), scale, tol, &mut rng)?;
    println!("damped NLinkPendulum<6> vs automatic: {worst:.1e}");
    Ok(())
}

/// The cart-pole of Barto, Sutton and Anderson (1983) without friction, as corrected by Florian
/// (2007), written as published:
///
/// ```text
/// th'' = (g sin th + cos th (-F - m l th'^2 sin th) / (M + m)) / (l (4/3 - m cos^2 th / (M + m)))
/// x''  = (F + m l (th'^2 sin th - th'' cos th)) / (M + m)
/// ```
fn florian<T: Real>(cp: &CartPole<T>, s: &State<T, 2>) -> SVector<T, 2> {
    let (m_c, m, l, g) = (
        cp.cart_mass(),
        cp.pole_mass(),
        cp.pole_half_length(),
        cp.gravity(),
    );
    let f = cp.force();
    let total = m_c + m;
    let (sin, cos) = s.q[1].sin_cos();
    let w = s.qd[1];
    let thdd = (g * sin + cos * (-f - m * l * w * w * sin) / total)
        / (l * (T::from_f64(4.0 / 3.0) - m * cos * cos / total));
    let xdd = (f + m * l * (w * w * sin - thdd * cos)) / total;
    SVector::from([xdd, thdd])
}

/// At random parameters, states and input forces. Measured worst: f64 3.3e-16, f32 1.9e-7;
/// bounds 2e-15 and 1e-6.
fn cart_pole_matches_florian<T: Real>() -> Result<(), Error> {
    let mut rng = Rng::new(14);
    let tol = pick::<T>(1e-6, 2e-15);
    let mut worst = 0.0f64;
    for _ in 0..5 {
        let l: T = rng.uniform(0.1, 2.0);
        let mut cp = CartPole::new(
            rng.uniform(0.2, 5.0),
            rng.uniform(0.05, 2.0),
            l,
            T::from_f64(G),
        )?;
        for _ in 0..STATES / 5 {
            cp.set_force(rng.uniform(-20.0, 20.0))?;
            let s = random_state(&mut rng, (-5.0, 5.0), RATES);
            let (a, b) = (cp.acceleration(&s)?, florian(&cp, &s));
            let e = relative(a.iter().copied(), b.iter().copied(), G / l.to_f64());
            assert!(e < tol, "at {s:?}: {a:?} against {b:?} ({e:e})");
            worst = worst.max(e);
        }
    }
    println!("CartPole vs Florian: {worst:.1e}");
    Ok(())
}

/// Spong's acrobot as Sutton and Barto implement it (the "book" form of their `_dsdt`), with
/// `th1 = 0` hanging down and `th2` relative:
///
/// ```text
/// d1 = m1 lc1^2 + m2 (l1^2 + lc2^2 + 2 l1 lc2 cos th2) + I1 + I2
/// d2 = m2 (lc2^2 + l1 lc2 cos th2) + I2
/// phi2 = m2 lc2 g cos(th1 + th2 - pi/2)
/// phi1 = -m2 l1 lc2 th2'^2 sin th2 - 2 m2 l1 lc2 th2' th1' sin th2
///        + (m1 lc1 + m2 l1) g cos(th1 - pi/2) + phi2
/// th2'' = (tau + d2/d1 phi1 - m2 l1 lc2 th1'^2 sin th2 - phi2) / (m2 lc2^2 + I2 - d2^2/d1)
/// th1'' = -(d2 th2'' + phi1) / d1
/// ```
fn sutton_barto<T: Real>(a: &Acrobot<T>, s: &State<T, 2>) -> SVector<T, 2> {
    let ([m1, m2], [l1, _], [lc1, lc2], [i1, i2]) =
        (a.masses(), a.lengths(), a.com_distances(), a.inertias());
    let (g, tau) = (a.gravity(), a.torque());
    let (th1, th2, w1, w2) = (s.q[0], s.q[1], s.qd[0], s.qd[1]);
    let half_pi = T::HALF * T::PI;
    let d1 = m1 * lc1 * lc1 + m2 * (l1 * l1 + lc2 * lc2 + T::TWO * l1 * lc2 * th2.cos()) + i1 + i2;
    let d2 = m2 * (lc2 * lc2 + l1 * lc2 * th2.cos()) + i2;
    let phi2 = m2 * lc2 * g * (th1 + th2 - half_pi).cos();
    let phi1 = -m2 * l1 * lc2 * w2 * w2 * th2.sin() - T::TWO * m2 * l1 * lc2 * w2 * w1 * th2.sin()
        + (m1 * lc1 + m2 * l1) * g * (th1 - half_pi).cos()
        + phi2;
    let dd2 = (tau + d2 / d1 * phi1 - m2 * l1 * lc2 * w1 * w1 * th2.sin() - phi2)
        / (m2 * lc2 * lc2 + i2 - d2 * d2 / d1);
    let dd1 = -(d2 * dd2 + phi1) / d1;
    SVector::from([dd1, dd2])
}

/// At Spong's parameters and at random ones, random states and torques. Measured worst: f64
/// 4.0e-15, f32 2.3e-6 (the published form cancels in `d22 - d2^2 / d1`); bounds 2e-14 and
/// 1e-5.
fn acrobot_matches_spong<T: Real>() -> Result<(), Error> {
    let mut rng = Rng::new(15);
    let tol = pick::<T>(1e-5, 2e-14);
    let mut worst = 0.0f64;
    let mut acrobots = vec![Acrobot::<T>::spong()];
    for _ in 0..4 {
        let (l1, l2): (T, T) = (rng.uniform(0.2, 3.0), rng.uniform(0.2, 3.0));
        acrobots.push(Acrobot::new(
            rng.uniform(0.2, 5.0),
            rng.uniform(0.2, 5.0),
            l1,
            l2,
            l1 * rng.uniform(0.1, 1.0),
            l2 * rng.uniform(0.1, 1.0),
            rng.uniform(0.0, 2.0),
            rng.uniform(0.0, 2.0),
            T::from_f64(G),
        )?);
    }
    for mut a in acrobots {
        let scale = G / a.lengths()[0].to_f64();
        for _ in 0..STATES / 5 {
            a.set_torque(rng.uniform(-5.0, 5.0))?;
            let s = random_state(&mut rng, ANGLES, RATES);
            let (x, y) = (a.acceleration(&s)?, sutton_barto(&a, &s));
            let e = relative(x.iter().copied(), y.iter().copied(), scale);
            assert!(e < tol, "at {s:?}: {x:?} against {y:?} ({e:e})");
            worst = worst.max(e);
        }
    }
    println!("Acrobot vs Sutton-Barto: {worst:.1e}");
    Ok(())
}

for_f32_and_f64!(
    one_link_is_the_pendulum,
    two_links_are_the_double_pendulum,
    wrapped_force_on_the_chain,
    cart_pole_matches_florian,
    acrobot_matches_spong
);

/// The f32 chain against the f64 chain with the same (f32-rounded) parameters and states: the
/// accelerations of the tension recursion lose little to single precision even at N = 8.
/// Measured worst: 2.2e-6; bound 1e-5. (Solving `M q'' = f` by Cholesky in f32 errs by 3.5e-6
/// at the same states.)
#[test]
fn f32_chain_tracks_f64() -> Result<(), Error> {
    let mut rng = Rng::new(16);
    let masses: [f32; 8] = core::array::from_fn(|_| rng.uniform(0.2, 5.0));
    let lengths: [f32; 8] = core::array::from_fn(|_| rng.uniform(0.2, 3.0));
    let c32 = NLinkPendulum::new(masses, lengths, 9.81f32)?;
    let c64 = NLinkPendulum::new(masses.map(f64::from), lengths.map(f64::from), 9.81)?;
    let scale = G / lengths
        .iter()
        .fold(f64::INFINITY, |a, l| a.min(f64::from(*l)));
    let (mut worst, mut worst_cholesky) = (0.0f64, 0.0f64);
    for _ in 0..STATES {
        let s: State<f32, 8> = random_state(&mut rng, ANGLES, RATES);
        let wide = State {
            t: f64::from(s.t),
            q: s.q.map(f64::from),
            qd: s.qd.map(f64::from),
        };
        let truth = c64.acceleration(&wide)?;
        let a = c32.acceleration(&s)?.map(f64::from);
        let e = relative(truth.iter().copied(), a.iter().copied(), scale);
        assert!(e < 1e-5, "at {s:?}: {a:?} against {truth:?} ({e:e})");
        worst = worst.max(e);
        let c = lagrange_core::solve_spd(&c32.mass_matrix(&s), &c32.rhs(&s))?.map(f64::from);
        worst_cholesky =
            worst_cholesky.max(relative(truth.iter().copied(), c.iter().copied(), scale));
    }
    println!("f32 chain, N = 8, against f64: tension {worst:.1e}, Cholesky {worst_cholesky:.1e}");
    Ok(())
}

/// The chain's mass positions and the acrobot's tip: at known configurations, and the chain's
/// potential energy is `g sum_i m_i y_i` of its positions at random states (measured 2.3e-16 and
/// 1.2e-7 relative to `g sum_j mu_j l_j`, about one ulp; bound 4 ulps).
fn positions_and_tip<T: Real>() -> Result<(), Error> {
    let c = T::from_f64;
    let chain = NLinkPendulum::new([c(1.0), c(2.0), c(3.0)], [c(0.5), c(1.0), c(1.5)], c(G))?;
    let hanging = chain.positions(&SVector::zeros());
    assert_eq!(hanging[2], (T::zero(), c(-3.0)));
    let level = chain.positions(&SVector::repeat(T::HALF * T::PI));
    let tol = 8.0 * T::EPSILON.to_f64();
    assert!((level[1].0 - c(1.5)).abs().to_f64() < tol && level[1].1.abs().to_f64() < tol);

    let acrobot = Acrobot::<T>::spong();
    let (x, y) = acrobot.tip(&State::at_rest([T::zero(); 2]));
    assert!(x.abs().to_f64() < tol && (y + c(2.0)).abs().to_f64() < tol);
    let (x, y) = acrobot.tip(&State::at_rest([T::HALF * T::PI, -T::HALF * T::PI]));
    assert!((x - T::one()).abs().to_f64() < tol && (y + T::one()).abs().to_f64() < tol);

    let mut rng = Rng::new(17);
    let scale = G * (6.0 * 0.5 + 5.0 * 1.0 + 3.0 * 1.5);
    let mut worst = 0.0f64;
    for _ in 0..STATES {
        let s: State<T, 3> = random_state(&mut rng, ANGLES, RATES);
        let from_positions: f64 = chain
            .positions(&s.q)
            .iter()
            .zip(chain.masses())
            .map(|(p, m)| G * m.to_f64() * p.1.to_f64())
            .sum();
        let e = (chain.potential_energy(&s).to_f64() - from_positions).abs() / scale;
        assert!(e < 4.0 * T::EPSILON.to_f64(), "at {s:?}: {e:e}");
        worst = worst.max(e);
    }
    println!("chain potential from positions: {worst:.1e}");
    Ok(())
}

for_f32_and_f64!(positions_and_tip);
