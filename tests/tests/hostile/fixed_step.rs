//! Family `fixed-step`: every fixed-step integrator (explicit, symmetric, implicit,
//! variational, composed) on drawn mechanisms, states and steps: `step`, `integrate`, a step
//! against a one-step run (they must agree), and a run of no steps (it must check what a step
//! checks); and `NewtonSettings::new`.

use crate::checks::{num, state, verdict};
use crate::core::Spring;
use crate::harness::{lit, ty, Ctx, Entry, Family, Verdict};
use crate::values::Kind;
use crate::{entries, say};
use lagrange_core::{Constrained, Error, EulerLagrange, Mechanism, Real, State};
use lagrange_integrators::{
    BackwardEuler, ExplicitEuler, GaussLegendre2, ImplicitMidpoint, Integrator, NewtonSettings,
    RadauIIA2, Rk4, SemiImplicitEuler, StormerVerlet, SymmetricBase, VariationalMidpoint,
    VelocityVerlet, Yoshida4,
};
use lagrange_systems::{CartesianPendulum, DoublePendulum, Kepler, SimplePendulum};

/// Early return with a verdict: `let x = tryv!(result_with_verdict_error);`
#[macro_export]
macro_rules! tryv {
    ($e:expr) => {
        match $e {
            Ok(v) => v,
            Err(v) => return v,
        }
    };
}

/// The most steps a drawn run takes (a long run is not a hang).
const MAX_RUN: u64 = 50;

pub fn pendulum<T: Real>(ctx: &mut Ctx) -> Result<SimplePendulum<T>, Verdict> {
    let [a, b, c, d] = ctx.values::<T, 4>(Kind::Param);
    say!(
        ctx,
        "let m = SimplePendulum::<{}>::new({}, {}, {}, {})?;",
        ty::<T>(),
        lit(a),
        lit(b),
        lit(c),
        lit(d)
    );
    let r = SimplePendulum::new(a, b, c, d);
    setup(r, &["mass", "length", "gravity", "damping"])
}

pub fn double<T: Real>(ctx: &mut Ctx) -> Result<DoublePendulum<T>, Verdict> {
    let [a, b, c, d, e] = ctx.values::<T, 5>(Kind::Param);
    say!(
        ctx,
        "let m = DoublePendulum::<{}>::new({}, {}, {}, {}, {})?;",
        ty::<T>(),
        lit(a),
        lit(b),
        lit(c),
        lit(d),
        lit(e)
    );
    setup(
        DoublePendulum::new(a, b, c, d, e),
        &["m1", "m2", "l1", "l2", "gravity"],
    )
}

pub fn kepler<T: Real>(ctx: &mut Ctx) -> Result<Kepler<T>, Verdict> {
    let mu = ctx.value::<T>(Kind::Param);
    say!(ctx, "let m = Kepler::<{}>::new({})?;", ty::<T>(), lit(mu));
    setup(Kepler::new(mu), &["mu"])
}

pub fn user_spring<T: Real>(ctx: &mut Ctx) -> EulerLagrange<T, 1, Spring<T>> {
    let [m, k] = ctx.values::<T, 2>(Kind::Signed);
    say!(
        ctx,
        "let m = EulerLagrange::new(Spring::<{}> {{ m: {}, k: {} }});",
        ty::<T>(),
        lit(m),
        lit(k)
    );
    EulerLagrange::new(Spring { m, k })
}

pub fn cartesian<T: Real>(
    ctx: &mut Ctx,
) -> Result<Constrained<T, 1, CartesianPendulum<T>>, Verdict> {
    let [a, b, c] = ctx.values::<T, 3>(Kind::Param);
    say!(
        ctx,
        "let m = Constrained::new(CartesianPendulum::<{}>::new({}, {}, {})?);",
        ty::<T>(),
        lit(a),
        lit(b),
        lit(c)
    );
    Ok(Constrained::new(setup(
        CartesianPendulum::new(a, b, c),
        &["mass", "length", "gravity"],
    )?))
}

