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
mod ragdoll;
mod ragdoll_capsules;
mod scenes;
mod setups;
mod spring_chain;
mod world;

pub use case::{Case, Outcome, Precision, Stopwatch, Untimed, MAX_WORDS};
pub use kernels::{Kernel, KERNELS, KERNEL_CALLS};
pub use lanes::{pendulums_alone, pendulums_in_a_bank, pendulums_in_lanes, LANE_INSTANCES};
pub use libm_trig_pendulum::LibmTrigPendulum;
pub use ragdoll::{
    ragdoll_free, ragdoll_landing, ragdoll_thrown, RAGDOLL_DT, RAGDOLL_FREE, RAGDOLL_ITERATIONS,
    RAGDOLL_LANDING, RAGDOLL_ROWS,
};
pub use ragdoll_capsules::{ragdoll_capsules, RAGDOLL_CAPSULE_RADII};
pub use scenes::{many_sleepers, no_sleepers, scripted, with_sleepers, SLEEPERS};
pub use setups::{
    CartPoleLagrangianSetup, CartPoleSetup, DoublePendulumSetup, LibmTrigPendulumSetup,
    PendulumSetup, Setup,
};
pub use spring_chain::SpringChain;
pub use world::world_in_a_box;

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
/// dual numbers). The ragdoll is thrown onto the floor and lands and settles under the
/// impulse stepper (steps of 1/240 s: 4.2 s), beside the same throw with no floor stepped by
/// RK4; both take their steps one by one, so that the firmware times the worst step of each.
/// The world is three balls and a crate dropped into a box, at 60 Hz for 1000 steps (they
/// bounce, touch, come to rest and sleep).
pub const CASES: [Case; 28] = [
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
    Case::stepwise(
        RAGDOLL_LANDING,
        "impulses, semi-implicit Euler",
        "f32",
        9,
        ragdoll_landing,
    ),
    Case::stepwise(RAGDOLL_FREE, "RK4", "f32", 5, ragdoll_free),
    Case::scripted(
        "world: 3 balls and a crate in a box",
        "sequential impulses",
        "f32",
        2,
        world_in_a_box,
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

    /// A case that times its steps calls the stopwatch once a step, and the run timed ends
    /// with the bits of the run untimed; any other case never calls it.
    #[test]
    fn stepwise_cases_time_every_step() -> Result<(), lagrange_core::Error> {
        /// Counts the steps it runs.
        struct Count(u32);
        impl Stopwatch for Count {
            fn time(
                &mut self,
                step: &mut dyn FnMut() -> Result<(), lagrange_core::Error>,
            ) -> Result<(), lagrange_core::Error> {
                self.0 += 1;
                step()
            }
        }
        for case in &CASES {
            let mut count = Count(0);
            let timed = case.run_timed(20, &mut count)?;
            assert_eq!(timed, case.run(20)?, "{}", case.system);
            assert_eq!(count.0, if case.times_steps() { 20 } else { 0 });
        }
        assert_eq!(CASES.iter().filter(|c| c.times_steps()).count(), 2);
        Ok(())
    }

    /// The thrown ragdoll has landed and rests within the run: its torso moves by less than
    /// 1e-5 (m, rad) over 100 more steps, lies above the floor, and the stepper's peak work
    /// is within its documented cap (at most the 31 rows of the set; at most
    /// `RAGDOLL_ITERATIONS + 3` rounds, `ImpulseSettings::max_rounds`).
    #[test]
    fn the_ragdoll_lands_and_rests() -> Result<(), lagrange_core::Error> {
        let at = |steps| -> Result<[f32; 3], lagrange_core::Error> {
            let words = ragdoll_landing(steps, &mut Untimed)?;
            Ok(core::array::from_fn(|k| {
                f32::from_bits(u32::try_from(words.words()[2 + k]).unwrap_or(0))
            }))
        };
        let (end, later) = (at(STEPS)?, at(STEPS + 100)?);
        for (a, b) in end.iter().zip(&later) {
            assert!((a - b).abs() < 1e-5, "{end:?} then {later:?}");
        }
        assert!(end[1] > 0.0 && end[1] < 1.0, "torso at {end:?}");
        let words = ragdoll_landing(STEPS, &mut Untimed)?;
        let [rows, _, frictional, rounds] = [5, 6, 7, 8].map(|k| words.words()[k]);
        let cap = RAGDOLL_ROWS as u64;
        assert!(rows > 0 && rows <= cap, "{rows} rows");
        assert!(
            frictional <= rows,
            "{frictional} of {rows} rows with friction"
        );
        assert!(
            rounds <= u64::from(RAGDOLL_ITERATIONS) + 3,
            "{rounds} rounds"
        );
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
