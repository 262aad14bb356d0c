//! What a step says it did is what it did: every method's [`Method::last_step`] counts exactly
//! the acceleration evaluations and Jacobian evaluations of its last step, as a mechanism that
//! counts its own calls sees them. Checked on a first step, on steps that continue from the
//! method's own result (where a method may reuse what it learnt: Stormer-Verlet's first
//! guess, an adaptive pair's last stage), and on a step from a state set from outside (where
//! it must start afresh), in f32 and f64. The bench's evaluation counts and the scenes' cost
//! figures read these numbers.

use core::cell::Cell;
use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{
    Error, GeneralizedForce, Jacobian, Lagrangian, Mechanism, Real, Scalar, State,
};
use lagrange_integrators::{
    AdaptiveSettings, BackwardEuler, DormandPrince54, DormandPrince853, ExplicitEuler,
    GaussLegendre2, ImplicitMidpoint, Integrator, Method, RadauIIA2, Rk4, SemiImplicitEuler,
    StormerVerlet, VariationalMidpoint, VelocityVerlet, Work, Yoshida4,
};
use lagrange_systems::SimplePendulum;
use lagrange_tests::for_f32_and_f64;

/// A mechanism that counts the calls of its law and of its law's Jacobian.
struct Counting<M> {
    inner: M,
    laws: Cell<u32>,
    jacobians: Cell<u32>,
    /// Evaluations of `V` (in any scalar: the variational method differentiates `L` itself).
    potentials: Cell<u32>,
}

impl<M> Counting<M> {
    fn new(inner: M) -> Self {
        Self {
            inner,
            laws: Cell::new(0),
            jacobians: Cell::new(0),
            potentials: Cell::new(0),
        }
    }

    /// The counts since the last call, and zero them.
    fn take(&self) -> (u32, u32, u32) {
        (
            self.laws.replace(0),
            self.jacobians.replace(0),
            self.potentials.replace(0),
        )
    }
}

impl<T: Real, const N: usize, M: Mechanism<T, N>> Lagrangian<T, N> for Counting<M> {
    const EXPLICIT_TIME: bool = M::EXPLICIT_TIME;
    const CONSTANT_MASS: bool = M::CONSTANT_MASS;
    const DRIVEN: bool = M::DRIVEN;
    const READS_TIME: bool = M::READS_TIME;
    fn kinetic<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>, qd: &SVector<S, N>) -> S {
        self.inner.kinetic(t, q, qd)
    }
    fn potential<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>) -> S {
        self.potentials.set(self.potentials.get() + 1);
        self.inner.potential(t, q)
    }
    fn non_conservative_force(&self, s: &State<T, N>) -> SVector<T, N> {
        self.inner.non_conservative_force(s)
    }
}

impl<T: Real, const N: usize, M: Mechanism<T, N>> Mechanism<T, N> for Counting<M> {
    fn mass_matrix(&self, s: &State<T, N>) -> SMatrix<T, N, N> {
        self.inner.mass_matrix(s)
    }
    fn rhs(&self, s: &State<T, N>) -> SVector<T, N> {
        self.inner.rhs(s)
    }
    fn solve_mass(&self, s: &State<T, N>, b: &SVector<T, N>) -> Result<SVector<T, N>, Error> {
        self.inner.solve_mass(s, b)
    }
    fn law<F: GeneralizedForce<T, N>>(
        &self,
        s: &State<T, N>,
        extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        self.laws.set(self.laws.get() + 1);
        self.inner.law(s, extra)
    }
    fn law_jacobian<F: GeneralizedForce<T, N>>(
        &self,
        s: &State<T, N>,
        extra: &F,
    ) -> Result<(SVector<T, N>, Jacobian<T, N>), Error> {
        self.jacobians.set(self.jacobians.get() + 1);
        self.inner.law_jacobian(s, extra)
    }
    fn law_force<F: GeneralizedForce<T, N>>(
        &self,
        s: &State<T, N>,
        extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        self.inner.law_force(s, extra)
    }
}

/// A pendulum (1 kg, 1 m) with viscous damping `b`, its law and Jacobian calls counted.
fn pendulum<T: Real>(b: f64) -> Result<Counting<SimplePendulum<T>>, Error> {
    Ok(Counting::new(SimplePendulum::new(
        T::one(),
        T::one(),
        T::from_f64(9.81),
        T::from_f64(b),
    )?))
}

