//! The page's mechanisms: each one's parameters, start, integrator wrapping (projection for
//! the four-bar, contacts for the floor), sleep rule and drawing points; [`make`] builds one
//! in a scalar type with a chosen integrator.

use lagrange_core::nalgebra::{SVector, Vector4};
use lagrange_core::{
    Constrained, Controlled, Error, Gather, Holonomic, HolonomicConstraints, Projection, Real,
    Scalar, State,
};
use lagrange_integrators::scene::{Bank, Id, InLanes, Layout, Sleeps};
use lagrange_integrators::{
    ContactModel, ImpulseSettings, ImpulseStepper, Integrator, Projected, Rk4, SemiImplicitEuler,
    StormerVerlet,
};
use lagrange_systems::exact::pendulum_from_rest;
use lagrange_systems::{
    Branch, CartPole, DoublePendulum, FourBarLinkage, NLinkPendulum, Ragdoll, RagdollBody,
    RagdollContacts, SimplePendulum, RAGDOLL_COORDINATES,
};

use crate::sim::{Panel, Recipe, Sim};

/// Gravity of every mechanism, m/s^2.
const G: f64 = 9.81;

/// The mechanisms, in the order of the page's panels.
pub const KINDS: [&str; 7] = [
    "origin's pendulum + exact",
    "chaotic double pendulum + twin 1e-9 rad away",
    "chain of 8 links",
    "four-bar linkage",
    "cart-pole (arrow keys)",
    "double pendulum onto a floor",
    "ragdoll thrown onto the floor",
];

/// The integrators the page offers.
pub const METHODS: [&str; 3] = ["RK4", "Stormer-Verlet", "semi-implicit Euler"];

/// The origin's 30 degrees.
const TH0: f64 = core::f64::consts::FRAC_PI_6;

/// `(x, y)` of each point, as f64.
fn xy<T: Real>(x: T, y: T) -> [f64; 2] {
    [x.to_f64(), y.to_f64()]
}

/// A pendulum of length 1 from the origin.
fn pendulum_points<T: Real>(_: &SimplePendulum<T>, q: &SVector<T, 1>) -> Vec<[f64; 2]> {
    let (s, c) = q[0].sin_cos();
    vec![[0.0, 0.0], xy(s, -c)]
}

/// The exact solution's bob at `t` (Jacobi elliptic functions).
fn exact_pendulum(t: f64) -> Vec<[f64; 2]> {
    match pendulum_from_rest(TH0, G.sqrt(), t) {
        Ok((th, _)) => vec![[0.0, 0.0], [th.sin(), -th.cos()]],
        Err(_) => Vec::new(),
    }
}

/// A double pendulum of unit rods from the origin.
fn double_points<T: Real>(_: &DoublePendulum<T>, q: &SVector<T, 2>) -> Vec<[f64; 2]> {
    let (s1, c1) = q[0].sin_cos();
    let (s2, c2) = q[1].sin_cos();
    vec![[0.0, 0.0], xy(s1, -c1), xy(s1 + s2, -c1 - c2)]
}

/// Links of the chain.
const LINKS: usize = 8;

/// The chain from the origin.
fn chain_points<T: Real>(m: &NLinkPendulum<T, LINKS>, q: &SVector<T, LINKS>) -> Vec<[f64; 2]> {
    core::iter::once([0.0, 0.0])
        .chain(m.positions(q).iter().map(|&(x, y)| xy(x, y)))
        .collect()
}

/// The four-bar: ground pivots `A = (0, 0)` and `D = (d, 0)`, crank tip `B`, coupler tip `C`.
fn four_bar_points<T: Real>(
    m: &Constrained<T, 2, FourBarLinkage<T>>,
    q: &SVector<T, 3>,
) -> Vec<[f64; 2]> {
    let [d, a, b, _] = m.parts().lengths();
    let (s1, c1) = q[0].sin_cos();
    let (s2, c2) = q[1].sin_cos();
    let (bx, by) = (a * s1, -a * c1);
    vec![
        [0.0, 0.0],
        xy(bx, by),
        xy(bx + b * s2, by - b * c2),
        xy(d, T::zero()),
    ]
}

