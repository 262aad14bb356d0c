//! Family `scenes`: the scene API of lagrange-integrators. `FrameClock` (frames of every
//! length, resets, a step that fails, a huge frame and then frames of `dt`), the `Sleeps`
//! settings, and sessions of a `Scene` over a `Bank` of each kind (mechanisms that gather and
//! step in lanes on x86_64 and one that does not; `Rk4` and `SemiImplicitEuler`, which step
//! lanes, and `StormerVerlet`, which does not; never sleeping and sleeping): drawn sequences
//! of frames and of every per-instance call, with stale and foreign ids and a full bank.
//!
//! After every call: no panic or hang; no `Ok` with a non-finite state, drawn state or energy;
//! errors name the call's own parameter; a call that fails leaves the bank and the scene as
//! they were (every call but a frame whose clock overflows promises it); a stale id gets
//! `NoSuchInstance`; a sleeper rests (zero velocities); a frame of exactly `dt` after a huge
//! frame takes one step; and where the integrator keeps nothing between steps and the bank
//! never sleeps, a frame of one step gives every awake instance, bit for bit, what the
//! integrator's own `run_step` gives it alone (lanes or not), or sets it aside with that
//! step's error.

use crate::checks::{refused, state, vector, verdict};
use crate::harness::{lit, lits, ty, Ctx, Entry, Family, Verdict};
use crate::values::Kind;
use crate::{entries, say};
use lagrange_core::Projection;
use lagrange_core::{Error, Forced, Input, Lanes, Mechanism, Real, Scalar, State};
use lagrange_integrators::scene::{Bank, Id, NeverSleeps, Scene, Sleep, Sleeps, Status};
use lagrange_integrators::{ContactModel, ContactStepper};
use lagrange_integrators::{
    FrameClock, Integrator, NewtonSettings, Rk4, SemiImplicitEuler, StormerVerlet,
};
use lagrange_systems::{
    Acrobot, CartPole, DoublePendulum, FallingParticle, Ragdoll, RagdollBody, RagdollContacts,
    SimplePendulum, SpringMassDamper, RAGDOLL_CONTACTS, RAGDOLL_COORDINATES,
};
use std::fmt::Debug;

/// The capacity of the banks: one chunk of 8 lanes and a remainder of 3.
const K: usize = 11;

/// A frame time for a clock of step `dt`: a fraction of a step to a few steps, `dt`, a drawn
/// step, or anything.
fn frame_time<T: Real>(ctx: &mut Ctx, dt: T) -> T {
    match ctx.pick(5) {
        0 => dt * ctx.value::<T>(Kind::Param),
        1 | 2 => dt,
        3 => ctx.value::<T>(Kind::Step),
        _ => ctx.value::<T>(Kind::Signed),
    }
}

/// A huge frame time: the largest value, half of it, a long pause, or a huge number of steps.
fn huge<T: Real>(ctx: &mut Ctx, dt: T) -> T {
    match ctx.pick(4) {
        0 => T::MAX,
        1 => T::MAX * T::HALF,
        2 => T::from_f64(3600.0),
        _ => dt * T::from_f64(2f64.powi(ctx.pick(40) as i32 + 10)),
    }
}

/// The `FrameClock`: new, frames (some of whose steps fail), resets, a huge frame then frames
/// of `dt`.
fn frame_clock<T: Real>(ctx: &mut Ctx) -> Verdict {
    let dt = ctx.value::<T>(Kind::Step);
    let cap = u32::try_from(ctx.count()).unwrap_or(u32::MAX).min(64);
    let t0 = ctx.value::<T>(Kind::Time);
    say!(
        ctx,
        "let mut c = FrameClock::new({}, {cap}, {})?;",
        lit(dt),
        lit(t0)
    );
    let mut c = match FrameClock::new(dt, cap, t0) {
        Ok(c) => c,
        Err(e) => return refused(e, &["dt", "max_steps_per_frame", "t0"]),
    };
    let mut after_huge = false;
    for call in 0..=ctx.pick(8) {
        let before = c;
        let op = ctx.pick(6);
        if op == 0 {
            let t = ctx.value::<T>(Kind::Time);
            say!(ctx, "c.reset({})?;", lit(t));
            let v = verdict(&c.reset(t), &["t"]);
            if v.class().is_finding() {
                return v;
            }
            if matches!(v, Verdict::Error(_)) && c != before {
                return Verdict::Changed(format!("reset({t:?}): {before:?} -> {c:?}"));
            }
            after_huge = false;
            continue;
        }
        let f = match op {
            1 => huge(ctx, dt),
            2 if after_huge => dt,
            _ => frame_time(ctx, dt),
        };
        // A step fails now and then: the frame stops there.
        let fail_at = if ctx.pick(6) == 0 {
            ctx.pick(4) as u32
        } else {
            u32::MAX
        };
        say!(ctx, "c.advance({}, |t| ...)", lit(f));
        let (mut k, mut last, mut bad) = (0u32, before.time(), None);
        let r = c.advance(f, |t| {
            if !(t.is_finite() && t >= last) {
                bad = Some(format!("step {k} at {t:?} after {last:?}"));
            }
            if k == fail_at {
                return Err(Error::StepSizeUnderflow);
            }
            last = t;
            k += 1;
            Ok(())
        });
        if let Some(b) = bad {
            return Verdict::Inconsistent(format!("call {call}: {b}"));
        }
        let v = verdict(&r, &["frame_time"]);
        if v.class().is_finding() {
            return v;
        }
        if !(c.alpha() >= T::zero() && c.alpha() <= T::one() && c.time().is_finite()) {
            return Verdict::Silent(format!("call {call}: {c:?}"));
        }
        match r {
            Ok(frame) => {
                if frame.steps > cap
                    || frame.steps != k
                    || frame
                        .dropped
                        .partial_cmp(&T::zero())
                        .is_none_or(|o| o.is_lt())
                {
                    return Verdict::Inconsistent(format!("call {call}: {frame:?}, cap {cap}"));
                }
                // A frame of exactly dt after a huge one takes one step: the huge one
                // corrupted nothing.
                if after_huge && f == dt && frame.steps != 1 {
                    return Verdict::Inconsistent(format!(
                        "call {call}: a frame of dt after a huge one took {frame:?}"
                    ));
                }
                after_huge = op == 1 || (after_huge && f == dt);
            }
            Err(Error::InvalidParameter { .. }) => {
                if c != before {
                    return Verdict::Changed(format!("advance({f:?}): {before:?} -> {c:?}"));
                }
            }
            Err(_) => after_huge = false,
        }
    }
    Verdict::Ok
}