/// Four steps of `method` (from `start`, twice from its own result, once from a state set
/// from outside), each one's reported work against the counted calls; returns the
/// evaluations counted over all four, so that the caller can see the method did work.
fn counts<T: Real, I: Integrator<T, 1, Counting<SimplePendulum<T>>>>(
    name: &str,
    (damping, dt): (f64, f64),
    stateless: bool,
    mut method: I,
) -> Result<u32, Error> {
    // Damped, so that a guess carried over from a step is not exact (and Newton iterates).
    let m = pendulum(damping)?;
    let dt = T::from_f64(dt);
    let outside = State::new(T::from_f64(0.2), [T::from_f64(-1.1)], [T::from_f64(0.7)]);
    let mut s = State::new(T::zero(), [T::from_f64(0.9)], [T::from_f64(-0.4)]);
    let mut total = 0;
    for k in 0..4 {
        if k == 3 {
            s = outside;
        }
        m.take();
        let t = s.t;
        s = method.step(&m, &s, dt)?;
        assert!(
            s.t == t + dt,
            "{name}, step {k}: lands at {:?}",
            s.t.to_f64()
        );
        let (laws, jacobians, _) = m.take();
        let work = method.last_step();
        assert_eq!(
            (work.evaluations, work.jacobians),
            (laws, jacobians),
            "{name}, step {k}: reported (evaluations, Jacobians) against counted"
        );
        if stateless {
            // A method that keeps nothing between steps costs what its COST says, but for
            // the Jacobians Newton refreshes when it converges slowly (the long steps).
            let cost = Work::of(I::COST, work.iterations);
            let refreshed = Work {
                jacobians: work.jacobians,
                ..cost
            };
            assert_eq!(work, refreshed, "{name}, step {k}: against COST");
            assert!(
                work.jacobians >= cost.jacobians,
                "{name}, step {k}: {work:?}"
            );
            if dt < T::from_f64(0.1) {
                assert_eq!(work, cost, "{name}, step {k}: no refresh at short steps");
            }
        }
        total += laws;
    }
    // An adaptive pair may answer a step from its dense output, with no evaluation at all.
    assert!(total > 0, "{name}: no evaluation in four steps");
    Ok(total)
}

/// The variational midpoint differentiates `L` itself and never calls the law: its work is
/// stated in its own unit, evaluations of `L` in dual numbers counted as accelerations, and
/// follows its documented `COST` on every step, fresh or continuing, alone or composed by
/// Yoshida. Counted here as the evaluations of `V`, one per evaluation of `L`.
fn variational<T: Real>() -> Result<(), Error> {
    let m = pendulum(0.3)?;
    let mut method = VariationalMidpoint::default();
    let dt = T::from_f64(0.05);
    let outside = State::new(T::from_f64(0.2), [T::from_f64(-1.1)], [T::from_f64(0.7)]);
    let mut s = State::new(T::zero(), [T::from_f64(0.9)], [T::from_f64(-0.4)]);
    for k in 0..4 {
        let fresh = k == 0 || k == 3;
        if k == 3 {
            s = outside;
        }
        m.take();
        s = Integrator::<T, 1, _>::step(&mut method, &m, &s, dt)?;
        let (laws, jacobians, lagrangians) = m.take();
        let work = method.last_step();
        assert_eq!((laws, jacobians), (0, 0), "step {k}: the law was called");
        assert!(work.iterations > 0, "step {k}: no Newton iteration");
        assert_eq!(
            work,
            Work::of(<VariationalMidpoint<T, 1> as Method>::COST, work.iterations),
            "step {k}: the work is not the documented cost"
        );
        // The conversions between velocities and momenta are small Newton solves of their
        // own (a residual and a matrix each, exact in one iteration for a quadratic T),
        // counted as one evaluation: L is evaluated a little more often than reported, and
        // never less. Measured: 2 more on a continuing step, 3 on a fresh one.
        let reported = work.evaluations + work.jacobians;
        let uncounted = 2 + u32::from(fresh);
        assert_eq!(
            lagrangians,
            reported + uncounted,
            "step {k}: {work:?} against {lagrangians} evaluations of L"
        );
    }
    // Composed, three substeps of the same cost model: three times the fixed part.
    let mut yoshida = Yoshida4::new(VariationalMidpoint::default());
    for k in 0..3 {
        s = Integrator::<T, 1, _>::step(&mut yoshida, &m, &s, dt)?;
        let work = yoshida.last_step();
        assert!(work.iterations >= 3, "Yoshida step {k}: {work:?}");
        assert_eq!(
            work,
            Work::of(
                <Yoshida4<VariationalMidpoint<T, 1>> as Method>::COST,
                work.iterations
            ),
            "Yoshida step {k}"
        );
    }
    Ok(())
}

