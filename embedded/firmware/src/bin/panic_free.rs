//! The panic-free check: steps every shipped unconstrained mechanism with every shipped
//! fixed-step integrator (explicit, symplectic, Yoshida, implicit Runge-Kutta with Newton), in
//! `f32` and `f64`, plus the automatic Euler-Lagrange path with a damping force and the
//! variational integrator, a scene that sleeps and wakes, and the impulse stepper with the
//! ragdoll's 31 rows (every setting and inner method it is built with), from inputs the
//! optimiser cannot see (`black_box`), with `panic-never` as the panic handler. That handler
//! references an undefined symbol, so the image links only if the optimised stepping code
//! holds no panic path at all (no bounds check, unwrap or overflow check left). `cargo xtask
//! qemu` builds it in release (opt-level 3) and runs it.

#![no_std]
#![no_main]

use core::hint::black_box;

use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, EulerLagrange, Mechanism, Real, State, ViscousDamping};
use lagrange_firmware::{entry, exit};
use lagrange_integrators::scene::{Bank, Scene, Sleeps};
use lagrange_integrators::{
    BackwardEuler, ExplicitEuler, GaussLegendre2, ImplicitMidpoint, Integrator, RadauIIA2, Rk4,
    SemiImplicitEuler, StormerVerlet, VariationalMidpoint, VelocityVerlet, Yoshida4,
};
use lagrange_systems::{
    Acrobot, BeadOnRotatingHoop, CartPole, DoublePendulum, ElasticPendulum, FallingParticle,
    Kepler, NLinkPendulum, SimplePendulum, SphericalPendulum, SpringMassDamper, SwingingAtwood,
};
use panic_never as _;

/// Steps per run: the count is opaque to the optimiser anyway.
const STEPS: u32 = 10;

/// `STEPS` steps of `m` from `start` with every shipped integrator; `true` when all succeed.
fn every_integrator<T: Real, const N: usize, M: Mechanism<T, N>>(
    m: &M,
    start: State<T, N>,
) -> bool {
    fn run<T: Real, const N: usize, M: Mechanism<T, N>, I: Integrator<T, N, M>>(
        mut integrator: I,
        m: &M,
        start: State<T, N>,
    ) -> Result<State<T, N>, Error> {
        let dt = black_box(T::from_f64(1e-3));
        let mut s = black_box(start);
        for _ in 0..black_box(STEPS) {
            s = integrator.step(black_box(m), &s, dt)?;
        }
        Ok(black_box(s))
    }
    run(ExplicitEuler, m, start).is_ok()
        & run(SemiImplicitEuler, m, start).is_ok()
        & run(VelocityVerlet, m, start).is_ok()
        & run(Rk4, m, start).is_ok()
        & run(StormerVerlet::default(), m, start).is_ok()
        & run(Yoshida4::new(StormerVerlet::default()), m, start).is_ok()
        & run(ImplicitMidpoint::default(), m, start).is_ok()
        & run(BackwardEuler::default(), m, start).is_ok()
        & run(GaussLegendre2::default(), m, start).is_ok()
        & run(RadauIIA2::default(), m, start).is_ok()
        & run(VariationalMidpoint::default(), m, start).is_ok()
}

/// `STEPS` steps of the variational midpoint rule in position-momentum form throughout (its
/// `integrate`).
fn variational<T: Real, const N: usize, M: Mechanism<T, N>>(m: &M, start: State<T, N>) -> bool {
    let dt = black_box(T::from_f64(1e-3));
    VariationalMidpoint::default()
        .integrate(
            black_box(m),
            &black_box(start),
            dt,
            u64::from(black_box(STEPS)),
        )
        .is_ok()
}

/// A scene of pendulums that fall asleep, with every per-instance operation: `STEPS` frames,
/// a wake by each event, a removal; `true` when every call succeeds.
fn scene<T: Real>() -> Result<bool, Error> {
    let v = |x: f64| black_box(T::from_f64(x));
    let rule = Sleeps::new(v(1e-6), v(1e-3), black_box(4))?;
    let mut bank: Bank<T, 1, 4, SimplePendulum<T>, StormerVerlet<T, 1>, Sleeps<T>> =
        Bank::new(StormerVerlet::default(), rule)?;
    let p = SimplePendulum::new(v(1.0), v(1.0), v(9.81), v(0.5))?;
    let a = bank.add(p, State::at_rest([v(0.5)]))?;
    let b = bank.add_asleep(p, [v(0.0)])?;
    let mut scene = Scene::new(&mut bank, v(1.0 / 120.0), 4)?;
    for _ in 0..black_box(STEPS) {
        scene.advance(v(1.0 / 60.0))?;
    }
    let bank = scene.banks_mut();
    bank.apply_impulse(b, &SVector::from([v(0.1)]))?;
    bank.set_state(a, State::at_rest([v(0.2)]))?;
    bank.wake(b)?;
    bank.modify(a, |m| {
        *m = SimplePendulum::new(v(1.0), v(2.0), v(9.81), v(0.5))?;
        Ok(())
    })?;
    let drawn = bank.interpolated(a, v(0.5))?;
    let energy = bank.energies(a)?.total();
    bank.remove(b)?;
    Ok(black_box(drawn.q[0] + energy).is_finite())
}

/// The impulse stepper with the ragdoll's rows.
mod ragdoll {
    use core::hint::black_box;

