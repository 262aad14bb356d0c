//! Family `core`: lagrange-core's own constructors (damping, stabilisation, projection, the
//! contact model), the Cholesky solve, a user's Lagrangian, force and constraints that may
//! return NaN, and the constrained, projected and contact laws.

use crate::checks::{num, state, vector, verdict};
use crate::harness::{lit, lits, ty, Ctx, Entry, Family, Verdict};
use crate::systems::exercise;
use crate::values::Kind;
use crate::{call, entries, say};
use lagrange_core::constraints::contact::{
    drop_dependent_contacts, ActiveRows, ContactModel, Contacts, Impacts,
};
use lagrange_core::constraints::{Constraints, Holonomic, HolonomicConstraints};
use lagrange_core::nalgebra::{SMatrix, SVector, Vector1, Vector2};
use lagrange_core::{
    solve_spd, Constrained, EulerLagrange, Lagrangian, Mechanism, Projection, Real, Scalar,
    Stabilization, State, ViscousDamping,
};
use lagrange_systems::{
    CartesianPendulum, FallingParticle, FourBarLinkage, RollingDisk, SimplePendulum,
};

/// A user's unit of account: `T = m q'^2 / 2`, `V = k q^2 / 2`, nothing validated (so `m` and
/// `k` may be NaN, zero or negative).
#[derive(Debug, Clone, Copy)]
pub struct Spring<T> {
    pub m: T,
    pub k: T,
}

impl<T: Real> Lagrangian<T, 1> for Spring<T> {
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, _q: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
        qd[0] * qd[0] * (T::HALF * self.m)
    }
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 1>) -> S {
        q[0] * q[0] * (T::HALF * self.k)
    }
}

/// A user's point mass in the plane in gravity `g` along -y, unvalidated.
#[derive(Debug, Clone, Copy)]
pub struct Particle<T> {
    pub m: T,
    pub g: T,
}

impl<T: Real> Lagrangian<T, 2> for Particle<T> {
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, _q: &SVector<S, 2>, v: &SVector<S, 2>) -> S {
        (v[0] * v[0] + v[1] * v[1]) * (T::HALF * self.m)
    }
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 2>) -> S {
        q[1] * (self.m * self.g)
    }
}

/// A user's constraint: the point on a circle of radius `r` (unvalidated).
#[derive(Debug, Clone, Copy)]
pub struct Circle<T> {
    pub r: T,
}

impl<T: Real> HolonomicConstraints<T, 2, 1> for Circle<T> {
    fn phi<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 2>) -> SVector<S, 1> {
        Vector1::new((q[0] * q[0] + q[1] * q[1] - S::from_real(self.r * self.r)) * T::HALF)
    }
}

/// A user's contact set in the plane: the floor `y >= floor` and the wall `x <= wall`.
#[derive(Debug, Clone, Copy)]
pub struct Box2<T> {
    pub floor: T,
    pub wall: T,
}

impl<T: Real> HolonomicConstraints<T, 2, 2> for Box2<T> {
    fn phi<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 2>) -> SVector<S, 2> {
        Vector2::new(
            q[1] - S::from_real(self.floor),
            S::from_real(self.wall) - q[0],
        )
    }
}

/// A user's floor `y >= floor` under a point in the plane, with its tangent for friction.
#[derive(Debug, Clone, Copy)]
pub struct Floor<T> {
    pub floor: T,
}

impl<T: Real> Constraints<T, 2, 1> for Floor<T> {
    fn position_residual(&self, q: &SVector<T, 2>) -> SVector<T, 1> {
        Vector1::new(q[1] - self.floor)
    }
    fn jacobian(&self, _q: &SVector<T, 2>) -> SMatrix<T, 1, 2> {
        SMatrix::<T, 1, 2>::new(T::zero(), T::one())
    }
    fn velocity_product(&self, _q: &SVector<T, 2>, _qd: &SVector<T, 2>) -> SVector<T, 1> {
        Vector1::zeros()
    }
}