/// The value of a constructor, or the verdict of its error.
pub fn setup<V>(r: Result<V, Error>, params: &[&str]) -> Result<V, Verdict> {
    r.map_err(|e| crate::checks::refused(e, params))
}

/// Newton settings drawn, or the defaults.
pub fn newton<T: Real>(ctx: &mut Ctx) -> Result<(NewtonSettings<T>, String), Verdict> {
    if ctx.pick(2) == 0 {
        return Ok((
            NewtonSettings::default(),
            "NewtonSettings::default()".into(),
        ));
    }
    let tol = ctx.value::<T>(Kind::Tolerance);
    let n = u32::try_from(ctx.count()).unwrap_or(u32::MAX);
    let r = NewtonSettings::new(tol, n);
    match verdict(
        &r.map(|s| num(s.tolerance())),
        &["tolerance", "max_iterations"],
    ) {
        Verdict::Ok => r
            .map(|s| {
                (
                    s,
                    format!("NewtonSettings::<{}>::new({}, {n})?", ty::<T>(), lit(tol)),
                )
            })
            .map_err(Verdict::Error),
        v => Err(v),
    }
}

fn newton_settings<T: Real>(ctx: &mut Ctx) -> Verdict {
    let tol = ctx.value::<T>(Kind::Tolerance);
    let n = u32::try_from(ctx.count()).unwrap_or(u32::MAX);
    say!(
        ctx,
        "NewtonSettings::<{}>::new({}, {n})",
        ty::<T>(),
        lit(tol)
    );
    let r = NewtonSettings::new(tol, n);
    verdict(
        &r.map(|s| num(s.tolerance())),
        &["tolerance", "max_iterations"],
    )
}

/// An integrator and its expression in the reproducer.
pub type Made<I> = Result<(I, String), Verdict>;

// Generic like every maker, so that one macro calls them all.
#[allow(clippy::extra_unused_type_parameters)]
fn explicit_euler<T: Real, const N: usize>(_: &mut Ctx) -> Made<ExplicitEuler> {
    Ok((ExplicitEuler, "ExplicitEuler".into()))
}
// Generic like every maker, so that one macro calls them all.
#[allow(clippy::extra_unused_type_parameters)]
fn semi_implicit_euler<T: Real, const N: usize>(_: &mut Ctx) -> Made<SemiImplicitEuler> {
    Ok((SemiImplicitEuler, "SemiImplicitEuler".into()))
}
// Generic like every maker, so that one macro calls them all.
#[allow(clippy::extra_unused_type_parameters)]
fn velocity_verlet<T: Real, const N: usize>(_: &mut Ctx) -> Made<VelocityVerlet> {
    Ok((VelocityVerlet, "VelocityVerlet".into()))
}
// Generic like every maker, so that one macro calls them all.
#[allow(clippy::extra_unused_type_parameters)]
pub fn rk4<T: Real, const N: usize>(_: &mut Ctx) -> Made<Rk4> {
    Ok((Rk4, "Rk4".into()))
}
pub fn stormer<T: Real, const N: usize>(ctx: &mut Ctx) -> Made<StormerVerlet<T, N>> {
    let (s, e) = newton::<T>(ctx)?;
    Ok((
        StormerVerlet::new(s),
        format!("StormerVerlet::<{}, {N}>::new({e})", ty::<T>()),
    ))
}
pub fn yoshida<T: Real, const N: usize>(ctx: &mut Ctx) -> Made<Yoshida4<StormerVerlet<T, N>>> {
    let (b, e) = stormer::<T, N>(ctx)?;
    Ok((Yoshida4::new(b), format!("Yoshida4::new({e})")))
}
fn midpoint<T: Real, const N: usize>(ctx: &mut Ctx) -> Made<ImplicitMidpoint<T>> {
    let (s, e) = newton::<T>(ctx)?;
    Ok((
        ImplicitMidpoint::new(s),
        format!("ImplicitMidpoint::new({e})"),
    ))
}
fn gauss<T: Real, const N: usize>(ctx: &mut Ctx) -> Made<GaussLegendre2<T>> {
    let (s, e) = newton::<T>(ctx)?;
    Ok((GaussLegendre2::new(s), format!("GaussLegendre2::new({e})")))
}
fn backward<T: Real, const N: usize>(ctx: &mut Ctx) -> Made<BackwardEuler<T>> {
    let (s, e) = newton::<T>(ctx)?;
    Ok((BackwardEuler::new(s), format!("BackwardEuler::new({e})")))
}
fn radau<T: Real, const N: usize>(ctx: &mut Ctx) -> Made<RadauIIA2<T>> {
    let (s, e) = newton::<T>(ctx)?;
    Ok((RadauIIA2::new(s), format!("RadauIIA2::new({e})")))
}
fn variational<T: Real, const N: usize>(ctx: &mut Ctx) -> Made<VariationalMidpoint<T, N>> {
    let (s, e) = newton::<T>(ctx)?;
    Ok((
        VariationalMidpoint::new(s),
        format!("VariationalMidpoint::<{}, {N}>::new({e})", ty::<T>()),
    ))
}
fn yoshida_variational<T: Real, const N: usize>(
    ctx: &mut Ctx,
) -> Made<Yoshida4<VariationalMidpoint<T, N>>> {
    let (b, e) = variational::<T, N>(ctx)?;
    Ok((Yoshida4::new(b), format!("Yoshida4::new({e})")))
}