/// The cart and the tip of its pole (`th` from the upward vertical).
fn cart_points<T: Real>(m: &CartPole<T>, q: &SVector<T, 2>) -> Vec<[f64; 2]> {
    let (s, c) = q[1].sin_cos();
    let l = m.pole_half_length() * T::TWO;
    vec![xy(q[0], T::zero()), xy(q[0] + l * s, l * c)]
}

/// The floor under the double pendulum, m below its pivot (both unit rods reach it).
pub const FLOOR: f64 = 0.8;
/// The double pendulum's bend limit, rad.
const BEND: f64 = 2.5;

/// Rows 0 and 1: both masses above the floor; rows 2 and 3: `|th2 - th1| <= BEND`.
#[derive(Debug, Clone, Copy)]
pub struct FloorAndLimits;

impl<T: Real> HolonomicConstraints<T, 2, 4> for FloorAndLimits {
    fn phi<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, 2>) -> SVector<S, 4> {
        let (floor, bend) = (S::from_f64(FLOOR), S::from_f64(BEND));
        let y1 = -q[0].cos();
        let y2 = y1 - q[1].cos();
        let relative = q[1] - q[0];
        Vector4::new(y1 + floor, y2 + floor, bend - relative, bend + relative)
    }
}

/// The ragdoll's ten links, start and end of each.
fn ragdoll_points<T: Real>(m: &Ragdoll<T>, q: &SVector<T, RAGDOLL_COORDINATES>) -> Vec<[f64; 2]> {
    m.segments(q)
        .iter()
        .flatten()
        .map(|&[x, y]| xy(x, y))
        .collect()
}

/// The ragdoll's throw: torso centre 1.6 m up, tilted 0.6 rad, limbs spread, moving at
/// (2, 1) m/s and turning at 3 rad/s.
pub fn thrown<T: Real>() -> State<T, RAGDOLL_COORDINATES> {
    let mut q = [T::zero(); RAGDOLL_COORDINATES];
    let mut qd = [T::zero(); RAGDOLL_COORDINATES];
    q[0] = T::from_f64(-1.5);
    q[1] = T::from_f64(1.6);
    q[2] = T::from_f64(0.6);
    for (k, spread) in [
        (4, -1.0),
        (6, 1.0),
        (8, -0.4),
        (9, 0.5),
        (10, 0.4),
        (11, -0.5),
    ] {
        q[k] = T::from_f64(spread);
    }
    qd[0] = T::from_f64(2.0);
    qd[1] = T::from_f64(1.0);
    qd[2] = T::from_f64(3.0);
    State::new(T::zero(), q, qd)
}

/// The twin's first angle: 1e-9 rad beyond `th`, or in `f32`, where `th + 1e-9` rounds to
/// `th`, the next `f32` above it (2.4e-7 rad beyond 2.2).
pub fn twin_angle<T: Real>(th: T) -> T {
    let twin = th + T::from_f64(1e-9);
    if twin == th {
        th * (T::one() + T::EPSILON)
    } else {
        twin
    }
}

/// `tol_f32` in f32, `tol_f64` in f64.
fn pick<T: Real>(tol_f32: f64, tol_f64: f64) -> T {
    T::from_f64(if T::EPSILON.to_f64() > 1e-10 {
        tol_f32
    } else {
        tol_f64
    })
}

/// Sleep when the kinetic energy stays below `kinetic` J and the acceleration at rest below
/// `acceleration` for 60 steps.
fn sleeps<T: Real>(kinetic: f64, acceleration: f64) -> Result<Sleeps<T>, Error> {
    Sleeps::new(T::from_f64(kinetic), T::from_f64(acceleration), 60)
}

/// Runs `$body` with `$i` bound to the integrator `$method` names.
macro_rules! by_method {
    ($method:expr, $t:ty, $n:expr, |$i:ident| $body:expr) => {
        match $method {
            1 => {
                let $i = StormerVerlet::<$t, $n>::default();
                $body
            }
            2 => {
                let $i = SemiImplicitEuler;
                $body
            }
            _ => {
                let $i = Rk4;
                $body
            }
        }
    };
}

