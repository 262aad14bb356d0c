//! A planar ragdoll thrown onto a floor (impulses, Coulomb friction, joint limits, rest) with
//! `ImpulseStepper`, the real-time contact stepper, and its cost per step beside a free step,
//! beside `ContactStepper` (which locates every contact inside the step), and beside a
//! chain's: the articulated-body recursion against the same ragdoll solved densely, and
//! against `NLinkPendulum` with as many links and coordinates.
//!
//! `cargo run --release --example ragdoll`

use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{Constraints, Projection};
use lagrange_examples::ns_per_step;
use lagrange_integrators::prelude::*;
use lagrange_systems::{
    NLinkPendulum, Ragdoll, RagdollBody, RagdollContacts, RAGDOLL_COORDINATES as N,
};

/// The step, s.
const DT: f64 = 1.0 / 240.0;

/// Torso 1.6 m up, tilted 0.6 rad, limbs spread, moving at (2, 1) m/s, turning at 3 rad/s.
fn thrown() -> State<f64, N> {
    let mut q = [0.0; N];
    let mut qd = [0.0; N];
    q[1] = 1.6;
    q[2] = 0.6;
    for (k, spread) in [
        (4, -1.0),
        (6, 1.0),
        (8, -0.4),
        (9, 0.5),
        (10, 0.4),
        (11, -0.5),
    ] {
        q[k] = spread;
    }
    qd[0] = 2.0;
    qd[1] = 1.0;
    qd[2] = 3.0;
    State::new(0.0, q, qd)
}

/// The same ragdoll with the default law: its mass matrix (composite rigid bodies) and
/// right-hand side (inverse dynamics), solved by a dense Cholesky factorisation.
#[derive(Clone, Copy)]
struct Dense(Ragdoll<f64>);

impl Lagrangian<f64, N> for Dense {
    fn kinetic<S: Scalar<Real = f64>>(&self, t: S, q: &SVector<S, N>, qd: &SVector<S, N>) -> S {
        self.0.kinetic(t, q, qd)
    }
    fn potential<S: Scalar<Real = f64>>(&self, t: S, q: &SVector<S, N>) -> S {
        self.0.potential(t, q)
    }
    fn non_conservative_force(&self, s: &State<f64, N>) -> SVector<f64, N> {
        self.0.non_conservative_force(s)
    }
}

impl Mechanism<f64, N> for Dense {
    fn mass_matrix(&self, s: &State<f64, N>) -> SMatrix<f64, N, N> {
        self.0.mass_matrix(s)
    }
    fn rhs(&self, s: &State<f64, N>) -> SVector<f64, N> {
        self.0.rhs(s)
    }
}

fn main() -> Result<(), Error> {
    let doll = Ragdoll::new(RagdollBody::adult())?;
    let contacts = RagdollContacts::adult(&doll, 0.0)?;
    let model = ContactModel::new(0.3, 0.3, 1e-7)?.with_friction(0.8)?;
    let projection = Projection::new(1e-9, 8)?;
    // A slop above a step's free fall (dt^2 g = 0.17 mm), and at most 4 rounds a solve.
    let settings = ImpulseSettings::new(2e-3, 4)?;
    let real_time = || ImpulseStepper::new(SemiImplicitEuler, contacts, model, settings);
    let located = || ContactStepper::new(Rk4, contacts, model, projection);
    let mut floor = real_time();
    let mut s = thrown();
    let (mut rise, mut deepest, mut rest) = (f64::NEG_INFINITY, f64::INFINITY, None);
    let e0 = doll.energy(&s);
    for _ in 0..(6.0 / DT) as usize {
        let before = doll.energy(&s);
        s = floor.step(&doll, &s, DT)?;
        if floor.last_report().rows > 0 {
            rise = rise.max(doll.energy(&s) - before);
        }
        let gaps = contacts.position_residual(&s.q);
        deepest = gaps.iter().fold(deepest, |d, &g| d.min(g));
        if rest.is_none() && doll.kinetic_energy(&s) < 1e-3 {
            rest = Some(s.t);
        }
    }
    let peak = floor.peak_report();
    println!(
        "Ragdoll (70 kg adult, 10 links, 12 coordinates) thrown onto the floor with \
         ImpulseStepper (semi-implicit Euler inside, 1/240 s, e = 0.3, friction 0.8, 13 floor \
         points and 9 joint limits): largest change of T + V over a step in contact {rise:.1e} J \
         (never a gain), deepest gap {deepest:.1e} m (the slop: -2.0e-3 m), energy {e0:.1} J -> \
         {:.1} J, kinetic energy below 1 mJ from t = {}; the busiest step: {} rows, {} with \
         friction, {} rounds (the cap: 4 solves of 4)",
        doll.energy(&s),
        rest.map_or_else(|| "-".into(), |t| format!("{t:.2} s")),
        peak.rows,
        peak.frictional,
        peak.rounds,
    );

    let start = thrown();
    let chain10 = NLinkPendulum::<f64, 10>::new([1.0; 10], [0.2; 10], 9.81)?;
    let chain12 = NLinkPendulum::<f64, 12>::new([1.0; 12], [0.2; 12], 9.81)?;
    let steps = 20_000;
    let ragdoll = ns_per_step(Rk4, &doll, &start, DT, steps);
    let dense = ns_per_step(Rk4, &Dense(doll), &start, DT, steps);
    let throw = (6.0 / DT) as u64;
    let impulses = ns_per_step(real_time(), &doll, &start, DT, throw);
    let free_sie = ns_per_step(SemiImplicitEuler, &doll, &start, DT, throw);
    let with_events = ns_per_step(located(), &doll, &start, DT, throw);
    let c10 = ns_per_step(
        Rk4,
        &chain10,
        &State::new(0.0, [0.3; 10], [0.0; 10]),
        DT,
        steps,
    );
    let c12 = ns_per_step(
        Rk4,
        &chain12,
        &State::new(0.0, [0.3; 12], [0.0; 12]),
        DT,
        steps,
    );
    println!("\nCost per step of the ragdoll thrown onto the floor (f64, 6 s), ns:");
    println!("  ImpulseStepper, semi-implicit Euler       {impulses:>8.0}");
    println!("  semi-implicit Euler, no floor             {free_sie:>8.0}");
    println!("  ContactStepper, RK4 (contacts located)    {with_events:>8.0}");
    println!("\nCost per RK4 step (f64, 4 accelerations), ns:");
    println!("  ragdoll, articulated-body recursion      {ragdoll:>8.0}");
    println!("  ragdoll, mass matrix + dense Cholesky    {dense:>8.0}");
    println!("  chain of 10 links (NLinkPendulum)        {c10:>8.0}");
    println!("  chain of 12 links (NLinkPendulum)        {c12:>8.0}");
    Ok(())
}
