//! Where the standard chains' links are (`Links`): each mechanism's own documented positions
//! (a bob at `(l sin th, -l cos th)` from its pivot, the cart-pole's pole centre at
//! `(x + l sin th, l cos th)`) from its link poses, and, from the point Jacobians, the kinetic
//! energy of the masses on the links equal to the mechanism's own at random states: the
//! Jacobians are the velocities the mechanism's equations use. Both precisions.

use lagrange_core::links::{Links, Pose};
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, Lagrangian, Real, Scalar, State};
use lagrange_systems::{
    Acrobot, CartPole, DoublePendulum, NLinkPendulum, Ragdoll, RagdollBody, RigidBody,
    SimplePendulum, RAGDOLL_LINKS,
};
use lagrange_tests::{for_f32_and_f64, pick, random_state, Rng};

const G: f64 = 9.81;

/// `|J q'|^2 m / 2` of the point `local` of `link`.
fn point_energy<T: Real, L: Links<T, N>, const N: usize>(
    l: &L,
    s: &State<T, N>,
    link: usize,
    local: [f64; 2],
    mass: f64,
) -> f64 {
    let v = l.point(&s.q, link, local.map(T::from_f64)).jacobian * s.qd;
    mass * (v[0].to_f64().powi(2) + v[1].to_f64().powi(2)) / 2.0
}

/// The relative difference of `a` and `b`, over `1 + |b|`.
fn off(a: f64, b: f64) -> f64 {
    (a - b).abs() / (1.0 + b.abs())
}

/// Kinetic energies from the links against the mechanism's own, at 200 random states: to 1e-12
/// in f64 and 1e-4 in f32 (the sums of a few products of rates up to 5 rad/s).
fn energies_agree<T: Real>() -> Result<(), Error> {
    let tol = pick::<T>(1e-4, 1e-12);
    let mut rng = Rng::new(340);
    let simple = SimplePendulum::new(
        T::from_f64(1.5),
        T::from_f64(0.8),
        T::from_f64(G),
        T::zero(),
    )?;
    let double = DoublePendulum::new(
        T::one(),
        T::from_f64(2.0),
        T::from_f64(0.7),
        T::from_f64(1.1),
        T::from_f64(G),
    )?;
    let chain = NLinkPendulum::new(
        [1.0, 0.5, 2.0].map(T::from_f64),
        [0.4, 0.9, 0.6].map(T::from_f64),
        T::from_f64(G),
    )?;
    let cart = CartPole::new(T::from_f64(3.0), T::HALF, T::from_f64(0.6), T::from_f64(G))?;
    let (m, l, lc, i) = ([1.0, 1.5], [1.0, 1.2], [0.5, 0.7], [0.08, 0.2]);
    let acrobot = Acrobot::new(
        T::from_f64(m[0]),
        T::from_f64(m[1]),
        T::from_f64(l[0]),
        T::from_f64(l[1]),
        T::from_f64(lc[0]),
        T::from_f64(lc[1]),
        T::from_f64(i[0]),
        T::from_f64(i[1]),
        T::from_f64(G),
    )?;
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let s1 = random_state::<T, 1>(&mut rng, (-3.2, 3.2), (-5.0, 5.0));
        let e = point_energy(&simple, &s1, 0, [0.0, -0.8], 1.5);
        worst = worst.max(off(e, simple.kinetic_energy(&s1).to_f64()));
        let s2 = random_state::<T, 2>(&mut rng, (-3.2, 3.2), (-5.0, 5.0));
        let e = point_energy(&double, &s2, 0, [0.0, -0.7], 1.0)
            + point_energy(&double, &s2, 1, [0.0, -1.1], 2.0);
        worst = worst.max(off(e, double.kinetic_energy(&s2).to_f64()));
        let s3 = random_state::<T, 3>(&mut rng, (-3.2, 3.2), (-5.0, 5.0));
        let e: f64 = [(0.4, 1.0), (0.9, 0.5), (0.6, 2.0)]
            .iter()
            .enumerate()
            .map(|(k, &(len, mass))| point_energy(&chain, &s3, k, [0.0, -len], mass))
            .sum();
        worst = worst.max(off(e, chain.kinetic_energy(&s3).to_f64()));
        let s = random_state::<T, 2>(&mut rng, (-3.2, 3.2), (-5.0, 5.0));
        // The cart, the pole's centre of mass, the pole's turning (m (2l)^2 / 12 = m l^2 / 3).
        let pole_turn = 0.5 * 0.6 * 0.6 / 3.0 * s.qd[1].to_f64().powi(2) / 2.0;
        let e = point_energy(&cart, &s, 0, [0.0, 0.0], 3.0)
            + point_energy(&cart, &s, 1, [0.0, 0.6], 0.5)
            + pole_turn;
        worst = worst.max(off(e, cart.kinetic_energy(&s).to_f64()));
        let s = random_state::<T, 2>(&mut rng, (-3.2, 3.2), (-5.0, 5.0));
        let (w1, w2) = (s.qd[0].to_f64(), s.qd[0].to_f64() + s.qd[1].to_f64());
        let e = point_energy(&acrobot, &s, 0, [0.0, -lc[0]], m[0])
            + point_energy(&acrobot, &s, 1, [0.0, -lc[1]], m[1])
            + (i[0] * w1 * w1 + i[1] * w2 * w2) / 2.0;
        worst = worst.max(off(e, acrobot.kinetic_energy(&s).to_f64()));
    }
    println!(
        "{}: worst relative difference {worst:e}",
        core::any::type_name::<T>()
    );
    assert!(worst <= tol, "{worst:e}");
    Ok(())
}

