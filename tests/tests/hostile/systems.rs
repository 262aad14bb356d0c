//! Family `systems`: every standard mechanism's constructor with drawn parameters, then one of
//! its `Result` methods (acceleration, with an input, the mass solve, the law, its force and
//! its Jacobian) or one without an error channel (energies, `rhs`, mass matrix: no panic) at a
//! drawn state.

use crate::checks::{state, vector, verdict};
use crate::harness::{lit, lits, ty, Ctx, Entry, Family, Verdict};
use crate::values::Kind;
use crate::{call, entries, say};
use lagrange_core::{Input, Mechanism, NoForce, Real};
use lagrange_systems::{
    Acrobot, BeadOnRotatingHoop, CartPole, CartesianPendulum, DoublePendulum, ElasticPendulum,
    FallingParticle, FourBarLinkage, Kepler, NLinkPendulum, RollingDisk, SimplePendulum,
    SphericalPendulum, SpringMassDamper, SwingingAtwood,
};

/// One of a mechanism's methods at a drawn state, `m` being its name in the reproducer.
pub fn exercise<T: Real, M: Mechanism<T, N>, const N: usize>(ctx: &mut Ctx, m: &M) -> Verdict {
    let s = state::<T, N>(ctx, "s");
    match ctx.pick(10) {
        0 => {
            say!(ctx, "m.acceleration(&s)");
            verdict(&m.acceleration(&s), &["state"])
        }
        1 => {
            let (f, fs) = vector::<T, N>(ctx, Kind::Signed);
            say!(ctx, "m.acceleration_with(&s, &Input {{ value: {fs} }})");
            verdict(
                &m.acceleration_with(&s, &Input { value: f }),
                &["state", "extra"],
            )
        }
        2 => {
            let (b, bs) = vector::<T, N>(ctx, Kind::Signed);
            say!(ctx, "m.solve_mass(&s, &{bs})");
            verdict(&m.solve_mass(&s, &b), &["state", "b"])
        }
        3 => {
            say!(ctx, "m.law(&s, &NoForce)");
            verdict(&m.law(&s, &NoForce), &["state", "extra"])
        }
        4 => {
            let (f, fs) = vector::<T, N>(ctx, Kind::Signed);
            say!(ctx, "m.law_force(&s, &Input {{ value: {fs} }})");
            verdict(&m.law_force(&s, &Input { value: f }), &["state", "extra"])
        }
        5 => {
            say!(ctx, "m.acceleration_jacobian(&s)");
            verdict(&m.acceleration_jacobian(&s), &["state"])
        }
        6 => {
            let (f, fs) = vector::<T, N>(ctx, Kind::Signed);
            say!(ctx, "m.law_jacobian(&s, &Input {{ value: {fs} }})");
            verdict(
                &m.law_jacobian(&s, &Input { value: f }),
                &["state", "extra"],
            )
        }
        // No error channel: documented to return NaN or infinity for extreme input, never
        // to panic.
        7 => {
            say!(ctx, "m.energy(&s)");
            let _ = m.energy(&s);
            Verdict::Ok
        }
        8 => {
            say!(ctx, "m.rhs(&s)");
            let _ = m.rhs(&s);
            Verdict::Ok
        }
        _ => {
            say!(ctx, "m.mass_matrix(&s)");
            let _ = m.mass_matrix(&s);
            Verdict::Ok
        }
    }
}

fn falling_particle<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [a, b] = ctx.values::<T, 2>(Kind::Param);
    say!(
        ctx,
        "let m = FallingParticle::<{}>::new({}, {})?;",
        ty::<T>(),
        lit(a),
        lit(b)
    );
    let m = call!(FallingParticle::new(a, b), &["mass", "gravity"]);
    exercise(ctx, &m)
}

fn simple_pendulum<T: Real>(ctx: &mut Ctx) -> Verdict {
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
    let m = call!(
        SimplePendulum::new(a, b, c, d),
        &["mass", "length", "gravity", "damping"]
    );
    exercise(ctx, &m)
}