/// A sleep rule drawn: the usual one, or drawn thresholds, interval and driven flag.
fn rule<T: Real>(ctx: &mut Ctx) -> Result<Sleeps<T>, Verdict> {
    if ctx.pick(3) == 0 {
        say!(
            ctx,
            "let rule = Sleeps::<{}>::new(1e-6, 1e-3, 8)?;",
            ty::<T>()
        );
        return Sleeps::new(T::from_f64(1e-6), T::from_f64(1e-3), 8).map_err(Verdict::Error);
    }
    let [kinetic, acceleration] = ctx.values::<T, 2>(Kind::Tolerance);
    let steps = u32::try_from(ctx.count()).unwrap_or(u32::MAX);
    say!(
        ctx,
        "let rule = Sleeps::<{}>::new({}, {}, {steps})?;",
        ty::<T>(),
        lit(kinetic),
        lit(acceleration)
    );
    let mut r = Sleeps::new(kinetic, acceleration, steps)
        .map_err(|e| refused(e, &["kinetic", "acceleration", "steps"]))?;
    if ctx.pick(2) == 0 {
        let every = u32::try_from(ctx.count()).unwrap_or(u32::MAX);
        say!(ctx, "let rule = rule.checked_every({every})?;");
        r = r
            .checked_every(every)
            .map_err(|e| refused(e, &["interval"]))?;
    }
    if ctx.pick(2) == 0 {
        say!(ctx, "let rule = rule.even_when_driven();");
        r = r.even_when_driven();
    }
    Ok(r)
}

/// The `Sleeps` settings alone: what is accepted reads back as given.
fn sleeps<T: Real>(ctx: &mut Ctx) -> Verdict {
    match rule::<T>(ctx) {
        Err(v) => v,
        Ok(r) => {
            let fine = r.kinetic().is_finite()
                && r.kinetic() >= T::zero()
                && r.acceleration().is_finite()
                && r.acceleration() >= T::zero()
                && r.interval() >= 1
                && r.interval() <= r.steps();
            if fine {
                Verdict::Ok
            } else {
                Verdict::Silent(format!("{r:?}"))
            }
        }
    }
}

/// A mechanism a bank holds in the campaign: how to draw one, and its input if it has one.
trait Piece<T: Real, const N: usize>: Mechanism<T, N> + Clone + PartialEq + Debug {
    /// A mechanism of drawn parameters (with its reproducer line), and the names of the
    /// constructor's parameters.
    fn draw(ctx: &mut Ctx) -> (Result<Self, Error>, &'static [&'static str]);

    /// Sets a drawn input through the bank, when the mechanism has one: the result, and the
    /// parameter names the call may give.
    fn input<I, Z>(
        _ctx: &mut Ctx,
        _bank: &mut Bank<T, N, K, Self, I, Z>,
        _id: Id,
    ) -> Option<Result<(), Error>>
    where
        I: Integrator<T, N, Self> + Clone,
        Z: Sleep<T>,
    {
        None
    }
}

/// `Piece::draw` for a constructor of the parameters `$i` (kind Param) named `$name`.
macro_rules! piece {
    ($ty:ident, $n:literal, [$($i:literal),*], [$($name:literal),*]) => {
        fn draw(ctx: &mut Ctx) -> (Result<Self, Error>, &'static [&'static str]) {
            let p = ctx.values::<T, $n>(Kind::Param);
            say!(ctx, "let m = {}::<{}>::new{}?;", stringify!($ty), ty::<T>(),
                lits(&p).replace('[', "(").replace(']', ")"));
            ($ty::new($(p[$i]),*), &[$($name),*])
        }
    };
}

impl<T: Real> Piece<T, 1> for SimplePendulum<T> {
    piece!(
        SimplePendulum,
        4,
        [0, 1, 2, 3],
        ["mass", "length", "gravity", "damping"]
    );
}

impl<T: Real> Piece<T, 2> for DoublePendulum<T> {
    piece!(
        DoublePendulum,
        5,
        [0, 1, 2, 3, 4],
        ["m1", "m2", "l1", "l2", "gravity"]
    );
}

impl<T: Real> Piece<T, 1> for SpringMassDamper<T> {
    piece!(
        SpringMassDamper,
        3,
        [0, 1, 2],
        ["mass", "stiffness", "damping"]
    );
}

impl<T: Real> Piece<T, 1> for FallingParticle<T> {
    piece!(FallingParticle, 2, [0, 1], ["mass", "gravity"]);
}

impl<T: Real> Piece<T, 2> for CartPole<T> {
    piece!(
        CartPole,
        4,
        [0, 1, 2, 3],
        ["cart_mass", "pole_mass", "pole_half_length", "gravity"]
    );
    fn input<I, Z>(
        ctx: &mut Ctx,
        bank: &mut Bank<T, 2, K, Self, I, Z>,
        id: Id,
    ) -> Option<Result<(), Error>>
    where
        I: Integrator<T, 2, Self> + Clone,
        Z: Sleep<T>,
    {
        let u = ctx.value::<T>(Kind::Signed);
        say!(ctx, "bank.set_input(id, {})", lit(u));
        Some(bank.set_input(id, u))
    }
}

