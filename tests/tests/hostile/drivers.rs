//! Family `drivers`: `FixedTimestep` (frames of every length, resets, over a fixed-step and an
//! adaptive integrator), `Projected` and `ContactStepper`, each with drawn settings and
//! sequences of calls. After every error a driver's observable state must be as before.

use crate::checks::{state, verdict};
use crate::core::{Floor, Ground, Particle, Spring};
use crate::fixed_step::{cartesian, pendulum, rk4, setup, stormer, user_spring, yoshida, Made};
use crate::harness::{lit, ty, Ctx, Entry, Family, Verdict};
use crate::values::Kind;
use crate::{entries, say, tryv};
use lagrange_core::constraints::{Constraints, Holonomic};
use lagrange_core::{EulerLagrange, Lagrangian, Mechanism, Projection, Real, State};
use lagrange_integrators::StormerVerlet;
use lagrange_integrators::{
    ContactModel, ContactStepper, DormandPrince54, FixedTimestep, ImpulseSettings, ImpulseStepper,
    Integrator, Projected, SemiImplicitEuler,
};
use lagrange_systems::FallingParticle;

/// What a caller can see of a fixed-timestep loop.
fn observe<T: Real, const N: usize, I>(f: &FixedTimestep<T, N, I>) -> String {
    format!(
        "{:?} {:?} {:?} {:?} {:?}",
        f.current(),
        f.previous(),
        f.alpha(),
        f.interpolated(),
        f.dt()
    )
}

/// A frame time: ordinary (a fraction of a step to a few steps), huge, or nasty.
fn frame_time<T: Real>(ctx: &mut Ctx, dt: T) -> T {
    match ctx.pick(4) {
        0 => dt * ctx.value::<T>(Kind::Param),
        1 => dt,
        2 => ctx.value::<T>(Kind::Step),
        _ => ctx.value::<T>(Kind::Signed),
    }
}

/// Frames and resets of a fixed-timestep loop over the integrator `make` gives.
fn frames<T, M, I, const N: usize>(ctx: &mut Ctx, m: &M, make: fn(&mut Ctx) -> Made<I>) -> Verdict
where
    T: Real,
    M: Mechanism<T, N>,
    I: Integrator<T, N, M>,
{
    let (integrator, expr) = tryv!(make(ctx));
    let dt = ctx.value::<T>(Kind::Step);
    // The cap is kept small: a frame of T::MAX seconds takes the cap's steps.
    let cap = u32::try_from(ctx.count()).unwrap_or(u32::MAX).min(64);
    let start = state::<T, N>(ctx, "s0");
    say!(
        ctx,
        "let mut sim = FixedTimestep::new({expr}, {}, {cap}, s0)?;",
        lit(dt)
    );
    let r = FixedTimestep::new(integrator, dt, cap, start);
    let mut sim = match r {
        Ok(sim) => sim,
        Err(e) => return crate::checks::refused(e, &["dt", "max_steps_per_frame", "start"]),
    };
    for call in 0..=ctx.pick(6) {
        let before = observe(&sim);
        let v = if ctx.pick(5) == 0 {
            let s = state::<T, N>(ctx, "s");
            say!(ctx, "sim.reset(s)?;");
            verdict(&sim.reset(s), &["state"])
        } else {
            let f = frame_time(ctx, dt);
            say!(ctx, "sim.advance(&m, {})?;", lit(f));
            verdict(&sim.advance(m, f), &["frame_time"])
        };
        if v.class().is_finding() {
            return v;
        }
        // After a frame or a reset that succeeded, the state held is finite.
        if v == Verdict::Ok && !(sim.current().is_finite() && sim.previous().is_finite()) {
            return Verdict::Silent(observe(&sim));
        }
        if let Verdict::Error(e) = v {
            let after = observe(&sim);
            if after != before {
                return Verdict::Changed(format!(
                    "call {call} failed with {e:?}: {before} -> {after}"
                ));
            }
        }
    }
    Verdict::Ok
}

fn dopri<T: Real, const N: usize>(ctx: &mut Ctx) -> Made<DormandPrince54<T, N>> {
    let s = crate::adaptive::settings::<T>(ctx, false)?;
    Ok((
        DormandPrince54::new(s),
        format!("DormandPrince54::<{}, {N}>::new(settings)", ty::<T>()),
    ))
}

