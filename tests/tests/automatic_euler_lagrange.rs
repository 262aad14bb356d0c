//! Every hand-derived system agrees with the automatic Euler-Lagrange path (dual numbers) at
//! 1,000 random states and random valid parameters.

use lagrange_core::{Error, EulerLagrange, Lagrangian, Mechanism, Real, State};
use lagrange_systems::{BeadOnRotatingHoop, DoublePendulum, FallingParticle, SimplePendulum};
use lagrange_tests::{for_f32_and_f64, pick, Rng};

const STATES: usize = 1000;

/// Relative agreement of accelerations, mass matrices and energies. Both paths compute the same
/// terms in a different order, so they agree to a few ulps of the largest term, more where the
/// 2x2 solve cancels. f64: the 1e-12, ~4500 ulps. f32: the largest difference measured
/// over these states is 6e-7 (~5 ulps); the bound 5e-6 leaves a factor 8.
fn tolerance<T: Real>() -> f64 {
    pick::<T>(5e-6, 1e-12)
}

/// `|a - b|_inf / (|a|_inf + scale)`: relative, with `scale` the system's natural size of the
/// quantity so that a state where it happens to vanish is not judged on rounding alone.
fn relative<T: Real>(
    a: impl IntoIterator<Item = T>,
    b: impl IntoIterator<Item = T>,
    scale: f64,
) -> f64 {
    let (mut diff, mut size) = (0.0f64, 0.0f64);
    for (x, y) in a.into_iter().zip(b) {
        diff = diff.max((x - y).abs().to_f64());
        size = size.max(x.abs().to_f64());
    }
    diff / (size + scale)
}

/// Compares `hand` with `EulerLagrange::new(hand)` at `STATES` random states from `state`;
/// `scale` is a natural acceleration of the system (e.g. g / l).
fn agree<T, S, const N: usize>(hand: &S, scale: f64, rng: &mut Rng) -> Result<(), Error>
where
    T: Real,
    S: Mechanism<T, N> + Lagrangian<T, N> + Clone,
{
    let auto = EulerLagrange::new(hand.clone());
    let tol = tolerance::<T>();
    for _ in 0..STATES {
        let q: [T; N] = core::array::from_fn(|_| rng.uniform(-3.2, 3.2));
        let qd: [T; N] = core::array::from_fn(|_| rng.uniform(-5.0, 5.0));
        let s = State::new(rng.uniform(0.0, 10.0), q, qd);
        let (a, b) = (hand.acceleration(&s)?, auto.acceleration(&s)?);
        let e = relative(a.iter().copied(), b.iter().copied(), scale);
        assert!(
            e < tol,
            "acceleration at {s:?}: hand {a:?} auto {b:?} ({e:e})"
        );
        let (ma, mb) = (hand.mass_matrix(&s), auto.mass_matrix(&s));
        let e = relative(ma.iter().copied(), mb.iter().copied(), 0.0);
        assert!(
            e < tol,
            "mass matrix at {s:?}: hand {ma:?} auto {mb:?} ({e:e})"
        );
        let e = relative([hand.energy(&s)], [auto.energy(&s)], scale);
        assert!(e < tol, "energy at {s:?} ({e:e})");
    }
    Ok(())
}

fn double_pendulum<T: Real>() -> Result<(), Error> {
    let mut rng = Rng::new(1);
    for _ in 0..5 {
        let l1 = rng.uniform(0.2, 3.0);
        let dp = DoublePendulum::<T>::new(
            rng.uniform(0.2, 5.0),
            rng.uniform(0.2, 5.0),
            l1,
            rng.uniform(0.2, 3.0),
            T::from_f64(9.81),
        )?;
        agree(&dp, 9.81 / l1.to_f64(), &mut rng)?;
    }
    Ok(())
}

fn bead_on_rotating_hoop<T: Real>() -> Result<(), Error> {
    let mut rng = Rng::new(2);
    for _ in 0..5 {
        let r = rng.uniform(0.1, 2.0);
        let w = rng.uniform(-10.0, 10.0);
        let hoop = BeadOnRotatingHoop::<T>::new(rng.uniform(0.1, 5.0), r, w, T::from_f64(9.81))?;
        agree(&hoop, 9.81 / r.to_f64() + w.to_f64() * w.to_f64(), &mut rng)?;
    }
    Ok(())
}

fn simple_pendulum<T: Real>() -> Result<(), Error> {
    let mut rng = Rng::new(3);
    let l = rng.uniform(0.1, 3.0);
    let p = SimplePendulum::<T>::new(
        rng.uniform(0.1, 5.0),
        l,
        T::from_f64(9.81),
        rng.uniform(0.0, 2.0),
    )?;
    agree(&p, 9.81 / l.to_f64(), &mut rng)
}

fn falling_particle<T: Real>() -> Result<(), Error> {
    let mut rng = Rng::new(4);
    let p = FallingParticle::<T>::new(rng.uniform(0.1, 5.0), T::from_f64(9.81))?;
    agree(&p, 9.81, &mut rng)
}

for_f32_and_f64!(
    double_pendulum,
    bead_on_rotating_hoop,
    simple_pendulum,
    falling_particle
);
