//! The peer: the thrown ragdoll built in rapier2d as a multibody (reduced coordinates, as
//! lagrange's; built by the module it shares with the world bench, `shared/rapier_ragdoll.rs`),
//! with capsule colliders on a ground, stepped at the same `dt`.

use std::time::Instant;

use lagrange_core::State;
use lagrange_systems::{Ragdoll, RagdollBody, RAGDOLL_COORDINATES as N, RAGDOLL_LINKS};
use rapier2d::prelude::*;

use crate::rapier_ragdoll::{self, link_poses, v2};

/// Radius of every link's capsule, m: a limb's thickness is not part of lagrange's ragdoll
/// (its floor points have none), so a small one; penetration is measured at its surface.
pub const CAPSULE_RADIUS: f64 = 0.04;

/// Gravity, m/s^2 (the adult body's).
const GRAVITY: f64 = 9.81;

/// The rapier world of the thrown ragdoll and what the bench reads from it.
pub struct Peer {
    /// The world: bodies, colliders, the multibody, ground, pipeline.
    pub world: PhysicsWorld,
    /// The links' bodies, in lagrange's order.
    bodies: [RigidBodyHandle; RAGDOLL_LINKS],
    /// The ground's collider.
    ground: ColliderHandle,
    /// Each link's mass, moment of inertia and length.
    links: [(f64, f64, f64); RAGDOLL_LINKS],
}

impl Peer {
    /// The adult ragdoll at lagrange's state `s` (its pose and velocities), as a rapier
    /// multibody ([`rapier_ragdoll::insert`]) with capsules of [`CAPSULE_RADIUS`] on a
    /// ground at y = 0, stepped at `dt`; `sleep`: whether its bodies may fall asleep.
    ///
    /// # Errors
    /// As [`rapier_ragdoll::insert`].
    pub fn new(s: &State<f64, N>, dt: f64, sleep: bool) -> Result<Self, String> {
        let mut world = PhysicsWorld::new();
        world.gravity = v2(0.0, -GRAVITY);
        world.integration_parameters.dt = dt as f32;
        let ground_body = world.insert_body(RigidBodyBuilder::fixed());
        // A thick slab whose top face is y = 0.
        let ground = world.insert_collider(
            ColliderBuilder::cuboid(100.0, 1.0)
                .translation(v2(0.0, -1.0))
                .friction(0.8)
                .restitution(0.3),
            Some(ground_body),
        );
        let colliders = rapier_ragdoll::Colliders {
            radii: [CAPSULE_RADIUS; RAGDOLL_LINKS],
            friction: 0.8,
            restitution: 0.3,
        };
        let built = rapier_ragdoll::insert(&mut world, s, &colliders, sleep)?;
        Ok(Self {
            world,
            bodies: built.bodies,
            ground,
            links: built.links,
        })
    }

    /// One step.
    pub fn step(&mut self) {
        self.world.step();
    }

    /// Each link's centre of mass, m.
    pub fn centres(&self) -> [[f64; 2]; RAGDOLL_LINKS] {
        self.bodies.map(|h| {
            let t = self.world.bodies[h].translation();
            [f64::from(t.x), f64::from(t.y)]
        })
    }

    /// `T + V` of the links, J (computed in f64 from rapier's f32 state).
    pub fn energy(&self) -> f64 {
        self.bodies
            .iter()
            .zip(&self.links)
            .map(|(&h, &(m, i, _))| {
                let rb = &self.world.bodies[h];
                let (v, w) = (rb.linvel(), f64::from(rb.angvel()));
                let y = f64::from(rb.center_of_mass().y);
                let v2 = f64::from(v.x).powi(2) + f64::from(v.y).powi(2);
                0.5 * m * v2 + 0.5 * i * w * w + m * GRAVITY * y
            })
            .sum()
    }

    /// The deepest penetration of a capsule into the ground at the bodies' current poses,
    /// m (zero when none is below the ground's top face): exact for a capsule on a plane.
    pub fn geometric_depth(&self) -> f64 {
        self.bodies
            .iter()
            .zip(&self.links)
            .map(|(&h, &(_, _, l))| {
                let pose = self.world.bodies[h].position();
                let half = (l / 2.0) as f32;
                let reach = (pose.rotation * Vector::new(0.0, half)).y.abs();
                -(f64::from(pose.translation.y - reach) - CAPSULE_RADIUS)
            })
            .fold(0.0, f64::max)
    }

    /// The deepest penetration in the contact manifolds of the last step (from the poses its
    /// collision detection saw: those at its start), m (zero when none).
    pub fn manifold_depth(&self) -> f64 {
        let mut deepest = 0.0f64;
        for pair in self.world.narrow_phase.contact_pairs() {
            if let PairContacts::Rigid(c) = &pair.contacts {
                for m in &c.manifolds {
                    for p in &m.points {
                        deepest = deepest.max(-f64::from(p.dist));
                    }
                }
            }
        }
        deepest
    }