/// True when the two states are the same but for the rounding of their times (a step adds
/// `dt` once, a run sums it on a compensated clock).
fn same<T: Real, const N: usize>(a: &State<T, N>, b: &State<T, N>) -> bool {
    let bits = |x: &T| x.to_f64().to_bits();
    let slack = T::from_f64(4.0) * T::EPSILON * a.t.abs().max(b.t.abs());
    a.q.iter().map(bits).eq(b.q.iter().map(bits))
        && a.qd.iter().map(bits).eq(b.qd.iter().map(bits))
        && (a.t - b.t).abs() <= slack
}

/// One drawn use of the integrator `make` gives on `m`.
pub fn drive<T, M, I, const N: usize>(
    ctx: &mut Ctx,
    m: &M,
    make: fn(&mut Ctx) -> Made<I>,
) -> Verdict
where
    T: Real,
    M: Mechanism<T, N>,
    I: Integrator<T, N, M> + Clone,
{
    let (mut a, expr) = tryv!(make(ctx));
    say!(ctx, "let mut a = {expr};");
    let s = state::<T, N>(ctx, "s");
    let dt = ctx.value::<T>(Kind::Step);
    let params: &[&str] = &["dt", "state", "steps"];
    match ctx.pick(6) {
        0 => {
            say!(ctx, "a.step(&m, &s, {})", lit(dt));
            verdict(&a.step(m, &s, dt), params)
        }
        4 => {
            say!(ctx, "a.run_step(&m, &s, {})", lit(dt));
            verdict(&a.run_step(m, &s, dt), params)
        }
        5 => {
            // A step of a run is a step, but for a dt below the resolution of the time.
            let mut b = a.clone();
            say!(ctx, "let mut b = a.clone();");
            say!(ctx, "let one = a.step(&m, &s, {});", lit(dt));
            let one = a.step(m, &s, dt);
            say!(ctx, "let run = b.run_step(&m, &s, {});", lit(dt));
            let run = b.run_step(m, &s, dt);
            let v = verdict(&one, params);
            if v.class().is_finding() {
                return v;
            }
            let w = verdict(&run, params);
            if w.class().is_finding() {
                return w;
            }
            match (&one, &run) {
                (Ok(x), Ok(y)) if same(x, y) => v,
                (Err(e), Err(f)) if e == f => v,
                // Below the resolution of the time a step is refused; the run's step is
                // taken, and may fail for its own reasons (a step of 1e-45 s).
                (Err(Error::StepSizeUnderflow), _) => w,
                _ => Verdict::Inconsistent(format!("step {one:?}, run step {run:?}")),
            }
        }
        1 => {
            let n = ctx.count().min(MAX_RUN);
            say!(ctx, "a.integrate(&m, &s, {}, {n})", lit(dt));
            verdict(&a.integrate(m, &s, dt, n).map_err(|f| f.error), params)
        }
        2 => {
            let mut b = a.clone();
            say!(ctx, "let mut b = a.clone();");
            say!(ctx, "let one = a.step(&m, &s, {});", lit(dt));
            let one = a.step(m, &s, dt);
            say!(ctx, "let run = b.integrate(&m, &s, {}, 1);", lit(dt));
            let run = b.integrate(m, &s, dt, 1).map_err(|f| f.error);
            let v = verdict(&one, params);
            if v.class().is_finding() {
                return v;
            }
            let w = verdict(&run, params);
            if w.class().is_finding() {
                return w;
            }
            match (&one, &run) {
                (Ok(x), Ok(y)) if same(x, y) => v,
                (Err(e), Err(f)) if e == f => v,
                _ => Verdict::Inconsistent(format!("step {one:?}, one-step run {run:?}")),
            }
        }
        _ => {
            say!(ctx, "a.integrate(&m, &s, {}, 0)", lit(dt));
            let r = a.integrate(m, &s, dt, 0).map_err(|f| f.error);
            let v = verdict(&r, params);
            if v.class().is_finding() {
                return v;
            }
            let end = s.t + dt;
            let refusable = !(dt.is_finite()
                && dt > T::zero()
                && s.is_finite()
                && end != s.t
                && end.is_finite());
            match &r {
                Ok(x) if !refusable && x == &s => v,
                Err(_) if refusable => v,
                _ => Verdict::Inconsistent(format!("a run of no steps gave {r:?}")),
            }
        }
    }
}

