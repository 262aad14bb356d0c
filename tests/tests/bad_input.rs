//! Bad parameters and bad states give specific errors, never a panic or a silent NaN.

use lagrange_core::nalgebra::SVector;
use lagrange_core::{
    Error, EulerLagrange, Lagrangian, Mechanism, Real, Scalar, State, ViscousDamping,
};
use lagrange_integrators::{
    AdaptiveSettings, BackwardEuler, DormandPrince54, ExplicitEuler, Failure, GaussLegendre2,
    ImplicitMidpoint, Integrator, RadauIIA2, Rk4, SemiImplicitEuler, StormerVerlet,
    VariationalMidpoint, VelocityVerlet, Yoshida4,
};
use lagrange_systems::exact::{jacobi_sn_cn, pendulum_from_rest};
use lagrange_systems::{BeadOnRotatingHoop, DoublePendulum, FallingParticle, SimplePendulum};
use lagrange_tests::for_f32_and_f64;

/// The values no positive parameter may take.
fn not_positive<T: Real>() -> [T; 5] {
    [
        T::zero(),
        -T::one(),
        T::from_f64(f64::NAN),
        T::INFINITY,
        -T::INFINITY,
    ]
}

/// `Err(InvalidParameter { name, .. })` with exactly this name.
fn refuses<V: core::fmt::Debug>(result: Result<V, Error>, expected: &str) {
    assert!(
        matches!(result, Err(Error::InvalidParameter { name, .. }) if name == expected),
        "expected InvalidParameter {{ name: {expected} }}, got {result:?}"
    );
}

fn constructors_name_the_bad_parameter<T: Real>() -> Result<(), Error> {
    let one = T::one();
    let g = T::from_f64(9.81);
    for bad in not_positive::<T>() {
        refuses(FallingParticle::new(bad, g), "mass");
        refuses(SimplePendulum::new(bad, one, g, T::zero()), "mass");
        refuses(SimplePendulum::new(one, bad, g, T::zero()), "length");
        refuses(BeadOnRotatingHoop::new(bad, one, one, g), "mass");
        refuses(BeadOnRotatingHoop::new(one, bad, one, g), "radius");
        refuses(DoublePendulum::new(bad, one, one, one, g), "m1");
        refuses(DoublePendulum::new(one, bad, one, one, g), "m2");
        refuses(DoublePendulum::new(one, one, bad, one, g), "l1");
        refuses(DoublePendulum::new(one, one, one, bad, g), "l2");
    }
    // Zero gravity and zero damping are valid; negative or non-finite are not.
    for bad in [-T::one(), T::from_f64(f64::NAN), T::INFINITY] {
        refuses(FallingParticle::new(one, bad), "gravity");
        refuses(SimplePendulum::new(one, one, bad, T::zero()), "gravity");
        refuses(SimplePendulum::new(one, one, g, bad), "damping");
        refuses(BeadOnRotatingHoop::new(one, one, one, bad), "gravity");
        refuses(DoublePendulum::new(one, one, one, one, bad), "gravity");
        refuses(
            ViscousDamping::<T, 2>::new([T::zero(), bad]),
            "coefficients[1]",
        );
        refuses(ViscousDamping::<T, 2>::uniform(bad), "coefficient");
    }
    refuses(
        BeadOnRotatingHoop::new(one, one, T::from_f64(f64::NAN), g),
        "omega",
    );
    SimplePendulum::new(one, one, T::zero(), T::zero())?;
    BeadOnRotatingHoop::new(one, one, -T::from_f64(3.0), g)?;
    Ok(())
}

/// Every integrator refuses a NaN or infinite state with `NonFiniteState` and a zero,
/// negative or non-finite step with `InvalidParameter { name: "dt" }` (every method runs
/// forward in time).
fn check_integrator<T: Real, I: Integrator<T, 2, DoublePendulum<T>>>(
    mut i: I,
) -> Result<(), Error> {
    let dp = DoublePendulum::new(T::one(), T::one(), T::one(), T::one(), T::from_f64(9.81))?;
    let nan = T::from_f64(f64::NAN);
    let good = State::new(T::zero(), [T::HALF, T::zero()], [T::zero(); 2]);
    for bad in [
        State::new(T::zero(), [nan, T::zero()], [T::zero(); 2]),
        State::new(T::zero(), [T::zero(); 2], [T::zero(), nan]),
        State::new(T::zero(), [T::zero(); 2], [T::INFINITY, T::zero()]),
        State::new(nan, [T::zero(); 2], [T::zero(); 2]),
    ] {
        assert_eq!(
            i.step(&dp, &bad, T::from_f64(1e-3)),
            Err(Error::NonFiniteState),
            "{}",
            I::NAME
        );
    }
    for dt in [T::zero(), nan, T::INFINITY, -T::from_f64(1e-3)] {
        refuses(i.step(&dp, &good, dt), "dt");
        refuses(i.integrate(&dp, &good, dt, 0).map_err(|f| f.error), "dt");
    }
    i.step(&dp, &good, T::from_f64(1e-3))?;
    Ok(())
}

