//! The adaptive pairs' energy projection (`AdaptiveSettings::with_energy_projection`): a Kepler
//! orbit holds its energy to rounding and its phase with it, a pendulum through its turning
//! points too at no evaluation more, the dense output ends on the projected state, events are
//! found and a run continues past them, and a driven or damped mechanism is refused.

use core::cell::Cell;
use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{
    Constrained, Constraints, Error, GeneralizedForce, Lagrangian, Mechanism, Real, Scalar, State,
    ViscousDamping,
};
use lagrange_integrators::{
    AdaptiveSettings, DormandPrince853, DormandPrinceNystrom86, EmbeddedPair, EmbeddedRungeKutta,
    Failure, Integrator, Stop, Verner98,
};
use lagrange_systems::exact::kepler_orbit;
use lagrange_systems::{BeadOnRotatingHoop, CartesianPendulum, Kepler, SimplePendulum};
use lagrange_tests::{for_f32_and_f64, kepler_periapsis, pick};

/// Every accepted step's end holds the start's energy to within this many machine epsilons,
/// relative: `T + V` rounded in a handful of operations, where `T` and `V` are each up to 8
/// times `|E|` (the Kepler orbit's periapsis; the pendulum's are at most `|E|`). Measured:
/// 2.2e-15 (10 epsilons) in f64, 7.2e-7 (6) in f32.
const HELD_EPSILONS: f64 = 64.0;

/// What a test returns where a call succeeded that should have failed, or the reverse.
const UNEXPECTED: Error = Error::NoConvergence { iterations: 0 };

/// The failure of a run the projection refused by naming the mechanism (`UNEXPECTED` where
/// the run succeeded; a failure of another kind fails the test).
fn refused<T: Real, const N: usize>(
    run: Result<State<T, N>, Failure<T, N>>,
) -> Result<Failure<T, N>, Error> {
    let Err(failure) = run else {
        return Err(UNEXPECTED);
    };
    assert!(
        matches!(
            failure.error,
            Error::InvalidParameter {
                name: "mechanism",
                ..
            }
        ),
        "{failure}"
    );
    Ok(failure)
}

/// Settings at `tol` (relative and absolute), with the projection where `held`.
fn settings<T: Real>(tol: f64, held: bool) -> Result<AdaptiveSettings<T>, Error> {
    let s = AdaptiveSettings::new(T::from_f64(tol), T::from_f64(tol))?.with_max_steps(1_000_000)?;
    Ok(if held { s.with_energy_projection() } else { s })
}

/// A run of `rk` on `m` to `t_end`, and the worst relative energy error at the end of any of
/// its steps (seen through a guard that never changes sign).
fn run<T, M, const N: usize, const S: usize, const R: usize, P>(
    rk: &mut EmbeddedRungeKutta<T, N, S, R, P>,
    m: &M,
    start: &State<T, N>,
    t_end: f64,
) -> Result<(State<T, N>, f64), Error>
where
    T: Real,
    M: Mechanism<T, N>,
    P: EmbeddedPair<S, R>,
{
    let e0 = m.energy(start).to_f64();
    let mut worst = 0.0f64;
    let stop = rk.integrate_until_event(m, start, T::from_f64(t_end), |s| {
        worst = worst.max(((m.energy(s).to_f64() - e0) / e0).abs());
        T::one()
    })?;
    Ok((*stop.state(), worst))
}