fn every_method<T: Real>() -> Result<(), Error> {
    // Lightly damped (Stormer-Verlet's kick converges by fixed point) and heavily damped
    // (where it needs Newton, and Jacobians), and long steps.
    // Stateless methods (`true`) cost what their COST says; the others reuse what their
    // last step learnt.
    // Steps of 0.4 s (a fifth of the period) make Newton refresh its Jacobians.
    for b in [(0.3, 0.05), (40.0, 0.05), (0.3, 0.4)] {
        counts::<T, _>("explicit Euler", b, true, ExplicitEuler)?;
        counts::<T, _>("semi-implicit Euler", b, true, SemiImplicitEuler)?;
        counts::<T, _>("velocity Verlet", b, true, VelocityVerlet)?;
        counts::<T, _>("RK4", b, true, Rk4)?;
        counts::<T, _>(
            "Yoshida 4 (implicit midpoint)",
            b,
            true,
            Yoshida4::new(ImplicitMidpoint::default()),
        )?;
        counts::<T, _>("Stormer-Verlet", b, false, StormerVerlet::default())?;
        counts::<T, _>(
            "Yoshida 4",
            b,
            false,
            Yoshida4::new(StormerVerlet::default()),
        )?;
        counts::<T, _>("implicit midpoint", b, true, ImplicitMidpoint::default())?;
        counts::<T, _>("Gauss-Legendre 2", b, true, GaussLegendre2::default())?;
        counts::<T, _>("backward Euler", b, true, BackwardEuler::default())?;
        counts::<T, _>("Radau IIA 2", b, true, RadauIIA2::default())?;
        let settings = AdaptiveSettings::new(T::from_f64(1e-5), T::from_f64(1e-5))?;
        counts::<T, _>(
            "Dormand-Prince 5(4)",
            b,
            false,
            DormandPrince54::new(settings),
        )?;
        counts::<T, _>("DOP853", b, false, DormandPrince853::new(settings))?;
    }
    Ok(())
}

/// Stormer-Verlet's implicit kick starts from the explicit one and reuses the acceleration at
/// the end of its last step when it continues from it: one evaluation per iteration plus one
/// at the end, and one more on a fresh start. The fixed-point iteration contracts by about
/// `h b / 2` per iteration (0.0075 here), so that from the explicit guess it reaches its
/// tolerance (8 EPSILON, relative to `|v| + |a h / 2|`) in exactly 7 iterations in f64 and 3
/// in f32 on every step, also from a turning point (`v = 0`, step 5), where the weights are
/// the kick's alone: a worse guess takes more, weights that are off take more or fewer.
fn stormer_verlet_reuses<T: Real>() -> Result<(), Error> {
    let m = pendulum(0.3)?;
    let iterations = if T::EPSILON > T::from_f64(1e-10) {
        3
    } else {
        7
    };
    let mut sv = StormerVerlet::default();
    let mut s = State::new(T::zero(), [T::from_f64(0.9)], [T::from_f64(-0.4)]);
    for k in 0..8 {
        let fresh = k == 0 || k == 5;
        if k == 5 {
            s = State::new(T::from_f64(0.2), [T::from_f64(-1.1)], [T::zero()]);
        }
        s = sv.step(&m, &s, T::from_f64(0.05))?;
        let work = Method::last_step(&sv);
        assert_eq!(
            work.evaluations,
            work.iterations + 1 + u32::from(fresh),
            "step {k} (fresh {fresh}): {work:?}"
        );
        assert_eq!(work.iterations, iterations, "step {k}: {work:?}");
    }
    Ok(())
}

/// An adaptive pair's statistics since its run started count the evaluations it made, and
/// its accepted and rejected steps add up to the work of each call: over runs that reject
/// (a tight tolerance from a first step fixed far too long) and a fresh start in between.
fn adaptive_statistics<T: Real>() -> Result<(), Error> {
    let m = pendulum(0.3)?;
    let settings = AdaptiveSettings::new(T::from_f64(1e-5), T::from_f64(1e-5))?
        .with_initial_step(T::from_f64(0.5))?;
    let mut dp = DormandPrince54::new(settings);
    for start in [
        State::new(T::zero(), [T::from_f64(2.0)], [T::zero()]),
        State::new(T::from_f64(3.0), [T::from_f64(-1.0)], [T::from_f64(1.5)]),
    ] {
        m.take();
        dp.integrate_to(&m, &start, start.t + T::from_f64(2.0))?;
        let (laws, _, _) = m.take();
        let (stats, work) = (dp.statistics(), dp.last_step());
        assert_eq!(stats.evaluations, u64::from(laws), "{stats:?}");
        assert_eq!(
            (stats.accepted, stats.rejected),
            (u64::from(work.steps), u64::from(work.rejected)),
            "{stats:?} against {work:?}"
        );
        assert!(stats.rejected > 0, "no rejection to count: {stats:?}");
    }
    Ok(())
}

for_f32_and_f64!(
    every_method,
    variational,
    stormer_verlet_reuses,
    adaptive_statistics
);