/// The case of one integrator over the drawn mechanisms.
macro_rules! fixed_case {
    ($name:ident, $make:ident) => {
        fn $name<T: Real>(ctx: &mut Ctx) -> Verdict {
            match ctx.pick(5) {
                0 => {
                    let m = tryv!(pendulum::<T>(ctx));
                    drive(ctx, &m, $make::<T, 1>)
                }
                1 => {
                    let m = tryv!(double::<T>(ctx));
                    drive(ctx, &m, $make::<T, 2>)
                }
                2 => {
                    let m = tryv!(kepler::<T>(ctx));
                    drive(ctx, &m, $make::<T, 2>)
                }
                3 => {
                    let m = user_spring::<T>(ctx);
                    drive(ctx, &m, $make::<T, 1>)
                }
                _ => {
                    let m = tryv!(cartesian::<T>(ctx));
                    drive(ctx, &m, $make::<T, 2>)
                }
            }
        }
    };
}

fixed_case!(explicit_euler_case, explicit_euler);
fixed_case!(semi_implicit_euler_case, semi_implicit_euler);
fixed_case!(velocity_verlet_case, velocity_verlet);
fixed_case!(stormer_case, stormer);
fixed_case!(rk4_case, rk4);
fixed_case!(yoshida_case, yoshida);
fixed_case!(midpoint_case, midpoint);
fixed_case!(gauss_case, gauss);
fixed_case!(backward_case, backward);
fixed_case!(radau_case, radau);
fixed_case!(variational_case, variational);
fixed_case!(yoshida_variational_case, yoshida_variational);

/// A signed substep (what a composition takes) of a symmetric base, `h` of either sign.
fn signed<T: Real, B, M, const N: usize>(
    ctx: &mut Ctx,
    m: &M,
    make: fn(&mut Ctx) -> Made<B>,
) -> Verdict
where
    M: Mechanism<T, N>,
    B: SymmetricBase<T, N, M>,
{
    let (mut b, expr) = tryv!(make(ctx));
    say!(ctx, "let mut b = {expr};");
    let s = state::<T, N>(ctx, "s");
    let h = ctx.value::<T>(Kind::Step)
        * if ctx.pick(2) == 0 {
            T::one()
        } else {
            -T::one()
        };
    say!(ctx, "b.signed_step(&m, &s, {})", lit(h));
    verdict(&b.signed_step(m, &s, h), &["h", "state"])
}