impl<T: Real> Contacts<T, 2, 1> for Floor<T> {
    fn tangent_jacobian(&self, _q: &SVector<T, 2>) -> Option<SMatrix<T, 1, 2>> {
        Some(SMatrix::<T, 1, 2>::new(T::one(), T::zero()))
    }
}

/// A user's ground under a falling particle: `y >= h`.
#[derive(Debug, Clone, Copy)]
pub struct Ground<T> {
    pub h: T,
}

impl<T: Real> HolonomicConstraints<T, 1, 1> for Ground<T> {
    fn phi<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 1>) -> SVector<S, 1> {
        Vector1::new(q[0] - S::from_real(self.h))
    }
}

fn damping<T: Real>(ctx: &mut Ctx) -> Verdict {
    if ctx.pick(2) == 0 {
        let c = ctx.values::<T, 3>(Kind::Param);
        say!(ctx, "ViscousDamping::<{}, 3>::new({})", ty::<T>(), lits(&c));
        let d = call!(ViscousDamping::new(c), &["coefficients"]);
        verdict(&Ok(*d.coefficients()), &[])
    } else {
        let c = ctx.value::<T>(Kind::Param);
        say!(
            ctx,
            "ViscousDamping::<{}, 2>::uniform({})",
            ty::<T>(),
            lit(c)
        );
        let d = call!(ViscousDamping::<T, 2>::uniform(c), &["coefficient"]);
        verdict(&Ok(*d.coefficients()), &[])
    }
}

/// The gains of a stabilisation, for the finiteness check.
fn gains<T: Real>(s: &Stabilization<T>) -> Vector2<T> {
    match *s {
        Stabilization::Baumgarte { alpha, beta } => Vector2::new(alpha, beta),
        _ => Vector2::zeros(),
    }
}

/// A stabilisation drawn (one of its three constructors, or none).
fn stabilization<T: Real>(ctx: &mut Ctx) -> Result<Stabilization<T>, Verdict> {
    let (r, params): (_, &[&str]) = match ctx.pick(4) {
        0 => {
            let [a, b] = ctx.values::<T, 2>(Kind::Param);
            say!(
                ctx,
                "let stab = Stabilization::<{}>::baumgarte({}, {})?;",
                ty::<T>(),
                lit(a),
                lit(b)
            );
            (Stabilization::baumgarte(a, b), &["alpha", "beta"])
        }
        1 => {
            let r = ctx.value::<T>(Kind::Param);
            say!(
                ctx,
                "let stab = Stabilization::<{}>::critical({})?;",
                ty::<T>(),
                lit(r)
            );
            (Stabilization::critical(r), &["rate"])
        }
        2 => {
            let dt = ctx.value::<T>(Kind::Step);
            say!(
                ctx,
                "let stab = Stabilization::<{}>::for_step({})?;",
                ty::<T>(),
                lit(dt)
            );
            (Stabilization::for_step(dt), &["dt"])
        }
        _ => {
            say!(ctx, "let stab = Stabilization::<{}>::None;", ty::<T>());
            (Ok(Stabilization::None), &[])
        }
    };
    match (&r, verdict(&r.map(|s| gains(&s)), params)) {
        (Ok(s), Verdict::Ok) => Ok(*s),
        (_, v) => Err(v),
    }
}

fn stabilizations<T: Real>(ctx: &mut Ctx) -> Verdict {
    match stabilization::<T>(ctx) {
        Ok(_) => Verdict::Ok,
        Err(v) => v,
    }
}

/// A projection drawn.
fn projection<T: Real>(ctx: &mut Ctx) -> Result<Projection<T>, Verdict> {
    let tol = ctx.value::<T>(Kind::Tolerance);
    let n = u32::try_from(ctx.count()).unwrap_or(u32::MAX);
    say!(
        ctx,
        "let proj = Projection::<{}>::new({}, {n})?;",
        ty::<T>(),
        lit(tol)
    );
    let r = Projection::new(tol, n);
    match verdict(
        &r.map(|p| num(p.tolerance())),
        &["tolerance", "max_iterations"],
    ) {
        Verdict::Ok => r.map_err(Verdict::Error),
        v => Err(v),
    }
}

