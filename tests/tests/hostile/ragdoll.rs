//! Family `ragdoll`: the planar [`Ragdoll`] (issue 18) with drawn bodies (each field of
//! [`RagdollBody`] left at the adult's value or drawn; an error must name a field the call
//! drew, by its path `torso.mass`), its `Result` methods and those without an error channel at
//! drawn states, [`RagdollContacts`] (a drawn floor and drawn joint limits; an error must name
//! the joint, `limits[3]`) with its rows and tangents, and a `ContactStepper` over `Rk4` or
//! `StormerVerlet` stepping it with drawn models, steps and states. After every error the
//! stepper's observable state must be as before.

use crate::checks::{refused, state, verdict};
use crate::fixed_step::setup;
use crate::harness::{lit, lits, ty, Ctx, Entry, Family, Verdict};
use crate::systems::exercise;
use crate::values::Kind;
use crate::{entries, say, tryv};
use lagrange_core::constraints::contact::Contacts;
use lagrange_core::{Constraints, Error, Lagrangian, Projection, Real, State};
use lagrange_integrators::{
    ActiveRows, ContactModel, ContactStepper, ImpulseSettings, ImpulseStepper, Integrator, Rk4,
    SemiImplicitEuler, StormerVerlet, VelocityVerlet,
};
use lagrange_systems::{
    Ragdoll, RagdollBody, RagdollContacts, ADULT_JOINT_LIMITS, RAGDOLL_CONTACTS,
    RAGDOLL_COORDINATES as N,
};

/// The fields of a [`RagdollBody`], by the path a caller writes.
pub const FIELDS: [&str; 16] = [
    "torso.mass",
    "torso.length",
    "head.mass",
    "head.length",
    "upper_arm.mass",
    "upper_arm.length",
    "forearm.mass",
    "forearm.length",
    "thigh.mass",
    "thigh.length",
    "shin.mass",
    "shin.length",
    "shoulder_width",
    "hip_width",
    "gravity",
    "joint_damping",
];

/// Field `i` of `b` (in the order of [`FIELDS`]).
fn field<T>(b: &mut RagdollBody<T>, i: usize) -> &mut T {
    match i {
        0 => &mut b.torso.mass,
        1 => &mut b.torso.length,
        2 => &mut b.head.mass,
        3 => &mut b.head.length,
        4 => &mut b.upper_arm.mass,
        5 => &mut b.upper_arm.length,
        6 => &mut b.forearm.mass,
        7 => &mut b.forearm.length,
        8 => &mut b.thigh.mass,
        9 => &mut b.thigh.length,
        10 => &mut b.shin.mass,
        11 => &mut b.shin.length,
        12 => &mut b.shoulder_width,
        13 => &mut b.hip_width,
        14 => &mut b.gravity,
        _ => &mut b.joint_damping,
    }
}

/// A body: the adult's, some fields drawn (a masses' or lengths' scale drawn for every
/// segment at once now and then); the fields drawn are the names an error may give.
pub fn body<T: Real>(ctx: &mut Ctx) -> (RagdollBody<T>, Vec<&'static str>) {
    let mut b = RagdollBody::<T>::adult();
    let mut drawn = Vec::new();
    say!(ctx, "let mut b = RagdollBody::<{}>::adult();", ty::<T>());
    if ctx.pick(6) == 0 {
        // Every mass, or every length, scaled by one drawn factor.
        let which = ctx.pick(2);
        let k = ctx.value::<T>(Kind::Param);
        for i in (which..12).step_by(2) {
            let x = field(&mut b, i);
            *x *= k;
            say!(ctx, "b.{} = {};", FIELDS[i], lit(*x));
            drawn.push(FIELDS[i]);
        }
    }
    for (i, name) in FIELDS.iter().enumerate() {
        if ctx.pick(5) == 0 {
            let v = if i >= 12 && ctx.pick(3) == 0 {
                ctx.value::<T>(Kind::Signed)
            } else {
                ctx.value::<T>(Kind::Param)
            };
            *field(&mut b, i) = v;
            say!(ctx, "b.{name} = {};", lit(v));
            drawn.push(name);
        }
    }
    (b, drawn)
}

/// The verdict of a refused body: the error names one of the fields drawn, by its path.
fn refused_body(e: Error, drawn: &[&str]) -> Verdict {
    match e {
        Error::InvalidParameter { name, .. } if !drawn.contains(&name) => Verdict::WrongName(
            format!("{e:?}, the fields the call set are {drawn:?} (a body's field by its path)"),
        ),
        _ => Verdict::Error(e),
    }
}

