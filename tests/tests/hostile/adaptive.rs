//! Family `adaptive`: `AdaptiveSettings` and its builders, and sequences of calls of the
//! adaptive pairs, now and then holding the energy: `integrate_to`, `next_step`, the landing
//! `step`, `integrate_until_event` with a guard that may return NaN, `dense_output`, from
//! continued, repeated and new states, with end times at their edges (an ulp away, before the
//! start, huge, NaN). After every error the integrator's observable state (step size, dense
//! interval and output) must be as before.

use crate::checks::{state, verdict};
use crate::core::Spring;
use crate::fixed_step::{double, kepler, pendulum, setup, user_spring};
use crate::harness::{lit, ty, Ctx, Entry, Family, Verdict};
use crate::values::Kind;
use crate::{entries, say, tryv};
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Mechanism, Real, State};
use lagrange_integrators::{
    AdaptiveSettings, Dop853Pair, Dopri5Pair, EmbeddedPair, EmbeddedRungeKutta, Integrator,
    Verner76Pair, Verner98Pair,
};
use lagrange_systems::FallingParticle;

/// Settings drawn: tolerances at their edges, and each builder now and then (the energy
/// projection only where `projecting` may be drawn: its callers then allow the error that
/// names the mechanism). The step limit is kept small most of the time (a long run is not a
/// hang).
pub fn settings<T: Real>(ctx: &mut Ctx, projecting: bool) -> Result<AdaptiveSettings<T>, Verdict> {
    let [rtol, atol] = ctx.values::<T, 2>(Kind::Tolerance);
    say!(
        ctx,
        "let settings = AdaptiveSettings::<{}>::new({}, {})?;",
        ty::<T>(),
        lit(rtol),
        lit(atol)
    );
    let mut s = checked(AdaptiveSettings::new(rtol, atol), &["rtol", "atol"])?;
    if ctx.pick(3) == 0 {
        let [lo, hi] = ctx.values::<T, 2>(Kind::Step);
        say!(
            ctx,
            "let settings = settings.with_step_bounds({}, {})?;",
            lit(lo),
            lit(hi)
        );
        s = checked(s.with_step_bounds(lo, hi), &["h_min", "h_max"])?;
    }
    if ctx.pick(3) == 0 {
        let h = ctx.value::<T>(Kind::Step);
        say!(
            ctx,
            "let settings = settings.with_initial_step({})?;",
            lit(h)
        );
        s = checked(s.with_initial_step(h), &["h_initial"])?;
    }
    if ctx.pick(3) == 0 {
        let e = ctx.value::<T>(Kind::Tolerance);
        say!(
            ctx,
            "let settings = settings.with_event_tolerance({})?;",
            lit(e)
        );
        s = checked(s.with_event_tolerance(e), &["event_tolerance"])?;
    }
    if projecting && ctx.pick(4) == 0 {
        say!(ctx, "let settings = settings.with_energy_projection();");
        s = s.with_energy_projection();
    }
    if ctx.pick(20) != 0 {
        let n = ctx.count().min(2000);
        say!(ctx, "let settings = settings.with_max_steps({n})?;");
        s = checked(s.with_max_steps(n), &["max_steps"])?;
    }
    Ok(s)
}

/// The settings, or the verdict of their error; their numbers must be finite (`h_max` may be
/// infinite, never NaN).
fn checked<T: Real>(
    r: Result<AdaptiveSettings<T>, lagrange_core::Error>,
    params: &[&str],
) -> Result<AdaptiveSettings<T>, Verdict> {
    let numbers = r.map(|s| {
        let h_max = if s.h_max().partial_cmp(&T::zero()).is_some() {
            T::one()
        } else {
            s.h_max()
        };
        SVector::<T, 6>::from([
            s.rtol(),
            s.atol(),
            s.h_min(),
            s.h_initial().unwrap_or(T::one()),
            s.event_tolerance(),
            h_max,
        ])
    });
    match verdict(&numbers, params) {
        Verdict::Ok => r.map_err(Verdict::Error),
        v => Err(v),
    }
}

fn settings_case<T: Real>(ctx: &mut Ctx) -> Verdict {
    match settings::<T>(ctx, true) {
        Ok(_) => Verdict::Ok,
        Err(v) => v,
    }
}

