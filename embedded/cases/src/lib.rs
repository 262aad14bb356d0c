//! # lagrange-cases
//!
//! The lockstep cases: one `const` table, [`CASES`], of mechanism x integrator x scalar runs
//! from fixed initial states. The firmware (`embedded/firmware`, on a Cortex-M4F under QEMU)
//! and the host (`cargo xtask qemu`) both call [`Case::run`] on the same table, and the final
//! states must agree bit for bit: the same code, the same IEEE-754 operations, the same `libm`
//! and [`fast_trig`](lagrange_core::fast_trig), no fused multiply-add.
//!
//! [`KERNELS`] does the same for the math functions a step spends its time in (sine, cosine,
//! square root), over fixed input sets, compared as digests of every result's bits.
//!
//! Adding a case is one line in [`CASES`]; a new mechanism needs a [`Setup`] (parameters and
//! initial state) first, as [`DoublePendulumSetup`] shows.
//!
//! ```
//! use lagrange_cases::CASES;
//! let case = &CASES[0];
//! let a = case.run(100)?;
//! let b = case.run(100)?;
//! assert_eq!(a.words(), b.words());
//! # Ok::<(), lagrange_core::Error>(())
//! ```

#![no_std]
#![forbid(unsafe_code)]

mod case;
mod kernels;
mod lanes;
mod libm_trig_pendulum;
mod scenes;
mod setups;
mod spring_chain;

pub use case::{Case, Outcome, Precision, MAX_WORDS};
pub use kernels::{Kernel, KERNELS, KERNEL_CALLS};
pub use lanes::{pendulums_alone, pendulums_in_a_bank, pendulums_in_lanes, LANE_INSTANCES};
pub use libm_trig_pendulum::LibmTrigPendulum;
pub use scenes::{many_sleepers, no_sleepers, scripted, with_sleepers, SLEEPERS};
pub use setups::{
    CartPoleLagrangianSetup, CartPoleSetup, DoublePendulumSetup, LibmTrigPendulumSetup,
    PendulumSetup, Setup,
};
pub use spring_chain::SpringChain;

use lagrange_integrators::{Rk4, SemiImplicitEuler, StormerVerlet, VelocityVerlet};

/// Steps of every case in the lockstep comparison (1 s of simulated time at the setups' 1 ms).
pub const STEPS: u32 = 1000;

/// Every case the firmware runs and the host checks, in order (the index is the case's id in
/// the firmware's log).
///
/// The pendulum is the origin's (30 degrees, undamped), the double pendulum starts both links
/// horizontal, chaotic, so any difference of one bit grows to a visible one within the run.
/// Velocity Verlet and semi-implicit Euler are the symplectic methods (for the pendulum;
/// velocity Verlet is not symplectic for the double pendulum, whose mass matrix depends on
/// `q`). The libm-trig pendulum is the same pendulum with `libm::sinf`: the cost it is
/// compared against. The cart-pole (mass matrix depending on `q`) is stepped by RK4, by
/// Stormer-Verlet (symmetric, with an implicit kick), and by the variational midpoint rule,
/// symplectic for any Lagrangian (on the automatic Euler-Lagrange path, Newton iterations in
/// dual numbers).
pub const CASES: [Case; 25] = [
    Case::new::<f32, 1, PendulumSetup, Rk4>(),
    Case::new::<f64, 1, PendulumSetup, Rk4>(),
    Case::new::<f32, 1, PendulumSetup, VelocityVerlet>(),
    Case::new::<f64, 1, PendulumSetup, VelocityVerlet>(),
    Case::new::<f32, 1, PendulumSetup, SemiImplicitEuler>(),
    Case::new::<f64, 1, PendulumSetup, SemiImplicitEuler>(),
    Case::new::<f32, 1, LibmTrigPendulumSetup, Rk4>(),
    Case::new::<f32, 1, LibmTrigPendulumSetup, VelocityVerlet>(),
    Case::new::<f32, 2, DoublePendulumSetup, Rk4>(),
    Case::new::<f64, 2, DoublePendulumSetup, Rk4>(),
    Case::new::<f32, 2, DoublePendulumSetup, VelocityVerlet>(),
    Case::new::<f64, 2, DoublePendulumSetup, VelocityVerlet>(),
    Case::new::<f32, 2, CartPoleSetup, Rk4>(),
    Case::new::<f64, 2, CartPoleSetup, Rk4>(),
    Case::new::<f32, 2, CartPoleSetup, StormerVerlet<f32, 2>>(),
    Case::new::<f64, 2, CartPoleSetup, StormerVerlet<f64, 2>>(),
    Case::variational::<f32, 2, CartPoleLagrangianSetup>(),
    Case::variational::<f64, 2, CartPoleLagrangianSetup>(),
    Case::scripted(
        "scene (sleep, wake)",
        "Stormer-Verlet, RK4",
        "f32",
        4,
        scripted::<f32>,
    ),
    Case::scripted(
        "scene (sleep, wake)",
        "Stormer-Verlet, RK4",
        "f64",
        4,
        scripted::<f64>,
    ),
    Case::scripted("scene, 1 awake", "RK4", "f32", 4, no_sleepers),
    Case::scripted("scene, 1 awake + 64 asleep", "RK4", "f32", 4, many_sleepers),
    Case::scripted("16 pendulums, one by one", "RK4", "f32", 1, pendulums_alone),
    Case::scripted(
        "16 pendulums, in lanes",
        "RK4",
        "f32",
        1,
        pendulums_in_lanes,
    ),
    Case::scripted(
        "16 pendulums, a scene's bank",
        "RK4",
        "f32",
        1,
        pendulums_in_a_bank,
    ),
];

#[cfg(test)]
mod tests {
    use super::*;

    /// Every case runs on the host and its outcome holds the words it says (`t`, `q` and `q'`
    /// for a mechanism's run); no two cases are
    /// the same run (the firmware's log names them by index only).
    #[test]
    fn every_case_runs_and_is_distinct() -> Result<(), lagrange_core::Error> {
        for (i, case) in CASES.iter().enumerate() {
            let outcome = case.run(STEPS)?;
            assert_eq!(outcome.words().len(), case.words, "case {i}");
            for other in &CASES[..i] {
                assert!(
                    (other.system, other.method, other.precision)
                        != (case.system, case.method, case.precision),
                    "case {i} repeats an earlier one"
                );
            }
        }
        Ok(())
    }

    /// The pendulums in lanes end with the bits of the pendulums one by one.
    #[test]
    fn lanes_give_the_bits_of_one_by_one() -> Result<(), lagrange_core::Error> {
        assert_eq!(pendulums_in_lanes(STEPS)?, pendulums_alone(STEPS)?);
        Ok(())
    }

    /// The pendulums in a scene's bank end with the angles and rates of one by one (their
    /// times are the scene's).
    #[test]
    fn a_bank_gives_the_bits_of_one_by_one() -> Result<(), lagrange_core::Error> {
        assert_eq!(pendulums_in_a_bank(STEPS)?, lanes::alone_untimed(STEPS)?);
        Ok(())
    }
}