fn projections<T: Real>(ctx: &mut Ctx) -> Verdict {
    match projection::<T>(ctx) {
        Ok(_) => Verdict::Ok,
        Err(v) => v,
    }
}

/// A contact model drawn, with friction sometimes.
fn model<T: Real>(ctx: &mut Ctx) -> Result<ContactModel<T>, Verdict> {
    let e = ctx.value::<T>(Kind::Tolerance);
    let rest = ctx.value::<T>(Kind::Step);
    let tol = ctx.value::<T>(Kind::Tolerance);
    say!(
        ctx,
        "let model = ContactModel::<{}>::new({}, {}, {})?;",
        ty::<T>(),
        lit(e),
        lit(rest),
        lit(tol)
    );
    let r = ContactModel::new(e, rest, tol);
    let m = match verdict(
        &r.map(|m| Vector2::new(m.rest_speed(), m.time_tolerance())),
        &["restitution", "rest_speed", "time_tolerance"],
    ) {
        Verdict::Ok => r.map_err(Verdict::Error)?,
        v => return Err(v),
    };
    if ctx.pick(2) == 0 {
        return Ok(m);
    }
    let f = ctx.value::<T>(Kind::Param);
    say!(ctx, "let model = model.with_friction({})?;", lit(f));
    let r = m.with_friction(f);
    match verdict(&r.map(|m| num(m.friction())), &["friction"]) {
        Verdict::Ok => r.map_err(Verdict::Error),
        v => Err(v),
    }
}

fn models<T: Real>(ctx: &mut Ctx) -> Verdict {
    match model::<T>(ctx) {
        Ok(_) => Verdict::Ok,
        Err(v) => v,
    }
}

fn cholesky<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [a, b, d] = ctx.values::<T, 3>(Kind::Signed);
    let (rhs, rs) = vector::<T, 2>(ctx, Kind::Signed);
    say!(
        ctx,
        "solve_spd(&Matrix2::<{}>::new({}, {}, {}, {}), &{rs})",
        ty::<T>(),
        lit(a),
        lit(b),
        lit(b),
        lit(d)
    );
    let m = SMatrix::<T, 2, 2>::new(a, b, b, d);
    verdict(&solve_spd(&m, &rhs), &["m", "b"])
}

fn user_lagrangian<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [m, k] = ctx.values::<T, 2>(Kind::Signed);
    say!(
        ctx,
        "let m = EulerLagrange::new(Spring::<{}> {{ m: {}, k: {} }});",
        ty::<T>(),
        lit(m),
        lit(k)
    );
    let sys = EulerLagrange::new(Spring { m, k });
    exercise(ctx, &sys)
}

fn user_force<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [m, l, g, b] = ctx.values::<T, 4>(Kind::Param);
    say!(
        ctx,
        "let p = SimplePendulum::<{}>::new({}, {}, {}, {})?;",
        ty::<T>(),
        lit(m),
        lit(l),
        lit(g),
        lit(b)
    );
    let p = call!(
        SimplePendulum::new(m, l, g, b),
        &["mass", "length", "gravity", "damping"]
    );
    let gain = ctx.value::<T>(Kind::Signed);
    say!(
        ctx,
        "let m = p.with_force(move |s: &State<{}, 1>| Vector1::new({} * s.qd[0]));",
        ty::<T>(),
        lit(gain)
    );
    let sys = p.with_force(move |s: &State<T, 1>| Vector1::new(gain * s.qd[0]));
    exercise(ctx, &sys)
}

/// Drawn checks of a constrained mechanism: its solve, its state check, a projection, or one
/// of its `Mechanism` methods.
fn constrained<T, P, const N: usize, const C: usize>(
    ctx: &mut Ctx,
    c: &Constrained<T, C, P>,
) -> Verdict
where
    T: Real,
    P: Mechanism<T, N> + Constraints<T, N, C>,
{
    match ctx.pick(5) {
        0 => {
            let s = state::<T, N>(ctx, "s");
            say!(ctx, "c.solve(&s)");
            verdict(&c.solve(&s), &["state"])
        }
        1 => {
            let s = state::<T, N>(ctx, "s");
            let tol = ctx.value::<T>(Kind::Tolerance);
            say!(ctx, "c.check_state(&s, {})", lit(tol));
            let _ = c.residual(&s);
            verdict(&c.check_state(&s, tol), &["state", "tolerance"])
        }
        2 => {
            let p = match projection::<T>(ctx) {
                Ok(p) => p,
                Err(v) => return v,
            };
            let s = state::<T, N>(ctx, "s");
            say!(ctx, "proj.project(&c, &c, &s)");
            verdict(&p.project(c, c, &s), &["state"])
        }
        _ => exercise(ctx, c),
    }
}

