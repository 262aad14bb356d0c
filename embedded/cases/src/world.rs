//! The world case: three balls and a crate dropped into a box (a floor, two walls) in a
//! `lagrange_world::World`, compared bit for bit between the host and each core: contact
//! detection, the impulse solve, islands and sleep in the same IEEE operations everywhere.

use core::hint::black_box;

use lagrange_core::constraints::contact::ContactModel;
use lagrange_core::{Error, State};
use lagrange_systems::RigidBody;
use lagrange_world::{HalfPlane, Shape, World, WorldSettings};

use crate::Outcome;

/// The step, s: 60 Hz.
const DT: f32 = 1.0 / 60.0;

/// Four bodies, their shapes, 32 contact points: 5 kB in `f32`.
type Box4 = World<f32, RigidBody<f32>, 3, 4, 4, 32>;

/// The world, `steps` steps of [`DT`]: a digest of every body's coordinates and rates, and
/// how many are asleep at the end.
///
/// # Errors
/// A step's error (none for these values).
pub fn world_in_a_box(steps: u32) -> Result<Outcome, Error> {
    let model = ContactModel::new(0.4, 0.2, 1.0)?.with_friction(0.5)?;
    let settings = WorldSettings::new(model, 2e-3, 8)?.with_sleep(0.02, 0.5)?;
    let mut world = Box4::new(settings);
    world.add_plane(100, HalfPlane::floor())?;
    world.add_plane(101, HalfPlane::new([1.0, 0.0], -1.5)?)?;
    world.add_plane(102, HalfPlane::new([-1.0, 0.0], -1.5)?)?;
    let crate_ = RigidBody::rectangle(2.0, 0.6, 0.4, 9.81)?;
    world.add_body(0, crate_, State::new(0.0, [0.2, 0.5, 0.3], [1.0, 0.0, 2.0]))?;
    world.add_shape(10, 0, 0, Shape::rectangle(0.6, 0.4)?)?;
    for k in 1..4u32 {
        let ball = RigidBody::disk(0.5, 0.15, 9.81)?;
        let x = -0.8 + 0.5 * k as f32;
        let at = State::new(0.0, [x, 1.0 + 0.4 * k as f32, 0.0], [-1.5 * x, 0.0, 0.0]);
        world.add_body(k, ball, at)?;
        world.add_shape(10 + k, k, 0, Shape::circle(0.15)?)?;
    }
    let dt = black_box(DT);
    for _ in 0..black_box(steps) {
        world.step(dt)?;
    }
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for key in 0..4 {
        let s = world.state(key).ok_or(Error::NonFiniteState)?;
        for x in s.q.iter().chain(s.qd.iter()) {
            hash = (hash ^ u64::from(x.to_bits())).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    Ok(Outcome::from_words(&[
        hash,
        u64::from(world.report().asleep),
    ]))
}