fn fixed_timestep<T: Real>(ctx: &mut Ctx) -> Verdict {
    match ctx.pick(5) {
        4 => {
            let m = tryv!(pendulum::<T>(ctx));
            frames(ctx, &m, yoshida::<T, 1>)
        }
        0 => {
            let m = tryv!(pendulum::<T>(ctx));
            frames(ctx, &m, rk4::<T, 1>)
        }
        1 => {
            let m: EulerLagrange<T, 1, Spring<T>> = user_spring::<T>(ctx);
            frames(ctx, &m, stormer::<T, 1>)
        }
        2 => {
            let m = tryv!(pendulum::<T>(ctx));
            frames(ctx, &m, dopri::<T, 1>)
        }
        _ => {
            let m = tryv!(cartesian::<T>(ctx));
            frames(ctx, &m, rk4::<T, 2>)
        }
    }
}

/// A projection drawn (its tolerance may be invalid).
fn projection<T: Real>(ctx: &mut Ctx) -> Result<Projection<T>, Verdict> {
    let tol = ctx.value::<T>(Kind::Tolerance);
    let n = u32::try_from(ctx.count()).unwrap_or(u32::MAX);
    say!(
        ctx,
        "let proj = Projection::<{}>::new({}, {n})?;",
        ty::<T>(),
        lit(tol)
    );
    setup(Projection::new(tol, n), &["tolerance", "max_iterations"])
}

fn projected<T: Real>(ctx: &mut Ctx) -> Verdict {
    let m = tryv!(cartesian::<T>(ctx));
    let p = tryv!(projection::<T>(ctx));
    say!(ctx, "let mut a = Projected::new(Rk4, proj);");
    let mut a = Projected::<T, 2, 1, _>::new(lagrange_integrators::Rk4, p);
    let s = if ctx.pick(2) == 0 {
        let [t, th, thd] = ctx.values::<T, 3>(Kind::State);
        say!(
            ctx,
            "let s = m.parts().state_from_angle({}, {}, {});",
            lit(t),
            lit(th),
            lit(thd)
        );
        m.parts().state_from_angle(t, th, thd)
    } else {
        state::<T, 2>(ctx, "s")
    };
    let _ = m.residual(&s);
    let dt = ctx.value::<T>(Kind::Step);
    if ctx.pick(2) == 0 {
        say!(ctx, "a.step(&m, &s, {})", lit(dt));
        verdict(&a.step(&m, &s, dt), &["dt", "state"])
    } else {
        let n = ctx.count().min(50);
        say!(ctx, "a.integrate(&m, &s, {}, {n})", lit(dt));
        verdict(
            &a.integrate(&m, &s, dt, n).map_err(|f| f.error),
            &["dt", "state", "steps"],
        )
    }
}

/// What a caller can see of a time-stepping contact stepper.
fn observe_impulses<T: Real, const N: usize, const C: usize, I, K>(
    c: &ImpulseStepper<T, N, C, I, K>,
) -> String {
    format!(
        "{:?} {:?} {:?}",
        c.last_report(),
        c.peak_report(),
        c.impulses()
    )
}

