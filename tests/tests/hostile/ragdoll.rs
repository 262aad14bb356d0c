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
use lagrange_core::{Constraints, Error, Projection, Real, State};
use lagrange_integrators::{ContactModel, ContactStepper, Integrator, Rk4, StormerVerlet};
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
    }
    Family {
        name: "ragdoll",
        entries: v,
    }
}