fn cartesian<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [m, l, g] = ctx.values::<T, 3>(Kind::Param);
    say!(
        ctx,
        "let p = CartesianPendulum::<{}>::new({}, {}, {})?;",
        ty::<T>(),
        lit(m),
        lit(l),
        lit(g)
    );
    let p = call!(
        CartesianPendulum::new(m, l, g),
        &["mass", "length", "gravity"]
    );
    let stab = match stabilization::<T>(ctx) {
        Ok(s) => s,
        Err(v) => return v,
    };
    say!(ctx, "let c = Constrained::new(p).with_stabilization(stab);");
    let c = Constrained::new(p).with_stabilization(stab);
    constrained(ctx, &c)
}

fn user_constraint<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [m, g] = ctx.values::<T, 2>(Kind::Signed);
    let r = ctx.value::<T>(Kind::Param);
    say!(ctx, "let c = EulerLagrange::new(Particle::<{}> {{ m: {}, g: {} }}).held_by(Holonomic::new(Circle {{ r: {} }}));", ty::<T>(), lit(m), lit(g), lit(r));
    let c = EulerLagrange::new(Particle { m, g }).held_by(Holonomic::new(Circle { r }));
    constrained(ctx, &c)
}

fn four_bar<T: Real>(ctx: &mut Ctx) -> Verdict {
    let lengths = ctx.values::<T, 4>(Kind::Param);
    let masses = ctx.values::<T, 3>(Kind::Param);
    let g = ctx.value::<T>(Kind::Param);
    say!(
        ctx,
        "let p = FourBarLinkage::<{}>::new({}, {}, {})?;",
        ty::<T>(),
        lits(&lengths),
        lits(&masses),
        lit(g)
    );
    let p = call!(
        FourBarLinkage::new(lengths, masses, g),
        &["lengths", "masses", "gravity"]
    );
    let [t, crank, rate] = ctx.values::<T, 3>(Kind::State);
    let branch = if ctx.pick(2) == 0 {
        lagrange_systems::Branch::Left
    } else {
        lagrange_systems::Branch::Right
    };
    say!(
        ctx,
        "let s = p.assemble({}, {}, {}, Branch::{branch:?})?;",
        lit(t),
        lit(crank),
        lit(rate)
    );
    let s = call!(
        p.assemble(t, crank, rate, branch),
        &["t", "crank", "crank_rate", "branch"]
    );
    say!(ctx, "let c = Constrained::new(p);");
    let c = Constrained::new(p);
    if ctx.pick(2) == 0 {
        say!(ctx, "c.acceleration(&s)");
        return verdict(&c.acceleration(&s), &["state"]);
    }
    constrained(ctx, &c)
}

fn rolling_disk<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [m, r] = ctx.values::<T, 2>(Kind::Param);
    say!(
        ctx,
        "let p = RollingDisk::<{}>::new({}, {})?;",
        ty::<T>(),
        lit(m),
        lit(r)
    );
    let p = call!(RollingDisk::new(m, r), &["mass", "radius"]);
    let t = ctx.value::<T>(Kind::Time);
    let q = ctx.values::<T, 4>(Kind::State);
    let [turn, roll] = ctx.values::<T, 2>(Kind::Signed);
    say!(
        ctx,
        "let s = p.rolling({}, {}, {}, {})?;",
        lit(t),
        lits(&q),
        lit(turn),
        lit(roll)
    );
    let s = call!(
        p.rolling(t, q, turn, roll),
        &["t", "q", "turn_rate", "roll_rate"]
    );
    say!(ctx, "let c = Constrained::new(p);");
    let c = Constrained::new(p);
    if ctx.pick(2) == 0 {
        say!(ctx, "c.acceleration(&s)");
        return verdict(&c.acceleration(&s), &["state"]);
    }
    constrained(ctx, &c)
}