/// A boxed [`Sim`] of `recipe`, its bank laid out by `Y`: [`InLanes`] for the mechanisms that
/// gather (pendulum, double pendulum, cart-pole: the same bits as one by one).
fn boxed<T, const N: usize, M, I, Y>(recipe: Recipe<T, N, M, I, Y>) -> Result<Box<dyn Panel>, Error>
where
    T: Real,
    Y: Layout<T, N, 2, M> + 'static,
    M: lagrange_core::Mechanism<T, N> + Clone + 'static,
    I: Integrator<T, N, M> + Clone + 'static,
{
    Ok(Box::new(Sim::new(recipe)?))
}

/// A boxed [`Sim`] of `recipe`, stepped one by one.
fn one_by_one<T, const N: usize, M, I>(recipe: Recipe<T, N, M, I>) -> Result<Box<dyn Panel>, Error>
where
    T: Real,
    M: lagrange_core::Mechanism<T, N> + Clone + 'static,
    I: Integrator<T, N, M> + Clone + 'static,
{
    boxed(recipe)
}

/// A boxed [`Sim`] of `recipe`, in lanes.
fn in_lanes<T, const N: usize, M, I>(
    recipe: Recipe<T, N, M, I, InLanes>,
) -> Result<Box<dyn Panel>, Error>
where
    T: Real,
    M: Gather<T, N> + Clone + 'static,
    I: Integrator<T, N, M> + Clone + 'static,
{
    boxed(recipe)
}

/// The cart-pole's input: its force, N.
fn push<T: Real, I, Y: Layout<T, 2, 2, CartPole<T>>>(
    bank: &mut Bank<T, 2, 2, CartPole<T>, I, Sleeps<T>, Y>,
    id: Id,
    force: f64,
) -> Result<(), Error>
where
    I: Integrator<T, 2, CartPole<T>> + Clone,
    CartPole<T>: Controlled<T, Input = T>,
{
    bank.set_input(id, T::from_f64(force))
}

/// The contact solver's settings on the page: 2 mm (or 2 mrad) of slop, above a step's free
/// fall at 120 Hz (0.7 mm), and at most 4 rounds a solve.
fn impulse_settings<T: Real>() -> Result<ImpulseSettings<T>, Error> {
    ImpulseSettings::new(T::from_f64(CONTACT_SLOP), CONTACT_ITERATIONS)
}

/// The contact solver's slop on the page, m (or rad).
const CONTACT_SLOP: f64 = 2e-3;

/// The contact solver's cap on rounds per solve on the page.
pub const CONTACT_ITERATIONS: u32 = 4;

/// The most rounds a step of the page's contact solver may take: the plastic solve's cap,
/// and one more for each of the three solves that may follow it
/// (`ImpulseSettings::max_rounds`).
pub const CONTACT_ROUNDS_CAP: u32 = CONTACT_ITERATIONS + 3;

/// The worst `[rows, rounds]` of an impulse stepper's steps.
fn peak_work<T: Real, const N: usize, const C: usize, I, K>(
    stepper: &ImpulseStepper<T, N, C, I, K>,
) -> [u32; 2] {
    let peak = stepper.peak_report();
    [peak.rows, peak.rounds]
}

