//! The peer: the thrown ragdoll built in rapier2d as a multibody (reduced coordinates, as
//! lagrange's), with capsule colliders on a ground, stepped at the same `dt`.

use std::time::Instant;

use lagrange_core::nalgebra::SVector;
use lagrange_core::State;
use lagrange_systems::{
    Ragdoll, RagdollBody, ADULT_JOINT_LIMITS, RAGDOLL_COORDINATES as N, RAGDOLL_LINKS,
};
use rapier2d::prelude::*;

/// Radius of every link's capsule, m: a limb's thickness is not part of lagrange's ragdoll
/// (its floor points have none), so a small one; penetration is measured at its surface.
pub const CAPSULE_RADIUS: f64 = 0.04;

/// Gravity, m/s^2 (the adult body's).
const GRAVITY: f64 = 9.81;

/// The parent of each link, in lagrange's order (torso, head, left upper arm, left forearm,
/// right upper arm, right forearm, left thigh, left shin, right thigh, right shin).
const PARENT: [usize; RAGDOLL_LINKS] = [0, 0, 0, 2, 0, 4, 0, 6, 0, 8];

/// The head's rest angle relative to the torso: it points up at a neck angle of zero.
const HEAD_REST: f64 = core::f64::consts::PI;

/// Each link's mass and length, kg and m, in lagrange's order.
fn links(body: &RagdollBody<f64>) -> [(f64, f64); RAGDOLL_LINKS] {
    let s = |seg: lagrange_systems::Segment<f64>| (seg.mass, seg.length);
    [
        s(body.torso),
        s(body.head),
        s(body.upper_arm),
        s(body.forearm),
        s(body.upper_arm),
        s(body.forearm),
        s(body.thigh),
        s(body.shin),
        s(body.thigh),
        s(body.shin),
    ]
}

/// The direction, in its body's frame, from a link's joint along the link: every rigid body
/// sits at its link's centre of mass, turned by its absolute angle less its rest angle, so
/// that a rapier joint angle is lagrange's relative joint angle. A limb (and the torso, neck
/// to pelvis) points along -y; the head, turned by pi, along +y.
fn axis(link: usize) -> f64 {
    if link == 1 {
        1.0
    } else {
        -1.0
    }
}

/// Where link `k`'s joint sits, in its parent's frame (parent's centre of mass at the
/// origin), and in its own, m.
fn anchors(body: &RagdollBody<f64>, k: usize) -> ([f64; 2], [f64; 2]) {
    let lengths = links(body).map(|(_, l)| l);
    let half_torso = lengths[0] / 2.0;
    // The torso's frame: along its axis (neck to pelvis) is -y, across it (towards the
    // right limbs, lagrange's n0) is +x.
    let (ws, wh) = (body.shoulder_width / 2.0, body.hip_width / 2.0);
    let parent = match k {
        1 => [0.0, half_torso],
        2 => [-ws, half_torso],
        4 => [ws, half_torso],
        6 => [-wh, -half_torso],
        8 => [wh, -half_torso],
        // A forearm at its upper arm's far end, a shin at its thigh's.
        _ => [0.0, -lengths[PARENT[k]] / 2.0],
    };
    let own = [0.0, -axis(k) * lengths[k] / 2.0];
    (parent, own)
}

/// Each link's centre of mass, body angle (absolute angle less rest angle) and their rates
/// at lagrange's state `s`, from `Ragdoll::segments`: the midpoint and direction of each
/// segment, the rates by central differences along `q'` (step `H` in time).
fn link_poses(
    doll: &Ragdoll<f64>,
    s: &State<f64, N>,
) -> [([f64; 2], f64, [f64; 2], f64); RAGDOLL_LINKS] {
    const H: f64 = 1e-6;
    let pose = |q: &SVector<f64, N>| {
        doll.segments(q).map(|[a, b]| {
            let mid = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
            // A link of absolute angle th points along (sin th, -cos th).
            let angle = (b[0] - a[0]).atan2(a[1] - b[1]);
            (mid, angle)
        })
    };
    let now = pose(&s.q);
    let ahead = pose(&(s.q + s.qd * H));
    let behind = pose(&(s.q - s.qd * H));
    core::array::from_fn(|k| {
        let rest = if k == 1 { HEAD_REST } else { 0.0 };
        let (c, a) = now[k];
        let v = [
            (ahead[k].0[0] - behind[k].0[0]) / (2.0 * H),
            (ahead[k].0[1] - behind[k].0[1]) / (2.0 * H),
        ];
        let mut da = ahead[k].1 - behind[k].1;
        // Unwrap across +-pi.
        if da > core::f64::consts::PI {
            da -= 2.0 * core::f64::consts::PI;
        } else if da < -core::f64::consts::PI {
            da += 2.0 * core::f64::consts::PI;
        }
        (c, a - rest, v, da / (2.0 * H))
    })
}

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

/// An `f32` vector.
fn v2(x: f64, y: f64) -> Vector {
    Vector::new(x as f32, y as f32)
}