/// Problem P4's orbit (`e = 0.5`) by Verner 9(8): 100 periods in f64 at `rtol = 1e-9`, 10 in
/// f32 at `1e-5`. Held, every step ends at the start's energy to [`HELD_EPSILONS`], and the
/// position at the end is at least 50 times nearer the exact orbit than without (measured
/// 1,190 times: 1.3e-8 against 1.6e-5 in f64; 154 times, 2.7e-6 against 4.2e-4, in f32): the
/// energy error is what a long orbit's phase error is made of. The price is one evaluation
/// per step of 16, the polar law reading the velocities: at most 10% more (measured 5.4% and
/// 6.5%).
fn kepler_orbit_holds_its_energy_and_phase<T: Real>() -> Result<(), Error> {
    let (tol, periods) = (pick::<T>(1e-5, 1e-9), pick::<T>(10.0, 100.0));
    let t_end = 2.0 * core::f64::consts::PI * periods;
    let kepler = Kepler::new(T::one())?;
    let exact = kepler_orbit(1.0f64, 1.0, 0.5, t_end)?;
    let miss = |s: &State<T, 2>| {
        let (r, phi) = (s.q[0].to_f64(), s.q[1].to_f64());
        let (re, phie) = (exact.q[0], exact.q[1]);
        (r * phi.cos() - re * phie.cos()).hypot(r * phi.sin() - re * phie.sin())
    };
    let mut plain = Verner98::new(settings::<T>(tol, false)?);
    let (end, drift) = run(&mut plain, &kepler, &kepler_periapsis(), t_end)?;
    let mut held = Verner98::new(settings::<T>(tol, true)?);
    let (end_held, worst) = run(&mut held, &kepler, &kepler_periapsis(), t_end)?;
    let (e_plain, e_held) = (miss(&end), miss(&end_held));
    let evals = [
        plain.statistics().evaluations,
        held.statistics().evaluations,
    ];
    println!(
        "Kepler: energy error {drift:.1e} -> {worst:.1e}, position error {e_plain:.2e} -> \
         {e_held:.2e}, evaluations {evals:?}"
    );
    assert!(worst <= HELD_EPSILONS * T::EPSILON.to_f64(), "{worst:e}");
    assert!(e_held * 50.0 <= e_plain, "{e_held:e} against {e_plain:e}");
    assert!(evals[1] as f64 <= 1.1 * evals[0] as f64, "{evals:?}");
    Ok(())
}

/// The pendulum released from 1 rad, 200 s (about 100 swings) by DOP853 and by the Nyström
/// 8(6) pair: held, its energy stays at the start's to [`HELD_EPSILONS`] (DOP853 measured
/// 5.0e-16 in f64 and 1.8e-7 in f32, against 1.5e-7 and 3.3e-4 without), although every
/// swing passes two turning points where the kinetic energy is too small to carry the
/// correction (those steps are left as they are, and no NaN comes of them). Its law does not
/// read the velocities, so the derivative at a projected end is the stages' own: no evaluation
/// more per step (at most 2% more in all, the steps taken differing by a few; measured 0% and
/// -0.2%).
fn pendulum_holds_its_energy_through_turning_points<T: Real>() -> Result<(), Error> {
    let tol = pick::<T>(1e-5, 1e-8);
    let p = SimplePendulum::new(T::one(), T::one(), T::from_f64(9.81), T::zero())?;
    let start = State::at_rest([T::one()]);
    let mut plain = DormandPrince853::new(settings::<T>(tol, false)?);
    let (_, drift) = run(&mut plain, &p, &start, 200.0)?;
    let mut held = DormandPrince853::new(settings::<T>(tol, true)?);
    let (end, worst) = run(&mut held, &p, &start, 200.0)?;
    let evals = [
        plain.statistics().evaluations,
        held.statistics().evaluations,
    ];
    println!("pendulum, DOP853: energy error {drift:.1e} -> {worst:.1e}, evaluations {evals:?}");
    assert!(end.is_finite());
    assert!(worst <= HELD_EPSILONS * T::EPSILON.to_f64(), "{worst:e}");
    assert!(worst * 100.0 <= drift, "{worst:e} against {drift:e}");
    assert!(evals[1] as f64 <= 1.02 * evals[0] as f64, "{evals:?}");
    let mut nystrom = DormandPrinceNystrom86::new(settings::<T>(tol, true)?);
    let (end, worst) = run(&mut nystrom, &p, &start, 200.0)?;
    println!("pendulum, Nystrom 8(6): energy error {worst:.1e}");
    assert!(end.is_finite());
    assert!(worst <= HELD_EPSILONS * T::EPSILON.to_f64(), "{worst:e}");
    Ok(())
}

for_f32_and_f64!(
    kepler_orbit_holds_its_energy_and_phase,
    pendulum_holds_its_energy_through_turning_points,
);