/// A ball on drawn ground (or held to it, bilateral) by an `ImpulseStepper` over
/// semi-implicit Euler, every parameter drawn (restitution, friction, slop, cap, tolerance,
/// `max_rows`): each setting refused by its name or accepted; after a step that succeeds the
/// promises hold: the ball at most the slop below the ground (drift corrected; the guard may
/// leave it deeper only where no kinetic energy pays for the lift, which a ball resting on
/// its own ground never needs beyond 1%), every impulse within the cone, the energy at most
/// the larger of the start's and the free step's plus the free step's own error, to 18
/// ulps of the terms; after a failure the stepper as it was.
fn impulse_stepper<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [mass, g] = ctx.values::<T, 2>(Kind::Param);
    say!(
        ctx,
        "let m = FallingParticle::<{}>::new({}, {})?;",
        ty::<T>(),
        lit(mass),
        lit(g)
    );
    let m = tryv!(setup(FallingParticle::new(mass, g), &["mass", "gravity"]));
    let h = ctx.value::<T>(Kind::Signed);
    let [e, rest, mu] = [
        ctx.value::<T>(Kind::Tolerance),
        ctx.value::<T>(Kind::Step),
        ctx.value::<T>(Kind::Param),
    ];
    say!(
        ctx,
        "let model = ContactModel::<{}>::new({}, {}, 1.0)?.with_friction({})?;",
        ty::<T>(),
        lit(e),
        lit(rest),
        lit(mu)
    );
    let model = tryv!(setup(
        ContactModel::new(e, rest, T::one()).and_then(|m| m.with_friction(mu)),
        &["restitution", "rest_speed", "friction"]
    ));
    let slop = ctx.value::<T>(Kind::Tolerance);
    let iterations = u32::try_from(ctx.count()).unwrap_or(u32::MAX);
    say!(
        ctx,
        "let settings = ImpulseSettings::<{}>::new({}, {iterations})?;",
        ty::<T>(),
        lit(slop)
    );
    let mut settings = tryv!(setup(
        ImpulseSettings::new(slop, iterations),
        &["slop", "max_iterations"]
    ));
    if ctx.pick(4) == 0 {
        let tolerance = ctx.value::<T>(Kind::Tolerance);
        say!(
            ctx,
            "let settings = settings.with_tolerance({})?;",
            lit(tolerance)
        );
        settings = tryv!(setup(settings.with_tolerance(tolerance), &["tolerance"]));
    }
    if ctx.pick(4) == 0 {
        let rows = u32::try_from(ctx.count()).unwrap_or(u32::MAX);
        say!(ctx, "let settings = settings.with_max_rows({rows})?;");
        settings = tryv!(setup(settings.with_max_rows(rows), &["max_rows"]));
    }
    let bilateral = ctx.pick(4) == 0;
    say!(ctx, "let mut c = ImpulseStepper::new(SemiImplicitEuler, Holonomic::new(Ground {{ h: {} }}), model, settings).with_bilateral([{bilateral}]);", lit(h));
    let rows = Holonomic::new(Ground { h });
    let mut c = ImpulseStepper::<T, 1, 1, _, _>::new(SemiImplicitEuler, rows, model, settings)
        .with_bilateral([bilateral]);
    let start = state::<T, 1>(ctx, "s0");
    let mut last: Option<State<T, 1>> = None;
    for call in 0..=ctx.pick(5) {
        let from = match (ctx.pick(3), last) {
            (0, Some(l)) => {
                say!(ctx, "let s = last;");
                l
            }
            (1, _) => {
                say!(ctx, "let s = s0;");
                start
            }
            _ => state::<T, 1>(ctx, "s"),
        };
        let dt = ctx.value::<T>(Kind::Step);
        let before = observe_impulses(&c);
        say!(ctx, "let last = c.step(&m, &s, {})?;", lit(dt));
        let r = c.step(&m, &from, dt);
        let v = verdict(&r, &["dt", "state", "max_rows"]);
        if v.class().is_finding() {
            return v;
        }
        match r {
            Ok(next) => {
                if let Some(broken) =
                    impulse_promises(&c, &m, &rows, &from, &next, dt, mu, slop, bilateral)
                {
                    return Verdict::Broken(format!("call {call}: {broken}"));
                }
                last = Some(next);
            }
            Err(e) => {
                let after = observe_impulses(&c);
                if after != before {
                    return Verdict::Changed(format!(
                        "call {call} failed with {e:?}: {before} -> {after}"
                    ));
                }
            }
        }
    }
    Verdict::Ok
}