/// Rows marked from a drawn mask.
fn mask<const C: usize>(ctx: &mut Ctx) -> [bool; C] {
    core::array::from_fn(|_| ctx.pick(2) == 1)
}

fn contact_laws<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [m, g] = ctx.values::<T, 2>(Kind::Signed);
    let [floor, wall] = ctx.values::<T, 2>(Kind::Signed);
    say!(
        ctx,
        "let m = EulerLagrange::new(Particle::<{}> {{ m: {}, g: {} }});",
        ty::<T>(),
        lit(m),
        lit(g)
    );
    say!(
        ctx,
        "let k = Holonomic::new(Box2 {{ floor: {}, wall: {} }});",
        lit(floor),
        lit(wall)
    );
    let mech = EulerLagrange::new(Particle { m, g });
    let k = Holonomic::new(Box2 { floor, wall });
    let model = match model::<T>(ctx) {
        Ok(m) => m,
        Err(v) => return v,
    };
    let bilateral = mask::<2>(ctx);
    let mut resting = mask::<2>(ctx);
    let s = state::<T, 2>(ctx, "s");
    match ctx.pick(4) {
        0 => {
            say!(
                ctx,
                "let rows = ActiveRows::new(&m, &k, &model, &{bilateral:?}, &{resting:?});"
            );
            let rows = ActiveRows::new(&mech, &k, &model, &bilateral, &resting);
            say!(ctx, "rows.acceleration(&s)");
            verdict(&rows.acceleration(&s), &["state"])
        }
        1 => {
            say!(
                ctx,
                "let rows = ActiveRows::new(&m, &k, &model, &{bilateral:?}, &{resting:?});"
            );
            let rows = ActiveRows::new(&mech, &k, &model, &bilateral, &resting);
            say!(ctx, "rows.still_in_force(&s)");
            verdict(&rows.still_in_force(&s), &["state"])
        }
        2 => {
            let struck = mask::<2>(ctx);
            say!(ctx, "Impacts::new(&k, &model, {bilateral:?}).impact(&m, &s, {struck:?}, &mut {resting:?})");
            let impacts = Impacts::new(&k, &model, bilateral);
            verdict(
                &impacts.impact(&mech, &s, struck, &mut resting),
                &["state", "struck", "resting"],
            )
        }
        _ => {
            say!(
                ctx,
                "drop_dependent_contacts(&m, &k, &s, &mut {resting:?}, &{bilateral:?})"
            );
            verdict(
                &drop_dependent_contacts(&mech, &k, &s, &mut resting, &bilateral),
                &["state", "active", "bilateral"],
            )
        }
    }
}

/// Friction: a point in the plane on a floor with a tangent, its resting and sliding law and
/// its impacts with Coulomb impulses.
fn friction<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [m, g] = ctx.values::<T, 2>(Kind::Signed);
    let floor = ctx.value::<T>(Kind::Signed);
    say!(
        ctx,
        "let m = EulerLagrange::new(Particle::<{}> {{ m: {}, g: {} }});",
        ty::<T>(),
        lit(m),
        lit(g)
    );
    say!(ctx, "let k = Floor {{ floor: {} }};", lit(floor));
    let mech = EulerLagrange::new(Particle { m, g });
    let k = Floor { floor };
    let model = match model::<T>(ctx) {
        Ok(m) => m,
        Err(v) => return v,
    };
    let s = state::<T, 2>(ctx, "s");
    let mut resting = mask::<1>(ctx);
    if ctx.pick(2) == 0 {
        say!(
            ctx,
            "let rows = ActiveRows::new(&m, &k, &model, &[false], &{resting:?});"
        );
        let rows = ActiveRows::new(&mech, &k, &model, &[false], &resting);
        say!(ctx, "rows.acceleration(&s)");
        verdict(&rows.acceleration(&s), &["state"])
    } else {
        let struck = mask::<1>(ctx);
        say!(
            ctx,
            "Impacts::new(&k, &model, [false]).impact(&m, &s, {struck:?}, &mut {resting:?})"
        );
        verdict(
            &Impacts::new(&k, &model, [false]).impact(&mech, &s, struck, &mut resting),
            &["state", "struck", "resting"],
        )
    }
}