    /// A copy of the world with the ground disabled and the joint limits removed: the
    /// free step from the same state (what the contacts and limits changed is measured
    /// against it).
    pub fn free_copy(&self) -> Self {
        let w = &self.world;
        let mut world = PhysicsWorld {
            gravity: w.gravity,
            integration_parameters: w.integration_parameters,
            physics_pipeline: PhysicsPipeline::new(),
            collision_pipeline: CollisionPipeline::new(),
            islands: w.islands.clone(),
            broad_phase: w.broad_phase.clone(),
            narrow_phase: w.narrow_phase.clone(),
            bodies: w.bodies.clone(),
            colliders: w.colliders.clone(),
            impulse_joints: w.impulse_joints.clone(),
            multibody_joints: w.multibody_joints.clone(),
            soft_bodies: w.soft_bodies.clone(),
            ccd_solver: w.ccd_solver.clone(),
        };
        if let Some(g) = world.colliders.get_mut(self.ground) {
            g.set_enabled(false);
        }
        if let Some(link) = world
            .multibody_joints
            .rigid_body_link(self.bodies[0])
            .copied()
        {
            if let Some(mb) = world.multibody_joints.get_multibody_mut(link.multibody) {
                for l in mb.links_mut() {
                    l.joint.data.limit_axes = JointAxesMask::empty();
                }
            }
        }
        Self {
            world,
            bodies: self.bodies,
            ground: self.ground,
            links: self.links,
        }
    }

    /// Whether two worlds' links have the same poses and velocities, bit for bit.
    pub fn same_state(&self, other: &Self) -> bool {
        self.bodies.iter().zip(&other.bodies).all(|(&a, &b)| {
            let (x, y) = (&self.world.bodies[a], &other.world.bodies[b]);
            x.position() == y.position() && x.linvel() == y.linvel() && x.angvel() == y.angvel()
        })
    }
}

/// One timed run: the world built at `s` (not timed), then `steps` steps; with `per_step`
/// each timed (ns of each), without the whole run (one entry), as lagrange's runs.
///
/// # Errors
/// As [`Peer::new`].
pub fn timed_run(
    s: &State<f64, N>,
    dt: f64,
    steps: usize,
    sleep: bool,
    per_step: bool,
) -> Result<Vec<f64>, String> {
    let mut peer = Peer::new(s, dt, sleep)?;
    if !per_step {
        let clock = Instant::now();
        for _ in 0..steps {
            peer.step();
        }
        let ns = clock.elapsed().as_nanos() as f64;
        std::hint::black_box(peer.centres());
        return Ok(vec![ns]);
    }
    let mut ns = Vec::with_capacity(steps);
    for _ in 0..steps {
        let clock = Instant::now();
        peer.step();
        ns.push(clock.elapsed().as_nanos() as f64);
    }
    std::hint::black_box(peer.centres());
    Ok(ns)
}

/// What an untimed run measured: the deepest penetration (from the manifolds, and from the
/// capsules' poses after each step), the largest energy gain of a step the contacts or the
/// limits changed, and the free flight's agreement with lagrange's.
#[derive(Debug, Clone, Copy)]
pub struct PeerFigures {
    /// From the contact manifolds, m.
    pub manifold_depth: f64,
    /// From the capsules' poses after each step, m.
    pub geometric_depth: f64,
    /// `T + V` after a step less the larger of before and after its free step, the largest
    /// over the steps the contacts or limits changed, J.
    pub energy_gain: f64,
    /// Steps the contacts or limits changed.
    pub contact_steps: usize,
}

/// The untimed run of `steps` steps that measures [`PeerFigures`].
///
/// # Errors
/// As [`Peer::new`].
pub fn figures(s: &State<f64, N>, dt: f64, steps: usize) -> Result<PeerFigures, String> {
    let mut peer = Peer::new(s, dt, false)?;
    let mut f = PeerFigures {
        manifold_depth: 0.0,
        geometric_depth: peer.geometric_depth(),
        energy_gain: f64::NEG_INFINITY,
        contact_steps: 0,
    };
    for _ in 0..steps {
        let before = peer.energy();
        let mut free = peer.free_copy();
        free.step();
        peer.step();
        if !peer.same_state(&free) {
            f.contact_steps += 1;
            let gain = peer.energy() - before.max(free.energy());
            f.energy_gain = f.energy_gain.max(gain);
        }
        f.manifold_depth = f.manifold_depth.max(peer.manifold_depth());
        f.geometric_depth = f.geometric_depth.max(peer.geometric_depth());
    }
    Ok(f)
}

/// The largest distance between a link's centre of mass in rapier and in lagrange (free
/// RK4 at the same `dt`) over `steps` steps of free flight (no ground, no limit reached),
/// m: how closely the two ragdolls agree before anything touches.
///
/// # Errors
/// As [`Peer::new`], and lagrange's errors.
pub fn free_flight_agreement(s: &State<f64, N>, dt: f64, steps: usize) -> Result<f64, String> {
    use lagrange_integrators::{Integrator, Rk4};
    let doll = Ragdoll::new(RagdollBody::<f64>::adult()).map_err(|e| e.to_string())?;
    let mut peer = Peer::new(s, dt, false)?.free_copy();
    let mut state = *s;
    let mut worst = 0.0f64;
    for _ in 0..steps {
        peer.step();
        state = Rk4.step(&doll, &state, dt).map_err(|e| e.to_string())?;
        let ours = link_poses(&doll, &state);
        for (k, c) in peer.centres().iter().enumerate() {
            let o = ours[k].0;
            worst = worst.max((c[0] - o[0]).hypot(c[1] - o[1]));
        }
    }
    Ok(worst)
}
