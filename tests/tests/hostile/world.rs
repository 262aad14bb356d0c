//! Family `world`: `lagrange_world::World` of rigid bodies, with drawn settings (contact
//! model, slop, sweeps, margin, sleep), bodies (rectangles and disks of drawn sizes at drawn
//! states, some keys taken twice), shapes (circles, capsules, boxes, polygons, offset by drawn
//! amounts; keys drawn from a small range so that some clash; on bodies that may not exist,
//! on links that do not), static shapes and half-planes, collision filters, and a drawn
//! sequence of steps (drawn `dt`), state writes, wakes, ray casts and point queries.
//!
//! After every call: no panic or hang; no `Ok` leaving a body's state, a report count or a
//! query's answer non-finite or out of range; errors name the call's own parameter; a step
//! that fails leaves every body's state as it was.

use crate::checks::{refused, state, verdict};
use crate::harness::{lit, lits, ty, Ctx, Entry, Family, Verdict};
use crate::values::Kind;
use crate::{entries, say};
use lagrange_core::constraints::contact::ContactModel;
use lagrange_core::links::Links;
use lagrange_core::{Mechanism, Real, State};
use lagrange_systems::{
    Ragdoll, RagdollBody, RigidBody, ADULT_JOINT_LIMITS, RAGDOLL_COORDINATES, RAGDOLL_LINKS,
};
use lagrange_world::{CoordinateLimits, HalfPlane, Limits, NoLimits, Shape, World, WorldSettings};

/// Drawn settings, or the verdict of the error that refused them.
fn settings<T: Real>(ctx: &mut Ctx) -> Result<WorldSettings<T>, Verdict> {
    // Ordinary values mostly (a world that steps), drawn ones now and then.
    let ordinary = |ctx: &mut Ctx, lo: f64, hi: f64| -> T {
        if ctx.pick(4) == 0 {
            ctx.value::<T>(Kind::Param)
        } else {
            ctx.uniform::<T>(lo, hi)
        }
    };
    let (e, rest, tol) = (
        ordinary(ctx, 0.0, 1.0),
        ordinary(ctx, 0.0, 1.0),
        ordinary(ctx, 1e-6, 1.0),
    );
    let friction = ordinary(ctx, 0.0, 1.0);
    let slop = ordinary(ctx, 1e-4, 1e-2);
    let sweeps = u32::try_from(ctx.count()).unwrap_or(u32::MAX).min(64);
    say!(
        ctx,
        "let model = ContactModel::<{}>::new({}, {}, {})?.with_friction({})?;",
        ty::<T>(),
        lit(e),
        lit(rest),
        lit(tol),
        lit(friction)
    );
    let model = ContactModel::new(e, rest, tol)
        .and_then(|m| m.with_friction(friction))
        .map_err(|err| {
            refused(
                err,
                &["restitution", "rest_speed", "time_tolerance", "friction"],
            )
        })?;
    say!(
        ctx,
        "let settings = WorldSettings::new(model, {}, {sweeps})?;",
        lit(slop)
    );
    let mut s =
        WorldSettings::new(model, slop, sweeps).map_err(|err| refused(err, &["slop", "sweeps"]))?;
    if ctx.pick(3) == 0 {
        let margin = ctx.value::<T>(Kind::Param);
        say!(
            ctx,
            "let settings = settings.with_margin({})?;",
            lit(margin)
        );
        s = s
            .with_margin(margin)
            .map_err(|err| refused(err, &["margin"]))?;
    }
    if ctx.pick(2) == 0 {
        let (speed, time) = (ctx.value::<T>(Kind::Param), ctx.value::<T>(Kind::Time));
        say!(
            ctx,
            "let settings = settings.with_sleep({}, {})?;",
            lit(speed),
            lit(time)
        );
        s = s
            .with_sleep(speed, time)
            .map_err(|err| refused(err, &["speed", "time"]))?;
    }
    Ok(s)
}