impl<T: Real> Piece<T, 2> for Acrobot<T> {
    piece!(
        Acrobot,
        9,
        [0, 1, 2, 3, 4, 5, 6, 7, 8],
        ["m1", "m2", "l1", "l2", "lc1", "lc2", "i1", "i2", "gravity"]
    );
    fn input<I, Z>(
        ctx: &mut Ctx,
        bank: &mut Bank<T, 2, K, Self, I, Z>,
        id: Id,
    ) -> Option<Result<(), Error>>
    where
        I: Integrator<T, 2, Self> + Clone,
        Z: Sleep<T>,
    {
        let u = ctx.value::<T>(Kind::Signed);
        say!(ctx, "bank.set_input(id, {})", lit(u));
        Some(bank.set_input(id, u))
    }
}

/// A pendulum with an input torque (`Forced` does not gather: stepped one by one).
type Driven<T> = Forced<SimplePendulum<T>, Input<T, 1>>;

impl<T: Real> Piece<T, 1> for Driven<T> {
    fn draw(ctx: &mut Ctx) -> (Result<Self, Error>, &'static [&'static str]) {
        let (m, names) = <SimplePendulum<T> as Piece<T, 1>>::draw(ctx);
        let u = ctx.value::<T>(Kind::Signed);
        say!(ctx, "let m = m.with_force(Input::new([{}]));", lit(u));
        (m.map(|m| m.with_force(Input::new([u]))), names)
    }
    fn input<I, Z>(
        ctx: &mut Ctx,
        bank: &mut Bank<T, 1, K, Self, I, Z>,
        id: Id,
    ) -> Option<Result<(), Error>>
    where
        I: Integrator<T, 1, Self> + Clone,
        Z: Sleep<T>,
    {
        let (u, us) = vector::<T, 1>(ctx, Kind::Signed);
        say!(ctx, "bank.set_input(id, {us})");
        Some(bank.set_input(id, u))
    }
}

/// Everything a caller can see of a scene: the bank (every instance, its integrator and
/// what it keeps), the clock's alpha and time.
fn observe<T: Real, B: lagrange_integrators::scene::Banks<T> + Debug>(
    scene: &Scene<T, B>,
) -> String {
    format!(
        "{:?} alpha {:?} time {:?}",
        scene.banks(),
        scene.alpha().to_f64().to_bits(),
        scene.time().to_f64().to_bits()
    )
}

/// The bits of a state.
fn bits<T: Real, const N: usize>(s: &State<T, N>) -> Vec<u64> {
    core::iter::once(s.t)
        .chain(s.q.iter().copied())
        .chain(s.qd.iter().copied())
        .map(|x| x.to_f64().to_bits())
        .collect()
}

/// `Bank::add_asleep`, where the bank sleeps.
type AddAsleep<T, const N: usize, M, I, Z> =
    fn(&mut Bank<T, N, K, M, I, Z>, M, [T; N]) -> Result<Id, Error>;

/// What a session of a bank needs besides its mechanism: its integrator, its sleep rule, how
/// to add a sleeper (banks that sleep), and whether the integrator keeps nothing between
/// steps (then a step of the bank is checked against the integrator's own).
struct Kit<T: Real, const N: usize, M, I, Z> {
    integrator: fn(&mut Ctx) -> (I, String),
    sleep: fn(&mut Ctx) -> Result<Z, Verdict>,
    asleep: Option<AddAsleep<T, N, M, I, Z>>,
    stateless: bool,
}

// Generic like every maker, so that one kit type takes them all.
#[allow(clippy::extra_unused_type_parameters)]
fn rk4<T: Real>(_: &mut Ctx) -> (Rk4, String) {
    (Rk4, "Rk4".into())
}
#[allow(clippy::extra_unused_type_parameters)]
fn euler<T: Real>(_: &mut Ctx) -> (SemiImplicitEuler, String) {
    (SemiImplicitEuler, "SemiImplicitEuler".into())
}
fn stormer<T: Real, const N: usize>(ctx: &mut Ctx) -> (StormerVerlet<T, N>, String) {
    // Newton settings drawn, or the defaults (a refused one: the defaults).
    match crate::fixed_step::newton::<T>(ctx) {
        Ok((s, e)) => (StormerVerlet::new(s), format!("StormerVerlet::new({e})")),
        Err(_) => (
            StormerVerlet::new(NewtonSettings::default()),
            "StormerVerlet::default()".into(),
        ),
    }
}
// Generic like every maker, so that one kit type takes them all.
#[allow(clippy::extra_unused_type_parameters)]
fn never<T: Real>(ctx: &mut Ctx) -> Result<NeverSleeps, Verdict> {
    say!(ctx, "let rule = NeverSleeps;");
    Ok(NeverSleeps)
}

/// The id a call is given: a live one, a stale one (removed), one of another bank, or none.
fn pick_id(ctx: &mut Ctx, live: &[Id], stale: &[Id], foreign: Option<Id>) -> Option<(Id, bool)> {
    match ctx.pick(8) {
        0 if !stale.is_empty() => Some((stale[ctx.pick(stale.len())], false)),
        1 => foreign.map(|f| (f, false)),
        _ if !live.is_empty() => Some((live[ctx.pick(live.len())], true)),
        _ => stale.last().map(|&s| (s, false)),
    }
}