    use lagrange_core::{Error, Real, State};
    use lagrange_integrators::{
        ContactModel, ImpulseSettings, ImpulseStepper, Integrator, SemiImplicitEuler,
    };
    use lagrange_systems::{Ragdoll, RagdollBody, RagdollContacts, RAGDOLL_COORDINATES};

    use super::STEPS;

    /// The ragdoll on the floor under the impulse stepper (semi-implicit Euler inside, the 31
    /// rows of `RagdollContacts`, friction): `STEPS` steps of 1/240 s from the throw of the
    /// lockstep case lowered into the floor (so that rows are solved and the drift corrected
    /// from the first step), a run by `integrate`, and the sleep test's law; `true` when every
    /// call succeeds and rows were solved.
    pub fn run<T: Real>() -> Result<bool, Error> {
        let v = |x: f64| black_box(T::from_f64(x));
        let doll = Ragdoll::new(black_box(RagdollBody::adult()))?;
        let contacts = RagdollContacts::adult(&doll, v(0.0))?;
        let model = ContactModel::new(v(0.3), v(0.3), v(1.0))?.with_friction(v(0.8))?;
        let settings = ImpulseSettings::new(v(2e-3), black_box(4))?;
        let mut stepper = ImpulseStepper::new(SemiImplicitEuler, contacts, model, settings);
        let dt = v(1.0 / 240.0);
        let mut start: State<T, RAGDOLL_COORDINATES> = lagrange_cases::ragdoll_thrown();
        start.q[1] = v(0.8);
        let mut s = black_box(start);
        for _ in 0..black_box(STEPS) {
            s = stepper.step(black_box(&doll), &s, dt)?;
        }
        let rows = stepper.last_report().rows + stepper.peak_report().rows;
        let (normal, tangent) = stepper.impulses();
        let end = stepper.integrate(&doll, &s, dt, u64::from(black_box(STEPS)))?;
        let law = stepper.law_acceleration(&doll, &end)?;
        Ok(rows > 0 && black_box(end.q[0] + law[0] + normal[0] + tangent[0]).is_finite())
    }
}

/// Every shipped mechanism, and the automatic path, in `T`; `true` when every run succeeds.
fn every_mechanism<T: Real>() -> Result<bool, Error> {
    let v = |x: f64| black_box(T::from_f64(x));
    let pendulum = SimplePendulum::new(v(1.0), v(1.0), v(9.81), v(0.1))?;
    let automatic = EulerLagrange::new(SimplePendulum::new(v(1.0), v(1.0), v(9.81), v(0.0))?)
        .with_force(ViscousDamping::uniform(v(0.1))?);
    Ok(every_integrator(
        &FallingParticle::new(v(1.0), v(9.81))?,
        State::at_rest([v(1.0)]),
    ) & every_integrator(&pendulum, State::at_rest([v(0.5)]))
        & every_integrator(
            &BeadOnRotatingHoop::new(v(1.0), v(1.0), v(5.0), v(9.81))?,
            State::at_rest([v(0.5)]),
        )
        & every_integrator(
            &DoublePendulum::new(v(1.0), v(1.0), v(1.0), v(1.0), v(9.81))?,
            State::at_rest([v(1.5), v(-1.5)]),
        )
        & every_integrator(&automatic, State::at_rest([v(0.5)]))
        & every_integrator(
            &CartPole::new(v(1.0), v(0.1), v(0.5), v(9.8))?,
            State::at_rest([v(0.0), v(0.3)]),
        )
        & every_integrator(
            &Acrobot::new(
                v(1.0),
                v(1.0),
                v(1.0),
                v(2.0),
                v(0.5),
                v(1.0),
                v(0.083),
                v(0.33),
                v(9.8),
            )?,
            State::at_rest([v(0.3), v(0.2)]),
        )
        & every_integrator(
            &SpringMassDamper::new(v(1.0), v(4.0), v(0.1))?,
            State::at_rest([v(1.0)]),
        )
        & every_integrator(
            &ElasticPendulum::new(v(1.0), v(40.0), v(1.0), v(9.81))?,
            State::at_rest([v(1.1), v(0.3)]),
        )
        & every_integrator(
            &SwingingAtwood::new(v(3.0), v(1.0), v(9.81))?,
            State::at_rest([v(1.0), v(0.5)]),
        )
        & every_integrator(
            &Kepler::new(v(1.0))?,
            State::new(v(0.0), [v(1.0), v(0.0)], [v(0.0), v(1.1)]),
        )
        & every_integrator(
            &SphericalPendulum::new(v(1.0), v(1.0), v(9.81))?,
            State::new(v(0.0), [v(0.5), v(0.0)], [v(0.0), v(1.0)]),
        )
        & every_integrator(
            &NLinkPendulum::new([v(1.0); 3], [v(1.0); 3], v(9.81))?,
            State::at_rest([v(0.5), v(-0.2), v(0.1)]),
        )
        & variational(&automatic, State::at_rest([v(0.5)])))
}

#[entry]
fn main() -> ! {
    let f32_ok = matches!(every_mechanism::<f32>(), Ok(true));
    let f64_ok = matches!(every_mechanism::<f64>(), Ok(true));
    let scenes_ok = matches!(scene::<f32>(), Ok(true)) && matches!(scene::<f64>(), Ok(true));
    let contacts_ok =
        matches!(ragdoll::run::<f32>(), Ok(true)) && matches!(ragdoll::run::<f64>(), Ok(true));
    exit(f32_ok && f64_ok && scenes_ok && contacts_ok)
}