/// The bobs and the pole's centre where each mechanism's docs put them (to 4 ulps of 2 m).
fn positions_follow_the_conventions<T: Real>() -> Result<(), Error> {
    let tol = 8.0 * T::EPSILON.to_f64() * 2.0;
    let near = |p: [T; 2], x: f64, y: f64| {
        (p[0].to_f64() - x).abs() < tol && (p[1].to_f64() - y).abs() < tol
    };
    let (t1, t2) = (0.7_f64, -1.9_f64);
    let simple = SimplePendulum::new(T::one(), T::from_f64(0.8), T::from_f64(G), T::zero())?;
    let bob = simple.point(
        &SVector::from([T::from_f64(t1)]),
        0,
        [T::zero(), T::from_f64(-0.8)],
    );
    assert!(
        near(bob.position, 0.8 * t1.sin(), -0.8 * t1.cos()),
        "{bob:?}"
    );
    let double = DoublePendulum::new(
        T::one(),
        T::one(),
        T::from_f64(0.7),
        T::from_f64(1.1),
        T::from_f64(G),
    )?;
    let q = SVector::from([T::from_f64(t1), T::from_f64(t2)]);
    let second = double.point(&q, 1, [T::zero(), T::from_f64(-1.1)]);
    let (x, y) = (
        0.7 * t1.sin() + 1.1 * t2.sin(),
        -0.7 * t1.cos() - 1.1 * t2.cos(),
    );
    assert!(near(second.position, x, y), "{second:?}");
    let cart = CartPole::new(T::one(), T::one(), T::from_f64(0.6), T::from_f64(G))?;
    let q = SVector::from([T::from_f64(0.3), T::from_f64(t1)]);
    let centre = cart.point(&q, 1, [T::zero(), T::from_f64(0.6)]);
    assert!(
        near(centre.position, 0.3 + 0.6 * t1.sin(), 0.6 * t1.cos()),
        "{centre:?}"
    );
    let acrobot = Acrobot::new(
        T::one(),
        T::one(),
        T::from_f64(0.7),
        T::from_f64(1.1),
        T::from_f64(0.35),
        T::from_f64(0.55),
        T::from_f64(0.1),
        T::from_f64(0.1),
        T::from_f64(G),
    )?;
    let q = SVector::from([T::from_f64(t1), T::from_f64(t2)]);
    let tip = acrobot.point(&q, 1, [T::zero(), T::from_f64(-1.1)]);
    let (x, y) = (
        0.7 * t1.sin() + 1.1 * (t1 + t2).sin(),
        -0.7 * t1.cos() - 1.1 * (t1 + t2).cos(),
    );
    assert!(near(tip.position, x, y), "{tip:?}");
    Ok(())
}