/// What an `ImpulseStepper`'s step from `from` to `next` broke of its promises (see
/// [`impulse_stepper`]), if anything. Only for a start the ground's row can hold: a start
/// deeper than the slop is the caller's (lifting it out adds energy the step has none of).
#[allow(clippy::too_many_arguments)]
fn impulse_promises<T: Real>(
    c: &ImpulseStepper<T, 1, 1, SemiImplicitEuler, Holonomic<Ground<T>>>,
    m: &FallingParticle<T>,
    rows: &Holonomic<Ground<T>>,
    from: &State<T, 1>,
    next: &State<T, 1>,
    dt: T,
    mu: T,
    slop: T,
    bilateral: bool,
) -> Option<String> {
    let (normal, tangent) = c.impulses();
    if !(tangent[0].abs() <= mu * normal[0] || tangent[0] == T::zero()) {
        return Some(format!(
            "friction {:?} outside the cone of {:?}",
            tangent[0], normal[0]
        ));
    }
    let g0 = rows.position_residual(&from.q)[0];
    let free = SemiImplicitEuler.step(m, from, dt).ok()?;
    let (e0, ef, e1) = (
        m.energy(from).to_f64(),
        m.energy(&free).to_f64(),
        m.energy(next).to_f64(),
    );
    let sizes = e0.abs() + ef.abs() + e1.abs() + 2.0 * m.potential_energy(next).to_f64().abs();
    let allowed = e0.max(ef) + (ef - e0).abs() + 18.0 * T::EPSILON.to_f64() * sizes;
    let finite = [e0, ef, e1, sizes]
        .iter()
        .all(|x| x.is_finite() && x.abs() < 1e30);
    if finite && e1 > allowed {
        return Some(format!("energy {e0:e} -> {e1:e} (free step {ef:e})"));
    }
    let g1 = rows.position_residual(&next.q)[0].to_f64();
    let depth = -g1;
    let held = !bilateral && g0.to_f64() >= -slop.to_f64() && finite;
    // The stepper's drift correction is done again on the gap it left, to the rounding of a
    // gap of the end's size (64 ulps); 1% more for the energy guard.
    let rounding = 64.0 * T::EPSILON.to_f64() * (1.0 + next.q[0].to_f64().abs());
    if held && depth > 1.01 * slop.to_f64() + rounding {
        return Some(format!("ended {depth:e} below the ground, slop {:?}", slop));
    }
    None
}

/// What a caller can see of a contact stepper.
fn observe_contacts<T: Real, const N: usize, const C: usize, I, K>(
    c: &ContactStepper<T, N, C, I, K>,
) -> String {
    format!("{:?} {:?}", c.resting(), c.impacts())
}

fn contact_stepper<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [mass, g] = ctx.values::<T, 2>(Kind::Param);
    say!(
        ctx,
        "let m = FallingParticle::<{}>::new({}, {})?;",
        ty::<T>(),
        lit(mass),
        lit(g)
    );
    let m = tryv!(setup(FallingParticle::new(mass, g), &["mass", "gravity"]));
    let h = ctx.value::<T>(Kind::Signed);
    let [e, rest, tol] = [
        ctx.value::<T>(Kind::Tolerance),
        ctx.value::<T>(Kind::Step),
        ctx.value::<T>(Kind::Tolerance),
    ];
    say!(
        ctx,
        "let model = ContactModel::<{}>::new({}, {}, {})?;",
        ty::<T>(),
        lit(e),
        lit(rest),
        lit(tol)
    );
    let model = tryv!(setup(
        ContactModel::new(e, rest, tol),
        &["restitution", "rest_speed", "time_tolerance"]
    ));
    let p = tryv!(projection::<T>(ctx));
    let bilateral = ctx.pick(4) == 0;
    say!(ctx, "let mut c = ContactStepper::new(Rk4, Holonomic::new(Ground {{ h: {} }}), model, proj).with_bilateral([{bilateral}]);", lit(h));
    let mut c = ContactStepper::<T, 1, 1, _, _>::new(
        lagrange_integrators::Rk4,
        Holonomic::new(Ground { h }),
        model,
        p,
    )
    .with_bilateral([bilateral]);
    let start = state::<T, 1>(ctx, "s0");
    let mut last: Option<State<T, 1>> = None;
    for call in 0..=ctx.pick(5) {
        let from = match (ctx.pick(3), last) {
            (0, Some(l)) => {
                say!(ctx, "let s = last;");
                l
            }
            (1, _) => {
                say!(ctx, "let s = s0;");
                start
            }
            _ => state::<T, 1>(ctx, "s"),
        };
        let dt = ctx.value::<T>(Kind::Step);
        let before = observe_contacts(&c);
        let (v, out) = if ctx.pick(2) == 0 {
            say!(ctx, "let last = c.step(&m, &s, {})?;", lit(dt));
            let r = c.step(&m, &from, dt);
            (verdict(&r, &["dt", "state"]), r.ok())
        } else {
            let n = ctx.count().min(50);
            say!(ctx, "let last = c.integrate(&m, &s, {}, {n})?;", lit(dt));
            let r = c.integrate(&m, &from, dt, n).map_err(|f| f.error);
            (verdict(&r, &["dt", "state", "steps"]), r.ok())
        };
        if v.class().is_finding() {
            return v;
        }
        if let Verdict::Error(e) = v {
            let after = observe_contacts(&c);
            if after != before {
                return Verdict::Changed(format!(
                    "call {call} failed with {e:?}: {before} -> {after}"
                ));
            }
        }
        if let Some(o) = out {
            last = Some(o);
        }
    }
    Verdict::Ok
}

