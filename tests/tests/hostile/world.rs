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
use lagrange_core::{Real, State};
use lagrange_systems::RigidBody;
use lagrange_world::{HalfPlane, Shape, World, WorldSettings};

/// Up to 4 bodies, 6 shapes, 24 contact points: full now and then.
type Bodies<T> = World<T, RigidBody<T>, 3, 4, 6, 24>;

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

/// Every body's state, by key `0..8` (those that exist).
fn states<T: Real>(w: &Bodies<T>) -> Vec<Option<State<T, 3>>> {
    (0..8).map(|k| w.state(k)).collect()
}

/// A world built from drawn parts, then a drawn sequence of calls.
fn rigid_bodies<T: Real>(ctx: &mut Ctx) -> Verdict {
    let settings = match settings::<T>(ctx) {
        Ok(s) => s,
        Err(v) => return v,
    };
    let mut w = Box::new(Bodies::<T>::new(settings));
    say!(
        ctx,
        "let mut w = World::<{}, RigidBody<{}>, 3, 4, 6, 24>::new(settings);",
        ty::<T>(),
        ty::<T>()
    );
    for _ in 0..=ctx.pick(5) {
        let key = ctx.pick(8) as u32;
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
            Err(e) => {
                let v = refused(e, params);
                if v.class().is_finding() {
                    return v;
                }
                continue;
            }
        };
        let s = state::<T, 3>(ctx, "s");
        say!(ctx, "w.add_body({key}, body, s)?;");
        let v = verdict(&w.add_body(key, body, s), &["key", "capacity"]);
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
                let (body, link) = (ctx.pick(8) as u32, ctx.pick(3) / 2);
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
                let s = state::<T, 3>(ctx, "s");
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
    Family {
        name: "world",
        entries: v,
    }
}