/// A driven mechanism (the bead on a hoop spun at a constant rate, whose `T + V` the drive
/// changes) is refused when the run starts, before any evaluation; the integrator then runs
/// a conservative one as a new one would.
#[test]
fn a_driven_mechanism_is_refused() -> Result<(), Error> {
    let bead = BeadOnRotatingHoop::new(1.0, 0.5, 5.0, 9.81)?;
    let mut rk = DormandPrince853::new(settings::<f64>(1e-8, true)?);
    let failure = refused(rk.integrate_to(&bead, &State::new(0.0, [0.3], [0.0]), 1.0))?;
    assert_eq!((failure.step, rk.statistics().evaluations), (0, 0));
    let p = SimplePendulum::new(1.0, 1.0, 9.81, 0.0)?;
    let start = State::at_rest([0.5]);
    let after = rk.integrate_to(&p, &start, 1.0)?;
    let fresh =
        DormandPrince853::new(settings::<f64>(1e-8, true)?).integrate_to(&p, &start, 1.0)?;
    assert_eq!(after, fresh);
    Ok(())
}

/// A damped pendulum released from rest feels no damping at its start, so its run starts;
/// the first step's end moves, the damping acts there, and that step fails with
/// `InvalidParameter` `mechanism` (never a state whose energy the projection pumped back).
/// Undamped, the same run succeeds.
#[test]
fn a_damped_mechanism_fails_its_first_moving_step() -> Result<(), Error> {
    let start = State::at_rest([0.5]);
    let damped = SimplePendulum::new(1.0, 1.0, 9.81, 0.2)?;
    let mut rk = Verner98::new(settings::<f64>(1e-8, true)?);
    let failure = refused(rk.integrate_to(&damped, &start, 5.0))?;
    assert_eq!((failure.step, failure.last), (0, start));
    let undamped = SimplePendulum::new(1.0, 1.0, 9.81, 0.0)?;
    assert!(rk.integrate_to(&undamped, &start, 5.0)?.is_finite());
    Ok(())
}

/// The dense output of a projected step ends on the projected state: sampled a billionth of
/// the step before its end it is within 1e-8 of it (the step's `1e-9 h |y'|`), where the
/// step's own end is off the projected one by the energy correction: at rtol 1e-4 on the
/// Kepler orbit a plain step changes the energy by up to the printed figure (asserted above
/// 1e-7 of it), which at speeds below 3.5 moves the velocities by more than 1e-8: a dense
/// output that ended on the step's own end would miss by that much.
#[test]
fn the_dense_output_ends_on_the_projected_state() -> Result<(), Error> {
    let kepler = Kepler::new(1.0)?;
    let e0 = kepler.energy(&kepler_periapsis::<f64>());
    let mut worst = [0.0f64; 2];
    for (held, worst) in [true, false].into_iter().zip(&mut worst) {
        let mut rk = DormandPrince853::new(settings::<f64>(1e-4, held)?);
        let mut s = kepler_periapsis::<f64>();
        // Until the end (a step to an end the run has reached is refused).
        for _ in 0..200 {
            if s.t >= 100.0 {
                break;
            }
            let next = rk.next_step(&kepler, &s, 100.0)?;
            if held {
                let (t0, t1) = rk.dense_interval().ok_or(UNEXPECTED)?;
                let before = rk.dense_output(t1 - (t1 - t0) * 1e-9)?;
                let gap = (before.q - next.q).amax().max((before.qd - next.qd).amax());
                *worst = worst.max(gap);
            } else {
                let step = ((kepler.energy(&next) - kepler.energy(&s)) / e0).abs();
                *worst = worst.max(step);
            }
            s = next;
        }
    }
    let [gap, step] = worst;
    println!("dense output {gap:.1e} from the projected end; a plain step changes E by {step:.1e}");
    assert!(gap <= 1e-8, "{gap:e}");
    assert!(step >= 1e-7, "{step:e}");
    Ok(())
}

/// Events on a held run: the undamped pendulum from 0.5 rad crosses `th = 0` every half
/// period; DOP853 (on its dense output) and Verner 9(8) (again on steps) each find four
/// crossings in a row, continuing from each stop, within 1e-9 s of the exact quarter
/// periods (the state at an event is the step's, not projected), the dense output of the
/// step cut there ends on it (a billionth of the step before, within 1e-8), and the run's
/// energy after the last is still the start's to [`HELD_EPSILONS`].
#[test]
fn events_are_found_and_the_run_goes_on_holding() -> Result<(), Error> {
    let p = SimplePendulum::new(1.0, 1.0, 9.81, 0.0)?;
    let period = lagrange_systems::exact::pendulum_period(0.5, 9.81f64.sqrt())?;
    let start = State::at_rest([0.5]);
    crossings(
        &mut DormandPrince853::new(settings::<f64>(1e-10, true)?),
        &p,
        &start,
        period,
    )?;
    crossings(
        &mut Verner98::new(settings::<f64>(1e-10, true)?),
        &p,
        &start,
        period,
    )?;
    Ok(())
}

