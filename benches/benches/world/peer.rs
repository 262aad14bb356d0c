//! The peer: each scene built in rapier2d the same way (the same bodies, masses, inertias,
//! shapes, surfaces, walls and start), stepped at the same `dt`. The ragdolls are multibodies
//! (reduced coordinates, as lagrange's), built by the module this bench shares with the
//! contacts bench (`shared/rapier_ragdoll.rs`).

use std::collections::HashMap;

use lagrange_systems::RAGDOLL_LINKS;
use rapier2d::prelude::*;

use crate::rapier_ragdoll::{self, v2};
use crate::scenes::{self, Probe, Sim, Surfaces, BALL, BALLS, BALL_PIT, DT, G, PILE, PYRAMID};

/// A rapier2d world and its dynamic bodies.
pub struct Rapier {
    world: PhysicsWorld,
    /// Its dynamic bodies, `group` by `group` one of lagrange's bodies (a ragdoll's ten
    /// links; a box or a ball alone).
    bodies: Vec<RigidBodyHandle>,
    group: usize,
}

impl Sim for Rapier {
    fn step(&mut self) -> Result<(), String> {
        self.world.step();
        Ok(())
    }

    /// lagrange's bodies of which a link is awake.
    fn awake(&self) -> usize {
        self.bodies
            .chunks(self.group.max(1))
            .filter(|links| links.iter().any(|&h| !self.world.bodies[h].is_sleeping()))
            .count()
    }

    /// The deepest penetration in the contact manifolds of the last step (`dist` of their
    /// points: the poses its collision detection saw, those at the step's start, which are
    /// the previous step's end), m; not of two links of one ragdoll (its narrow phase
    /// keeps their pairs, whose capsules overlap at the joints by design, though the solver
    /// skips them with self-contacts off).
    fn probe(&mut self) -> Probe {
        let group = self.group.max(1);
        let owner: HashMap<RigidBodyHandle, usize> = self
            .bodies
            .iter()
            .enumerate()
            .map(|(i, &h)| (h, i / group))
            .collect();
        let of = |c: ColliderHandle| {
            self.world
                .colliders
                .get(c)
                .and_then(|c| c.parent())
                .and_then(|b| owner.get(&b).copied())
        };
        let mut deepest = 0.0f64;
        for pair in self.world.narrow_phase.contact_pairs() {
            let (a, b) = (of(pair.collider1), of(pair.collider2));
            if a.is_some() && a == b {
                continue;
            }
            if let PairContacts::Rigid(c) = &pair.contacts {
                for m in &c.manifolds {
                    for p in &m.points {
                        deepest = deepest.max(-f64::from(p.dist));
                    }
                }
            }
        }
        Probe {
            depth: deepest,
            ..Probe::default()
        }
    }
}

/// An empty world at [`DT`] with rapier's default integration parameters (4 solver
/// iterations, each one PGS pass and one stabilisation pass; allowed linear error 5 mm and
/// prediction distance 2 cm, lagrange's slop and margin), the floor (a slab whose top is
/// y = 0) and, for `half`, walls whose inner faces are at `x = +-half`.
fn world(surfaces: Surfaces, half: Option<f64>) -> PhysicsWorld {
    let mut world = PhysicsWorld::new();
    world.gravity = v2(0.0, -G);
    world.integration_parameters.dt = DT as f32;
    let ground = world.insert_body(RigidBodyBuilder::fixed());
    let slab = |hx: f64, hy: f64, x: f64, y: f64| {
        ColliderBuilder::cuboid(hx as f32, hy as f32)
            .translation(v2(x, y))
            .friction(surfaces.friction as f32)
            .restitution(surfaces.restitution as f32)
    };
    world.insert_collider(slab(200.0, 1.0, 0.0, -1.0), Some(ground));
    if let Some(h) = half {
        for side in [-1.0, 1.0] {
            world.insert_collider(slab(1.0, 200.0, side * (h + 1.0), 199.0), Some(ground));
        }
    }
    world
}

/// Rigid bodies at rest at `centres`, each with a collider made by `shape`, never asleep.
fn rigid(
    centres: &[[f64; 2]],
    shape: impl Fn() -> ColliderBuilder,
    surfaces: Surfaces,
    half: Option<f64>,
) -> Rapier {
    let mut world = world(surfaces, half);
    let bodies = centres
        .iter()
        .map(|c| {
            let h = world.insert_body(
                RigidBodyBuilder::dynamic()
                    .translation(v2(c[0], c[1]))
                    .can_sleep(false),
            );
            world.insert_collider(
                shape()
                    .friction(surfaces.friction as f32)
                    .restitution(surfaces.restitution as f32),
                Some(h),
            );
            h
        })
        .collect();
    Rapier {
        world,
        bodies,
        group: 1,
    }
}

/// The pyramid of `rows` rows: 1 m cuboids of density 1 (1 kg, `m (w^2 + h^2) / 12`, as
/// lagrange's `RigidBody::rectangle`).
pub fn pyramid(rows: usize) -> Rapier {
    rigid(
        &scenes::pyramid(rows),
        || ColliderBuilder::cuboid(0.5, 0.5).density(1.0),
        PYRAMID,
        None,
    )
}

/// `count` balls poured into the pit: balls of [`BALL`]'s radius and mass (`m r^2 / 2`, as
/// lagrange's `RigidBody::disk`).
pub fn balls(count: usize) -> Rapier {
    let (r, m) = BALL;
    let density = m / (core::f64::consts::PI * r * r);
    rigid(
        &scenes::balls(count),
        || ColliderBuilder::ball(r as f32).density(density as f32),
        BALLS,
        Some(BALL_PIT),
    )
}

/// `dolls` ragdolls thrown into their pit, as lagrange's; `sleep`: whether they may fall
/// asleep (rapier's own thresholds).
///
/// # Errors
/// As [`rapier_ragdoll::insert`].
pub fn pile(dolls: usize, sleep: bool) -> Result<Rapier, String> {
    let mut world = world(PILE, Some(scenes::pile_pit(dolls)));
    let colliders = rapier_ragdoll::Colliders {
        radii: lagrange_cases::RAGDOLL_CAPSULE_RADII,
        friction: PILE.friction,
        restitution: PILE.restitution,
    };
    let mut bodies = Vec::new();
    for s in scenes::throw(dolls) {
        let built = rapier_ragdoll::insert(&mut world, &s, &colliders, sleep)?;
        bodies.extend(built.bodies);
    }
    Ok(Rapier {
        world,
        bodies,
        group: RAGDOLL_LINKS,
    })
}