/// A drawn shape, or the verdict of the error that refused it.
fn shape<T: Real>(ctx: &mut Ctx) -> Result<Shape<T>, Verdict> {
    let [a, b] = ctx.values::<T, 2>(Kind::Param);
    let (made, params): (Result<Shape<T>, _>, &[&str]) = match ctx.pick(4) {
        0 => {
            say!(ctx, "let shape = Shape::circle({})?;", lit(a));
            (Shape::circle(a), &["radius"])
        }
        1 => {
            say!(ctx, "let shape = Shape::capsule({}, {})?;", lit(a), lit(b));
            (Shape::capsule(a, b), &["half_length", "radius"])
        }
        2 => {
            say!(
                ctx,
                "let shape = Shape::rectangle({}, {})?;",
                lit(a),
                lit(b)
            );
            (Shape::rectangle(a, b), &["width", "height"])
        }
        _ => {
            let v = ctx.values::<T, 6>(Kind::State);
            say!(ctx, "let shape = Shape::polygon(&{})?;", lits(&v));
            (
                Shape::polygon(&[[v[0], v[1]], [v[2], v[3]], [v[4], v[5]]]),
                &["vertices"],
            )
        }
    };
    let s = made.map_err(|e| refused(e, params))?;
    if ctx.pick(3) == 0 {
        let [x, y, angle] = ctx.values::<T, 3>(Kind::State);
        say!(
            ctx,
            "let shape = shape.offset([{}, {}], {});",
            lit(x),
            lit(y),
            lit(angle)
        );
        return Ok(s.offset([x, y], angle));
    }
    Ok(s)
}

/// A world of `M` with `N` coordinates and own rows `L`, up to 4 bodies, 6 shapes and 24
/// contact points.
type Drawn<T, M, L, const N: usize> = World<T, M, N, 4, 6, 24, L>;

/// Every body's state, by key `0..8` (those that exist).
fn states<T: Real, M, L, const N: usize>(w: &Drawn<T, M, L, N>) -> Vec<Option<State<T, N>>>
where
    M: Mechanism<T, N> + Links<T, N> + Clone,
    L: Limits<T, N>,
{
    (0..8).map(|k| w.state(k)).collect()
}

/// A world of rigid bodies built from drawn parts, then a drawn sequence of calls.
fn rigid_bodies<T: Real>(ctx: &mut Ctx) -> Verdict {
    drawn_world::<T, RigidBody<T>, NoLimits, 3>(ctx, "RigidBody", 1, rigid_body)
}

/// A world of ragdolls (the adult, with drawn joint limits now and then) built from drawn
/// parts, then a drawn sequence of calls: the world's paths for a mechanism of many links
/// (their poses from one call, contact mobilities batched per body) and for own rows.
fn ragdolls<T: Real>(ctx: &mut Ctx) -> Verdict {
    drawn_world::<T, Ragdoll<T>, CoordinateLimits<9>, RAGDOLL_COORDINATES>(
        ctx,
        "Ragdoll",
        RAGDOLL_LINKS,
        ragdoll,
    )
}

/// A drawn rigid body added as `key`: the verdict.
fn rigid_body<T: Real>(
    ctx: &mut Ctx,
    w: &mut Drawn<T, RigidBody<T>, NoLimits, 3>,
    key: u32,
) -> Verdict {
    let [m, a, b] = ctx.values::<T, 3>(Kind::Param);
    let g = ctx.value::<T>(Kind::Param);
    let (body, params): (Result<RigidBody<T>, _>, &[&str]) = if ctx.pick(2) == 0 {
        say!(
            ctx,
            "let body = RigidBody::rectangle({}, {}, {}, {})?;",
            lit(m),
            lit(a),
            lit(b),
            lit(g)
        );
        (
            RigidBody::rectangle(m, a, b, g),
            &["mass", "width", "height", "gravity"],
        )
    } else {
        say!(
            ctx,
            "let body = RigidBody::disk({}, {}, {})?;",
            lit(m),
            lit(a),
            lit(g)
        );
        (RigidBody::disk(m, a, g), &["mass", "radius", "gravity"])
    };
    let body = match body {
        Ok(b) => b,
        Err(e) => return refused(e, params),
    };
    let s = state::<T, 3>(ctx, "s");
    say!(ctx, "w.add_body({key}, body, s)?;");
    verdict(&w.add_body(key, body, s), &["key", "capacity"])
}