fn integrators_refuse_bad_states_and_steps<T: Real>() -> Result<(), Error> {
    check_integrator::<T, _>(ExplicitEuler)?;
    check_integrator::<T, _>(SemiImplicitEuler)?;
    check_integrator::<T, _>(VelocityVerlet)?;
    check_integrator::<T, _>(Rk4)?;
    check_integrator::<T, _>(StormerVerlet::default())?;
    check_integrator::<T, _>(Yoshida4::<StormerVerlet<T, 2>>::default())?;
    check_integrator::<T, _>(ImplicitMidpoint::default())?;
    check_integrator::<T, _>(GaussLegendre2::default())?;
    check_integrator::<T, _>(BackwardEuler::default())?;
    check_integrator::<T, _>(RadauIIA2::default())?;
    check_integrator::<T, _>(VariationalMidpoint::default())?;
    check_integrator::<T, _>(Yoshida4::<VariationalMidpoint<T, 2>>::default())?;
    check_integrator::<T, _>(DormandPrince54::new(AdaptiveSettings::new(
        T::from_f64(1e-5),
        T::from_f64(1e-7),
    )?))?;
    check_variational::<T>()
}

/// The variational integrator on the automatic path, stepping and integrating in momentum
/// form, refuses the same states and steps.
fn check_variational<T: Real>() -> Result<(), Error> {
    let one = T::one();
    let dp = EulerLagrange::new(DoublePendulum::new(one, one, one, one, T::from_f64(9.81))?);
    let nan = T::from_f64(f64::NAN);
    let mut vi = VariationalMidpoint::default();
    let good = State::new(T::zero(), [T::HALF, T::zero()], [T::zero(); 2]);
    for bad in [
        State::new(T::zero(), [nan, T::zero()], [T::zero(); 2]),
        State::new(T::zero(), [T::zero(); 2], [T::INFINITY, T::zero()]),
        State::new(nan, [T::zero(); 2], [T::zero(); 2]),
    ] {
        assert_eq!(
            vi.step(&dp, &bad, T::from_f64(1e-3)),
            Err(Error::NonFiniteState)
        );
        assert_eq!(
            vi.integrate(&dp, &bad, T::from_f64(1e-3), 3)
                .map_err(|f| f.error),
            Err(Error::NonFiniteState)
        );
    }
    for dt in [T::zero(), nan, T::INFINITY, -T::from_f64(1e-3)] {
        refuses(vi.step(&dp, &good, dt), "dt");
    }
    vi.step(&dp, &good, T::from_f64(1e-3))?;
    Ok(())
}

/// A unit mass on a spring of stiffness `k`, through the automatic path.
struct Spring<T> {
    k: T,
}

impl<T: Real> Lagrangian<T, 1> for Spring<T> {
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, _q: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
        S::from_f64(0.5) * qd[0] * qd[0]
    }
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 1>) -> S {
        S::from_f64(0.5) * S::from_real(self.k) * q[0] * q[0]
    }
}

/// Far past the stability limit an explicit method blows up (explicit Euler multiplies the
/// amplitude of an oscillator by `sqrt(1 + (h w)^2)` per step, here ~100): the outcome is
/// `NonFiniteState` once the state overflows, never a state with NaN or infinity in it.
fn blow_up_is_an_error<T: Real>() -> Result<(), Error> {
    let spring = EulerLagrange::new(Spring {
        k: T::from_f64(1e4),
    });
    let start = State::new(T::zero(), [T::one()], [T::zero()]);
    for steps in [1, 10] {
        let s = ExplicitEuler.integrate(&spring, &start, T::one(), steps)?;
        assert!(s.is_finite());
    }
    let result = ExplicitEuler.integrate(&spring, &start, T::one(), 1000);
    assert_eq!(result.map_err(|f| f.error), Err(Error::NonFiniteState));
    // The failure names the step and keeps the last good state.
    assert!(result.is_err_and(|f| f.step > 10 && f.step < 1000 && f.last.is_finite()));
    Ok(())
}

for_f32_and_f64!(
    constructors_name_the_bad_parameter,
    integrators_refuse_bad_states_and_steps,
    blow_up_is_an_error
);

/// A Lagrangian whose mass matrix is singular is reported as such, through any integrator.
#[test]
fn singular_mass_matrix_through_an_integrator() {
    struct OnlyFirst;
    impl Lagrangian<f64, 2> for OnlyFirst {
        fn kinetic<S: Scalar<Real = f64>>(
            &self,
            _t: S,
            _q: &SVector<S, 2>,
            qd: &SVector<S, 2>,
        ) -> S {
            qd[0] * qd[0]
        }
        fn potential<S: Scalar<Real = f64>>(&self, _t: S, _q: &SVector<S, 2>) -> S {
            S::zero()
        }
    }
    let m = EulerLagrange::new(OnlyFirst);
    assert_eq!(
        Rk4.step(&m, &State::at_rest([0.0, 0.0]), 1e-3),
        Err(Error::SingularMassMatrix { pivot: 1 })
    );
    assert!(m.mass_matrix(&State::at_rest([0.0, 0.0]))[(1, 1)] == 0.0);
}

