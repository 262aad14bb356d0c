//! A world of two kinds of body (`lagrange_world::OneOf`): a ball that strikes a hanging
//! pendulum in one `World`, against the hand-computed impulse and the pair's angular momentum
//! about the pivot, and where its shapes are drawn; and the wrapped bodies' own laws,
//! energies and links, the idle coordinates idle. Both precisions.

use lagrange_core::constraints::contact::ContactModel;
use lagrange_core::links::Links;
use lagrange_core::{Error, Lagrangian, Mechanism, Real, State};
use lagrange_systems::{Ragdoll, RagdollBody, RigidBody, SimplePendulum, RAGDOLL_COORDINATES};
use lagrange_tests::{for_f32_and_f64, pick};
use lagrange_world::{OneOf, Shape, World, WorldSettings};

/// A pendulum (1 coordinate) or a rigid body (3), as bodies of 3 coordinates.
type Body<T> = OneOf<SimplePendulum<T>, RigidBody<T>, 1, 3>;

/// A world of such bodies: up to 8 bodies and shapes, 32 contact points.
type Mixed<T> = World<T, Body<T>, 3, 8, 8, 32>;

/// The pendulum's key and its bob's shape's; the ball's and its shape's.
const PENDULUM: u32 = 1;
const BOB: u32 = 11;
const BALL: u32 = 2;
const DISK: u32 = 12;

/// A 1 kg ball of radius 0.1 m at 2 m/s strikes square on the 1 kg bob (radius 0.1 m) of a
/// pendulum of 1 m hanging from the origin, no gravity, restitution 1, no friction, the two
/// touching as the first step begins. By hand: the bob's effective mass along the strike
/// (perpendicular to the rod at its lowest) is `m l^2 / l^2 = 1 kg`, so the impulse is
/// `(1 + e) v / (1 / m_ball + 1 / m_bob) = 2 N s`, the ball stops and the bob leaves at
/// `2 rad/s`: the contact's event reports that impulse, and the end velocities follow, to
/// 1e-9 (1e-4 in f32, whose rows round at 1e-7 of the unit speeds and positions). The
/// angular momentum about the pivot, `m (x v_y - y v_x) + I w + m_p l^2 th'`, is kept at
/// every step to rounding (the rows are taken at the step's start and act on both bodies
/// through their own Jacobians), and the idle coordinates of the pendulum stay exactly zero.
fn a_ball_strikes_a_pendulum_in_one_world<T: Real>() -> Result<(), Error> {
    let model = ContactModel::new(T::one(), T::from_f64(0.01), T::one())?;
    let mut world = Box::new(Mixed::<T>::new(WorldSettings::new(
        model,
        T::from_f64(1e-4),
        8,
    )?));
    let pendulum = SimplePendulum::new(T::one(), T::one(), T::zero(), T::zero())?;
    let ball = RigidBody::disk(T::one(), T::from_f64(0.1), T::zero())?;
    let hanging = Body::<T>::first_state(&State::at_rest([T::zero()]));
    world.add_body(PENDULUM, OneOf::First(pendulum), hanging)?;
    let bob = Shape::circle(T::from_f64(0.1))?.offset([T::zero(), -T::one()], T::zero());
    world.add_shape(BOB, PENDULUM, 0, bob)?;
    let thrown = State::new(
        T::zero(),
        [-0.2, -1.0, 0.0].map(T::from_f64),
        [2.0, 0.0, 0.0].map(T::from_f64),
    );
    world.add_body(BALL, OneOf::Second(ball), Body::<T>::second_state(&thrown))?;
    world.add_shape(DISK, BALL, 0, Shape::circle(T::from_f64(0.1))?)?;
    let about_pivot = |w: &Mixed<T>| -> f64 {
        let (Some(b), Some(p)) = (w.state(BALL), w.state(PENDULUM)) else {
            return f64::NAN;
        };
        let (x, y) = (b.q[0].to_f64(), b.q[1].to_f64());
        let (vx, vy, spin) = (b.qd[0].to_f64(), b.qd[1].to_f64(), b.qd[2].to_f64());
        (x * vy - y * vx) + 0.005 * spin + p.qd[0].to_f64()
    };
    let l0 = about_pivot(&world);
    let mut impulses = Vec::new();
    for step in 0..60 {
        world.step(T::from_f64(1.0 / 240.0))?;
        for e in world.events().iter().filter(|e| e.began) {
            assert_eq!(e.shapes, (BOB, DISK), "step {step}: {e:?}");
            impulses.push(e.impulse.to_f64());
        }
        let l = about_pivot(&world);
        assert!(
            (l - l0).abs() < pick::<T>(1e-5, 1e-12),
            "step {step}: {l} against {l0}"
        );
        let p = world.state(PENDULUM).ok_or(Error::NonFiniteState)?;
        assert_eq!(
            [p.q[1], p.q[2], p.qd[1], p.qd[2]],
            [T::zero(); 4],
            "step {step}"
        );
    }
    let tol = pick::<T>(1e-4, 1e-9);
    assert_eq!(impulses.len(), 1, "{impulses:?}");
    assert!((impulses[0] - 2.0).abs() < 2.0 * tol, "{impulses:?}");
    let b = world.state(BALL).ok_or(Error::NonFiniteState)?;
    let p = world.state(PENDULUM).ok_or(Error::NonFiniteState)?;
    assert!(
        b.qd[0].to_f64().abs() < tol && (p.qd[0].to_f64() - 2.0).abs() < tol,
        "{b:?} {p:?}"
    );
    // Where a renderer draws them: the ball's disk at its coordinates, the bob at the rod's
    // end, each with its body, in the shapes' keys' order.
    let placed: Vec<_> = world.placed_shapes().collect();
    assert_eq!(
        placed
            .iter()
            .map(|s| (s.key, s.body, s.asleep))
            .collect::<Vec<_>>(),
        [(BOB, Some(PENDULUM), false), (DISK, Some(BALL), false)]
    );
    let centre = |k: usize| placed[k].shape.vertices()[0].map(|x| x.to_f64());
    let th = p.q[0].to_f64();
    let bob = [th.sin(), -th.cos()];
    let near = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]) < pick::<T>(1e-6, 1e-14);
    assert!(near(centre(0), bob), "{:?} against {bob:?}", centre(0));
    let ball_at = [b.q[0].to_f64(), b.q[1].to_f64()];
    assert!(
        near(centre(1), ball_at),
        "{:?} against {ball_at:?}",
        centre(1)
    );
    Ok(())
}