/// The adult ragdoll added as `key`, its joint limits the adult's or (now and then) drawn,
/// its origin drawn: the verdict.
fn ragdoll<T: Real>(
    ctx: &mut Ctx,
    w: &mut Drawn<T, Ragdoll<T>, CoordinateLimits<9>, RAGDOLL_COORDINATES>,
    key: u32,
) -> Verdict {
    let doll = match Ragdoll::new(RagdollBody::<T>::adult()) {
        Ok(d) => d,
        Err(e) => return refused(e, &[]),
    };
    say!(
        ctx,
        "let doll = Ragdoll::new(RagdollBody::<{}>::adult())?;",
        ty::<T>()
    );
    let bounds = if ctx.pick(3) == 0 {
        let drawn = ctx.values::<f64, 18>(Kind::State);
        core::array::from_fn(|k| [drawn[2 * k], drawn[2 * k + 1]])
    } else {
        ADULT_JOINT_LIMITS
    };
    say!(
        ctx,
        "let limits = CoordinateLimits::new(core::array::from_fn(|j| j + 3), {bounds:?})?;"
    );
    let limits = match CoordinateLimits::new(core::array::from_fn(|j| j + 3), bounds) {
        Ok(l) => l,
        Err(e) => return refused(e, &["bounds"]),
    };
    let s = state::<T, RAGDOLL_COORDINATES>(ctx, "s");
    let origin = ctx.values::<T, 2>(Kind::State);
    say!(
        ctx,
        "w.add_body_with({key}, doll, limits, s, {})?;",
        lits(&origin)
    );
    verdict(
        &w.add_body_with(key, doll, limits, s, origin),
        &["key", "capacity", "origin"],
    )
}