/// A ragdoll of a drawn body.
fn doll<T: Real>(ctx: &mut Ctx) -> Result<Ragdoll<T>, Verdict> {
    let (b, drawn) = body::<T>(ctx);
    say!(ctx, "let m = Ragdoll::new(b)?;");
    Ragdoll::new(b).map_err(|e| refused_body(e, &drawn))
}

/// A state: wholly drawn, or a body upright at 1.5 m with some coordinates drawn.
fn doll_state<T: Real>(ctx: &mut Ctx, var: &str) -> State<T, N> {
    if ctx.pick(3) == 0 {
        return state::<T, N>(ctx, var);
    }
    let mut q = [T::zero(); N];
    q[1] = T::from_f64(1.5);
    let mut qd = [T::zero(); N];
    for i in 0..2 * N {
        if ctx.pick(6) == 0 {
            let v = ctx.value::<T>(Kind::State);
            if i < N {
                q[i] = v;
            } else {
                qd[i - N] = v;
            }
        }
    }
    say!(
        ctx,
        "let {var} = State::<{}, {N}>::new(0.0, {}, {});",
        ty::<T>(),
        lits(&q),
        lits(&qd)
    );
    State::new(T::zero(), q, qd)
}

fn ragdoll<T: Real>(ctx: &mut Ctx) -> Verdict {
    let m = tryv!(doll::<T>(ctx));
    match ctx.pick(4) {
        0 => {
            let s = doll_state::<T>(ctx, "s");
            say!(ctx, "m.segments(&s.q); m.total_mass()");
            let _ = m.segments(&s.q);
            let total = m.total_mass();
            if total.is_finite() {
                Verdict::Ok
            } else {
                Verdict::Silent(format!("total_mass() = {total:?} of an accepted body"))
            }
        }
        _ => exercise::<T, Ragdoll<T>, N>(ctx, &m),
    }
}

/// Contacts of a drawn floor and limits (the adult's, some bounds drawn); the limits an error
/// may name, each as `limits[j]`.
fn contacts<T: Real>(ctx: &mut Ctx, m: &Ragdoll<T>) -> Result<RagdollContacts<T>, Verdict> {
    let floor = if ctx.pick(2) == 0 {
        T::zero()
    } else {
        ctx.value::<T>(Kind::Signed)
    };
    let mut limits = ADULT_JOINT_LIMITS.map(|l| l.map(T::from_f64));
    let mut drawn: Vec<String> = vec!["floor".into()];
    say!(
        ctx,
        "let mut limits = ADULT_JOINT_LIMITS.map(|l| l.map({}::from));",
        ty::<T>()
    );
    for (j, bounds) in limits.iter_mut().enumerate() {
        for (k, x) in bounds.iter_mut().enumerate() {
            if ctx.pick(24) == 0 {
                *x = ctx.value::<T>(Kind::Signed);
                say!(ctx, "limits[{j}][{k}] = {};", lit(*x));
                drawn.push(format!("limits[{j}]"));
            }
        }
    }
    say!(
        ctx,
        "let c = RagdollContacts::new(&m, {}, limits)?;",
        lit(floor)
    );
    RagdollContacts::new(m, floor, limits).map_err(|e| match e {
        Error::InvalidParameter { name, .. } if !drawn.iter().any(|d| d == name) => {
            Verdict::WrongName(format!(
                "{e:?}, the call set {drawn:?} (a limit by its joint, limits[j])"
            ))
        }
        _ => Verdict::Error(e),
    })
}

fn ragdoll_contacts<T: Real>(ctx: &mut Ctx) -> Verdict {
    let m = tryv!(doll::<T>(ctx));
    let c = tryv!(contacts::<T>(ctx, &m));
    let s = doll_state::<T>(ctx, "s");
    // No error channel: documented to return NaN or infinity for extreme input, never to
    // panic.
    say!(ctx, "c.position_residual(&s.q); c.jacobian(&s.q); c.velocity_product(&s.q, &s.qd); c.tangent_jacobian(&s.q); c.floor_points(&s.q)");
    let _ = c.position_residual(&s.q);
    let _ = c.jacobian(&s.q);
    let _ = c.velocity_product(&s.q, &s.qd);
    let _ = c.tangent_jacobian(&s.q);
    let _ = c.floor_points(&s.q);
    let _ = (c.floor(), c.limits());
    Verdict::Ok
}

