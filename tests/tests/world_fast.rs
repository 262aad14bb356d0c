//! Fast bodies and thin ones in a `lagrange_world::World`: a ball shot at a plank 1 cm thick
//! at 60 Hz, many times the plank's thickness a step, never passes through it, whether the
//! plank is static or free, whatever the angle and wherever in its step the ball arrives.

use lagrange_core::constraints::contact::ContactModel;
use lagrange_core::links::Pose;
use lagrange_core::{Error, Real, State};
use lagrange_systems::RigidBody;
use lagrange_tests::for_f32_and_f64;
use lagrange_world::{collide, Shape, World, WorldSettings};

/// Two rigid bodies or one and a static plank.
type Pair<T> = World<T, RigidBody<T>, 3, 4, 4, 64>;

/// The plank: 4 m long, 1 cm thick.
const LENGTH: f64 = 4.0;
const THICKNESS: f64 = 0.01;
/// The ball's radius, m.
const RADIUS: f64 = 0.1;
/// The slop, m.
const SLOP: f64 = 5e-3;
/// The step, s.
const DT: f64 = 1.0 / 60.0;

/// A shot: the ball's speed (m/s), its path's angle from the plank's normal (rad), where on
/// the plank its path crosses (m from the middle), how far it starts from the plank along
/// its path (m), the plank's mass (none: static), its turn (rad) and the restitution.
#[derive(Debug, Clone, Copy)]
struct Shot {
    speed: f64,
    angle: f64,
    at: f64,
    start: f64,
    plank: Option<f64>,
    turn: f64,
    restitution: f64,
}

/// What a shot did: whether the ball's centre crossed the plank's line within its length,
/// the deepest overlap of ball and plank after any step, and the gap between them after the
/// last (m).
#[derive(Debug)]
struct Outcome {
    through: bool,
    deepest: f64,
    last: f64,
}

/// Where `key`'s body is, as a pose.
fn pose<T: Real>(world: &Pair<T>, key: u32) -> Pose<T> {
    let q = world
        .state(key)
        .map_or([T::zero(); 3], |s| [s.q[0], s.q[1], s.q[2]]);
    Pose {
        origin: [q[0], q[1]],
        angle: q[2],
    }
}

/// The pose `s` of the way from `a` to `b` (0 to 1), f64.
fn between<T: Real>(a: &Pose<T>, b: &Pose<T>, s: f64) -> Pose<f64> {
    let along = |x: T, y: T| x.to_f64() + (y.to_f64() - x.to_f64()) * s;
    Pose {
        origin: [
            along(a.origin[0], b.origin[0]),
            along(a.origin[1], b.origin[1]),
        ],
        angle: along(a.angle, b.angle),
    }
}

/// `p` in the frame of `pose`.
fn local(pose: &Pose<f64>, p: [f64; 2]) -> [f64; 2] {
    let (s, c) = pose.angle.sin_cos();
    let d = [p[0] - pose.origin[0], p[1] - pose.origin[1]];
    [c * d[0] + s * d[1], -s * d[0] + c * d[1]]
}