impl Peer {
    /// The adult ragdoll at lagrange's state `s` (its pose and velocities), as a rapier
    /// multibody on a ground at y = 0, stepped at `dt`; `sleep`: whether its bodies may fall
    /// asleep.
    ///
    /// # Errors
    /// When rapier refuses a joint, or when the built pose differs from lagrange's by more
    /// than 0.1 mm (a wrong anchor or angle convention).
    pub fn new(s: &State<f64, N>, dt: f64, sleep: bool) -> Result<Self, String> {
        let body = RagdollBody::<f64>::adult();
        let doll = Ragdoll::new(body).map_err(|e| e.to_string())?;
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
        let poses = link_poses(&doll, s);
        let masses = links(&body);
        let links: [(f64, f64, f64); RAGDOLL_LINKS] = core::array::from_fn(|k| {
            (
                masses[k].0,
                masses[k].0 * masses[k].1.powi(2) / 12.0,
                masses[k].1,
            )
        });
        let bodies: [RigidBodyHandle; RAGDOLL_LINKS] = core::array::from_fn(|k| {
            let (c, angle, v, w) = poses[k];
            let (m, i, l) = links[k];
            let rb = RigidBodyBuilder::dynamic()
                .pose(Pose::new(v2(c[0], c[1]), angle as f32))
                .linvel(v2(v[0], v[1]))
                .angvel(w as f32)
                .additional_mass_properties(MassProperties::new(Vector::ZERO, m as f32, i as f32))
                .can_sleep(sleep);
            let handle = world.insert_body(rb);
            world.insert_collider(
                ColliderBuilder::capsule_y((l / 2.0) as f32, CAPSULE_RADIUS as f32)
                    .density(0.0)
                    .friction(0.8)
                    .restitution(0.3),
                Some(handle),
            );
            handle
        });
        for k in 1..RAGDOLL_LINKS {
            let (parent, own) = anchors(&body, k);
            let [lower, upper] = ADULT_JOINT_LIMITS[k - 1];
            let joint = RevoluteJointBuilder::new()
                .local_anchor1(v2(parent[0], parent[1]))
                .local_anchor2(v2(own[0], own[1]))
                .limits([lower as f32, upper as f32]);
            world
                .insert_multibody_joint(bodies[PARENT[k]], bodies[k], joint)
                .ok_or_else(|| format!("rapier refused the multibody joint of link {k}"))?;
        }
        let peer = Self {
            world,
            bodies,
            ground,
            links,
        };
        peer.place(s)
    }

    /// The multibody's generalized coordinates and velocities set to lagrange's `s` (they
    /// map one to one: the root's free joint is the torso's `x, y, th`, then the nine
    /// hinges in lagrange's order), its damping to lagrange's (0.5 N m s/rad on the hinges,
    /// none on the root), self-contacts off (lagrange's links do not collide with each
    /// other), and the result checked against lagrange's pose.
    fn place(mut self, s: &State<f64, N>) -> Result<Self, String> {
        let world = &mut self.world;
        let link = *world
            .multibody_joints
            .rigid_body_link(self.bodies[0])
            .ok_or("the torso is not in a multibody")?;
        let mb = world
            .multibody_joints
            .get_multibody_mut(link.multibody)
            .ok_or("no multibody")?;
        mb.set_self_contacts_enabled(false);
        // The root's pose is read from the torso's body, and its angle goes in as a
        // displacement as well: in 2D rapier's free root joint keeps its angle coordinate
        // apart from its rotation, takes only the rotation from the body, and rebuilds the
        // rotation from the coordinate when it integrates, so that a root body created at
        // 0.6 rad is back at 0 after the first step (rapier2d 0.36.1) unless its coordinate
        // is set too. The hinges move from zero by lagrange's joint angles.
        mb.forward_kinematics(&world.bodies, true);
        let ndofs = mb.ndofs();
        let mut disp = vec![0.0f32; ndofs];
        let mut rates = vec![0.0f32; ndofs];
        let mut damping = vec![0.0f32; ndofs];
        for (k, &handle) in self.bodies.iter().enumerate() {
            let id = world
                .multibody_joints
                .rigid_body_link(handle)
                .ok_or("a link is not in the multibody")?
                .id;
            let mb = world
                .multibody_joints
                .get_multibody(link.multibody)
                .ok_or("no multibody")?;
            let at = mb.link(id).ok_or("no link")?.assembly_id();
            if k == 0 {
                let angle = mb.link(id).ok_or("no link")?.joint().coords()[2];
                disp[at + 2] = s.q[2] as f32 - angle;
                rates[at..at + 3].copy_from_slice(&[
                    s.qd[0] as f32,
                    s.qd[1] as f32,
                    s.qd[2] as f32,
                ]);
            } else {
                disp[at] = s.q[k + 2] as f32;
                rates[at] = s.qd[k + 2] as f32;
                damping[at] = RagdollBody::<f64>::adult().joint_damping as f32;
            }
        }
        let mb = world
            .multibody_joints
            .get_multibody_mut(link.multibody)
            .ok_or("no multibody")?;
        mb.apply_displacements(&disp);
        mb.forward_kinematics(&world.bodies, false);
        mb.update_rigid_bodies(&mut world.bodies, true);
        mb.generalized_velocity_mut().copy_from_slice(&rates);
        mb.damping_mut().copy_from_slice(&damping);
        self.check(s)?;
        Ok(self)
    }

    /// Whether the bodies sit where lagrange's links do at `s` (to 0.1 mm and 0.1 mrad).
    fn check(&self, s: &State<f64, N>) -> Result<(), String> {
        let doll = Ragdoll::new(RagdollBody::<f64>::adult()).map_err(|e| e.to_string())?;
        let poses = link_poses(&doll, s);
        for (k, &h) in self.bodies.iter().enumerate() {
            let rb = &self.world.bodies[h];
            let t = rb.translation();
            let (c, angle, _, _) = poses[k];
            let da = (f64::from(rb.rotation().angle()) - angle + core::f64::consts::PI)
                .rem_euclid(2.0 * core::f64::consts::PI)
                - core::f64::consts::PI;
            let dc = (f64::from(t.x) - c[0]).hypot(f64::from(t.y) - c[1]);
            if dc > 1e-4 || da.abs() > 1e-4 {
                return Err(format!(
                    "rapier's link {k} is off lagrange's pose by {dc:.2e} m, {da:.2e} rad"
                ));
            }
        }
        Ok(())
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