/// What a caller can see of a contact stepper.
fn observe<T: Real, const C: usize, I, K>(c: &ContactStepper<T, N, C, I, K>) -> String {
    format!("{:?} {:?}", c.resting(), c.impacts())
}

/// Steps and runs of a contact stepper over `method` from drawn states.
fn drive<T, I>(ctx: &mut Ctx, m: &Ragdoll<T>, method: I, name: &str) -> Verdict
where
    T: Real,
    I: Clone,
    ContactStepper<T, N, RAGDOLL_CONTACTS, I, RagdollContacts<T>>: Integrator<T, N, Ragdoll<T>>,
{
    let c = tryv!(contacts::<T>(ctx, m));
    // Half the time the test's own model (so that the steps get past the setup).
    let [e, rest, tol] = if ctx.pick(2) == 0 {
        [0.3, 0.3, 1e-6].map(T::from_f64)
    } else {
        [
            ctx.value::<T>(Kind::Tolerance),
            ctx.value::<T>(Kind::Step),
            ctx.value::<T>(Kind::Tolerance),
        ]
    };
    let mut model = tryv!(setup(
        ContactModel::new(e, rest, tol),
        &["restitution", "rest_speed", "time_tolerance"]
    ));
    if ctx.pick(2) == 0 {
        let mu = ctx.value::<T>(Kind::Param);
        say!(ctx, "let model = model.with_friction({})?;", lit(mu));
        model = tryv!(setup(model.with_friction(mu), &["friction"]));
    }
    let (ptol, iters) = if ctx.pick(2) == 0 {
        (T::from_f64(1e-6), 8)
    } else {
        (
            ctx.value::<T>(Kind::Tolerance),
            u32::try_from(ctx.count()).unwrap_or(u32::MAX).min(16),
        )
    };
    say!(
        ctx,
        "let proj = Projection::<{}>::new({}, {iters})?;",
        ty::<T>(),
        lit(ptol)
    );
    let p = tryv!(setup(
        Projection::new(ptol, iters),
        &["tolerance", "max_iterations"]
    ));
    say!(
        ctx,
        "let mut st = ContactStepper::new({name}, c, model, proj);"
    );
    let mut st = ContactStepper::<T, N, RAGDOLL_CONTACTS, _, _>::new(method, c, model, p);
    let start = doll_state::<T>(ctx, "s0");
    let mut last: Option<State<T, N>> = None;
    for call in 0..=ctx.pick(3) {
        let from = match (ctx.pick(3), last) {
            (0, Some(l)) => {
                say!(ctx, "let s = last;");
                l
            }
            (1, _) => {
                say!(ctx, "let s = s0;");
                start
            }
            _ => doll_state::<T>(ctx, "s"),
        };
        let dt = ctx.value::<T>(Kind::Step);
        let before = observe(&st);
        let (v, out) = if ctx.pick(2) == 0 {
            say!(ctx, "let last = st.step(&m, &s, {})?;", lit(dt));
            let r = st.step(m, &from, dt);
            (verdict(&r, &["dt", "state"]), r.ok())
        } else {
            let n = ctx.count().min(4);
            say!(ctx, "let last = st.integrate(&m, &s, {}, {n})?;", lit(dt));
            let r = st.integrate(m, &from, dt, n).map_err(|f| f.error);
            (verdict(&r, &["dt", "state", "steps"]), r.ok())
        };
        if v.class().is_finding() {
            return v;
        }
        if let Verdict::Error(e) = v {
            let after = observe(&st);
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

fn stepper_rk4<T: Real>(ctx: &mut Ctx) -> Verdict {
    let m = tryv!(doll::<T>(ctx));
    drive(ctx, &m, Rk4, "Rk4")
}

fn stepper_verlet<T: Real>(ctx: &mut Ctx) -> Verdict {
    let m = tryv!(doll::<T>(ctx));
    drive(
        ctx,
        &m,
        StormerVerlet::<T, N>::default(),
        "StormerVerlet::default()",
    )
}

/// What a contact stepper promises of a step from `from` that returned `to`: no contact ends
/// it deeper than it started and below the projection's tolerance `tol`. The row that broke
/// it, if any.
fn below<T: Real>(
    c: &RagdollContacts<T>,
    from: &State<T, N>,
    to: &State<T, N>,
    tol: T,
) -> Option<String> {
    let (g0, g1) = (c.position_residual(&from.q), c.position_residual(&to.q));
    (0..RAGDOLL_CONTACTS)
        .find(|&i| g1[i] < g0[i].min(-tol))
        .map(|i| {
            format!(
                "row {i}: gap {:?} -> {:?} (tolerance {tol:?})",
                g0[i], g1[i]
            )
        })
}

/// The classes a contact stepper's promises fall into (issue 32): a ragdoll dropped from
/// 1 to 2 m in a pose within its limits, spinning and moving at up to 5 m/s (now and then one
/// joint at up to 1e12 rad/s), stepped 60 times at 60, 120 or 240 Hz by semi-implicit Euler,
/// RK4 or velocity Verlet, restitution and friction drawn. After every step no contact may end
/// deeper than it started and below the projection's tolerance; at every impact the kinetic
/// energy after may not exceed the energy before, not by a rounding.
fn drop_promises<T: Real>(ctx: &mut Ctx) -> Verdict {
    let m = tryv!(setup(Ragdoll::new(RagdollBody::adult()), &[]));
    let c = tryv!(setup(RagdollContacts::adult(&m, T::zero()), &[]));
    let (e, mu) = (ctx.uniform::<T>(0.0, 1.0), ctx.uniform::<T>(0.0, 1.0));
    let tol = T::from_f64(if T::EPSILON.to_f64() > 1e-10 {
        1e-5
    } else {
        1e-8
    });
    let model = tryv!(setup(
        ContactModel::new(e, T::from_f64(0.3), T::from_f64(1e-6)).and_then(|m| m.with_friction(mu)),
        &[]
    ));
    let proj = tryv!(setup(Projection::new(tol, 8), &[]));
    let mut q = [T::zero(); N];
    let mut qd = [T::zero(); N];
    q[1] = ctx.uniform(1.0, 2.0);
    q[2] = ctx.uniform(-3.0, 3.0);
    for (k, [lo, hi]) in ADULT_JOINT_LIMITS.into_iter().enumerate() {
        q[k + 3] = ctx.uniform(lo, hi);
    }
    for v in &mut qd {
        *v = ctx.uniform(-5.0, 5.0);
    }
    if ctx.pick(4) == 0 {
        let joint = 3 + ctx.pick(N - 3);
        qd[joint] = ctx.uniform::<T>(3.0, 12.0);
        qd[joint] = -T::from_f64(10f64.powf(qd[joint].to_f64()));
    }
    let dt = T::from_f64([1.0 / 60.0, 1.0 / 120.0, 1.0 / 240.0][ctx.pick(3)]);
    say!(
        ctx,
        "let s0 = State::<{}, {N}>::new(0.0, {}, {});",
        ty::<T>(),
        lits(&q),
        lits(&qd)
    );
    let start = State::new(T::zero(), q, qd);
    match ctx.pick(3) {
        0 => {
            say!(ctx, "let mut st = ContactStepper::new(SemiImplicitEuler, c, ContactModel::new({}, 0.3, 1e-6)?.with_friction({})?, Projection::new({}, 8)?);", lit(e), lit(mu), lit(tol));
            promises(
                &m,
                &c,
                ContactStepper::new(SemiImplicitEuler, c, model, proj),
                start,
                dt,
                tol,
            )
        }
        1 => {
            say!(ctx, "let mut st = ContactStepper::new(Rk4, c, ContactModel::new({}, 0.3, 1e-6)?.with_friction({})?, Projection::new({}, 8)?);", lit(e), lit(mu), lit(tol));
            promises(
                &m,
                &c,
                ContactStepper::new(Rk4, c, model, proj),
                start,
                dt,
                tol,
            )
        }
        _ => {
            say!(ctx, "let mut st = ContactStepper::new(VelocityVerlet, c, ContactModel::new({}, 0.3, 1e-6)?.with_friction({})?, Projection::new({}, 8)?);", lit(e), lit(mu), lit(tol));
            promises(
                &m,
                &c,
                ContactStepper::new(VelocityVerlet, c, model, proj),
                start,
                dt,
                tol,
            )
        }
    }
}

/// Sixty steps of `st` from `start`, each checked against the promises of [`drop_promises`];
/// an error ends the run (an error is allowed, a broken promise is not).
fn promises<T, I>(
    m: &Ragdoll<T>,
    c: &RagdollContacts<T>,
    mut st: ContactStepper<T, N, RAGDOLL_CONTACTS, I, RagdollContacts<T>>,
    start: State<T, N>,
    dt: T,
    tol: T,
) -> Verdict
where
    T: Real,
    I: for<'a> Integrator<
        T,
        N,
        ActiveRows<'a, T, RAGDOLL_CONTACTS, Ragdoll<T>, RagdollContacts<T>>,
    >,
{
    let mut s = start;
    for step in 0..60 {
        let mut gain = None;
        let r = st.step_observed(m, &s, dt, |impact| {
            let (k0, k1) = (
                m.kinetic_energy(&impact.state_before()),
                m.kinetic_energy(&impact.state_after()),
            );
            if k1 > k0 && gain.is_none() {
                gain = Some(format!(
                    "impact at t = {:?}: kinetic energy {k0:?} -> {k1:?}",
                    impact.t
                ));
            }
        });
        if let Some(g) = gain {
            return Verdict::Broken(format!("step {step}: {g}"));
        }
        let Ok(next) = r else {
            return verdict(&r, &[]);
        };
        if let Some(row) = below(c, &s, &next, tol) {
            return Verdict::Broken(format!("step {step} from t = {:?}: {row}", s.t));
        }
        s = next;
    }
    Verdict::Ok
}

/// The time-stepping stepper's promises on the same drops as [`drop_promises`]: a ragdoll
/// (joint damping drawn 0 or the adult's) thrown by semi-implicit Euler inside an
/// `ImpulseStepper` (slop 2 mm, 1 to 8 rounds) at 60, 120 or 240 Hz for 120 steps. After every
/// step: the energy at most the larger of the start's and the free step's plus the free
/// step's own error (to 18 ulps of the terms), every friction impulse within the cone, no
/// floor point deeper than the slop and no limit further past than the slop (to 2^-10 of
/// the slop and [`rounding`]: the drift correction is done again on the gaps it left until
/// they are within that) unless it started deeper, and the work within the cap (rows at most
/// 31, rounds at most four times the cap).
fn impulse_drop_promises<T: Real>(ctx: &mut Ctx) -> Verdict {
    let damping = if ctx.pick(2) == 0 { 0.0 } else { 0.5 };
    let body = RagdollBody {
        joint_damping: T::from_f64(damping),
        ..RagdollBody::adult()
    };
    let m = tryv!(setup(Ragdoll::new(body), &[]));
    let c = tryv!(setup(RagdollContacts::adult(&m, T::zero()), &[]));
    let (e, mu) = (ctx.uniform::<T>(0.0, 1.0), ctx.uniform::<T>(0.0, 1.0));
    let model = tryv!(setup(
        ContactModel::new(e, T::from_f64(0.3), T::one()).and_then(|m| m.with_friction(mu)),
        &[]
    ));
    let rounds = 1 + u32::try_from(ctx.pick(8)).unwrap_or(0);
    let slop = T::from_f64(2e-3);
    let settings = tryv!(setup(ImpulseSettings::new(slop, rounds), &[]));
    let mut q = [T::zero(); N];
    let mut qd = [T::zero(); N];
    q[1] = ctx.uniform(1.0, 2.0);
    q[2] = ctx.uniform(-3.0, 3.0);
    for (k, [lo, hi]) in ADULT_JOINT_LIMITS.into_iter().enumerate() {
        q[k + 3] = ctx.uniform(lo, hi);
    }
    for v in &mut qd {
        *v = ctx.uniform(-5.0, 5.0);
    }
    let dt = T::from_f64([1.0 / 60.0, 1.0 / 120.0, 1.0 / 240.0][ctx.pick(3)]);
    say!(
        ctx,
        "let s0 = State::<{}, {N}>::new(0.0, {}, {});",
        ty::<T>(),
        lits(&q),
        lits(&qd)
    );
    say!(ctx, "let mut st = ImpulseStepper::new(SemiImplicitEuler, c, ContactModel::new({}, 0.3, 1.0)?.with_friction({})?, ImpulseSettings::new(2e-3, {rounds})?); // damping {damping}, dt {}", lit(e), lit(mu), lit(dt));
    let mut st = ImpulseStepper::new(SemiImplicitEuler, c, model, settings);
    let mut s = State::new(T::zero(), q, qd);
    for step in 0..120 {
        let free = match SemiImplicitEuler.step(&m, &s, dt) {
            Ok(f) => f,
            Err(e) => return Verdict::Error(e),
        };
        let r = st.step(&m, &s, dt);
        let Ok(next) = r else {
            // A normal scene never ends in an error (the exact solve of a degenerate set
            // that cycles hands over to projected Gauss-Seidel), but for a state the free
            // integrator itself blew up (semi-implicit Euler at 60 Hz, a ragdoll spun up).
            return match r {
                Err(Error::NonFiniteState) => verdict(&r, &[]),
                Err(e) => Verdict::Broken(format!("step {step}: {e:?} in a normal scene")),
                Ok(_) => Verdict::Ok,
            };
        };
        let (e0, ef, e1) = (
            m.energy(&s).to_f64(),
            m.energy(&free).to_f64(),
            m.energy(&next).to_f64(),
        );
        let sizes = e0.abs() + ef.abs() + e1.abs() + 2.0 * m.potential_energy(&next).to_f64().abs();
        let allowed = e0.max(ef) + (ef - e0).abs() + 18.0 * T::EPSILON.to_f64() * sizes;
        if e1 > allowed {
            return Verdict::Broken(format!("step {step}: energy {e0} -> {e1}, free step {ef}"));
        }
        let (normal, tangent) = st.impulses();
        if let Some(i) = (0..RAGDOLL_CONTACTS)
            .find(|&i| tangent[i].abs() > mu * normal[i] * T::from_f64(1.0 + 1e-6))
        {
            return Verdict::Broken(format!(
                "step {step}: row {i} friction {:?} outside the cone of {:?}",
                tangent[i], normal[i]
            ));
        }
        let (g0, g1) = (c.position_residual(&s.q), c.position_residual(&next.q));
        let floor = slop.to_f64() * (1.0 + 1.0 / 1024.0) + rounding(&next.q);
        if let Some(i) = (0..RAGDOLL_CONTACTS).find(|&i| -g1[i].to_f64() > floor && g1[i] < g0[i]) {
            return Verdict::Broken(format!(
                "step {step}: row {i} ended {:?} below zero (slop {slop:?}), from {:?}",
                g1[i], g0[i]
            ));
        }
        let peak = st.peak_report();
        if peak.rows > 31 || peak.rounds > 4 * rounds {
            return Verdict::Broken(format!("step {step}: work {peak:?} over the cap"));
        }
        s = next;
    }
    Verdict::Ok
}

/// The rounding of a gap of coordinates `q`: 64 ulps of the largest (a gap sums a few terms
/// of that size), as the stepper's drift correction allows.
fn rounding<T: Real, const N: usize>(q: &lagrange_core::nalgebra::SVector<T, N>) -> f64 {
    let largest = q.iter().fold(0.0_f64, |m, x| m.max(x.to_f64().abs()));
    64.0 * T::EPSILON.to_f64() * (1.0 + largest)
}

/// A body refused by its field, as `refused` would say of a plain parameter list (kept for
/// the constructor's own entry: every field drawn at once).
fn constructor<T: Real>(ctx: &mut Ctx) -> Verdict {
    let (b, drawn) = body::<T>(ctx);
    say!(ctx, "Ragdoll::new(b)");
    match Ragdoll::new(b) {
        Ok(m) => {
            let total = m.total_mass();
            if total.is_finite() {
                Verdict::Ok
            } else {
                Verdict::Silent(format!("total_mass() = {total:?} of an accepted body"))
            }
        }
        Err(e) => {
            let v = refused_body(e, &drawn);
            if v.class().is_finding() {
                v
            } else {
                refused(e, &FIELDS)
            }
        }
    }
}

/// The family.
pub fn family() -> Family {
    let mut v: Vec<Entry> = Vec::new();
    entries!(v, 0.6, "Ragdoll::new", constructor);
    entries!(v, 1.0, "Ragdoll methods", ragdoll);
    entries!(v, 0.6, "RagdollContacts rows", ragdoll_contacts);
    // The contact runs only optimised (`cargo xtask fuzz`): unoptimised, one ragdoll step that
    // spends its events before it fails takes up to 43 s, near the 60 s deadline of the short
    // run in `cargo test`, and the run as a whole a minute and a half more.
    if !cfg!(debug_assertions) {
        entries!(v, 0.5, "ContactStepper<Rk4, RagdollContacts>", stepper_rk4);
        entries!(
            v,
            0.5,
            "ContactStepper<StormerVerlet, RagdollContacts>",
            stepper_verlet
        );
        entries!(v, 0.1, "ContactStepper drops (promises)", drop_promises);
        entries!(
            v,
            0.1,
            "ImpulseStepper drops (promises)",
            impulse_drop_promises
        );
    }
    Family {
        name: "ragdoll",
        entries: v,
    }
}