/// What a caller can see of an adaptive integrator: its next step size, its dense interval
/// and the dense output at the interval's ends and middle.
fn observe<T: Real, const N: usize, const S: usize, const R: usize, P: EmbeddedPair<S, R>>(
    rk: &EmbeddedRungeKutta<T, N, S, R, P>,
) -> String {
    let interval = rk.dense_interval();
    let samples = interval
        .map(|(a, b)| [a, (a + b) * T::HALF, b].map(|t| format!("{:?}", rk.dense_output(t))));
    format!("{:?} {interval:?} {samples:?}", rk.step_size())
}

/// An end time after `from`: a drawn span, an ulp, the start itself, or drawn outright.
fn end<T: Real>(ctx: &mut Ctx, from: T) -> T {
    match ctx.pick(5) {
        0 => from + ctx.value::<T>(Kind::Step),
        1 => from + ctx.value::<T>(Kind::Step) * T::from_f64(100.0),
        2 => {
            // The next float above from (an ulp, or a subnormal step at zero).
            let up = from + from.abs() * T::EPSILON * T::HALF;
            if up > from {
                up
            } else {
                from + from.abs().max(T::MIN_POSITIVE) * T::EPSILON
            }
        }
        3 => from,
        _ => ctx.value::<T>(Kind::Time),
    }
}

