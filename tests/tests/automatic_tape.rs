//! The automatic path from 11 coordinates on, where `EulerLagrange` records `T` and `V` on a
//! tape instead of a jet: its exact law Jacobian (the tape over dual numbers), its refusal of
//! states that are not finite, its fallback to the jet for a `T` too large for a tape, and a
//! kinetic energy that depends on time. (Its agreement with the hand-derived chain is in
//! `automatic_exactness.rs`; each operation's partials against the jet are unit tests of
//! `lagrange-core`'s `tape` module.)

use lagrange_core::nalgebra::SVector;
use lagrange_core::{
    central_difference_jacobian, Error, EulerLagrange, Lagrangian, Mechanism, Scalar, State,
};
use lagrange_systems::NLinkPendulum;
use lagrange_tests::{random_state, Rng};

/// A chain of `N` links with masses and lengths from `rng`.
fn chain<const N: usize>(rng: &mut Rng) -> Result<NLinkPendulum<f64, N>, Error> {
    NLinkPendulum::new(
        core::array::from_fn(|_| rng.uniform(0.5, 2.0)),
        core::array::from_fn(|_| rng.uniform(0.5, 1.5)),
        9.81,
    )
}

/// The exact Jacobian of the 12-link chain's acceleration (on the tape, over dual numbers)
/// against central differences of the hand-derived law: measured worst 8.1e-10 relative over
/// 20 states (the differences' own truncation and rounding); bound 1e-7, far under a wrong
/// third derivative (a wrong partial moves whole columns).
#[test]
fn the_law_jacobian_on_a_tape_is_exact() -> Result<(), Error> {
    let mut rng = Rng::new(41);
    let mut worst = 0.0f64;
    for _ in 0..20 {
        let hand = chain::<12>(&mut rng)?;
        let auto = EulerLagrange::new(hand);
        let s: State<f64, 12> = random_state(&mut rng, (-1.5, 1.5), (-2.0, 2.0));
        let (a, exact) = auto.law_jacobian(&s, &lagrange_core::NoForce)?;
        let differences = central_difference_jacobian(&s, |x| {
            hand.acceleration(x)
                .unwrap_or_else(|_| SVector::from_element(f64::NAN))
        });
        let scale = differences.wrt_q.amax().max(differences.wrt_qd.amax());
        let e = (exact.wrt_q - differences.wrt_q)
            .amax()
            .max((exact.wrt_qd - differences.wrt_qd).amax())
            / scale;
        worst = worst.max(e);
        let h = hand.acceleration(&s)?;
        assert!((a - h).amax() <= 1e-12 * h.amax(), "{a} against {h}");
    }
    assert!(worst < 1e-7, "worst {worst:e}");
    Ok(())
}

/// A state that is not finite is refused, and a huge one is refused or answered finitely,
/// never with a NaN: on the tape as on the jet.
#[test]
fn states_that_are_not_finite_are_refused() -> Result<(), Error> {
    let mut rng = Rng::new(42);
    let auto = EulerLagrange::new(chain::<20>(&mut rng)?);
    let good: State<f64, 20> = random_state(&mut rng, (-1.0, 1.0), (-1.0, 1.0));
    assert!(auto.acceleration(&good).is_ok());
    for bad in [f64::NAN, f64::INFINITY, -f64::INFINITY, 1e300] {
        for k in [0, 7, 19] {
            for velocity in [false, true] {
                let mut s = good;
                if velocity {
                    s.qd[k] = bad;
                } else {
                    s.q[k] = bad;
                }
                let a = auto.acceleration(&s);
                if bad.is_finite() {
                    // Huge but finite: an answer must be finite.
                    if let Ok(a) = a {
                        assert!(a.iter().all(|x| x.is_finite()), "{bad} at {k}: {a}");
                    }
                } else {
                    assert!(a.is_err(), "{bad} at {k}: {a:?}");
                }
            }
        }
    }
    Ok(())
}

/// `N` unit masses on springs, the kinetic energy summed from `PIECES` equal parts per
/// coordinate (`PIECES` nodes a coordinate on the tape, and more), the potential `k q^2 / 2`:
/// `q'' = -k q` exactly, whichever way it is differentiated.
struct Pieces<const PIECES: usize> {
    k: f64,
}