/// Each kind wrapped is itself on its own coordinates: the same accelerations, energies,
/// mass matrix (the identity on the idle coordinates), mass solve and link points (zero
/// columns for the idle coordinates), bit for bit; an idle coordinate accelerates by its
/// entry of an extra force (unit mass) and adds `v^2 / 2` to the kinetic energy. The kinds
/// include a ragdoll (12 coordinates) in a body of 14.
fn each_kind_is_itself<T: Real>() -> Result<(), Error> {
    const N: usize = RAGDOLL_COORDINATES + 2;
    type Kinds<T> = OneOf<Ragdoll<T>, RigidBody<T>, RAGDOLL_COORDINATES, 3>;
    let doll = Ragdoll::new(RagdollBody::<T>::adult())?;
    let box_ = RigidBody::rectangle(T::from_f64(2.0), T::HALF, T::one(), T::from_f64(9.81))?;
    let own: State<T, RAGDOLL_COORDINATES> = State::new(
        T::zero(),
        core::array::from_fn(|k| T::from_f64(0.1 * k as f64 - 0.3)),
        core::array::from_fn(|k| T::from_f64(0.5 - 0.07 * k as f64)),
    );
    let wide: State<T, N> = Kinds::<T>::first_state(&own);
    let body: Kinds<T> = OneOf::First(doll);
    assert_eq!(Kinds::<T>::first_part(&wide), own);
    let a = body.acceleration(&wide)?;
    assert_eq!(
        a.as_slice()[..RAGDOLL_COORDINATES],
        doll.acceleration(&own)?.as_slice()[..]
    );
    assert_eq!(a.as_slice()[RAGDOLL_COORDINATES..], [T::zero(); 2]);
    assert_eq!(body.energy(&wide), doll.energy(&own));
    let m = body.mass_matrix(&wide);
    let inner = doll.mass_matrix(&own);
    for i in 0..N {
        for j in 0..N {
            let expected = match (i < RAGDOLL_COORDINATES, j < RAGDOLL_COORDINATES) {
                (true, true) => inner[(i, j)],
                _ if i == j => T::one(),
                _ => T::zero(),
            };
            assert_eq!(m[(i, j)], expected, "({i}, {j})");
        }
    }
    let b = lagrange_core::nalgebra::SVector::<T, N>::from_fn(|k, _| T::from_f64(k as f64 - 4.0));
    let x = body.solve_mass(&wide, &b)?;
    let own_b = lagrange_core::nalgebra::SVector::<T, RAGDOLL_COORDINATES>::from_fn(|k, _| b[k]);
    let own_x = doll.solve_mass(&own, &own_b)?;
    assert_eq!(x.as_slice()[..RAGDOLL_COORDINATES], own_x.as_slice()[..]);
    assert_eq!(
        x.as_slice()[RAGDOLL_COORDINATES..],
        b.as_slice()[RAGDOLL_COORDINATES..]
    );
    for link in 0..<Ragdoll<T> as Links<T, RAGDOLL_COORDINATES>>::LINKS {
        let local = [T::from_f64(0.05), T::from_f64(-0.1)];
        let p = body.point(&wide.q, link, local);
        let o = doll.point(&own.q, link, local);
        assert_eq!(p.position, o.position, "link {link}");
        for r in 0..2 {
            for c in 0..N {
                let expected = if c < RAGDOLL_COORDINATES {
                    o.jacobian[(r, c)]
                } else {
                    T::zero()
                };
                assert_eq!(p.jacobian[(r, c)], expected, "link {link} ({r}, {c})");
            }
        }
        assert_eq!(
            body.pose(&wide.q, link),
            doll.pose(&own.q, link),
            "link {link}"
        );
    }
    assert_eq!(
        <Kinds<T> as Links<T, N>>::LINKS,
        <Ragdoll<T> as Links<T, RAGDOLL_COORDINATES>>::LINKS
    );
    // Its poses from one call, and its batched mass solve: the ragdoll's own, the idle
    // rows as they were.
    let blank = lagrange_core::links::Pose {
        origin: [T::zero(); 2],
        angle: T::zero(),
    };
    let (mut wide_poses, mut own_poses) = ([blank; 10], [blank; 10]);
    body.poses(&wide.q, &mut wide_poses);
    doll.poses(&own.q, &mut own_poses);
    assert_eq!(wide_poses, own_poses);
    let columns = lagrange_core::nalgebra::SMatrix::<T, N, 3>::from_fn(|i, k| {
        T::from_f64((i * 3 + k) as f64 * 0.25 - 2.0)
    });
    let (mut jumps, mut own_jumps) = (
        columns,
        columns.fixed_rows::<RAGDOLL_COORDINATES>(0).into_owned(),
    );
    body.velocity_jumps(&wide, &mut jumps)?;
    doll.velocity_jumps(&own, &mut own_jumps)?;
    assert_eq!(jumps.fixed_rows::<RAGDOLL_COORDINATES>(0), own_jumps);
    assert_eq!(
        jumps.fixed_rows::<2>(RAGDOLL_COORDINATES),
        columns.fixed_rows::<2>(RAGDOLL_COORDINATES)
    );
    // The second kind, moving on an idle coordinate: pushed there by an extra force.
    let crate_: Kinds<T> = OneOf::Second(box_);
    let mut s: State<T, N> = Kinds::<T>::second_state(&State::new(
        T::zero(),
        [T::one(), T::TWO, T::HALF],
        [T::HALF, T::zero(), T::one()],
    ));
    s.qd[N - 1] = T::from_f64(3.0);
    let push = |_: &State<T, N>| {
        lagrange_core::nalgebra::SVector::<T, N>::from_fn(|k, _| {
            if k == N - 1 {
                T::from_f64(5.0)
            } else {
                T::zero()
            }
        })
    };
    let a = crate_.acceleration_with(&s, &push)?;
    assert_eq!(a[1], -T::from_f64(9.81));
    assert_eq!(a[N - 1], T::from_f64(5.0));
    let own = Kinds::<T>::second_part(&s);
    let idle = T::from_f64(4.5);
    assert_eq!(crate_.kinetic_energy(&s), box_.kinetic_energy(&own) + idle);
    assert_eq!(crate_.potential_energy(&s), box_.potential_energy(&own));
    Ok(())
}

for_f32_and_f64!(a_ball_strikes_a_pendulum_in_one_world, each_kind_is_itself);