#[test]
fn reference_solutions_refuse_bad_arguments() {
    refuses(pendulum_from_rest(4.0, 1.0, 0.0), "theta0");
    refuses(pendulum_from_rest(0.5, 0.0, 0.0), "omega");
    refuses(pendulum_from_rest(0.5, 1.0, f64::NAN), "t");
    refuses(jacobi_sn_cn(0.5, 1.0), "k");
    refuses(jacobi_sn_cn(f64::INFINITY, 0.5), "u");
}

/// A law that is not finite at one time only: unit springs whose accelerations are `poison`
/// (NaN or an infinity, in the last coordinate) at `t = at`, and `-q` elsewhere.
struct Poisoned {
    at: f64,
    poison: f64,
}

impl<const N: usize> Lagrangian<f64, N> for Poisoned {
    fn kinetic<S: Scalar<Real = f64>>(&self, _t: S, _q: &SVector<S, N>, qd: &SVector<S, N>) -> S {
        qd.iter().fold(S::zero(), |e, &v| e + v * v * 0.5)
    }
    fn potential<S: Scalar<Real = f64>>(&self, _t: S, q: &SVector<S, N>) -> S {
        q.iter().fold(S::zero(), |e, &x| e + x * x * 0.5)
    }
}

impl<const N: usize> Mechanism<f64, N> for Poisoned {
    fn mass_matrix(&self, _s: &State<f64, N>) -> lagrange_core::nalgebra::SMatrix<f64, N, N> {
        lagrange_core::nalgebra::SMatrix::identity()
    }
    fn rhs(&self, s: &State<f64, N>) -> SVector<f64, N> {
        let mut a = -s.q;
        if s.t == self.at {
            a[N - 1] = self.poison;
        }
        a
    }
    /// The right-hand side as it is (`M = 1`), with no test of its own: a hand-written law.
    fn law<F: lagrange_core::GeneralizedForce<f64, N>>(
        &self,
        s: &State<f64, N>,
        _extra: &F,
    ) -> Result<SVector<f64, N>, Error> {
        Ok(<Self as Mechanism<f64, N>>::rhs(self, s))
    }
}

/// RK4 with `N` coordinates, from t = 0 with h = 1: a stage whose accelerations are not finite,
/// whichever of the four, fails the step with `NonFiniteState`, one step or many, never a state
/// with NaN or an infinity in it.
fn rk4_refuses_poison<const N: usize>() -> Result<(), Error> {
    let start = State::<f64, N>::new(0.0, [0.3; N], [0.1; N]);
    // Stage times: 0 (stage 1), 0.5 (stages 2 and 3), 1 (stage 4).
    for at in [0.0, 0.5, 1.0] {
        for poison in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let m = Poisoned { at, poison };
            assert_eq!(
                Rk4.step(&m, &start, 1.0),
                Err(Error::NonFiniteState),
                "{at} {poison}"
            );
            let run = Rk4.integrate(&m, &start, 1.0, 3);
            assert!(
                run.is_err_and(|f| f.error == Error::NonFiniteState && f.step == 0),
                "{at} {poison}"
            );
        }
    }
    // Where no stage meets the poison, the step is the springs'.
    let m = Poisoned {
        at: 0.25,
        poison: f64::NAN,
    };
    assert!(Rk4.step(&m, &start, 1.0)?.is_finite());
    Ok(())
}

/// Both of RK4's ways of taking a stage: each stage's accelerations tested (one coordinate)
/// and only the new state tested (six, above the threshold where the stages take the law
/// unchecked).
#[test]
fn rk4_refuses_a_stage_that_is_not_finite() -> Result<(), Error> {
    rk4_refuses_poison::<1>()?;
    rk4_refuses_poison::<6>()
}

/// An error reads as a sentence that names what went wrong, and a failed run as the step, the
/// time it began at and its error; the failure converts back to its error for `?`.
#[test]
fn errors_read_as_sentences() {
    let nan = Error::NonFiniteState;
    assert_eq!(nan.to_string(), "state is not finite (NaN or infinity)");
    let dt = Error::InvalidParameter {
        name: "dt",
        reason: "must be positive and finite",
    };
    assert_eq!(
        dt.to_string(),
        "invalid parameter `dt`: must be positive and finite"
    );
    assert_eq!(
        Error::RedundantConstraints { row: 2 }.to_string(),
        "constraint 2 is singular here or depends on the ones before it (redundant or singular constraints)"
    );
    let failure = Failure {
        error: nan,
        step: 3,
        last: State::new(0.5, [1.0], [0.0]),
    };
    assert_eq!(
        failure.to_string(),
        "step 3 (from t = 0.5) failed: state is not finite (NaN or infinity)"
    );
    assert_eq!(Error::from(failure), nan);
}