/// A user's point in the plane (unvalidated mass and gravity) on a floor with friction, under
/// a contact stepper over a symmetric method, and that stepper driven by a fixed-timestep
/// loop.
fn friction_stepper<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [m, g] = ctx.values::<T, 2>(Kind::Signed);
    let floor = ctx.value::<T>(Kind::Signed);
    say!(
        ctx,
        "let m = EulerLagrange::new(Particle::<{}> {{ m: {}, g: {} }});",
        ty::<T>(),
        lit(m),
        lit(g)
    );
    let mech = EulerLagrange::new(Particle { m, g });
    let [e, rest, tol] = [
        ctx.value::<T>(Kind::Tolerance),
        ctx.value::<T>(Kind::Step),
        ctx.value::<T>(Kind::Tolerance),
    ];
    let mu = ctx.value::<T>(Kind::Param);
    say!(
        ctx,
        "let model = ContactModel::<{}>::new({}, {}, {})?.with_friction({})?;",
        ty::<T>(),
        lit(e),
        lit(rest),
        lit(tol),
        lit(mu)
    );
    let model = tryv!(setup(
        ContactModel::new(e, rest, tol),
        &["restitution", "rest_speed", "time_tolerance"]
    ));
    let model = tryv!(setup(model.with_friction(mu), &["friction"]));
    let p = tryv!(projection::<T>(ctx));
    say!(ctx, "let c = ContactStepper::new(StormerVerlet::default(), Floor {{ floor: {} }}, model, proj);", lit(floor));
    let c = ContactStepper::<T, 2, 1, _, _>::new(
        StormerVerlet::<T, 2>::default(),
        Floor { floor },
        model,
        p,
    );
    let dt = ctx.value::<T>(Kind::Step);
    let cap = u32::try_from(ctx.count()).unwrap_or(u32::MAX).min(16);
    let start = state::<T, 2>(ctx, "s0");
    say!(
        ctx,
        "let mut sim = FixedTimestep::new(c, {}, {cap}, s0)?;",
        lit(dt)
    );
    let mut sim = match FixedTimestep::new(c, dt, cap, start) {
        Ok(sim) => sim,
        Err(e) => return crate::checks::refused(e, &["dt", "max_steps_per_frame", "start"]),
    };
    for call in 0..=ctx.pick(4) {
        let before = observe(&sim);
        let f = frame_time(ctx, dt);
        say!(ctx, "sim.advance(&m, {})?;", lit(f));
        let v = verdict(&sim.advance(&mech, f), &["frame_time"]);
        if v.class().is_finding() {
            return v;
        }
        if v == Verdict::Ok && !sim.current().is_finite() {
            return Verdict::Silent(observe(&sim));
        }
        if let Verdict::Error(e) = v {
            let after = observe(&sim);
            if after != before {
                return Verdict::Changed(format!(
                    "call {call} failed with {e:?}: {before} -> {after}"
                ));
            }
        }
    }
    Verdict::Ok
}

/// The family.
pub fn family() -> Family {
    let mut v: Vec<Entry> = Vec::new();
    entries!(v, 1.0, "FixedTimestep::new/advance/reset", fixed_timestep);
    entries!(v, 0.6, "Projected<Rk4>", projected);
    entries!(v, 0.8, "ContactStepper<Rk4>", contact_stepper);
    entries!(v, 0.8, "ImpulseStepper<SemiImplicitEuler>", impulse_stepper);
    entries!(
        v,
        0.6,
        "FixedTimestep<ContactStepper<StormerVerlet>> with friction",
        friction_stepper
    );
    Family {
        name: "drivers",
        entries: v,
    }
}