/// A session of a scene over one bank: adds, frames and every per-instance call, drawn.
fn session<T, const N: usize, M, I, Z>(ctx: &mut Ctx, kit: &Kit<T, N, M, I, Z>) -> Verdict
where
    T: Real,
    M: Piece<T, N>,
    I: Integrator<T, N, M> + Clone + Debug,
    Z: Sleep<T> + Debug,
{
    let (integrator, expr) = (kit.integrator)(ctx);
    let sleep = match (kit.sleep)(ctx) {
        Ok(z) => z,
        Err(v) => return v,
    };
    say!(
        ctx,
        "let mut bank: Bank<{}, {N}, {K}, _, _, _> = Bank::new({expr}, rule)?;",
        ty::<T>()
    );
    let mut bank: Bank<T, N, K, M, I, Z> = match Bank::new(integrator.clone(), sleep) {
        Ok(b) => b,
        Err(e) => return Verdict::Error(e),
    };
    let mut live: Vec<Id> = Vec::new();
    let mut stale: Vec<Id> = Vec::new();
    let mut foreign = None;
    // Adds before the scene starts, a few past the capacity.
    for _ in 0..ctx.pick(K + 3) {
        let (m, names) = M::draw(ctx);
        let m = match m {
            Ok(m) => m,
            Err(e) => match refused(e, names) {
                v @ Verdict::WrongName(_) => return v,
                _ => continue,
            },
        };
        if foreign.is_none() {
            let mut other: Bank<T, N, 1, M, I, Z> = match Bank::new(integrator.clone(), sleep) {
                Ok(b) => b,
                Err(e) => return Verdict::Error(e),
            };
            foreign = other.add(m.clone(), State::at_rest([T::zero(); N])).ok();
        }
        let s = state::<T, N>(ctx, "s");
        say!(ctx, "let id = bank.add(m, s)?;");
        let before = format!("{bank:?}");
        match bank.add(m, s) {
            Ok(id) => live.push(id),
            Err(e) => {
                if format!("{bank:?}") != before {
                    return Verdict::Changed(format!("add failed with {e:?}"));
                }
                let expected = if s.is_finite() {
                    Error::BankFull { capacity: K }
                } else {
                    Error::NonFiniteState
                };
                if e != expected || (live.len() < K && s.is_finite()) {
                    return Verdict::Inconsistent(format!(
                        "add of {s:?} to a bank of {} failed with {e:?}",
                        live.len()
                    ));
                }
            }
        }
    }
    let dt = ctx.value::<T>(Kind::Step);
    let cap = u32::try_from(ctx.count()).unwrap_or(u32::MAX).min(16);
    say!(
        ctx,
        "let mut scene = Scene::new(bank, {}, {cap})?;",
        lit(dt)
    );
    let mut scene = match Scene::new(bank, dt, cap) {
        Ok(s) => s,
        Err(e) => return refused(e, &["dt", "max_steps_per_frame"]),
    };
    if scene.banks().iter().any(|(_, s)| s.t != T::zero()) {
        return Verdict::Inconsistent("an instance's time is not the new scene's 0".into());
    }
    let mut after_huge = false;
    for call in 0..=ctx.pick(24) {
        let before = observe(&scene);
        let op = ctx.pick(15);
        // Frames.
        if op <= 3 {
            let f = match op {
                0 => huge(ctx, dt),
                1 if after_huge => dt,
                _ => frame_time(ctx, dt),
            };
            // Where a step can be checked against the integrator's own: the instances awake
            // before the frame.
            let reference: Vec<(Id, State<T, N>, M)> = if kit.stateless && kit.asleep.is_none() {
                let bank = scene.banks();
                bank.iter()
                    .filter(|(id, _)| bank.status(*id) == Ok(Status::Awake))
                    .filter_map(|(id, s)| Some((id, s, bank.mechanism(id).ok()?.clone())))
                    .collect()
            } else {
                Vec::new()
            };
            say!(ctx, "scene.advance({})?;", lit(f));
            let r = scene.advance(f);
            let v = verdict(
                &r.map(|fr| fr.dropped).map(crate::checks::num),
                &["frame_time"],
            );
            if v.class().is_finding() {
                return v;
            }
            match r {
                Err(e @ Error::InvalidParameter { .. }) => {
                    if observe(&scene) != before {
                        return Verdict::Changed(format!("call {call}: advance failed with {e:?}"));
                    }
                }
                Err(_) => after_huge = false,
                Ok(frame) => {
                    if frame.steps > cap
                        || scene
                            .alpha()
                            .partial_cmp(&T::zero())
                            .is_none_or(|o| o.is_lt())
                        || scene.alpha() > T::one()
                    {
                        return Verdict::Inconsistent(format!(
                            "call {call}: {frame:?}, cap {cap}, alpha {:?}",
                            scene.alpha()
                        ));
                    }
                    if after_huge && f == dt && frame.steps != 1 {
                        return Verdict::Inconsistent(format!(
                            "call {call}: a frame of dt after a huge one took {frame:?}"
                        ));
                    }
                    after_huge = op == 0 || (after_huge && f == dt);
                    if frame.steps == 1 {
                        let (bank, time) = (scene.banks(), scene.time());
                        if let Some(v) = against_reference(bank, time, &reference, &integrator, dt)
                        {
                            return v;
                        }
                    }
                }
            }
        } else if op == 4 {
            // An add (asleep, where the bank sleeps, now and then).
            let (m, names) = M::draw(ctx);
            let m = match m {
                Ok(m) => m,
                Err(e) => match refused(e, names) {
                    v @ Verdict::WrongName(_) => return v,
                    _ => continue,
                },
            };
            let s = state::<T, N>(ctx, "s");
            let r = match kit.asleep {
                Some(asleep) if ctx.pick(2) == 0 => {
                    say!(
                        ctx,
                        "let id = bank.add_asleep(m, {})?;",
                        lits(s.q.as_slice())
                    );
                    asleep(scene.banks_mut(), m, s.q.into())
                }
                _ => {
                    say!(ctx, "let id = bank.add(m, s)?;");
                    scene.banks_mut().add(m, s)
                }
            };
            match r {
                Ok(id) => {
                    if live.len() >= K {
                        return Verdict::Inconsistent(format!("add to a full bank gave {id:?}"));
                    }
                    live.push(id);
                }
                Err(e) => {
                    if observe(&scene) != before {
                        return Verdict::Changed(format!("call {call}: add failed with {e:?}"));
                    }
                    if e == (Error::BankFull { capacity: K }) && live.len() < K {
                        return Verdict::Inconsistent(format!(
                            "call {call}: BankFull with {} instances",
                            live.len()
                        ));
                    }
                }
            }
        } else {
            // A call on one instance.
            let Some((id, valid)) = pick_id(ctx, &live, &stale, foreign) else {
                continue;
            };
            say!(ctx, "let id = {id:?};");
            let (r, params): (Result<(), Error>, &[&str]) = match op {
                5 => {
                    say!(ctx, "bank.remove(id)?;");
                    let r = scene.banks_mut().remove(id);
                    if let Ok((_, s)) = &r {
                        if !s.is_finite() {
                            return Verdict::Silent(format!("removed {s:?}"));
                        }
                        live.retain(|&l| l != id);
                        stale.push(id);
                    }
                    (r.map(|_| ()), &[])
                }
                6 => {
                    let alpha = match ctx.pick(3) {
                        0 => scene.alpha(),
                        1 => ctx.value::<T>(Kind::Tolerance),
                        _ => ctx.value::<T>(Kind::Signed),
                    };
                    say!(ctx, "bank.interpolated(id, {})?;", lit(alpha));
                    let r = scene.banks().interpolated(id, alpha);
                    let v = verdict(&r, &["alpha"]);
                    if v.class().is_finding() {
                        return v;
                    }
                    (r.map(|_| ()), &["alpha"])
                }
                7 => {
                    let s = state::<T, N>(ctx, "s");
                    say!(ctx, "bank.set_state(id, s)?;");
                    (scene.banks_mut().set_state(id, s), &["state"])
                }
                8 => {
                    let (p, ps) = vector::<T, N>(ctx, Kind::Signed);
                    say!(ctx, "bank.apply_impulse(id, &{ps})?;");
                    (scene.banks_mut().apply_impulse(id, &p), &["impulse"])
                }
                9 => match M::input(ctx, scene.banks_mut(), id) {
                    Some(r) => (r, &["input"]),
                    None => continue,
                },
                10 => {
                    // New parameters, or a change that refuses.
                    let (m, names) = M::draw(ctx);
                    say!(ctx, "bank.modify(id, |x| {{ *x = m; Ok(()) }})?;");
                    let r = scene.banks_mut().modify(id, move |x| {
                        *x = m?;
                        Ok(())
                    });
                    (r, names)
                }
                11 => {
                    if ctx.pick(2) == 0 {
                        say!(ctx, "bank.wake(id)?;");
                        (scene.banks_mut().wake(id), &[])
                    } else {
                        say!(ctx, "bank.contact(id)?;");
                        (scene.banks_mut().contact(id), &[])
                    }
                }
                12 => {
                    say!(ctx, "bank.energies(id)?;");
                    let r = scene.banks().energies(id);
                    let v = verdict(
                        &r.map(|e| crate::checks::pair((e.kinetic, e.potential))),
                        &[],
                    );
                    if v.class().is_finding() {
                        return v;
                    }
                    (r.map(|_| ()), &[])
                }
                13 => {
                    say!(ctx, "bank.status(id)?;");
                    let bank = scene.banks();
                    let r = bank.status(id);
                    if let (Ok(status), Ok(s)) = (r, bank.state(id)) {
                        if status == Status::Asleep && s.qd.iter().any(|&x| x != T::zero()) {
                            return Verdict::Inconsistent(format!("asleep at {s:?}"));
                        }
                    }
                    (r.and(bank.mechanism(id).map(|_| ())), &[])
                }
                _ => {
                    say!(ctx, "bank.state(id)?;");
                    let r = scene.banks().state(id);
                    let v = verdict(&r, &[]);
                    if v.class().is_finding() {
                        return v;
                    }
                    (r.map(|_| ()), &[])
                }
            };
            let v = verdict(&r, params);
            if v.class().is_finding() {
                return v;
            }
            if let Err(e) = r {
                if observe(&scene) != before {
                    return Verdict::Changed(format!("call {call} (op {op}) failed with {e:?}"));
                }
                if !valid && e != Error::NoSuchInstance {
                    return Verdict::Inconsistent(format!(
                        "call {call} (op {op}) on a stale or foreign id gave {e:?}"
                    ));
                }
            } else if !valid {
                return Verdict::Inconsistent(format!(
                    "call {call} (op {op}) on a stale or foreign id succeeded"
                ));
            }
        }
        // Whatever happened, every state held is finite.
        if let Some((id, s)) = scene.banks().iter().find(|(_, s)| !s.is_finite()) {
            return Verdict::Silent(format!("call {call}: instance {id:?} holds {s:?}"));
        }
        if scene.banks().len() != live.len() {
            return Verdict::Inconsistent(format!(
                "call {call}: {} instances, {} ids live",
                scene.banks().len(),
                live.len()
            ));
        }
    }
    Verdict::Ok
}