fn hoop<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [a, b] = ctx.values::<T, 2>(Kind::Param);
    let w = ctx.value::<T>(Kind::Signed);
    let g = ctx.value::<T>(Kind::Param);
    say!(
        ctx,
        "let m = BeadOnRotatingHoop::<{}>::new({}, {}, {}, {})?;",
        ty::<T>(),
        lit(a),
        lit(b),
        lit(w),
        lit(g)
    );
    let m = call!(
        BeadOnRotatingHoop::new(a, b, w, g),
        &["mass", "radius", "omega", "gravity"]
    );
    if ctx.pick(4) == 0 {
        let s = state::<T, 1>(ctx, "s");
        say!(ctx, "m.jacobi_integral(&s)");
        let _ = m.jacobi_integral(&s);
        return Verdict::Ok;
    }
    exercise(ctx, &m)
}

fn double_pendulum<T: Real>(ctx: &mut Ctx) -> Verdict {
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
    let m = call!(
        DoublePendulum::new(a, b, c, d, e),
        &["m1", "m2", "l1", "l2", "gravity"]
    );
    exercise(ctx, &m)
}

fn chain<T: Real, const N: usize>(ctx: &mut Ctx) -> Verdict {
    let masses = ctx.values::<T, N>(Kind::Param);
    let lengths = ctx.values::<T, N>(Kind::Param);
    let g = ctx.value::<T>(Kind::Param);
    say!(
        ctx,
        "let m = NLinkPendulum::<{}, {N}>::new({}, {}, {})?;",
        ty::<T>(),
        lits(&masses),
        lits(&lengths),
        lit(g)
    );
    let m = call!(
        NLinkPendulum::new(masses, lengths, g),
        &["masses", "lengths", "gravity"]
    );
    if ctx.pick(5) == 0 {
        let s = state::<T, N>(ctx, "s");
        say!(ctx, "m.positions(&s.q)");
        let _ = m.positions(&s.q);
        return Verdict::Ok;
    }
    exercise(ctx, &m)
}

fn chain3<T: Real>(ctx: &mut Ctx) -> Verdict {
    chain::<T, 3>(ctx)
}

fn chain6<T: Real>(ctx: &mut Ctx) -> Verdict {
    chain::<T, 6>(ctx)
}

fn spring<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [a, b, c] = ctx.values::<T, 3>(Kind::Param);
    say!(
        ctx,
        "let m = SpringMassDamper::<{}>::new({}, {}, {})?;",
        ty::<T>(),
        lit(a),
        lit(b),
        lit(c)
    );
    let m = call!(
        SpringMassDamper::new(a, b, c),
        &["mass", "stiffness", "damping"]
    );
    exercise(ctx, &m)
}

fn elastic<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [a, b, c, d] = ctx.values::<T, 4>(Kind::Param);
    say!(
        ctx,
        "let m = ElasticPendulum::<{}>::new({}, {}, {}, {})?;",
        ty::<T>(),
        lit(a),
        lit(b),
        lit(c),
        lit(d)
    );
    let m = call!(
        ElasticPendulum::new(a, b, c, d),
        &["mass", "stiffness", "rest_length", "gravity"]
    );
    exercise(ctx, &m)
}

fn spherical<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [a, b, c] = ctx.values::<T, 3>(Kind::Param);
    say!(
        ctx,
        "let m = SphericalPendulum::<{}>::new({}, {}, {})?;",
        ty::<T>(),
        lit(a),
        lit(b),
        lit(c)
    );
    let m = call!(
        SphericalPendulum::new(a, b, c),
        &["mass", "length", "gravity"]
    );
    if ctx.pick(5) == 0 {
        let s = state::<T, 2>(ctx, "s");
        say!(ctx, "m.angular_momentum(&s)");
        let _ = m.angular_momentum(&s);
        return Verdict::Ok;
    }
    exercise(ctx, &m)
}

fn cart_pole<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [a, b, c, d] = ctx.values::<T, 4>(Kind::Param);
    say!(
        ctx,
        "let mut m = CartPole::<{}>::new({}, {}, {}, {})?;",
        ty::<T>(),
        lit(a),
        lit(b),
        lit(c),
        lit(d)
    );
    let mut m = call!(
        CartPole::new(a, b, c, d),
        &["cart_mass", "pole_mass", "pole_half_length", "gravity"]
    );
    if ctx.pick(2) == 0 {
        let f = ctx.value::<T>(Kind::Signed);
        say!(ctx, "m.set_force({})?;", lit(f));
        let before = m.force();
        let r = m.set_force(f);
        if r.is_err() && m.force().to_bits_u64() != before.to_bits_u64() {
            return Verdict::Changed(format!("force {before:?} -> {:?}", m.force()));
        }
        call!(r, &["force"]);
    }
    exercise(ctx, &m)
}

