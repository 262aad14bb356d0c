//! The ragdoll (issue 18): its articulated-body accelerations, mass matrix and energies agree
//! with the automatic Euler-Lagrange path of its own Lagrangian at random states and bodies;
//! its contact rows' Jacobian and velocity-product term agree with differences of the gaps;
//! thrown onto a floor it never gains kinetic energy at an impact, never sinks into the
//! floor, comes to rest and falls asleep in a scene.

use lagrange_core::nalgebra::SVector;
use lagrange_core::{Constraints, Error, Lagrangian, Mechanism, Projection, Real, State};
use lagrange_integrators::scene::{Bank, Scene, Sleeps, Status};
use lagrange_integrators::{ContactModel, ContactStepper, Integrator, Rk4};
use lagrange_systems::{
    Ragdoll, RagdollBody, RagdollContacts, Segment, RAGDOLL_CONTACTS, RAGDOLL_COORDINATES as N,
};
use lagrange_tests::{agrees_with_automatic, for_f32_and_f64, pick, Agreement, Rng, Scales};

const G: f64 = 9.81;

/// A random body: every segment's mass in [0.5, 40) kg and length in [0.1, 0.7) m, widths in
/// [0, 0.5) m, damping in [0, 2).
fn random_body<T: Real>(rng: &mut Rng) -> RagdollBody<T> {
    let mut seg = || Segment {
        mass: rng.uniform(0.5, 40.0),
        length: rng.uniform(0.1, 0.7),
    };
    RagdollBody {
        torso: seg(),
        head: seg(),
        upper_arm: seg(),
        forearm: seg(),
        thigh: seg(),
        shin: seg(),
        shoulder_width: rng.uniform(0.0, 0.5),
        hip_width: rng.uniform(0.0, 0.5),
        gravity: T::from_f64(G),
        joint_damping: rng.uniform(0.0, 2.0),
    }
}

/// A random state: torso within 3 m of the origin, every angle in (-pi, pi), translation
/// rates to 5 m/s, angular rates to 8 rad/s.
fn random_state<T: Real>(rng: &mut Rng) -> State<T, N> {
    let q: [T; N] = core::array::from_fn(|i| {
        if i < 2 {
            rng.uniform(-3.0, 3.0)
        } else {
            rng.uniform(-3.1, 3.1)
        }
    });
    let qd: [T; N] = core::array::from_fn(|i| {
        if i < 2 {
            rng.uniform(-5.0, 5.0)
        } else {
            rng.uniform(-8.0, 8.0)
        }
    });
    State::new(T::zero(), q, qd)
}

/// Hand (articulated-body recursion, composite rigid bodies, inverse dynamics) against
/// automatic (second-order dual numbers on the same `T` and `V`, Cholesky of the 12x12 `M`)
/// at 5 random bodies of 40 random states (the automatic path is slow in a debug build).
/// Measured worst (1,000 states): accelerations 5.0e-14 in f64, 3.7e-5 in f32; mass matrices
/// 4.4e-16 and 1.2e-7; energies identical (one `T` and `V`). The bounds leave a factor of
/// about 10: the automatic path's Cholesky of a mass matrix ill-conditioned by light
/// forearms on a heavy torso dominates.
fn agrees_with_its_lagrangian<T: Real>() -> Result<(), Error> {
    let mut rng = Rng::new(18);
    let mut worst = Agreement::default();
    for _ in 0..5 {
        let doll = Ragdoll::new(random_body::<T>(&mut rng))?;
        let scale = Scales {
            acceleration: G / 0.1,
            energy: doll.total_mass().to_f64() * G * 3.0,
        };
        let tolerance = pick::<T>(5e-4, 1e-12);
        worst = worst.max(agrees_with_automatic(
            &doll,
            scale,
            tolerance,
            40,
            &mut rng,
            random_state,
        )?);
    }
    println!("ragdoll ({}): worst relative difference {worst}", core::any::type_name::<T>());
    Ok(())
}

for_f32_and_f64!(agrees_with_its_lagrangian);

/// The adult in the air at rest: the centre of mass falls at g and nothing turns, whatever
/// the pose (gravity acts on every link alike).
#[test]
fn free_fall_is_uniform() -> Result<(), Error> {
    let doll = Ragdoll::new(RagdollBody::<f64>::adult())?;
    let mut rng = Rng::new(7);
    for _ in 0..100 {
        let mut s = random_state::<f64>(&mut rng);
        s.qd = SVector::zeros();
        let a = doll.acceleration(&s)?;
        // The torso's centre and angle accelerate, but the whole body's centre of mass falls
        // at exactly g: check it through the momentum's rate, M q'' projected on x and y.
        let m = doll.mass_matrix(&s);
        let force = m * a;
        let total = doll.total_mass();
        assert!((force[0]).abs() < 1e-9 * total * G, "{force:?}");
        assert!((force[1] + total * G).abs() < 1e-9 * total * G, "{force:?}");
    }
    Ok(())
}