/// Shoots the ball at the plank for 40 steps in zero gravity.
fn shoot<T: Real>(shot: Shot) -> Result<Outcome, Error> {
    let f = T::from_f64;
    let model = ContactModel::new(f(shot.restitution), f(0.1), T::one())?.with_friction(f(0.3))?;
    let mut world = Box::new(Pair::<T>::new(WorldSettings::new(model, f(SLOP), 8)?));
    let plank = Shape::rectangle(f(LENGTH), f(THICKNESS))?;
    let plank_pose = Pose {
        origin: [T::zero(); 2],
        angle: f(shot.turn),
    };
    match shot.plank {
        Some(mass) => {
            let body = RigidBody::rectangle(f(mass), f(LENGTH), f(THICKNESS), T::zero())?;
            world.add_body(
                1,
                body,
                State::new(
                    T::zero(),
                    [T::zero(), T::zero(), f(shot.turn)],
                    [T::zero(); 3],
                ),
            )?;
            world.add_shape(11, 1, 0, plank)?;
        }
        None => world.add_static(11, plank.placed(&plank_pose))?,
    }
    // The path, in the plank's frame: through `(at, 0)`, coming down at `angle` from its
    // normal; the start `start` back along it.
    let (s, c) = shot.angle.sin_cos();
    let dir = [s, -c];
    let from = [shot.at - shot.start * dir[0], -shot.start * dir[1]];
    let (ts, tc) = shot.turn.sin_cos();
    let world_of = |p: [f64; 2]| [tc * p[0] - ts * p[1], ts * p[0] + tc * p[1]];
    let (x, v) = (world_of(from), world_of(dir));
    let ball = RigidBody::disk(T::one(), f(RADIUS), T::zero())?;
    world.add_body(
        2,
        ball,
        State::new(
            T::zero(),
            [f(x[0]), f(x[1]), T::zero()],
            [f(v[0] * shot.speed), f(v[1] * shot.speed), T::zero()],
        ),
    )?;
    world.add_shape(12, 2, 0, Shape::circle(f(RADIUS))?)?;
    let circle = Shape::circle(f(RADIUS))?;
    let mut outcome = Outcome {
        through: false,
        deepest: 0.0,
        last: f64::INFINITY,
    };
    let plank_at = |world: &Pair<T>| {
        if shot.plank.is_some() {
            pose(world, 1)
        } else {
            plank_pose
        }
    };
    let mut side = 1.0;
    let mut was = (plank_at(&world), pose(&world, 2));
    for _ in 0..40 {
        world.step(f(DT))?;
        let (p, b) = (plank_at(&world), pose(&world, 2));
        // The step moves each body's coordinates along a line: the ball's centre, looked at
        // from the plank at 32 points of it, never crosses the plank's line within its
        // length (around an end is no crossing: a ball may slide off an end and pass
        // behind it). A light plank struck off its middle spins two radians a step: once a
        // step is not enough.
        for k in 1..=32 {
            let s = f64::from(k) / 32.0;
            let centre = local(&between(&was.0, &p, s), between(&was.1, &b, s).origin);
            if centre[1] * side < 0.0 {
                if centre[0].abs() < LENGTH / 2.0 {
                    outcome.through = true;
                }
                side = -side;
            }
        }
        was = (p, b);
        // (Looked for a metre out: a gap a ball at rest keeps is a figure too.)
        let m = collide(&plank.placed(&p), &circle.placed(&b), T::one());
        outcome.last = m.gap().map_or(f64::INFINITY, |g| g.to_f64());
        outcome.deepest = outcome.deepest.max(-outcome.last);
    }
    Ok(outcome)
}

/// Where on the plank a shot is aimed (m from its middle along the path's crossing), for a
/// path `angle` off its normal. A plank of 0.1 or 1 kg struck 1.2 m off its middle spins half a
/// radian or more a step and, turning that far, sweeps round at its rows' points a way a
/// step's one look at them does not follow (see the module docs of `lagrange_world`'s
/// sweep): such planks are struck where the ball first touches them, at their middle or 5 cm
/// off it. Static and heavier planks are struck anywhere, near the ends too.
fn aims(plank: Option<f64>, angle: f64) -> std::vec::Vec<f64> {
    match plank {
        Some(mass) if mass < 10.0 => {
            // The ball touches the face where its centre is a radius and half the plank's
            // thickness off the plank's line, a radius below that centre.
            let touch = (RADIUS + THICKNESS / 2.0) * angle.tan();
            vec![touch, touch + 0.05]
        }
        _ => vec![0.0, 0.05, 1.2, -1.9],
    }
}