fn acrobot<T: Real>(ctx: &mut Ctx) -> Verdict {
    let p = ctx.values::<T, 9>(Kind::Param);
    say!(
        ctx,
        "let mut m = Acrobot::<{}>::new({})?;",
        ty::<T>(),
        p.map(lit).join(", ")
    );
    let names = ["m1", "m2", "l1", "l2", "lc1", "lc2", "i1", "i2", "gravity"];
    let mut m = call!(
        Acrobot::new(p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8]),
        &names
    );
    if ctx.pick(2) == 0 {
        let tau = ctx.value::<T>(Kind::Signed);
        say!(ctx, "m.set_torque({})?;", lit(tau));
        let before = m.torque();
        let r = m.set_torque(tau);
        if r.is_err() && m.torque().to_bits_u64() != before.to_bits_u64() {
            return Verdict::Changed(format!("torque {before:?} -> {:?}", m.torque()));
        }
        call!(r, &["torque"]);
    }
    if ctx.pick(5) == 0 {
        let s = state::<T, 2>(ctx, "s");
        say!(ctx, "m.tip(&s)");
        let _ = m.tip(&s);
        return Verdict::Ok;
    }
    exercise(ctx, &m)
}

fn atwood<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [a, b, c] = ctx.values::<T, 3>(Kind::Param);
    say!(
        ctx,
        "let m = SwingingAtwood::<{}>::new({}, {}, {})?;",
        ty::<T>(),
        lit(a),
        lit(b),
        lit(c)
    );
    let m = call!(
        SwingingAtwood::new(a, b, c),
        &["big_mass", "small_mass", "gravity"]
    );
    exercise(ctx, &m)
}

fn kepler<T: Real>(ctx: &mut Ctx) -> Verdict {
    let mu = ctx.value::<T>(Kind::Param);
    say!(ctx, "let m = Kepler::<{}>::new({})?;", ty::<T>(), lit(mu));
    let m = call!(Kepler::new(mu), &["mu"]);
    exercise(ctx, &m)
}

/// The open chain of each constrained mechanism (its parts), as a mechanism.
fn cartesian_parts<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [a, b, c] = ctx.values::<T, 3>(Kind::Param);
    say!(
        ctx,
        "let m = CartesianPendulum::<{}>::new({}, {}, {})?;",
        ty::<T>(),
        lit(a),
        lit(b),
        lit(c)
    );
    let m = call!(
        CartesianPendulum::new(a, b, c),
        &["mass", "length", "gravity"]
    );
    if ctx.pick(4) == 0 {
        let [t, th, thd] = ctx.values::<T, 3>(Kind::State);
        say!(
            ctx,
            "m.state_from_angle({}, {}, {})",
            lit(t),
            lit(th),
            lit(thd)
        );
        let s = m.state_from_angle(t, th, thd);
        say!(ctx, "m.angle(&s)");
        let _ = m.angle(&s);
        return Verdict::Ok;
    }
    exercise(ctx, &m)
}

fn four_bar_parts<T: Real>(ctx: &mut Ctx) -> Verdict {
    let lengths = ctx.values::<T, 4>(Kind::Param);
    let masses = ctx.values::<T, 3>(Kind::Param);
    let g = ctx.value::<T>(Kind::Param);
    say!(
        ctx,
        "let m = FourBarLinkage::<{}>::new({}, {}, {})?;",
        ty::<T>(),
        lits(&lengths),
        lits(&masses),
        lit(g)
    );
    let m = call!(
        FourBarLinkage::new(lengths, masses, g),
        &["lengths", "masses", "gravity"]
    );
    exercise(ctx, &m)
}

