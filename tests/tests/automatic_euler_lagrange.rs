//! Every hand-derived system agrees with the automatic Euler-Lagrange path (dual numbers) at
//! 1,000 random states and random valid parameters.

use lagrange_core::{Error, Lagrangian, Mechanism, Real};
use lagrange_systems::{BeadOnRotatingHoop, DoublePendulum, FallingParticle, SimplePendulum};
use lagrange_tests::{agrees_with_automatic, for_f32_and_f64, pick, random_state, Rng, Scales};

const STATES: usize = 1000;

/// Relative agreement of accelerations, mass matrices and energies. Both paths compute the same
/// terms in a different order, so they agree to a few ulps of the largest term, more where the
/// 2x2 solve cancels. Largest difference measured over these states: f64 9.1e-16 (the double
/// pendulum; the issue asked for 1e-12), f32 6.3e-7 (~5 ulps); bounds 4.5e-15 and 3e-6.
fn tolerance<T: Real>() -> f64 {
    pick::<T>(3e-6, 4.5e-15)
}

/// Compares `hand` with `EulerLagrange::new(hand)` at `STATES` random states (angles in
/// (-3.2, 3.2), rates in (-5, 5)); `scale` is a natural acceleration of the system (e.g. g / l),
/// also used as the energy scale.
fn agree<T, S, const N: usize>(hand: &S, scale: f64, rng: &mut Rng) -> Result<(), Error>
where
    T: Real,
    S: Mechanism<T, N> + Lagrangian<T, N> + Clone,
{
    let scale = Scales {
        acceleration: scale,
        energy: scale,
    };
    let worst = agrees_with_automatic(hand, scale, tolerance::<T>(), STATES, rng, |r| {
        random_state(r, (-3.2, 3.2), (-5.0, 5.0))
    })?;
    let name = core::any::type_name::<S>()
        .rsplit("::")
        .next()
        .unwrap_or("");
    println!("{name}: worst relative difference {worst}");
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