fn symmetric<T: Real>(ctx: &mut Ctx) -> Verdict {
    let pendulum = |ctx: &mut Ctx| pendulum::<T>(ctx);
    match ctx.pick(4) {
        0 => {
            let m = tryv!(pendulum(ctx));
            signed(ctx, &m, stormer::<T, 1>)
        }
        1 => {
            let m = tryv!(double::<T>(ctx));
            signed(ctx, &m, midpoint::<T, 2>)
        }
        2 => {
            let m = user_spring::<T>(ctx);
            signed(ctx, &m, variational::<T, 1>)
        }
        _ => {
            let m = tryv!(double::<T>(ctx));
            signed(ctx, &m, stormer::<T, 2>)
        }
    }
}

/// The variational integrator's phase-space interface: momenta, a step in `(q, p)` and the
/// velocities back from momenta.
fn phase<T: Real>(ctx: &mut Ctx) -> Verdict {
    let m = if ctx.pick(2) == 0 {
        tryv!(double::<T>(ctx))
    } else {
        let [a, b] = ctx.values::<T, 2>(Kind::Param);
        say!(
            ctx,
            "let m = DoublePendulum::<{}>::new({}, {}, 1.0, 1.0, 9.81)?;",
            ty::<T>(),
            lit(a),
            lit(b)
        );
        tryv!(setup(
            DoublePendulum::new(a, b, T::one(), T::one(), T::from_f64(9.81)),
            &["m1", "m2", "l1", "l2", "gravity"]
        ))
    };
    let (mut v, expr) = tryv!(variational::<T, 2>(ctx));
    say!(ctx, "let mut v = {expr};");
    let s = state::<T, 2>(ctx, "s");
    say!(ctx, "let z = v.phase_state(&m, &s);");
    let z = v.phase_state(&m, &s);
    match ctx.pick(2) {
        0 => {
            let dt = ctx.value::<T>(Kind::Step);
            say!(ctx, "v.step_phase(&m, &z, {})", lit(dt));
            verdict(&v.step_phase(&m, &z, dt), &["dt", "phase"])
        }
        _ => {
            let (g, gs) = crate::checks::vector::<T, 2>(ctx, Kind::State);
            say!(ctx, "v.velocity_state(&m, &z, &{gs})");
            verdict(&v.velocity_state(&m, &z, &g), &["phase", "guess"])
        }
    }
}

/// The family.
pub fn family() -> Family {
    let mut v: Vec<Entry> = Vec::new();
    entries!(v, 0.3, "NewtonSettings::new", newton_settings);
    entries!(v, 1.0, "ExplicitEuler", explicit_euler_case);
    entries!(v, 1.0, "SemiImplicitEuler", semi_implicit_euler_case);
    entries!(v, 1.0, "VelocityVerlet", velocity_verlet_case);
    entries!(v, 1.0, "StormerVerlet", stormer_case);
    entries!(v, 1.0, "Rk4", rk4_case);
    entries!(v, 0.7, "Yoshida4<StormerVerlet>", yoshida_case);
    entries!(v, 0.5, "ImplicitMidpoint", midpoint_case);
    entries!(v, 0.4, "GaussLegendre2", gauss_case);
    entries!(v, 0.5, "BackwardEuler", backward_case);
    entries!(v, 0.4, "RadauIIA2", radau_case);
    entries!(v, 0.5, "VariationalMidpoint", variational_case);
    entries!(
        v,
        0.3,
        "Yoshida4<VariationalMidpoint>",
        yoshida_variational_case
    );
    entries!(v, 0.5, "SymmetricBase::signed_step", symmetric);
    entries!(v, 0.5, "VariationalMidpoint phase space", phase);
    Family {
        name: "fixed-step",
        entries: v,
    }
}
