//! `RigidBody`, the free body in the plane: its law against the automatic Euler-Lagrange path
//! at random states, free flight against the exact parabola, its constructors' validation, and
//! its hand-derived link point (`Links::point`) against the dual-number default and against
//! central differences of the position. Both precisions.

use lagrange_core::links::{LinkPoint, Links, Pose};
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, Lagrangian, Mechanism, Real, Scalar, State};
use lagrange_integrators::{AdaptiveSettings, DormandPrinceNystrom64, Integrator, Rk4};
use lagrange_systems::RigidBody;
use lagrange_tests::{agrees_with_automatic, for_f32_and_f64, pick, random_state, Rng, Scales};

const G: f64 = 9.81;

/// The law agrees with the automatic path of the body's own Lagrangian at 1,000 random states
/// (5 bodies of 200), to the tolerance of the other constant-mass systems (5e-6 in f32,
/// 1.4e-14 in f64, relative to the scales).
fn agrees_with_its_lagrangian<T: Real>() -> Result<(), Error> {
    let mut rng = Rng::new(301);
    for _ in 0..5 {
        let (m, i): (T, T) = (rng.uniform(0.1, 5.0), rng.uniform(0.01, 2.0));
        let body = RigidBody::new(m, i, T::from_f64(G))?;
        let scale = Scales {
            acceleration: G + 1.0,
            energy: m.to_f64() * G + i.to_f64(),
        };
        agrees_with_automatic(&body, scale, pick::<T>(5e-6, 1.4e-14), 200, &mut rng, |r| {
            random_state(r, (-10.0, 10.0), (-5.0, 5.0))
        })?;
    }
    Ok(())
}

/// RK4 is exact on the constant acceleration: after 2 s of 1/60 s steps the body is on the
/// parabola `y0 + vy t - g t^2 / 2`, its angle `th0 + w t`, to the rounding of 120 steps
/// (1e-12 m in f64, 1e-4 in f32 of sums of order 10), and its energy where it began.
fn free_flight_is_the_parabola<T: Real>() -> Result<(), Error> {
    let body = RigidBody::rectangle(T::from_f64(2.0), T::HALF, T::from_f64(0.3), T::from_f64(G))?;
    let start = State::new(
        T::zero(),
        [T::zero(), T::one(), T::from_f64(0.2)],
        [T::from_f64(1.5), T::from_f64(4.0), T::from_f64(-3.0)],
    );
    let end = Rk4.integrate(&body, &start, T::from_f64(1.0 / 60.0), 120)?;
    let t = 2.0;
    let exact = [1.5 * t, 1.0 + 4.0 * t - G * t * t / 2.0, 0.2 - 3.0 * t];
    let tolerance = pick::<T>(1e-4, 1e-12);
    for (k, x) in exact.into_iter().enumerate() {
        assert!(
            (end.q[k].to_f64() - x).abs() <= tolerance,
            "q[{k}]: {:?} against {x}",
            end.q[k]
        );
    }
    let (e0, e1) = (body.energy(&start).to_f64(), body.energy(&end).to_f64());
    assert!(
        (e1 - e0).abs() <= pick::<T>(1e-4, 1e-12) * e0.abs(),
        "{e0} -> {e1}"
    );
    Ok(())
}

/// Each constructor refuses its bad parameters by name, and the shapes' inertias are the
/// textbook ones: a rectangle's `m (w^2 + h^2) / 12`, a disk's `m r^2 / 2`.
fn constructors_validate_and_give_inertias<T: Real>() -> Result<(), Error> {
    let named = |r: Result<RigidBody<T>, Error>, name: &str| {
        assert!(
            matches!(r, Err(Error::InvalidParameter { name: n, .. }) if n == name),
            "{name}: {r:?}"
        );
    };
    let (one, g) = (T::one(), T::from_f64(G));
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let bad = T::from_f64(bad);
        named(RigidBody::new(bad, one, g), "mass");
        named(RigidBody::new(one, bad, g), "inertia");
        named(RigidBody::rectangle(bad, one, one, g), "mass");
        named(RigidBody::rectangle(one, bad, one, g), "width");
        named(RigidBody::rectangle(one, one, bad, g), "height");
        named(RigidBody::disk(bad, one, g), "mass");
        named(RigidBody::disk(one, bad, g), "radius");
    }
    named(RigidBody::new(one, one, T::from_f64(-1.0)), "gravity");
    named(RigidBody::new(T::MAX, one, T::from_f64(2.0)), "mass");
    // A radius whose square underflows: no inertia.
    let tiny = T::from_f64(pick::<T>(1e-30, 1e-200));
    named(RigidBody::disk(one, tiny, g), "radius");
    // Sides whose squares underflow: the larger is named (the width of equal sides).
    let tinier = tiny * T::HALF;
    named(RigidBody::rectangle(one, tiny, tinier, g), "width");
    named(RigidBody::rectangle(one, tinier, tiny, g), "height");
    named(RigidBody::rectangle(one, tiny, tiny, g), "width");
    let plank = RigidBody::rectangle(T::from_f64(2.0), T::HALF, T::from_f64(0.3), g)?;
    let expected = 2.0 * (0.25 + 0.09) / 12.0;
    assert!(
        (plank.inertia().to_f64() - expected).abs() <= pick::<T>(1e-7, 1e-16),
        "{plank:?}"
    );
    let ball = RigidBody::disk(T::one(), T::HALF, g)?;
    assert_eq!(ball.inertia(), T::from_f64(0.125));
    assert_eq!((ball.mass(), ball.gravity()), (T::one(), g));
    Ok(())
}