/// The ragdoll's links: each link's two ends from its pose where `Ragdoll::segments` puts
/// them (the torso from `(0, L/2)` to `(0, -L/2)` of its frame, a limb from its joint to
/// `(0, -L)`), to 8 ulps of 2 m; and the kinetic energy of its uniform rods from the point
/// Jacobians of their centres and their turning rates (`m L^2 / 12`) equal to the ragdoll's
/// own at 200 random states, to 1e-12 (1e-4 in f32).
fn the_ragdoll_agrees<T: Real>() -> Result<(), Error> {
    let body = RagdollBody::<T>::adult();
    let doll = Ragdoll::new(body)?;
    let segments = [
        body.torso,
        body.head,
        body.upper_arm,
        body.forearm,
        body.upper_arm,
        body.forearm,
        body.thigh,
        body.shin,
        body.thigh,
        body.shin,
    ];
    let mut rng = Rng::new(344);
    let tol = 8.0 * T::EPSILON.to_f64() * 2.0;
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let s = random_state::<T, 12>(&mut rng, (-1.5, 1.5), (-5.0, 5.0));
        let ends = doll.segments(&s.q);
        let mut energy = 0.0;
        let angle = |k: usize| -> f64 {
            // The link's turning rate: the torso's, plus every joint up its chain.
            let parent = [0, 0, 0, 2, 0, 4, 0, 6, 0, 8];
            let mut w = s.qd[2].to_f64();
            let mut j = k;
            while j != 0 {
                w += s.qd[j + 2].to_f64();
                j = parent[j];
            }
            w
        };
        for (k, seg) in segments.iter().enumerate() {
            let l = seg.length.to_f64();
            let (start, end) = if k == 0 {
                (l / 2.0, -l / 2.0)
            } else {
                (0.0, -l)
            };
            let a = doll
                .point(&s.q, k, [T::zero(), T::from_f64(start)])
                .position;
            let b = doll.point(&s.q, k, [T::zero(), T::from_f64(end)]).position;
            for (p, e) in [(a, ends[k][0]), (b, ends[k][1])] {
                let d = (p[0] - e[0]).to_f64().abs() + (p[1] - e[1]).to_f64().abs();
                assert!(d < tol, "link {k}: {p:?} against {e:?}");
            }
            let m = seg.mass.to_f64();
            let w = angle(k);
            energy += point_energy(&doll, &s, k, [0.0, (start + end) / 2.0], m)
                + m * l * l / 12.0 * w * w / 2.0;
        }
        worst = worst.max(off(energy, doll.kinetic_energy(&s).to_f64()));
    }
    assert_eq!(<Ragdoll<T> as Links<T, 12>>::LINKS, RAGDOLL_LINKS);
    println!(
        "ragdoll, {}: worst relative difference {worst:e}",
        core::any::type_name::<T>()
    );
    assert!(worst <= pick::<T>(1e-4, 1e-12), "{worst:e}");
    Ok(())
}

/// A mechanism's poses alone, so that `Links::point` is the dual-number default.
struct Poses<'a, L>(&'a L);

impl<T: Real, L: Links<T, N>, const N: usize> Links<T, N> for Poses<'_, L> {
    const LINKS: usize = L::LINKS;
    fn pose<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, N>, link: usize) -> Pose<S> {
        self.0.pose(q, link)
    }
}

/// The acrobot of these tests: links `h` and `l` long, their centres at 0.35 and 0.55 m.
fn acrobot<T: Real>(h: T, l: T, g: T) -> Result<Acrobot<T>, Error> {
    Acrobot::new(
        T::one(),
        T::one(),
        h,
        l,
        T::from_f64(0.35),
        T::from_f64(0.55),
        T::from_f64(0.1),
        T::from_f64(0.1),
        g,
    )
}