/// After a frame of one step: every instance awake before it holds what the integrator's
/// own `run_step` gives it alone (at the scene's time `time`), or failed with that step's
/// error and kept its state.
fn against_reference<T, const N: usize, M, I, Z>(
    bank: &Bank<T, N, K, M, I, Z>,
    time: T,
    reference: &[(Id, State<T, N>, M)],
    integrator: &I,
    dt: T,
) -> Option<Verdict>
where
    T: Real,
    M: Piece<T, N>,
    I: Integrator<T, N, M> + Clone,
    Z: Sleep<T>,
{
    for (id, s, m) in reference {
        let alone = integrator.clone().run_step(m, s, dt);
        let (Ok(now), Ok(status)) = (bank.state(*id), bank.status(*id)) else {
            return Some(Verdict::Inconsistent(format!("{id:?} lost in a frame")));
        };
        let fine = match alone {
            Ok(n) => status == Status::Awake && bits(&now) == bits(&State { t: time, ..n }),
            Err(e) => status == Status::Failed(e) && bits(&now) == bits(s),
        };
        if !fine {
            return Some(Verdict::Inconsistent(format!(
                "{m:?} from {s:?} by {dt:?}: alone {alone:?}, in the bank {status:?} {now:?}"
            )));
        }
    }
    None
}