/// Viscous damping as a wrapped force, with its exact Jacobian, on a double pendulum; and
/// the projection onto some rows only, and a constrained solve with an extra force.
fn damped_and_masked<T: Real>(ctx: &mut Ctx) -> Verdict {
    match ctx.pick(3) {
        0 => {
            let [a, b] = ctx.values::<T, 2>(Kind::Param);
            let c = ctx.values::<T, 2>(Kind::Param);
            say!(ctx, "let m = DoublePendulum::<{}>::new({}, {}, 1.0, 1.0, 9.81)?.with_force(ViscousDamping::new({})?);", ty::<T>(), lit(a), lit(b), lits(&c));
            let p = call!(
                lagrange_systems::DoublePendulum::new(a, b, T::one(), T::one(), T::from_f64(9.81)),
                &["m1", "m2", "l1", "l2", "gravity"]
            );
            let d = call!(ViscousDamping::new(c), &["coefficients"]);
            exercise(ctx, &p.with_force(d))
        }
        1 => {
            let lengths = ctx.values::<T, 4>(Kind::Param);
            say!(
                ctx,
                "let c = Constrained::new(FourBarLinkage::<{}>::new({}, [1.0; 3], 9.81)?);",
                ty::<T>(),
                lits(&lengths)
            );
            let p = call!(
                FourBarLinkage::new(lengths, [T::one(); 3], T::from_f64(9.81)),
                &["lengths", "masses", "gravity"]
            );
            let c = Constrained::new(p);
            let proj = match projection::<T>(ctx) {
                Ok(p) => p,
                Err(v) => return v,
            };
            let active = mask::<2>(ctx);
            let s = state::<T, 3>(ctx, "s");
            say!(ctx, "proj.project_rows(&c, &c, &s, &{active:?})");
            verdict(
                &proj.project_rows(&c, &c, &s, &active),
                &["state", "active"],
            )
        }
        _ => {
            let [m, l, g] = ctx.values::<T, 3>(Kind::Param);
            say!(
                ctx,
                "let c = Constrained::new(CartesianPendulum::<{}>::new({}, {}, {})?);",
                ty::<T>(),
                lit(m),
                lit(l),
                lit(g)
            );
            let c = Constrained::new(call!(
                CartesianPendulum::new(m, l, g),
                &["mass", "length", "gravity"]
            ));
            let s = state::<T, 2>(ctx, "s");
            let (f, fs) = vector::<T, 2>(ctx, Kind::Signed);
            say!(ctx, "c.solve_with(&s, &Input {{ value: {fs} }})");
            verdict(
                &c.solve_with(&s, &lagrange_core::Input { value: f }),
                &["state", "extra"],
            )
        }
    }
}

fn falling_contact<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [m, g] = ctx.values::<T, 2>(Kind::Param);
    say!(
        ctx,
        "let m = FallingParticle::<{}>::new({}, {})?;",
        ty::<T>(),
        lit(m),
        lit(g)
    );
    let mech = call!(FallingParticle::new(m, g), &["mass", "gravity"]);
    let h = ctx.value::<T>(Kind::Signed);
    say!(ctx, "let k = Holonomic::new(Ground {{ h: {} }});", lit(h));
    let k = Holonomic::new(Ground { h });
    let model = match model::<T>(ctx) {
        Ok(m) => m,
        Err(v) => return v,
    };
    let mut resting = mask::<1>(ctx);
    let bilateral = mask::<1>(ctx);
    let s = state::<T, 1>(ctx, "s");
    let struck = mask::<1>(ctx);
    say!(
        ctx,
        "Impacts::new(&k, &model, {bilateral:?}).impact(&m, &s, {struck:?}, &mut {resting:?})"
    );
    verdict(
        &Impacts::new(&k, &model, bilateral).impact(&mech, &s, struck, &mut resting),
        &["state", "struck", "resting"],
    )
}