/// Mechanism `kind` (an index of [`KINDS`]) in `T`, stepped by `method` (an index of
/// [`METHODS`]).
///
/// # Errors
/// The library's errors building it (none for these values); [`Error::InvalidParameter`] for
/// an unknown kind.
pub fn make<T: Real>(kind: usize, method: usize) -> Result<Box<dyn Panel>, Error> {
    match kind {
        0 => {
            let mechanism = SimplePendulum::new(T::one(), T::one(), T::from_f64(G), T::zero())?;
            by_method!(method, T, 1, |i| in_lanes(Recipe {
                mechanism,
                start: State::at_rest([T::from_f64(TH0)]),
                twin: None,
                integrator: i,
                sleep: sleeps(1e-6, 1e-3)?,
                dt: 1.0 / 60.0,
                energy_scale: G,
                points: pendulum_points,
                exact: Some(exact_pendulum),
                input: None,
                work: None,
            }))
        }
        1 => {
            let mechanism =
                DoublePendulum::new(T::one(), T::one(), T::one(), T::one(), T::from_f64(G))?;
            let start = State::at_rest([T::from_f64(2.2), T::from_f64(2.6)]);
            let twin = State::at_rest([twin_angle(T::from_f64(2.2)), T::from_f64(2.6)]);
            by_method!(method, T, 2, |i| in_lanes(Recipe {
                mechanism,
                start,
                twin: Some(twin),
                integrator: i,
                sleep: sleeps(1e-6, 1e-3)?,
                dt: 1.0 / 240.0,
                energy_scale: 3.0 * G,
                points: double_points,
                exact: None,
                input: None,
                work: None,
            }))
        }
        2 => {
            let mechanism = NLinkPendulum::new(
                [T::from_f64(0.3); LINKS],
                [T::from_f64(0.35); LINKS],
                T::from_f64(G),
            )?;
            let start = State::at_rest([T::from_f64(1.3); LINKS]);
            by_method!(method, T, LINKS, |i| one_by_one(Recipe {
                mechanism,
                start,
                twin: None,
                integrator: i,
                sleep: sleeps(1e-6, 1e-3)?,
                dt: 1.0 / 240.0,
                energy_scale: 4.0 * G,
                points: chain_points,
                exact: None,
                input: None,
                work: None,
            }))
        }
        3 => {
            let mechanism = Constrained::new(FourBarLinkage::new(
                [1.0, 0.3, 1.0, 0.8].map(T::from_f64),
                [0.5, 1.0, 0.8].map(T::from_f64),
                T::from_f64(G),
            )?);
            let start = mechanism.parts().assemble(
                T::zero(),
                T::zero(),
                T::from_f64(12.0),
                Branch::Right,
            )?;
            let projection = Projection::new(pick::<T>(1e-5, 1e-10), 4)?;
            by_method!(method, T, 3, |i| one_by_one(Recipe {
                mechanism,
                start,
                twin: None,
                integrator: Projected::new(i, projection),
                sleep: sleeps(1e-6, 1e-3)?,
                dt: 1.0 / 240.0,
                energy_scale: G,
                points: four_bar_points,
                exact: None,
                input: None,
                work: None,
            }))
        }
        4 => {
            let mechanism = CartPole::new(
                T::one(),
                T::from_f64(0.1),
                T::from_f64(0.5),
                T::from_f64(9.8),
            )?;
            let start = State::at_rest([T::zero(), T::from_f64(0.05)]);
            by_method!(method, T, 2, |i| in_lanes(Recipe {
                mechanism,
                start,
                twin: None,
                integrator: i,
                sleep: sleeps(1e-6, 1e-3)?,
                dt: 1.0 / 120.0,
                energy_scale: 0.5,
                points: cart_points,
                exact: None,
                input: Some(push),
                work: None,
            }))
        }
        5 => {
            let mechanism =
                DoublePendulum::new(T::one(), T::one(), T::one(), T::one(), T::from_f64(G))?;
            let start = State::new(
                T::zero(),
                [T::from_f64(1.6), T::from_f64(2.2)],
                [T::from_f64(2.0), T::from_f64(-6.0)],
            );
            let model = ContactModel::new(T::from_f64(0.5), T::from_f64(0.1), T::one())?;
            let contacts = Holonomic::new(FloorAndLimits);
            by_method!(method, T, 2, |i| one_by_one(Recipe {
                mechanism,
                start,
                twin: None,
                integrator: ImpulseStepper::new(i, contacts, model, impulse_settings()?),
                sleep: sleeps(1e-4, 1e-2)?,
                dt: 1.0 / 240.0,
                energy_scale: 3.0 * G,
                points: double_points,
                exact: None,
                input: None,
                work: Some(peak_work),
            }))
        }
        6 => {
            let mechanism = Ragdoll::new(RagdollBody::adult())?;
            let model = ContactModel::new(T::from_f64(0.3), T::from_f64(0.3), T::one())?
                .with_friction(T::from_f64(0.8))?;
            let contacts = RagdollContacts::adult(&mechanism, T::zero())?;
            by_method!(method, T, RAGDOLL_COORDINATES, |i| one_by_one(Recipe {
                mechanism,
                start: thrown(),
                twin: None,
                integrator: ImpulseStepper::new(i, contacts, model, impulse_settings()?),
                sleep: sleeps(1e-3, 1e-2)?,
                dt: 1.0 / 120.0,
                energy_scale: 70.0 * G,
                points: ragdoll_points,
                exact: None,
                input: None,
                work: Some(peak_work),
            }))
        }
        _ => Err(Error::InvalidParameter {
            name: "kind",
            reason: "no such mechanism on the page",
        }),
    }
}