/// A world of `M` (named `name`, of `links` links) built from drawn parts, its bodies drawn
/// and added by `add`, then a drawn sequence of calls.
fn drawn_world<T, M, L, const N: usize>(
    ctx: &mut Ctx,
    name: &str,
    links: usize,
    add: fn(&mut Ctx, &mut Drawn<T, M, L, N>, u32) -> Verdict,
) -> Verdict
where
    T: Real,
    M: Mechanism<T, N> + Links<T, N> + Clone,
    L: Limits<T, N>,
{
    let settings = match settings::<T>(ctx) {
        Ok(s) => s,
        Err(v) => return v,
    };
    let mut w = Box::new(Drawn::<T, M, L, N>::new(settings));
    say!(
        ctx,
        "let mut w = World::<{}, {name}<{}>, {N}, 4, 6, 24, _>::new(settings);",
        ty::<T>(),
        ty::<T>()
    );
    for _ in 0..=ctx.pick(5) {
        let key = ctx.pick(8) as u32;
        let v = add(ctx, &mut w, key);
        if v.class().is_finding() {
            return v;
        }
    }
    for _ in 0..=ctx.pick(7) {
        let key = ctx.pick(12) as u32;
        let r = match ctx.pick(4) {
            0 => {
                let [nx, ny, offset] = ctx.values::<T, 3>(Kind::State);
                say!(
                    ctx,
                    "w.add_plane({key}, HalfPlane::new([{}, {}], {})?)?;",
                    lit(nx),
                    lit(ny),
                    lit(offset)
                );
                match HalfPlane::new([nx, ny], offset) {
                    Ok(p) => w.add_plane(key, p),
                    Err(e) => Err(e),
                }
            }
            1 => {
                let s = match shape::<T>(ctx) {
                    Ok(s) => s,
                    Err(v) if v.class().is_finding() => return v,
                    Err(_) => continue,
                };
                say!(ctx, "w.add_static({key}, shape)?;");
                w.add_static(key, s)
            }
            _ => {
                let s = match shape::<T>(ctx) {
                    Ok(s) => s,
                    Err(v) if v.class().is_finding() => return v,
                    Err(_) => continue,
                };
                // A link of the mechanism's, or one past them now and then.
                let body = ctx.pick(8) as u32;
                let link = if ctx.pick(3) == 0 {
                    links + ctx.pick(2)
                } else {
                    ctx.pick(links)
                };
                say!(ctx, "w.add_shape({key}, {body}, {link}, shape)?;");
                w.add_shape(key, body, link, s)
            }
        };
        let v = verdict(
            &r,
            &[
                "key", "capacity", "body", "link", "shape", "normal", "offset",
            ],
        );
        if v.class().is_finding() {
            return v;
        }
    }
    for call in 0..=ctx.pick(12) {
        let before = states(&w);
        let v = match ctx.pick(8) {
            0 => {
                let (shape, group, mask) =
                    (ctx.pick(12) as u32, ctx.pick(4) as u32, ctx.pick(4) as u32);
                say!(ctx, "w.set_filter({shape}, {group}, {mask})?;");
                verdict(&w.set_filter(shape, group, mask), &["shape"])
            }
            1 => {
                let key = ctx.pick(8) as u32;
                let s = state::<T, N>(ctx, "s");
                say!(ctx, "w.set_state({key}, s)?;");
                verdict(&w.set_state(key, s), &["body"])
            }
            2 => {
                let key = ctx.pick(8) as u32;
                say!(ctx, "w.wake({key})?;");
                verdict(&w.wake(key), &["body"])
            }
            3 => {
                let [ox, oy, dx, dy] = ctx.values::<T, 4>(Kind::State);
                let t_max = ctx.value::<T>(Kind::Param);
                say!(
                    ctx,
                    "w.ray([{}, {}], [{}, {}], {});",
                    lit(ox),
                    lit(oy),
                    lit(dx),
                    lit(dy),
                    lit(t_max)
                );
                match w.ray([ox, oy], [dx, dy], t_max) {
                    Some(h)
                        if !(h.hit.t.is_finite() && h.hit.t >= T::zero() && h.hit.t <= t_max) =>
                    {
                        Verdict::Silent(format!("call {call}: {h:?}"))
                    }
                    _ => Verdict::Ok,
                }
            }
            4 => {
                let [x, y] = ctx.values::<T, 2>(Kind::State);
                say!(ctx, "w.shape_at([{}, {}]);", lit(x), lit(y));
                let _ = w.shape_at([x, y]);
                Verdict::Ok
            }
            _ => {
                let dt = ctx.value::<T>(Kind::Step);
                say!(ctx, "w.step({})?;", lit(dt));
                let bodies = u32::try_from(before.iter().flatten().count()).unwrap_or(u32::MAX);
                match w.step(dt) {
                    Ok(r) => {
                        let bad = states(&w)
                            .iter()
                            .flatten()
                            .find(|s| s.check_finite().is_err())
                            .copied();
                        if let Some(s) = bad {
                            Verdict::Silent(format!("call {call}: {s:?}"))
                        } else if r.contacts > 24 || r.awake > bodies || r.asleep > bodies {
                            Verdict::Inconsistent(format!("call {call}: {r:?}"))
                        } else {
                            Verdict::Ok
                        }
                    }
                    Err(e) => {
                        if states(&w) != before {
                            return Verdict::Changed(format!(
                                "call {call}: step({dt:?}) failed with {e:?} and moved a body"
                            ));
                        }
                        refused(e, &["dt", "capacity"])
                    }
                }
            }
        };
        if v.class().is_finding() {
            return v;
        }
    }
    Verdict::Ok
}

/// The family.
pub fn family() -> Family {
    let mut v: Vec<Entry> = Vec::new();
    entries!(
        v,
        1.0,
        "World<RigidBody>: settings, bodies, shapes, planes, steps, queries",
        rigid_bodies
    );
    entries!(
        v,
        0.5,
        "World<Ragdoll> with joint limits: settings, bodies, shapes, planes, steps, queries",
        ragdolls
    );
    Family {
        name: "world",
        entries: v,
    }
}