/// Shoots the shots of `speeds` from 0 to 1.2 rad off the plank's normal at `planks`,
/// arriving at three points of their steps, with `restitution`, and asserts that none passes
/// through the plank or leaves the ball deeper in it than the slop after a step (listing
/// each that does).
fn every_shot_holds<T: Real>(
    speeds: &[f64],
    planks: &[Option<f64>],
    restitution: f64,
) -> Result<(), Error> {
    let mut failed = std::vec::Vec::new();
    let mut shots = 0;
    for &speed in speeds {
        for &angle in &[0.0, 0.5, -0.9, 1.2] {
            for &plank in planks {
                for at in aims(plank, angle) {
                    for &phase in &[0.1, 0.55, 0.95] {
                        let shot = Shot {
                            speed,
                            angle,
                            at,
                            start: 0.5 + speed * DT * phase,
                            plank,
                            turn: 0.3,
                            restitution,
                        };
                        shots += 1;
                        let out = shoot::<T>(shot)?;
                        // The slop and the rounding of the test's own overlap.
                        if out.through || out.deepest > SLOP * 1.01 {
                            failed.push(format!("{shot:?}: {out:?}"));
                        }
                    }
                }
            }
        }
    }
    assert!(
        failed.is_empty(),
        "{} of {shots} shots:\n{}",
        failed.len(),
        failed.join("\n")
    );
    Ok(())
}

/// A ball of 10 cm radius shot at 20 to 1,000 m/s (33 to 1,700 times the plank's thickness
/// and 1.7 to 83 times the ball's diameter a step at 60 Hz) at a plank 4 m long and 1 cm
/// thick, static or free (0.1 to 100 times the ball's mass), bouncing off it (restitution
/// 0.5): it never passes through the plank, and never overlaps it deeper than the slop after
/// a step. (36 of these 768 shots failed, 35 of them through the plank, with the contacts
/// taken at the features closest at the step's start.)
fn a_fast_ball_does_not_pass_through_a_thin_plank<T: Real>() -> Result<(), Error> {
    let planks = [None, Some(0.1), Some(1.0), Some(10.0), Some(100.0)];
    every_shot_holds::<T>(&[20.0, 100.0, 300.0, 1000.0], &planks, 0.5)
}

/// A ball shot at a static plank at 20 to 300 m/s with no bounce (restitution 0), left to slide
/// along it (up to 4.7 m a step at 1.2 rad): it stays on its side, no deeper than the slop.
fn a_ball_struck_flat_on_a_static_plank_stays_on_its_side<T: Real>() -> Result<(), Error> {
    every_shot_holds::<T>(&[20.0, 100.0, 300.0], &[None], 0.0)
}

/// A ball shot head-on at a static plank at 20 to 1,000 m/s with no bounce (restitution 0),
/// from anywhere in a step away: it comes to rest on the plank, within the slop of touching
/// (a contact whose gap were carried back wrong would stop it short, in the air).
fn a_ball_struck_head_on_without_a_bounce_rests_on_the_plank<T: Real>() -> Result<(), Error> {
    for speed in [20.0, 100.0, 300.0, 1000.0] {
        for at in [0.0, 1.2, -1.9] {
            for phase in [0.1, 0.55, 0.95] {
                let shot = Shot {
                    speed,
                    angle: 0.0,
                    at,
                    start: 0.5 + speed * DT * phase,
                    plank: None,
                    turn: 0.3,
                    restitution: 0.0,
                };
                let out = shoot::<T>(shot)?;
                // Resting: the drift leaves it no deeper than the slop; nothing pulls it off.
                assert!(
                    (-SLOP * 1.01..=SLOP).contains(&out.last),
                    "{shot:?}: {out:?}"
                );
            }
        }
    }
    Ok(())
}

for_f32_and_f64!(
    a_fast_ball_does_not_pass_through_a_thin_plank,
    a_ball_struck_flat_on_a_static_plank_stays_on_its_side,
    a_ball_struck_head_on_without_a_bounce_rests_on_the_plank
);
