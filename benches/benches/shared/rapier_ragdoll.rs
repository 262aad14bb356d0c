//! The adult ragdoll built in rapier2d as a multibody (reduced coordinates, as lagrange's),
//! with a capsule on every link, at a lagrange state: shared by the contacts bench's peer
//! (one thrown ragdoll on a ground) and the world bench's (a pile of them in a pit).

use lagrange_core::nalgebra::SVector;
use lagrange_core::State;
use lagrange_systems::{
    Ragdoll, RagdollBody, ADULT_JOINT_LIMITS, RAGDOLL_COORDINATES as N, RAGDOLL_LINKS,
};
use rapier2d::prelude::*;

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
pub fn link_poses(
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

/// An `f32` vector.
pub fn v2(x: f64, y: f64) -> Vector {
    Vector::new(x as f32, y as f32)
}

/// The capsules and their surfaces.
#[derive(Debug, Clone, Copy)]
pub struct Colliders {
    /// Each link's capsule radius, m, in lagrange's order.
    pub radii: [f64; RAGDOLL_LINKS],
    /// Friction of every capsule.
    pub friction: f64,
    /// Restitution of every capsule.
    pub restitution: f64,
}

/// A ragdoll in a rapier world: its links' bodies and what they are.
#[derive(Debug, Clone, Copy)]
pub struct Built {
    /// The links' bodies, in lagrange's order.
    pub bodies: [RigidBodyHandle; RAGDOLL_LINKS],
    /// Each link's mass, moment of inertia (`m L^2 / 12`) and length (the contacts bench
    /// reads them for its energies; the world bench does not).
    #[allow(dead_code)]
    pub links: [(f64, f64, f64); RAGDOLL_LINKS],
}

/// The adult ragdoll at lagrange's state `s` (its pose and velocities) inserted into
/// `world` as a multibody: the same ten links (masses, lengths, `m L^2 / 12`), joints at
/// lagrange's points with its limits, joint damping as lagrange's (rapier's per-DoF
/// multibody damping, none on the root), a capsule along every link (`colliders`), its own
/// links not colliding with each other (as lagrange's); `sleep`: whether its bodies may
/// fall asleep.
///
/// # Errors
/// When rapier refuses a joint, or when the built pose differs from lagrange's by more
/// than 0.1 mm (a wrong anchor or angle convention).
pub fn insert(
    world: &mut PhysicsWorld,
    s: &State<f64, N>,
    colliders: &Colliders,
    sleep: bool,
) -> Result<Built, String> {
    let body = RagdollBody::<f64>::adult();
    let doll = Ragdoll::new(body).map_err(|e| e.to_string())?;
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
            ColliderBuilder::capsule_y((l / 2.0) as f32, colliders.radii[k] as f32)
                .density(0.0)
                .friction(colliders.friction as f32)
                .restitution(colliders.restitution as f32),
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
    place(world, &bodies, s)?;
    check(world, &bodies, s)?;
    Ok(Built { bodies, links })
}

/// The multibody's generalized coordinates and velocities set to lagrange's `s` (they
/// map one to one: the root's free joint is the torso's `x, y, th`, then the nine
/// hinges in lagrange's order), its damping to lagrange's (0.5 N m s/rad on the hinges,
/// none on the root), self-contacts off (lagrange's links do not collide with each
/// other).
fn place(
    world: &mut PhysicsWorld,
    bodies: &[RigidBodyHandle; RAGDOLL_LINKS],
    s: &State<f64, N>,
) -> Result<(), String> {
    let link = *world
        .multibody_joints
        .rigid_body_link(bodies[0])
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
    for (k, &handle) in bodies.iter().enumerate() {
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
            rates[at..at + 3].copy_from_slice(&[s.qd[0] as f32, s.qd[1] as f32, s.qd[2] as f32]);
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
    Ok(())
}

/// Whether the bodies sit where lagrange's links do at `s` (to 0.1 mm and 0.1 mrad).
fn check(
    world: &PhysicsWorld,
    bodies: &[RigidBodyHandle; RAGDOLL_LINKS],
    s: &State<f64, N>,
) -> Result<(), String> {
    let doll = Ragdoll::new(RagdollBody::<f64>::adult()).map_err(|e| e.to_string())?;
    let poses = link_poses(&doll, s);
    for (k, &h) in bodies.iter().enumerate() {
        let rb = &world.bodies[h];
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