/// The sine and cosine of `lagrange_core::fast_trig` (no error channel): finite for every
/// finite argument, NaN otherwise, never a panic.
fn fast_trig(ctx: &mut Ctx) -> Verdict {
    let x = ctx.value::<f32>(Kind::Signed);
    say!(ctx, "lagrange_core::fast_trig::sin_cos({})", lit(x));
    let (s, c) = lagrange_core::fast_trig::sin_cos(x);
    let (s1, c1) = (
        lagrange_core::fast_trig::sin(x),
        lagrange_core::fast_trig::cos(x),
    );
    if x.is_finite() && !(s.is_finite() && c.is_finite() && s.abs() <= 1.0 && c.abs() <= 1.0) {
        return Verdict::Silent(format!("sin_cos({x:e}) = ({s}, {c})"));
    }
    if s.to_bits() != s1.to_bits() || c.to_bits() != c1.to_bits() {
        return Verdict::Inconsistent(format!(
            "sin_cos({x:e}) = ({s}, {c}), sin, cos = ({s1}, {c1})"
        ));
    }
    Verdict::Ok
}

/// The exact clock of the runs (no error channel): a few ticks of drawn steps, never a
/// panic; finite ticks from a finite start give a finite time within an ulp of the sum.
fn clock<T: Real>(ctx: &mut Ctx) -> Verdict {
    let t0 = ctx.value::<T>(Kind::Time);
    let dt = ctx.value::<T>(Kind::Step);
    let n = ctx.count().min(5000);
    say!(
        ctx,
        "let mut c = Clock::new({}); for _ in 0..{n} {{ c.tick({}); }} c.time()",
        lit(t0),
        lit(dt)
    );
    let mut c = lagrange_integrators::Clock::new(t0);
    for _ in 0..n {
        c.tick(dt);
    }
    let t = c.time();
    let exact = t0.to_f64() + n as f64 * dt.to_f64();
    let representable = exact.abs() < T::MAX.to_f64() * 0.5;
    if t0.is_finite() && dt.is_finite() && representable && T::EPSILON.to_f64() > 1e-10 {
        // In f32 the sum in f64 is exact enough to judge an ulp.
        let err = (t.to_f64() - exact).abs();
        let ulp = t.to_f64().abs().max(T::MIN_POSITIVE.to_f64()) * T::EPSILON.to_f64();
        if err.is_nan() || err > ulp {
            return Verdict::Inconsistent(format!("time {t:?} for {exact:e}"));
        }
    }
    Verdict::Ok
}