/// The four crossings of [`events_are_found_and_the_run_goes_on_holding`] by `rk`.
fn crossings<const S: usize, const R: usize, P: EmbeddedPair<S, R>>(
    rk: &mut EmbeddedRungeKutta<f64, 1, S, R, P>,
    p: &SimplePendulum<f64>,
    start: &State<f64, 1>,
    period: f64,
) -> Result<(), Error> {
    let mut s = *start;
    for k in 0..4 {
        let stop = rk.integrate_until_event(p, &s, 10.0, |s| s.q[0])?;
        let Stop::Event(at) = stop else {
            return Err(UNEXPECTED);
        };
        let exact = period * (0.25 + 0.5 * f64::from(k));
        assert!(
            (at.t - exact).abs() <= 1e-9,
            "{}: {} against {exact}",
            P::NAME,
            at.t
        );
        // The dense output of the step cut at the event ends on the event's state.
        let (t0, t1) = rk.dense_interval().ok_or(UNEXPECTED)?;
        let before = rk.dense_output(t1 - (t1 - t0) * 1e-9)?;
        let gap = (before.q - at.q).amax().max((before.qd - at.qd).amax());
        assert!(t1 == at.t && gap <= 1e-8, "{}: {gap:e} at {t1}", P::NAME);
        s = at;
    }
    let end = rk.integrate_to(p, &s, 4.0)?;
    let drift = (p.energy(&end) / p.energy(start) - 1.0).abs();
    assert!(
        drift <= HELD_EPSILONS * f64::EPSILON,
        "{}: {drift:e}",
        P::NAME
    );
    Ok(())
}

/// A constrained mechanism (the Cartesian pendulum: `T = m (x'^2 + y'^2) / 2`, one holonomic
/// row) holds its energy through its law's constraint forces, which do no work; scaling the
/// velocities scales `J q'` with them (by a factor within 1e-4 of 1 here), so the velocity
/// residual stays where the steps leave it: within 10% of the plain run's (measured equal,
/// 8.9e-7 m/s after 60 s at rtol 1e-6, no drift control). Driven by the frame loop
/// (`Integrator::step`, 120 frames of 0.5 s), every frame holds the start's energy to
/// [`HELD_EPSILONS`] (measured 6.7e-16), where the plain runs drift to 9.1e-4: Verner 9(8)
/// lands every frame by a step shortened to it, a projected step's end, and DOP853 on its
/// continuous extension inside a step, projected too.
#[test]
fn a_constrained_mechanism_holds_its_energy_at_every_frame() -> Result<(), Error> {
    // Frames long enough that the pair takes steps of its own choosing inside them.
    const FRAMES: usize = 120;
    const FRAME: f64 = 0.5;
    let pendulum = Constrained::new(CartesianPendulum::new(1.0, 1.0, 9.81)?);
    let start = pendulum.parts().state_from_angle(0.0, 1.2, 0.0);
    let e0 = pendulum.energy(&start);
    let mut results = [(0.0f64, 0.0f64); 2];
    for (held, result) in [false, true].into_iter().zip(&mut results) {
        let mut verner = Verner98::new(settings::<f64>(1e-6, held)?);
        let mut dop853 = DormandPrince853::new(settings::<f64>(1e-6, held)?);
        let (mut s, mut d) = (start, start);
        for _ in 0..FRAMES {
            s = verner.step(&pendulum, &s, FRAME)?;
            d = dop853.step(&pendulum, &d, FRAME)?;
            result.0 = result.0.max((pendulum.energy(&d) / e0 - 1.0).abs());
            result.0 = result.0.max((pendulum.energy(&s) / e0 - 1.0).abs());
        }
        result.1 = pendulum.residual(&s).velocity;
    }
    let [(drift, plain_residual), (worst, residual)] = results;
    println!(
        "constrained: energy {drift:.1e} -> {worst:.1e}, J q' {plain_residual:.1e} -> {residual:.1e}"
    );
    assert!(worst <= HELD_EPSILONS * f64::EPSILON, "{worst:e}");
    assert!(worst * 100.0 <= drift, "{worst:e} against {drift:e}");
    assert!(
        residual <= 1.1 * plain_residual,
        "{residual:e} against {plain_residual:e}"
    );
    Ok(())
}