/// A sequence of calls of the pair `P` on `m`; `damped` where `m` has a non-conservative
/// force, which a run holding the energy refuses by naming the mechanism.
fn sequence<T, M, P, const N: usize, const S: usize, const R: usize>(
    ctx: &mut Ctx,
    m: &M,
    pair: &str,
    damped: bool,
) -> Verdict
where
    T: Real,
    M: Mechanism<T, N>,
    P: EmbeddedPair<S, R>,
{
    let settings = tryv!(settings::<T>(ctx, true));
    // Holding the energy, a damped mechanism is refused by name; a conservative one never.
    let with = |params: &[&'static str]| -> Vec<&'static str> {
        let mut all = params.to_vec();
        if damped && settings.energy_projection() {
            all.push("mechanism");
        }
        all
    };
    say!(
        ctx,
        "let mut rk = {pair}::<{}, {N}>::new(settings);",
        ty::<T>()
    );
    let mut rk = EmbeddedRungeKutta::<T, N, S, R, P>::new(settings);
    let start = state::<T, N>(ctx, "s0");
    let mut last: Option<State<T, N>> = None;
    for call in 0..=ctx.pick(4) {
        let from = match (ctx.pick(3), last) {
            (0, Some(l)) => {
                say!(ctx, "let s = last;");
                l
            }
            (1, _) => {
                say!(ctx, "let s = s0;");
                start
            }
            _ => state::<T, N>(ctx, "s"),
        };
        if ctx.pick(8) == 0 {
            say!(ctx, "rk.restart();");
            rk.restart();
        }
        let before = observe(&rk);
        let (v, out) = match ctx.pick(5) {
            0 => {
                let t_end = end(ctx, from.t);
                say!(ctx, "let last = rk.integrate_to(&m, &s, {})?;", lit(t_end));
                let r = rk.integrate_to(m, &from, t_end).map_err(|f| f.error);
                (verdict(&r, &with(&["state", "t_end"])), r.ok())
            }
            1 => {
                let t_end = end(ctx, from.t);
                say!(ctx, "let last = rk.next_step(&m, &s, {})?;", lit(t_end));
                let r = rk.next_step(m, &from, t_end);
                let v = verdict(&r, &with(&["state", "t_end"]));
                // One accepted step: the time moves, and the returned state lies in the dense
                // interval it leaves.
                let stepped = |s: &State<T, N>| {
                    s.t > from.t
                        && rk
                            .dense_interval()
                            .is_some_and(|(a, b)| a <= s.t && s.t <= b)
                };
                match &r {
                    Ok(s) if v == Verdict::Ok && !stepped(s) => {
                        let dense = rk.dense_interval();
                        return Verdict::Broken(format!(
                            "next_step from t = {:?} to {t_end:?} returned t = {:?} with dense interval {dense:?}",
                            from.t, s.t
                        ));
                    }
                    _ => (v, r.ok()),
                }
            }
            2 => {
                let dt = ctx.value::<T>(Kind::Step);
                say!(ctx, "let last = rk.step(&m, &s, {})?;", lit(dt));
                let r = rk.step(m, &from, dt);
                (verdict(&r, &with(&["dt", "state"])), r.ok())
            }
            3 => {
                let t_end = end(ctx, from.t);
                let c = ctx.value::<T>(Kind::State);
                let nan = ctx.pick(8) == 0;
                say!(
                    ctx,
                    "let last = rk.integrate_until_event(&m, &s, {}, |s| {})?;",
                    lit(t_end),
                    if nan {
                        format!("{}::NAN", ty::<T>())
                    } else {
                        format!("s.q[0] - {}", lit(c))
                    }
                );
                let guard = move |s: &State<T, N>| {
                    if nan {
                        T::from_f64(f64::NAN)
                    } else {
                        s.q[0] - c
                    }
                };
                let r = rk
                    .integrate_until_event(m, &from, t_end, guard)
                    .map_err(|f| f.error);
                let v = verdict(&r, &with(&["state", "t_end", "guard"]));
                (v, r.ok().map(|stop| *stop.state()))
            }
            _ => {
                let t = match (rk.dense_interval(), ctx.pick(2)) {
                    (Some((a, b)), 0) => a + (b - a) * T::from_f64(0.37),
                    _ => ctx.value::<T>(Kind::Time),
                };
                say!(ctx, "rk.dense_output({})", lit(t));
                let r = rk.dense_output(t);
                (verdict(&r, &["t"]), None)
            }
        };
        if v.class().is_finding() {
            return v;
        }
        // The step size it will try next is finite (it may be zero before any step).
        if !rk.step_size().is_finite() {
            return Verdict::Silent(format!("step size {:?} after call {call}", rk.step_size()));
        }
        if let Verdict::Error(e) = v {
            let after = observe(&rk);
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

/// The case of one pair over the drawn mechanisms.
macro_rules! adaptive_case {
    ($name:ident, $pair:ty, $s:literal, $r:literal, $alias:literal) => {
        fn $name<T: Real>(ctx: &mut Ctx) -> Verdict {
            match ctx.pick(5) {
                0 => {
                    let m = tryv!(pendulum::<T>(ctx));
                    let damped = m.damping() != T::zero();
                    sequence::<T, _, $pair, 1, $s, $r>(ctx, &m, $alias, damped)
                }
                1 => {
                    let [a, b] = ctx.values::<T, 2>(Kind::Param);
                    say!(
                        ctx,
                        "let m = FallingParticle::<{}>::new({}, {})?;",
                        ty::<T>(),
                        lit(a),
                        lit(b)
                    );
                    let m = tryv!(setup(FallingParticle::new(a, b), &["mass", "gravity"]));
                    sequence::<T, _, $pair, 1, $s, $r>(ctx, &m, $alias, false)
                }
                2 => {
                    let m = tryv!(double::<T>(ctx));
                    sequence::<T, _, $pair, 2, $s, $r>(ctx, &m, $alias, false)
                }
                3 => {
                    let m: lagrange_core::EulerLagrange<T, 1, Spring<T>> = user_spring::<T>(ctx);
                    sequence::<T, _, $pair, 1, $s, $r>(ctx, &m, $alias, false)
                }
                _ => {
                    let m = tryv!(kepler::<T>(ctx));
                    sequence::<T, _, $pair, 2, $s, $r>(ctx, &m, $alias, false)
                }
            }
        }
    };
}

adaptive_case!(dopri5, Dopri5Pair, 7, 1, "DormandPrince54");
adaptive_case!(dop853, Dop853Pair, 16, 4, "DormandPrince853");
adaptive_case!(verner76, Verner76Pair, 11, 2, "Verner76");
adaptive_case!(verner98, Verner98Pair, 17, 2, "Verner98");

/// The family.
pub fn family() -> Family {
    let mut v: Vec<Entry> = Vec::new();
    entries!(v, 0.5, "AdaptiveSettings", settings_case);
    entries!(v, 0.6, "DormandPrince54 calls", dopri5);
    entries!(v, 0.4, "DormandPrince853 calls", dop853);
    entries!(v, 0.3, "Verner76 calls", verner76);
    entries!(v, 0.3, "Verner98 calls", verner98);
    Family {
        name: "adaptive",
        entries: v,
    }
}