/// The functions without an error channel, at drawn values: the scalar and dual-number math,
/// a user's constraint rows and residuals, central differences, and the text of every error.
/// Never a panic; whatever they return is documented as possibly NaN or infinite.
fn no_error_channel<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [x, y] = ctx.values::<T, 2>(Kind::Signed);
    let n = i32::try_from(ctx.count()).unwrap_or(i32::MIN);
    say!(ctx, "let (x, y) = ({}, {});", lit(x), lit(y));
    match ctx.pick(4) {
        0 => {
            say!(
                ctx,
                "x.powi({n}); x.powf(y); x.atan2(y); x.asin(); x.acos(); x.ln(); ..."
            );
            let _ = (
                x.powi(n),
                x.powf(y),
                x.atan2(y),
                x.asin(),
                x.acos(),
                x.atan(),
            );
            let _ = (
                x.ln(),
                x.exp(),
                x.sqrt(),
                x.tan(),
                x.floor(),
                x.round(),
                x.sin_cos(),
            );
            let _ = (x.recip(), x.abs(), x.max(y), x.min(y));
        }
        1 => {
            say!(
                ctx,
                "let d = Dual::<{}, 2>::variable(x, 0) * Dual::variable(y, 1); ...",
                ty::<T>()
            );
            let d =
                lagrange_core::Dual::<T, 2>::variable(x, 0) * lagrange_core::Dual::variable(y, 1);
            let _ = (
                d.sin(),
                d.cos(),
                d.tan(),
                d.sqrt(),
                d.exp(),
                d.ln(),
                d.powi(n),
            );
            let _ = (d.abs(), d.atan2(d), d.recip(), d / (d + x), d - d * y + x);
        }
        2 => {
            let r = ctx.value::<T>(Kind::Param);
            let s = state::<T, 2>(ctx, "s");
            say!(ctx, "let c = Holonomic::new(Circle {{ r: {} }}); c.jacobian(&s.q); c.velocity_product(&s.q, &s.qd); c.residual(&s)", lit(r));
            let c = Holonomic::new(Circle { r });
            let _ = (
                c.jacobian(&s.q),
                c.velocity_product(&s.q, &s.qd),
                c.residual(&s),
            );
            say!(
                ctx,
                "central_difference_jacobian(&s, |s| c.position_residual(&s.q).push(...))"
            );
            let _ = lagrange_core::central_difference_jacobian(&s, |s: &State<T, 2>| {
                let phi = c.position_residual(&s.q)[0];
                SVector::<T, 2>::new(phi, phi * s.qd[0])
            });
        }
        _ => {
            let errors = [
                lagrange_core::Error::NonFiniteState,
                lagrange_core::Error::SingularMassMatrix { pivot: usize::MAX },
                lagrange_core::Error::RedundantConstraints { row: 0 },
                lagrange_core::Error::RedundantConstraints { row: usize::MAX },
                lagrange_core::Error::ConstraintViolated { row: 3 },
                lagrange_core::Error::TooManySteps { steps: u64::MAX },
                lagrange_core::Error::NoConvergence {
                    iterations: u32::MAX,
                },
                lagrange_core::Error::StepSizeUnderflow,
                lagrange_core::Error::SingularJacobian,
                lagrange_core::Error::NonFiniteRow { row: usize::MAX },
                lagrange_core::Error::Singularity { what: "here" },
                lagrange_core::Error::InvalidParameter {
                    name: "x",
                    reason: "why",
                },
            ];
            say!(ctx, "format!(\"{{}}\", error) for every error");
            for e in errors {
                let text = e.to_string();
                if text.is_empty() {
                    return Verdict::Inconsistent(format!("{e:?} has no text"));
                }
            }
        }
    }
    Verdict::Ok
}

/// The family.
pub fn family() -> Family {
    let mut v: Vec<Entry> = Vec::new();
    entries!(v, 0.3, "ViscousDamping::new/uniform", damping);
    entries!(
        v,
        0.3,
        "Stabilization::baumgarte/critical/for_step",
        stabilizations
    );
    entries!(v, 0.3, "Projection::new", projections);
    entries!(v, 0.3, "ContactModel::new/with_friction", models);
    entries!(v, 0.5, "solve_spd", cholesky);
    entries!(v, 1.0, "EulerLagrange (user Lagrangian)", user_lagrangian);
    entries!(v, 1.0, "Forced (user force)", user_force);
    entries!(v, 1.0, "Constrained<CartesianPendulum>", cartesian);
    entries!(
        v,
        1.0,
        "Constrained<Held> (user constraint)",
        user_constraint
    );
    entries!(v, 1.0, "Constrained<FourBarLinkage>", four_bar);
    entries!(v, 0.7, "Constrained<RollingDisk>", rolling_disk);
    entries!(v, 1.0, "contact laws (ActiveRows, Impacts)", contact_laws);
    entries!(v, 0.5, "Impacts of a falling particle", falling_contact);
    entries!(v, 0.3, "Clock::tick/time", clock);
    entries!(
        v,
        0.3,
        "no error channel (math, duals, rows, differences, texts)",
        no_error_channel
    );
    entries!(v, 0.6, "friction (ActiveRows, Impacts)", friction);
    entries!(
        v,
        0.6,
        "ViscousDamping force, project_rows, solve_with",
        damped_and_masked
    );
    v.push(Entry {
        name: "fast_trig::sin/cos/sin_cos f32".into(),
        weight: 0.3,
        run: fast_trig,
    });
    Family {
        name: "core",
        entries: v,
    }
}
