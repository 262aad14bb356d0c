//! Family `exact`: the closed-form reference solutions of `lagrange_systems::exact`, every
//! argument drawn.

use crate::checks::{num, pair, verdict};
use crate::harness::{lit, ty, Ctx, Entry, Family, Verdict};
use crate::values::Kind;
use crate::{call, entries, say};
use lagrange_core::Real;
use lagrange_systems::exact::{
    damped_oscillator, eccentric_anomaly, elliptic_k, jacobi_sn_cn, kepler_orbit,
    pendulum_from_rest, pendulum_period, DrivenOscillator,
};

/// A modulus: in `[0, 1)` mostly, its edges and nasty values otherwise.
fn modulus<T: Real>(ctx: &mut Ctx) -> T {
    if ctx.pick(3) == 0 {
        ctx.value::<T>(Kind::Signed)
    } else {
        ctx.value::<T>(Kind::Tolerance)
    }
}

/// An angle: ordinary, or drawn from everything.
fn angle<T: Real>(ctx: &mut Ctx) -> T {
    ctx.value::<T>(Kind::State)
}

fn k<T: Real>(ctx: &mut Ctx) -> Verdict {
    let k = modulus::<T>(ctx);
    say!(ctx, "elliptic_k::<{}>({})", ty::<T>(), lit(k));
    verdict(&elliptic_k(k).map(num), &["k"])
}

fn sn_cn<T: Real>(ctx: &mut Ctx) -> Verdict {
    let u = ctx.value::<T>(Kind::Signed);
    let k = modulus::<T>(ctx);
    say!(ctx, "jacobi_sn_cn::<{}>({}, {})", ty::<T>(), lit(u), lit(k));
    verdict(&jacobi_sn_cn(u, k).map(pair), &["u", "k"])
}

fn from_rest<T: Real>(ctx: &mut Ctx) -> Verdict {
    let theta0 = angle::<T>(ctx);
    let omega = ctx.value::<T>(Kind::Param);
    let t = ctx.value::<T>(Kind::Time);
    say!(
        ctx,
        "pendulum_from_rest::<{}>({}, {}, {})",
        ty::<T>(),
        lit(theta0),
        lit(omega),
        lit(t)
    );
    verdict(
        &pendulum_from_rest(theta0, omega, t).map(pair),
        &["theta0", "omega", "t"],
    )
}

fn period<T: Real>(ctx: &mut Ctx) -> Verdict {
    let theta0 = angle::<T>(ctx);
    let omega = ctx.value::<T>(Kind::Param);
    say!(
        ctx,
        "pendulum_period::<{}>({}, {})",
        ty::<T>(),
        lit(theta0),
        lit(omega)
    );
    verdict(
        &pendulum_period(theta0, omega).map(num),
        &["theta0", "omega"],
    )
}

fn damped<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [m, k, c] = ctx.values::<T, 3>(Kind::Param);
    let [x0, v0] = ctx.values::<T, 2>(Kind::State);
    let t = if ctx.pick(2) == 0 {
        ctx.value::<T>(Kind::Time)
    } else {
        ctx.value::<T>(Kind::Signed)
    };
    say!(
        ctx,
        "damped_oscillator::<{}>({}, {}, {}, {}, {}, {})",
        ty::<T>(),
        lit(m),
        lit(k),
        lit(c),
        lit(x0),
        lit(v0),
        lit(t)
    );
    verdict(
        &damped_oscillator(m, k, c, x0, v0, t).map(pair),
        &["mass", "stiffness", "damping", "x0", "v0", "t"],
    )
}

fn driven<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [m, k, c] = ctx.values::<T, 3>(Kind::Param);
    let f0 = ctx.value::<T>(Kind::Signed);
    let w = ctx.value::<T>(Kind::Param);
    say!(
        ctx,
        "let osc = DrivenOscillator::<{}>::new({}, {}, {}, {}, {})?;",
        ty::<T>(),
        lit(m),
        lit(k),
        lit(c),
        lit(f0),
        lit(w)
    );
    let osc = call!(
        DrivenOscillator::new(m, k, c, f0, w),
        &["mass", "stiffness", "damping", "amplitude", "omega"]
    );
    let [x0, v0] = ctx.values::<T, 2>(Kind::State);
    let t = ctx.value::<T>(Kind::Time);
    say!(ctx, "osc.state({}, {}, {})", lit(x0), lit(v0), lit(t));
    verdict(&osc.state(x0, v0, t).map(pair), &["x0", "v0", "t"])
}

fn anomaly<T: Real>(ctx: &mut Ctx) -> Verdict {
    let m = ctx.value::<T>(Kind::Signed);
    let e = modulus::<T>(ctx);
    say!(
        ctx,
        "eccentric_anomaly::<{}>({}, {})",
        ty::<T>(),
        lit(m),
        lit(e)
    );
    verdict(
        &eccentric_anomaly(m, e).map(num),
        &["mean_anomaly", "eccentricity"],
    )
}

fn orbit<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [mu, a] = ctx.values::<T, 2>(Kind::Param);
    let e = modulus::<T>(ctx);
    let t = ctx.value::<T>(Kind::Time);
    say!(
        ctx,
        "kepler_orbit::<{}>({}, {}, {}, {})",
        ty::<T>(),
        lit(mu),
        lit(a),
        lit(e),
        lit(t)
    );
    verdict(
        &kepler_orbit(mu, a, e, t),
        &["mu", "semi_major_axis", "eccentricity", "t"],
    )
}

/// The family.
pub fn family() -> Family {
    let mut v: Vec<Entry> = Vec::new();
    entries!(v, 0.5, "exact::elliptic_k", k);
    entries!(v, 0.5, "exact::jacobi_sn_cn", sn_cn);
    entries!(v, 0.5, "exact::pendulum_from_rest", from_rest);
    entries!(v, 0.5, "exact::pendulum_period", period);
    entries!(v, 0.5, "exact::damped_oscillator", damped);
    entries!(v, 0.5, "exact::DrivenOscillator", driven);
    entries!(v, 0.5, "exact::eccentric_anomaly", anomaly);
    entries!(v, 0.5, "exact::kepler_orbit", orbit);
    Family {
        name: "exact",
        entries: v,
    }
}