fn rolling_disk_parts<T: Real>(ctx: &mut Ctx) -> Verdict {
    let [a, b] = ctx.values::<T, 2>(Kind::Param);
    say!(
        ctx,
        "let m = RollingDisk::<{}>::new({}, {})?;",
        ty::<T>(),
        lit(a),
        lit(b)
    );
    let m = call!(RollingDisk::new(a, b), &["mass", "radius"]);
    exercise(ctx, &m)
}

/// Bits of a scalar, for comparing a field before and after a refused change.
trait Bits {
    fn to_bits_u64(self) -> u64;
}

impl<T: Real> Bits for T {
    fn to_bits_u64(self) -> u64 {
        self.to_f64().to_bits()
    }
}

/// A generated mechanism of crate lagrange-generated (`cargo xtask derive`): its validated
/// constructor with drawn parameters, then one of its methods.
macro_rules! generated {
    ($name:ident, $ty:ident, $n:literal, [$($i:literal),*], [$($param:literal),*]) => {
        fn $name<T: Real>(ctx: &mut Ctx) -> Verdict {
            let p = ctx.values::<T, $n>(Kind::Param);
            say!(
                ctx,
                "let m = lagrange_generated::{}::<{}>::new{}?;",
                stringify!($ty),
                ty::<T>(),
                lits(&p).replace('[', "(").replace(']', ")")
            );
            let m = call!(lagrange_generated::$ty::new($(p[$i]),*), &[$($param),*]);
            exercise(ctx, &m)
        }
    };
}

generated!(
    gen_pendulum,
    Pendulum,
    4,
    [0, 1, 2, 3],
    ["m", "l", "g", "b"]
);
generated!(
    gen_double,
    DoublePendulum,
    5,
    [0, 1, 2, 3, 4],
    ["m1", "m2", "l1", "l2", "g"]
);
generated!(
    gen_spring_cart,
    SpringCartPendulum,
    6,
    [0, 1, 2, 3, 4, 5],
    ["m_cart", "m", "k", "c", "l", "g"]
);
generated!(
    gen_triple,
    TriplePendulum,
    7,
    [0, 1, 2, 3, 4, 5, 6],
    ["m1", "m2", "m3", "l1", "l2", "l3", "g"]
);
generated!(
    gen_kapitza,
    KapitzaPendulum,
    5,
    [0, 1, 2, 3, 4],
    ["m", "l", "g", "a", "w"]
);
generated!(
    gen_cartesian,
    CartesianPendulum,
    3,
    [0, 1, 2],
    ["m", "l", "g"]
);

/// The family.
pub fn family() -> Family {
    let mut v: Vec<Entry> = Vec::new();
    entries!(v, 1.0, "FallingParticle", falling_particle);
    entries!(v, 1.0, "SimplePendulum", simple_pendulum);
    entries!(v, 1.0, "BeadOnRotatingHoop", hoop);
    entries!(v, 1.0, "DoublePendulum", double_pendulum);
    entries!(v, 1.0, "NLinkPendulum<3>", chain3);
    entries!(v, 0.5, "NLinkPendulum<6>", chain6);
    entries!(v, 1.0, "SpringMassDamper", spring);
    entries!(v, 1.0, "ElasticPendulum", elastic);
    entries!(v, 1.0, "SphericalPendulum", spherical);
    entries!(v, 1.0, "CartPole", cart_pole);
    entries!(v, 1.0, "Acrobot", acrobot);
    entries!(v, 1.0, "SwingingAtwood", atwood);
    entries!(v, 1.0, "Kepler", kepler);
    entries!(v, 1.0, "CartesianPendulum (parts)", cartesian_parts);
    entries!(v, 1.0, "FourBarLinkage (parts)", four_bar_parts);
    entries!(v, 1.0, "RollingDisk (parts)", rolling_disk_parts);
    entries!(v, 0.5, "generated Pendulum", gen_pendulum);
    entries!(v, 0.5, "generated DoublePendulum", gen_double);
    entries!(v, 0.5, "generated SpringCartPendulum", gen_spring_cart);
    entries!(v, 0.5, "generated TriplePendulum", gen_triple);
    entries!(v, 0.5, "generated KapitzaPendulum", gen_kapitza);
    entries!(v, 0.5, "generated CartesianPendulum", gen_cartesian);
    Family {
        name: "systems",
        entries: v,
    }
}
