//! A mixed scene: pendulums, double pendulums, cart-poles, four-bar linkages and balls on a
//! floor, in one scene of five banks, at its start and once settled.

use super::frames::ns_per_frame;
use super::Row;
use lagrange_benches::timing::Budget;
use lagrange_core::{Holonomic, HolonomicConstraints};
use lagrange_integrators::prelude::*;
use lagrange_integrators::{ContactModel, ContactStepper};
use lagrange_systems::{
    Branch, CartPole, DoublePendulum, FallingParticle, FourBarLinkage, SimplePendulum,
};

/// The fixed step, s.
const DT: f32 = 1.0 / 120.0;
/// Instances of each bank.
const PENDULUMS: usize = 400;
const DOUBLES: usize = 200;
const CARTS: usize = 100;
const LINKAGES: usize = 100;
const BALLS: usize = 200;

/// The floor at height 0 under a ball.
#[derive(Debug, Clone, Copy)]
pub struct Floor;

impl HolonomicConstraints<f32, 1, 1> for Floor {
    fn phi<S: Scalar<Real = f32> + 'static>(&self, q: &SVector<S, 1>) -> SVector<S, 1> {
        *q
    }
}

type Ball = ContactStepper<f32, 1, 1, Rk4, Holonomic<Floor>>;
type Linkage = Constrained<f32, 2, FourBarLinkage<f32>>;

/// The five banks, in the order they step.
type Mixed = (
    Bank<f32, 1, PENDULUMS, SimplePendulum<f32>, StormerVerlet<f32, 1>, Sleeps<f32>>,
    Bank<f32, 2, DOUBLES, DoublePendulum<f32>, Rk4, Sleeps<f32>>,
    Bank<f32, 2, CARTS, CartPole<f32>, Rk4, Sleeps<f32>>,
    Bank<f32, 3, LINKAGES, Linkage, Rk4, Sleeps<f32>>,
    Bank<f32, 1, BALLS, FallingParticle<f32>, Ball, Sleeps<f32>>,
);

/// Instances in the scene.
pub const INSTANCES: usize = PENDULUMS + DOUBLES + CARTS + LINKAGES + BALLS;

/// The sleep rule of every bank: 1e-5 J, 1e-2 (m or rad)/s^2, 60 steps.
fn rule() -> Result<Sleeps<f32>, Error> {
    Sleeps::new(1e-5, 1e-2, 60)
}

/// The scene: half the pendulums swinging (well damped, so they settle in seconds), half at
/// rest; double pendulums swinging and at rest; cart-poles hanging, half of them pushed back
/// and forth; four-bars swinging (undamped: they never settle); balls dropped from 0.2 to 1 m.
fn scene() -> Result<Scene<f32, Mixed>, Error> {
    let model = ContactModel::new(0.5, 0.05, 1e-6)?;
    let ball = ContactStepper::new(Rk4, Holonomic::new(Floor), model, Projection::new(1e-5, 4)?);
    let mut banks: Mixed = (
        Bank::new(StormerVerlet::default(), rule()?)?,
        Bank::new(Rk4, rule()?)?,
        Bank::new(Rk4, rule()?)?,
        Bank::new(Rk4, rule()?)?,
        Bank::new(ball, rule()?)?,
    );
    let pendulum = SimplePendulum::new(1.0, 1.0, 9.81, 0.5)?;
    for k in 0..PENDULUMS {
        let th = if k % 2 == 0 { 0.8 } else { 0.0 };
        banks.0.add(pendulum, State::at_rest([th]))?;
    }
    let double = DoublePendulum::new(1.0, 1.0, 1.0, 1.0, 9.81)?;
    for k in 0..DOUBLES {
        let th = if k % 2 == 0 { [0.6, -0.4] } else { [0.0, 0.0] };
        banks.1.add(double, State::at_rest(th))?;
    }
    for k in 0..CARTS {
        let cart = CartPole::new(1.0, 0.1, 0.5, 9.8)?;
        let id = banks
            .2
            .add(cart, State::at_rest([0.0, core::f32::consts::PI]))?;
        if k % 2 == 0 {
            banks.2.set_input(id, 0.5)?;
        }
    }
    let linkage = Constrained::new(FourBarLinkage::new(
        [1.0, 0.3, 1.0, 0.8],
        [0.5, 1.0, 0.8],
        9.81,
    )?)
    .with_stabilization(Stabilization::critical(10.0)?);
    let start = linkage.parts().assemble(0.0, 0.5, 0.0, Branch::Right)?;
    for _ in 0..LINKAGES {
        banks.3.add(linkage, start)?;
    }
    let fall = FallingParticle::new(1.0, 9.81)?;
    for k in 0..BALLS {
        let h = 0.2 + 0.8 * (k as f32) / (BALLS as f32);
        banks.4.add(fall, State::at_rest([h]))?;
    }
    Scene::new(banks, DT, 8)
}

/// Awake instances of the five banks.
fn awake(banks: &Mixed) -> usize {
    banks.0.awake() + banks.1.awake() + banks.2.awake() + banks.3.awake() + banks.4.awake()
}

/// The mixed scene at its start and after 20 s of frames.
pub fn measure(budget: Budget, rows: &mut Vec<Row>) -> Result<(), Error> {
    let mut s = scene()?;
    for stage in ["mixed, at the start", "mixed, settled (20 s)"] {
        if stage.starts_with("mixed, settled") {
            for _ in 0..2400 {
                s.advance(DT)?;
            }
        }
        let fraction = awake(s.banks()) as f64 / INSTANCES as f64;
        let b = s.banks();
        println!(
            "  awake: {}/{PENDULUMS} pendulums, {}/{DOUBLES} double pendulums, {}/{CARTS} \
             cart-poles, {}/{LINKAGES} four-bars, {}/{BALLS} balls",
            b.0.awake(),
            b.1.awake(),
            b.2.awake(),
            b.3.awake(),
            b.4.awake()
        );
        let mut failed = 0;
        let mut failure = None;
        let ns = ns_per_frame(budget, || match s.advance(DT) {
            Ok(frame) => failed += frame.failed,
            Err(e) => failure = Some(e),
        });
        if let Some(e) = failure {
            return Err(e);
        }
        if failed > 0 {
            println!("  ({failed} instance steps failed)");
        }
        println!(
            "{stage:<44} {:<16} f32  {:>5.1}% awake  {ns:>10.0} ns/frame",
            "mixed",
            fraction * 100.0
        );
        rows.push(Row {
            scene: stage.into(),
            layout: "one_by_one",
            instances: INSTANCES,
            awake_fraction: fraction,
            integrator: "mixed",
            scalar: "f32",
            ns_per_frame: ns,
        });
    }
    Ok(())
}