impl<const N: usize, const PIECES: usize> Lagrangian<f64, N> for Pieces<PIECES> {
    fn kinetic<S: Scalar<Real = f64>>(&self, _t: S, _q: &SVector<S, N>, qd: &SVector<S, N>) -> S {
        let mut t = S::zero();
        for v in qd.iter() {
            for _ in 0..PIECES {
                t += *v * *v * (0.5 / PIECES as f64);
            }
        }
        t
    }
    fn potential<S: Scalar<Real = f64>>(&self, _t: S, q: &SVector<S, N>) -> S {
        q.iter().fold(S::zero(), |v, &x| v + x * x * (0.5 * self.k))
    }
}

/// A kinetic energy of 12 x 100 x 3 = 3,600 nodes does not fit the largest tape (1,024): the
/// jet takes it, with the same result as a small one that fits (2 pieces): `q'' = -k q` to
/// rounding (measured 7.2e-16 relative; bound 1e-13).
#[test]
fn a_kinetic_energy_too_large_for_a_tape_goes_to_the_jet() -> Result<(), Error> {
    let mut rng = Rng::new(43);
    for _ in 0..10 {
        let s: State<f64, 12> = random_state(&mut rng, (-1.0, 1.0), (-3.0, 3.0));
        let k = rng.uniform(0.5, 4.0);
        let exact = -s.q * k;
        for a in [
            EulerLagrange::new(Pieces::<2> { k }).acceleration(&s)?,
            EulerLagrange::new(Pieces::<100> { k }).acceleration(&s)?,
        ] {
            assert!(
                (a - exact).amax() <= 1e-13 * exact.amax(),
                "{a} against {exact}"
            );
        }
    }
    Ok(())
}

/// Twelve beads, each on a line carried at the speed `c t` (written in the fixed frame, so
/// that `T` depends on time): `T = sum m (q'_i - c t)^2 / 2`, `V = 0`. Then
/// `d/dt dT/dq' = m (q'' - c)` and `q'' = c` exactly; the tape's time input carries it.
struct Carried {
    c: f64,
}

impl Lagrangian<f64, 12> for Carried {
    const EXPLICIT_TIME: bool = true;
    fn kinetic<S: Scalar<Real = f64>>(&self, t: S, _q: &SVector<S, 12>, qd: &SVector<S, 12>) -> S {
        qd.iter().fold(S::zero(), |e, &v| {
            let w = v - t * self.c;
            e + w * w * 0.5
        })
    }
    fn potential<S: Scalar<Real = f64>>(&self, _t: S, _q: &SVector<S, 12>) -> S {
        S::zero()
    }
}

#[test]
fn time_in_the_kinetic_energy_enters_on_a_tape() -> Result<(), Error> {
    let mut rng = Rng::new(44);
    for _ in 0..10 {
        let c = rng.uniform(-3.0, 3.0);
        let mut s: State<f64, 12> = random_state(&mut rng, (-1.0, 1.0), (-3.0, 3.0));
        s.t = rng.uniform(0.0, 10.0);
        let a = EulerLagrange::new(Carried { c }).acceleration(&s)?;
        assert!(
            a.iter().all(|x| (x - c).abs() <= 1e-14 * c.abs().max(1.0)),
            "{a}"
        );
    }
    Ok(())
}

/// In f32 too: the 12-link chain's automatic accelerations (on the tape) against the
/// hand-derived law, relative to the largest: measured worst 1.5e-5 over 200 states (f32's
/// rounding through a solve of `M`, whose conditioning grows with `N`); bound 1e-4.
#[test]
fn in_f32_the_tape_agrees_with_the_hand_law() -> Result<(), Error> {
    let mut rng = Rng::new(45);
    let mut worst = 0.0f32;
    for _ in 0..4 {
        let hand = NLinkPendulum::<f32, 12>::new(
            core::array::from_fn(|_| rng.uniform(0.5, 2.0)),
            core::array::from_fn(|_| rng.uniform(0.5, 1.5)),
            9.81,
        )?;
        let auto = EulerLagrange::new(hand);
        for _ in 0..50 {
            let s: State<f32, 12> = random_state(&mut rng, (-1.5, 1.5), (-2.0, 2.0));
            let (a, h) = (auto.acceleration(&s)?, hand.acceleration(&s)?);
            worst = worst.max((a - h).amax() / h.amax());
        }
    }
    assert!(worst < 1e-4, "worst {worst:e}");
    Ok(())
}