/// The largest difference of the hand-derived points of `l` from the dual-number default,
/// over 100 random states and points on every link, relative to `1 + |q|`.
fn hand_against_duals<T: Real, L: Links<T, N>, const N: usize>(l: &L, rng: &mut Rng) -> f64 {
    let mut worst: f64 = 0.0;
    for _ in 0..100 {
        let q = random_state::<T, N>(rng, (-3.2, 3.2), (0.0, 0.0)).q;
        let size = 1.0 + q.iter().map(|x| x.to_f64().abs()).sum::<f64>();
        for link in 0..L::LINKS {
            let local = [rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)];
            let (hand, auto) = (l.point(&q, link, local), Poses(l).point(&q, link, local));
            for i in 0..2 {
                worst = worst.max((hand.position[i] - auto.position[i]).to_f64().abs() / size);
                for k in 0..N {
                    let d = (hand.jacobian[(i, k)] - auto.jacobian[(i, k)])
                        .to_f64()
                        .abs();
                    worst = worst.max(d / size);
                }
            }
        }
    }
    worst
}

/// A link number out of range is the caller's error, for which `Links::pose` promises any
/// pose and no panic: the pose, the point (hand-derived or dual) and the Jacobian at it of
/// links `LINKS`, `LINKS + 1` and `usize::MAX` are finite at a random state.
fn out_of_range_is_no_panic<T: Real, L: Links<T, N>, const N: usize>(l: &L, rng: &mut Rng) {
    let q = random_state::<T, N>(rng, (-3.2, 3.2), (0.0, 0.0)).q;
    for link in [L::LINKS, L::LINKS + 1, usize::MAX] {
        let pose: Pose<T> = l.pose(&q, link);
        let point = l.point(&q, link, [T::HALF, -T::one()]);
        let at = l.jacobian_at(&q, link, &pose, point.position);
        let finite = pose
            .origin
            .iter()
            .chain(&[pose.angle])
            .all(|x| x.is_finite())
            && point.position.iter().all(|x| x.is_finite())
            && point.jacobian.iter().all(|x| x.is_finite())
            && at.iter().all(|x| x.is_finite());
        assert!(
            finite,
            "{}, link {link}: {pose:?} {point:?}",
            core::any::type_name::<L>()
        );
    }
}

/// The chains' and the ragdoll's hand-derived points and Jacobians equal the dual-number default's, to 8 ulps of
/// the sizes (the same sums in another order).
fn hand_points_agree_with_duals<T: Real>() -> Result<(), Error> {
    let mut rng = Rng::new(345);
    let g = T::from_f64(G);
    let (h, l) = (T::from_f64(0.7), T::from_f64(1.1));
    let acrobot = acrobot(h, l, g)?;
    let worst = [
        hand_against_duals(
            &SimplePendulum::new(T::one(), T::from_f64(0.8), g, T::zero())?,
            &mut rng,
        ),
        hand_against_duals(&DoublePendulum::new(T::one(), T::one(), h, l, g)?, &mut rng),
        hand_against_duals(
            &NLinkPendulum::new([T::one(); 4], [0.4, 0.9, 0.6, 0.3].map(T::from_f64), g)?,
            &mut rng,
        ),
        hand_against_duals(
            &CartPole::new(T::one(), T::one(), T::from_f64(0.6), g)?,
            &mut rng,
        ),
        hand_against_duals(&acrobot, &mut rng),
        hand_against_duals(&Ragdoll::new(RagdollBody::<T>::adult())?, &mut rng),
    ];
    println!("{}: {worst:?}", core::any::type_name::<T>());
    assert!(
        worst.iter().all(|&w| w <= 8.0 * T::EPSILON.to_f64()),
        "{worst:?}"
    );
    Ok(())
}

/// A check of one mechanism with links, whatever its coordinates.
trait Check<T: Real> {
    fn check<L: Links<T, N>, const N: usize>(&mut self, l: &L);
}