/// A session of a scene over a bank of `M` stepped by `$integrator`, sleeping by `$sleep`.
macro_rules! bank_case {
    ($name:ident, $m:ident, $n:literal, $integrator:ident, never, $stateless:expr) => {
        fn $name<T: Real>(ctx: &mut Ctx) -> Verdict {
            let kit: Kit<T, $n, $m<T>, _, NeverSleeps> = Kit {
                integrator: $integrator::<T>,
                sleep: never::<T>,
                asleep: None,
                stateless: $stateless,
            };
            session(ctx, &kit)
        }
    };
    ($name:ident, $m:ident, $n:literal, $integrator:ident, sleeps, $stateless:expr) => {
        fn $name<T: Real>(ctx: &mut Ctx) -> Verdict {
            let kit: Kit<T, $n, $m<T>, _, Sleeps<T>> = Kit {
                integrator: $integrator::<T>,
                sleep: rule::<T>,
                asleep: Some(|b, m, q| b.add_asleep(m, q)),
                stateless: $stateless,
            };
            session(ctx, &kit)
        }
    };
}

fn stormer1<T: Real>(ctx: &mut Ctx) -> (StormerVerlet<T, 1>, String) {
    stormer::<T, 1>(ctx)
}

bank_case!(pendulums_rk4, SimplePendulum, 1, rk4, never, true);
bank_case!(
    pendulums_stormer,
    SimplePendulum,
    1,
    stormer1,
    sleeps,
    false
);
bank_case!(doubles_euler, DoublePendulum, 2, euler, sleeps, true);
bank_case!(carts_rk4, CartPole, 2, rk4, sleeps, true);
bank_case!(acrobots_euler, Acrobot, 2, euler, never, true);
bank_case!(
    springs_stormer,
    SpringMassDamper,
    1,
    stormer1,
    sleeps,
    false
);
bank_case!(particles_euler, FallingParticle, 1, euler, never, true);
bank_case!(driven_stormer, Driven, 1, stormer1, never, false);
bank_case!(driven_rk4, Driven, 1, rk4, sleeps, true);

/// A ragdoll of a drawn body (fields left at the adult's or drawn, as in the `ragdoll`
/// family); an error may name any of the body's fields.
impl<T: Real> Piece<T, RAGDOLL_COORDINATES> for Ragdoll<T> {
    fn draw(ctx: &mut Ctx) -> (Result<Self, Error>, &'static [&'static str]) {
        let (b, _) = crate::ragdoll::body::<T>(ctx);
        say!(ctx, "let m = Ragdoll::new(b)?;");
        (Ragdoll::new(b), &crate::ragdoll::FIELDS)
    }
}

/// A contact stepper over `Rk4` for the adult's floor at zero and joint limits, with the
/// ragdoll test's model and projection.
type DollStepper<T> =
    ContactStepper<T, RAGDOLL_COORDINATES, RAGDOLL_CONTACTS, Rk4, RagdollContacts<T>>;

fn doll_stepper<T: Real>(ctx: &mut Ctx) -> (DollStepper<T>, String) {
    let adult = RagdollBody::<T>::adult();
    let made = Ragdoll::new(adult).and_then(|doll| {
        Ok(ContactStepper::new(
            Rk4,
            RagdollContacts::adult(&doll, T::zero())?,
            ContactModel::new(T::from_f64(0.3), T::from_f64(0.3), T::from_f64(1e-6))?
                .with_friction(T::from_f64(0.8))?,
            Projection::new(T::from_f64(1e-6), 8)?,
        ))
    });
    let Ok(stepper) = made else {
        unreachable!("the adult's stepper is valid");
    };
    say!(ctx, "let stepper = ContactStepper::new(Rk4, RagdollContacts::adult(&Ragdoll::new(RagdollBody::adult())?, 0.0)?, ContactModel::new(0.3, 0.3, 1e-6)?.with_friction(0.8)?, Projection::new(1e-6, 8)?);");
    (stepper, "stepper".into())
}

fn ragdolls_contacts<T: Real>(ctx: &mut Ctx) -> Verdict {
    let kit: Kit<T, RAGDOLL_COORDINATES, Ragdoll<T>, _, Sleeps<T>> = Kit {
        integrator: doll_stepper::<T>,
        sleep: rule::<T>,
        asleep: Some(|b, m, q| b.add_asleep(m, q)),
        stateless: false,
    };
    session(ctx, &kit)
}

/// Adds up to `K` drawn instances to `bank` (refusals by name only).
fn fill<T, const N: usize, M, I, Z>(
    ctx: &mut Ctx,
    bank: &mut Bank<T, N, K, M, I, Z>,
) -> Result<(), Verdict>
where
    T: Real,
    M: Piece<T, N>,
    I: Integrator<T, N, M> + Clone,
    Z: Sleep<T>,
{
    for _ in 0..ctx.pick(K + 1) {
        let (m, names) = M::draw(ctx);
        match m {
            Ok(m) => {
                let s = state::<T, N>(ctx, "s");
                say!(ctx, "let _ = bank.add(m, s);");
                let _ = bank.add(m, s);
            }
            Err(e) => {
                if let v @ Verdict::WrongName(_) = refused(e, names) {
                    return Err(v);
                }
            }
        }
    }
    Ok(())
}