/// A mechanism that counts its law's calls and keeps the last state it was evaluated at.
struct Recording<M, const N: usize> {
    inner: M,
    calls: Cell<u64>,
    last: Cell<Option<State<f64, N>>>,
}

impl<M: Mechanism<f64, N>, const N: usize> Lagrangian<f64, N> for Recording<M, N> {
    const DRIVEN: bool = M::DRIVEN;
    const READS_TIME: bool = M::READS_TIME;
    fn kinetic<S: Scalar<Real = f64>>(&self, t: S, q: &SVector<S, N>, qd: &SVector<S, N>) -> S {
        self.inner.kinetic(t, q, qd)
    }
    fn potential<S: Scalar<Real = f64>>(&self, t: S, q: &SVector<S, N>) -> S {
        self.inner.potential(t, q)
    }
    fn non_conservative_force(&self, s: &State<f64, N>) -> SVector<f64, N> {
        self.inner.non_conservative_force(s)
    }
}

impl<M: Mechanism<f64, N>, const N: usize> Mechanism<f64, N> for Recording<M, N> {
    fn mass_matrix(&self, s: &State<f64, N>) -> SMatrix<f64, N, N> {
        self.inner.mass_matrix(s)
    }
    fn rhs(&self, s: &State<f64, N>) -> SVector<f64, N> {
        self.inner.rhs(s)
    }
    fn law<F: GeneralizedForce<f64, N>>(
        &self,
        s: &State<f64, N>,
        extra: &F,
    ) -> Result<SVector<f64, N>, Error> {
        self.calls.set(self.calls.get() + 1);
        self.last.set(Some(*s));
        self.inner.law(s, extra)
    }
}

/// Where the law reads the velocities (the polar Kepler orbit), a held run evaluates it once
/// more per accepted step, at the projected end: `integrate_to` from a fresh start costs the
/// first derivative, the initial step's estimate and `FSAL` evaluations per attempted step,
/// plus, held, one per accepted step exactly, the run's last evaluation being at the state it
/// returns (DOP853 at rtol 1e-8 over 10 periods).
#[test]
fn a_held_step_evaluates_the_law_once_more_at_its_end() -> Result<(), Error> {
    let kepler = Recording {
        inner: Kepler::new(1.0)?,
        calls: Cell::new(0),
        last: Cell::new(None),
    };
    let t_end = 20.0 * core::f64::consts::PI;
    for held in [false, true] {
        kepler.calls.set(0);
        let mut rk = DormandPrince853::new(settings::<f64>(1e-8, held)?);
        let end = rk.integrate_to(&kepler, &kepler_periapsis(), t_end)?;
        let st = rk.statistics();
        let fsal = <lagrange_integrators::Dop853Pair as EmbeddedPair<16, 4>>::FSAL as u64;
        let expected = 2 + fsal * (st.accepted + st.rejected) + u64::from(held) * st.accepted;
        assert_eq!(
            (kepler.calls.get(), st.evaluations),
            (expected, expected),
            "held {held}"
        );
        if held {
            assert_eq!(kepler.last.get(), Some(end));
        }
    }
    Ok(())
}

/// A call that fails leaves the energy held as it found it: a held Kepler run interrupted,
/// after 50 steps, by a call from another start with a damped orbit (it starts, then fails at
/// its first step's end) goes on to the bits of the same run never interrupted.
#[test]
fn a_failed_call_keeps_the_energy_held() -> Result<(), Error> {
    let kepler = Kepler::new(1.0)?;
    let damped = Kepler::new(1.0)?.with_force(ViscousDamping::uniform(0.1)?);
    let t_end = 20.0 * core::f64::consts::PI;
    let mut ends = [kepler_periapsis::<f64>(); 2];
    for (interrupted, end) in [false, true].into_iter().zip(&mut ends) {
        let mut rk = Verner98::new(settings::<f64>(1e-9, true)?);
        let mut s = kepler_periapsis::<f64>();
        for _ in 0..50 {
            s = rk.next_step(&kepler, &s, t_end)?;
        }
        if interrupted {
            let other = State::new(0.0, [0.7, 0.0], [0.1, 1.5]);
            refused(rk.integrate_to(&damped, &other, t_end))?;
        }
        *end = rk.integrate_to(&kepler, &s, t_end)?;
    }
    assert_eq!(ends[0], ends[1]);
    Ok(())
}