/// `check` of every standard mechanism with links.
fn every_mechanism<T: Real>(check: &mut impl Check<T>) -> Result<(), Error> {
    let g = T::from_f64(G);
    let (h, l) = (T::from_f64(0.7), T::from_f64(1.1));
    check.check(&SimplePendulum::new(T::one(), h, g, T::zero())?);
    check.check(&DoublePendulum::new(T::one(), T::one(), h, l, g)?);
    check.check(&NLinkPendulum::new([T::one(); 3], [h; 3], g)?);
    check.check(&CartPole::new(T::one(), T::one(), h, g)?);
    check.check(&acrobot(h, l, g)?);
    check.check(&Ragdoll::new(RagdollBody::<T>::adult())?);
    check.check(&RigidBody::disk(T::one(), h, g)?);
    Ok(())
}

/// Every standard mechanism with links, asked for a link it does not have.
fn out_of_range_links<T: Real>() -> Result<(), Error> {
    struct OutOfRange(Rng);
    impl<T: Real> Check<T> for OutOfRange {
        fn check<L: Links<T, N>, const N: usize>(&mut self, l: &L) {
            out_of_range_is_no_panic(l, &mut self.0);
        }
    }
    every_mechanism::<T>(&mut OutOfRange(Rng::new(346)))
}

/// `Links::poses` gives each link's `Links::pose`, bit for bit, at 20 random states, and
/// leaves the entries past the links as they were.
fn poses_are_each_pose<T: Real, L: Links<T, N>, const N: usize>(l: &L, rng: &mut Rng) {
    let marker = Pose {
        origin: [T::from_f64(7.0); 2],
        angle: T::from_f64(-7.0),
    };
    for _ in 0..20 {
        let q = random_state::<T, N>(rng, (-3.2, 3.2), (0.0, 0.0)).q;
        let mut poses = [marker; 12];
        l.poses(&q, &mut poses);
        for (link, pose) in poses.iter().enumerate() {
            let expected = if link < L::LINKS {
                l.pose(&q, link)
            } else {
                marker
            };
            assert_eq!(
                *pose,
                expected,
                "{}, link {link}",
                core::any::type_name::<L>()
            );
        }
    }
}

/// Every standard mechanism's poses from one call.
fn all_poses_at_once<T: Real>() -> Result<(), Error> {
    struct AtOnce(Rng);
    impl<T: Real> Check<T> for AtOnce {
        fn check<L: Links<T, N>, const N: usize>(&mut self, l: &L) {
            poses_are_each_pose(l, &mut self.0);
        }
    }
    every_mechanism::<T>(&mut AtOnce(Rng::new(347)))
}

/// `Links::jacobian_at` of a point where `Links::point` places it is that point's Jacobian,
/// to 8 ulps of the sizes of the coordinates and the point (a rigid body's own takes the
/// offset from its centre where the point is, not turned there from its frame), at 20
/// random states and points on every link.
fn jacobian_at_is_the_points<T: Real, L: Links<T, N>, const N: usize>(l: &L, rng: &mut Rng) {
    for _ in 0..20 {
        let q = random_state::<T, N>(rng, (-3.2, 3.2), (0.0, 0.0)).q;
        let size = 2.0 + q.iter().map(|x| x.to_f64().abs()).sum::<f64>();
        for link in 0..L::LINKS {
            let local = [rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)];
            let point = l.point(&q, link, local);
            let at = l.jacobian_at(&q, link, &l.pose(&q, link), point.position);
            let worst = (at - point.jacobian)
                .iter()
                .fold(0.0_f64, |m, x| m.max(x.to_f64().abs()));
            assert!(
                worst <= 8.0 * T::EPSILON.to_f64() * size,
                "{}, link {link}: {worst:e}",
                core::any::type_name::<L>()
            );
        }
    }
}

/// Every standard mechanism's Jacobians of points given where they are.
fn jacobians_at_points<T: Real>() -> Result<(), Error> {
    struct At(Rng);
    impl<T: Real> Check<T> for At {
        fn check<L: Links<T, N>, const N: usize>(&mut self, l: &L) {
            jacobian_at_is_the_points(l, &mut self.0);
        }
    }
    every_mechanism::<T>(&mut At(Rng::new(348)))
}

for_f32_and_f64!(
    jacobians_at_points,
    all_poses_at_once,
    energies_agree,
    positions_follow_the_conventions,
    the_ragdoll_agrees,
    hand_points_agree_with_duals,
    out_of_range_links
);