/// Frames of a scene of several banks: every frame's verdict, every state held finite, and
/// a frame of `dt` after a huge one takes one step.
fn frames_of<T: Real, B: lagrange_integrators::scene::Banks<T> + Debug>(
    ctx: &mut Ctx,
    scene: &mut Scene<T, B>,
    finite: impl Fn(&B) -> bool,
) -> Verdict {
    let dt = scene.dt();
    let mut after_huge = false;
    for call in 0..=ctx.pick(12) {
        let before = observe(scene);
        let op = ctx.pick(4);
        let f = match op {
            0 => huge(ctx, dt),
            1 if after_huge => dt,
            _ => frame_time(ctx, dt),
        };
        say!(ctx, "scene.advance({})?;", lit(f));
        let r = scene.advance(f);
        let v = verdict(
            &r.map(|fr| fr.dropped).map(crate::checks::num),
            &["frame_time"],
        );
        if v.class().is_finding() {
            return v;
        }
        match r {
            Err(e @ Error::InvalidParameter { .. }) => {
                if observe(scene) != before {
                    return Verdict::Changed(format!("call {call}: advance failed with {e:?}"));
                }
            }
            Err(_) => after_huge = false,
            Ok(frame) => {
                if after_huge && f == dt && frame.steps != 1 {
                    return Verdict::Inconsistent(format!(
                        "call {call}: a frame of dt after a huge one took {frame:?}"
                    ));
                }
                after_huge = op == 0 || (after_huge && f == dt);
            }
        }
        if !finite(scene.banks()) {
            return Verdict::Silent(format!("call {call}: {:?}", scene.banks()));
        }
    }
    Verdict::Ok
}

/// True when every state `bank` holds is finite.
fn all_finite<T, const N: usize, M, I, Z>(bank: &Bank<T, N, K, M, I, Z>) -> bool
where
    T: Real,
    M: Mechanism<T, N>,
    I: Integrator<T, N, M> + Clone,
    Z: Sleep<T>,
{
    bank.iter().all(|(_, s)| s.is_finite())
}

/// Scenes of several banks: a tuple of banks of different types and integrators (lanes and
/// not, sleeping and not), an array of banks, and banks borrowed (`&mut`).
fn many_banks<T: Real>(ctx: &mut Ctx) -> Verdict {
    let dt = ctx.value::<T>(Kind::Step);
    let cap = u32::try_from(ctx.count()).unwrap_or(u32::MAX).min(16);
    let rule = match rule::<T>(ctx) {
        Ok(r) => r,
        Err(v) => return v,
    };
    let made = (|| {
        let mut a: Bank<T, 1, K, SimplePendulum<T>, Rk4> =
            Bank::new(Rk4, NeverSleeps).map_err(Verdict::Error)?;
        let mut b: Bank<T, 2, K, CartPole<T>, SemiImplicitEuler, Sleeps<T>> =
            Bank::new(SemiImplicitEuler, rule).map_err(Verdict::Error)?;
        let mut c: Bank<T, 1, K, Driven<T>, StormerVerlet<T, 1>, Sleeps<T>> =
            Bank::new(StormerVerlet::default(), rule).map_err(Verdict::Error)?;
        fill(ctx, &mut a)?;
        fill(ctx, &mut b)?;
        fill(ctx, &mut c)?;
        Ok::<_, Verdict>((a, b, c))
    })();
    let (a, b, c) = match made {
        Ok(banks) => banks,
        Err(v) => return v,
    };
    match ctx.pick(3) {
        0 => {
            say!(
                ctx,
                "let mut scene = Scene::new((a, b, c), {}, {cap})?;",
                lit(dt)
            );
            let mut scene = match Scene::new((a, b, c), dt, cap) {
                Ok(s) => s,
                Err(e) => return refused(e, &["dt", "max_steps_per_frame"]),
            };
            frames_of(ctx, &mut scene, |(a, b, c)| {
                all_finite(a) && all_finite(b) && all_finite(c)
            })
        }
        1 => {
            let mut d: Bank<T, 1, K, SimplePendulum<T>, Rk4> = match Bank::new(Rk4, NeverSleeps) {
                Ok(d) => d,
                Err(e) => return Verdict::Error(e),
            };
            if let Err(v) = fill(ctx, &mut d) {
                return v;
            }
            say!(
                ctx,
                "let mut scene = Scene::new([a, d], {}, {cap})?;",
                lit(dt)
            );
            let mut scene = match Scene::new([a, d], dt, cap) {
                Ok(s) => s,
                Err(e) => return refused(e, &["dt", "max_steps_per_frame"]),
            };
            frames_of(ctx, &mut scene, |banks| banks.iter().all(all_finite))
        }
        _ => {
            let (mut a, mut b) = (a, b);
            say!(
                ctx,
                "let mut scene = Scene::new((&mut a, &mut b), {}, {cap})?;",
                lit(dt)
            );
            let mut scene = match Scene::new((&mut a, &mut b), dt, cap) {
                Ok(s) => s,
                Err(e) => return refused(e, &["dt", "max_steps_per_frame"]),
            };
            frames_of(ctx, &mut scene, |(a, b)| all_finite(a) && all_finite(b))
        }
    }
}