/// The body's pose alone, so that `Links::point` is the dual-number default.
struct Automatic<T: Real>(RigidBody<T>);

impl<T: Real> Links<T, 3> for Automatic<T> {
    const LINKS: usize = 1;
    fn pose<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 3>, link: usize) -> Pose<S> {
        self.0.pose(q, link)
    }
}

/// The hand-derived point of the body agrees with the dual-number default (to 4 ulps of the
/// point's size) and with central differences of its position (`h = 1e-6` in f64: the
/// truncation error `h^2 |p'''| / 6` and rounding `eps |p| / h` both below 1e-9; in f32
/// `h = 1e-2`, error 2e-3 from `h^2` and `eps / h`), at 200 random poses and points.
fn the_point_jacobian_agrees<T: Real>() -> Result<(), Error> {
    let body = RigidBody::new(T::one(), T::one(), T::from_f64(G))?;
    let mut rng = Rng::new(302);
    let mut worst: [f64; 2] = [0.0; 2];
    for _ in 0..200 {
        let q = random_state::<T, 3>(&mut rng, (-3.2, 3.2), (0.0, 0.0)).q;
        let local = [rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0)];
        let hand: LinkPoint<T, 3> = body.point(&q, 0, local);
        let auto = Automatic(body).point(&q, 0, local);
        let size = 1.0 + q.iter().map(|x| x.to_f64().abs()).sum::<f64>();
        for i in 0..2 {
            let d = (hand.position[i] - auto.position[i]).to_f64().abs() / size;
            worst[0] = worst[0].max(d);
            for k in 0..3 {
                let d = (hand.jacobian[(i, k)] - auto.jacobian[(i, k)])
                    .to_f64()
                    .abs()
                    / size;
                worst[0] = worst[0].max(d);
            }
        }
        let h = pick::<T>(1e-2, 1e-6);
        for k in 0..3 {
            let mut up = q;
            let mut down = q;
            up[k] += T::from_f64(h);
            down[k] -= T::from_f64(h);
            let (pu, pd) = (body.point(&up, 0, local), body.point(&down, 0, local));
            for i in 0..2 {
                let slope = (pu.position[i] - pd.position[i]).to_f64() / (2.0 * h);
                worst[1] = worst[1].max((slope - hand.jacobian[(i, k)].to_f64()).abs());
            }
        }
    }
    println!(
        "{}: hand against dual {:e}, against differences {:e}",
        core::any::type_name::<T>(),
        worst[0],
        worst[1]
    );
    assert!(worst[0] <= 4.0 * T::EPSILON.to_f64(), "{worst:?}");
    assert!(worst[1] <= pick::<T>(2e-3, 1e-9), "{worst:?}");
    Ok(())
}

/// The law reads no velocity (`(0, -g, 0)`), so the Nyström pairs, which step only such laws,
/// take the body: DOP-Nyström 6(4) lands on the parabola at `t = 2` to its tolerance (its
/// stages integrate a constant acceleration exactly; 1e-12 m in f64 and 1e-4 in f32 is the
/// rounding of a few dozen steps on sums of order 10).
fn nystrom_pairs_take_it<T: Real>() -> Result<(), Error> {
    let body = RigidBody::disk(T::one(), T::HALF, T::from_f64(G))?;
    assert!(!body.reads_velocities());
    let start = State::new(
        T::zero(),
        [T::zero(), T::one(), T::zero()],
        [T::one(), T::from_f64(4.0), T::from_f64(2.0)],
    );
    let tolerance = T::from_f64(pick::<T>(1e-4, 1e-8));
    let mut pair = DormandPrinceNystrom64::new(AdaptiveSettings::new(tolerance, tolerance)?);
    let end = pair.integrate_to(&body, &start, T::from_f64(2.0))?;
    let exact = [2.0, 1.0 + 8.0 - G * 2.0, 4.0];
    for (k, x) in exact.into_iter().enumerate() {
        let off = (end.q[k].to_f64() - x).abs();
        assert!(
            off <= pick::<T>(1e-4, 1e-12),
            "q[{k}]: {:?} against {x}",
            end.q[k]
        );
    }
    Ok(())
}

for_f32_and_f64!(
    nystrom_pairs_take_it,
    agrees_with_its_lagrangian,
    free_flight_is_the_parabola,
    constructors_validate_and_give_inertias,
    the_point_jacobian_agrees
);