/// Two values agree bit for bit, or are both NaN.
fn same<T: Real>(a: T, b: T) -> bool {
    let (a, b) = (a.to_f64(), b.to_f64());
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

/// `Lanes` and `sin_cos_lanes` (no error channel): every lane of every operation bit for bit
/// the scalar's (a NaN for a NaN), never a panic.
fn lanes<T: Real>(ctx: &mut Ctx) -> Verdict {
    const L: usize = 8;
    let kind = if ctx.pick(2) == 0 {
        Kind::Signed
    } else {
        Kind::State
    };
    let x = ctx.values::<T, L>(kind);
    let y = ctx.values::<T, L>(kind);
    let n = ctx.pick(7) as i32 - 3;
    say!(
        ctx,
        "let (x, y) = (Lanes::<{}, {L}>({}), Lanes({}));",
        ty::<T>(),
        lits(&x),
        lits(&y)
    );
    let (a, b) = (Lanes(x), Lanes(y));
    type Op<T> = (&'static str, fn(T, T) -> T);
    let ops: [Op<T>; 16] = [
        ("x + y", |x, y| x + y),
        ("x - y", |x, y| x - y),
        ("x * y", |x, y| x * y),
        ("x / y", |x, y| x / y),
        ("-x", |x, _| -x),
        ("x.sqrt()", |x, _| x.sqrt()),
        ("x.sin()", |x, _| x.sin()),
        ("x.cos()", |x, _| x.cos()),
        ("x.exp()", |x, _| x.exp()),
        ("x.ln()", |x, _| x.ln()),
        ("x.abs()", |x, _| x.abs()),
        ("x.atan2(y)", |x, y| x.atan2(y)),
        ("x.floor()", |x, _| x.floor()),
        ("x.max(y)", |x, y| x.max(y)),
        ("x.min(y)", |x, y| x.min(y)),
        ("x.recip()", |x, _| x.recip()),
    ];
    type LaneOp<T> = fn(Lanes<T, L>, Lanes<T, L>) -> Lanes<T, L>;
    let lane_ops: [LaneOp<T>; 16] = [
        |x, y| x + y,
        |x, y| x - y,
        |x, y| x * y,
        |x, y| x / y,
        |x, _| -x,
        |x, _| x.sqrt(),
        |x, _| x.sin(),
        |x, _| x.cos(),
        |x, _| x.exp(),
        |x, _| x.ln(),
        |x, _| x.abs(),
        |x, y| x.atan2(y),
        |x, _| x.floor(),
        |x, y| x.max(y),
        |x, y| x.min(y),
        |x, _| x.recip(),
    ];
    let i = ctx.pick(ops.len() + 2);
    if i < ops.len() {
        let (name, op) = ops[i];
        say!(ctx, "{name}");
        let got = lane_ops[i](a, b);
        for lane in 0..L {
            if !same(got.0[lane], op(x[lane], y[lane])) {
                return Verdict::Inconsistent(format!("{name}: lane {lane} {:?}", got.0[lane]));
            }
        }
    } else if i == ops.len() {
        say!(ctx, "x.powi({n})");
        let got = a.powi(n);
        for (lane, &xi) in x.iter().enumerate() {
            if !same(got.0[lane], xi.powi(n)) {
                return Verdict::Inconsistent(format!("powi: lane {lane} {:?}", got.0[lane]));
            }
        }
    } else {
        say!(ctx, "{}::sin_cos_lanes({})", ty::<T>(), lits(&x));
        let (s, c) = T::sin_cos_lanes(x);
        for (lane, &xi) in x.iter().enumerate() {
            let (s1, c1) = xi.sin_cos();
            if !(same(s[lane], s1) && same(c[lane], c1)) {
                return Verdict::Inconsistent(format!(
                    "sin_cos_lanes: lane {lane} ({:?}, {:?}), alone ({s1:?}, {c1:?})",
                    s[lane], c[lane]
                ));
            }
            if xi.is_finite() && !(s1.is_finite() && c1.is_finite()) {
                return Verdict::Silent(format!("sin_cos({xi:?}) = ({s1:?}, {c1:?})"));
            }
        }
    }
    Verdict::Ok
}

/// The family.
pub fn family() -> Family {
    let mut v: Vec<Entry> = Vec::new();
    entries!(v, 1.0, "FrameClock::new/advance/reset", frame_clock);
    entries!(v, 0.3, "Sleeps::new/checked_every/even_when_driven", sleeps);
    entries!(v, 1.0, "Scene<Bank<SimplePendulum, Rk4>>", pendulums_rk4);
    entries!(
        v,
        0.7,
        "Scene<Bank<SimplePendulum, StormerVerlet, Sleeps>>",
        pendulums_stormer
    );
    entries!(
        v,
        1.0,
        "Scene<Bank<DoublePendulum, SemiImplicitEuler, Sleeps>>",
        doubles_euler
    );
    entries!(v, 1.0, "Scene<Bank<CartPole, Rk4, Sleeps>>", carts_rk4);
    entries!(
        v,
        1.0,
        "Scene<Bank<Acrobot, SemiImplicitEuler>>",
        acrobots_euler
    );
    entries!(
        v,
        0.7,
        "Scene<Bank<SpringMassDamper, StormerVerlet, Sleeps>>",
        springs_stormer
    );
    entries!(
        v,
        1.0,
        "Scene<Bank<FallingParticle, SemiImplicitEuler>>",
        particles_euler
    );
    entries!(
        v,
        0.7,
        "Scene<Bank<Forced<SimplePendulum, Input>, StormerVerlet>>",
        driven_stormer
    );
    entries!(
        v,
        0.7,
        "Scene<Bank<Forced<SimplePendulum, Input>, Rk4, Sleeps>>",
        driven_rk4
    );
    entries!(
        v,
        0.7,
        "Scene of banks: (Bank, Bank, Bank), [Bank; 2], (&mut Bank, &mut Bank)",
        many_banks
    );
    // Optimised only, as the ragdoll family's contact runs (see there).
    if !cfg!(debug_assertions) {
        entries!(
            v,
            0.5,
            "Scene<Bank<Ragdoll, ContactStepper<Rk4, RagdollContacts>, Sleeps>>",
            ragdolls_contacts
        );
    }
    entries!(v, 0.5, "Lanes, sin_cos_lanes (no error channel)", lanes);
    Family {
        name: "scenes",
        entries: v,
    }
}
