//! A run that nothing observes (`Integrator::integrate`) may test its states for finiteness
//! once in a few steps rather than at every step (RK4 does, one state in 8), and take the
//! steps since the last tested state again, each tested, when a test or a step fails. Its
//! outcome must be that of the same run observed at every step (`integrate_with`, whose
//! states are each tested before the observer sees them): the same last state to the bit, or
//! the same error at the same step with the same last good state.

use core::cell::Cell;
use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{Error, GeneralizedForce, Lagrangian, Mechanism, Real, Scalar, State};
use lagrange_integrators::{Integrator, Rk4};
use lagrange_tests::for_f32_and_f64;

/// `q_i'' = k q_i^2` for each coordinate: unit masses in the potential `-k q^3 / 3`, which
/// run away to infinity in a finite time. Past `limit` on any coordinate (where given),
/// the law refuses the state instead, as a mechanism at a singular configuration does. A law
/// with a `budget` of calls (not a pure function of the state) fails once it is spent.
struct Runaway<T, const N: usize> {
    k: T,
    limit: Option<T>,
    budget: Option<Cell<u32>>,
}

impl<T: Real, const N: usize> Runaway<T, N> {
    fn new(k: T, limit: Option<T>, budget: Option<u32>) -> Self {
        Self {
            k,
            limit,
            budget: budget.map(Cell::new),
        }
    }
}

impl<T: Real, const N: usize> Lagrangian<T, N> for Runaway<T, N> {
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, _q: &SVector<S, N>, qd: &SVector<S, N>) -> S {
        qd.iter().fold(S::zero(), |t, v| t + *v * *v * T::HALF)
    }
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, N>) -> S {
        let third = T::one() / T::from_f64(3.0);
        q.iter()
            .fold(S::zero(), |v, x| v - *x * *x * *x * (self.k * third))
    }
}

impl<T: Real, const N: usize> Mechanism<T, N> for Runaway<T, N> {
    fn mass_matrix(&self, _s: &State<T, N>) -> SMatrix<T, N, N> {
        SMatrix::identity()
    }
    fn rhs(&self, s: &State<T, N>) -> SVector<T, N> {
        s.q.map(|x| self.k * x * x)
    }
    /// The accelerations as they come: infinite once `q^2` overflows (RK4 reads the law
    /// itself from 5 coordinates, and the run's own tests must catch the overflow).
    fn law<F: GeneralizedForce<T, N>>(
        &self,
        s: &State<T, N>,
        _extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        if let Some(left) = &self.budget {
            if left.get() == 0 {
                return Err(Error::NoConvergence { iterations: 0 });
            }
            left.set(left.get() - 1);
        }
        match self.limit {
            Some(limit) if s.q.as_slice().iter().any(|x| *x > limit) => Err(Error::Singularity {
                what: "past the limit",
            }),
            _ => Ok(self.rhs(s)),
        }
    }
}

/// How the runs of one mechanism ended: the failed steps seen, by error.
#[derive(Default)]
struct Seen {
    non_finite: Vec<u64>,
    refused: Vec<u64>,
    spent: Vec<u64>,
    finished: usize,
}

/// `integrate` against `integrate_with` for runs of many lengths and step sizes, each of a
/// mechanism made afresh by `make` (a budget of calls starts full).
fn compare<T: Real, const N: usize>(make: impl Fn() -> Runaway<T, N>, seen: &mut Seen) {
    let q0: [T; N] = core::array::from_fn(|i| T::from_f64(1.0 + 0.25 * i as f64));
    let start = State::new(T::from_f64(0.5), q0, [T::zero(); N]);
    for dt in [0.013, 0.021, 0.034, 0.055, 0.089, 0.144] {
        let dt = T::from_f64(dt);
        for steps in [0, 1, 7, 8, 9, 15, 16, 17, 23, 40, 63, 200] {
            let unobserved = Rk4.integrate(&make(), &start, dt, steps);
            let mut states = 0u64;
            let observed = Rk4.integrate_with(&make(), &start, dt, steps, |s| {
                assert!(s.is_finite(), "an observer saw {s:?}");
                states += 1;
            });
            // Debug prints each number so that it reads back to the same bits.
            assert_eq!(
                format!("{unobserved:?}"),
                format!("{observed:?}"),
                "dt {dt:?}, {steps} steps"
            );
            match observed {
                Ok(s) => {
                    assert!(s.is_finite());
                    assert_eq!(states, steps);
                    seen.finished += 1;
                }
                Err(f) => {
                    assert!(f.last.is_finite());
                    assert_eq!(states, f.step);
                    match f.error {
                        Error::NonFiniteState => seen.non_finite.push(f.step),
                        Error::Singularity { .. } => seen.refused.push(f.step),
                        Error::NoConvergence { .. } => seen.spent.push(f.step),
                        e => unreachable!("a runaway fails only so, not with {e:?}"),
                    }
                }
            }
        }
    }
}

/// Checks that some run failed within the untested steps of a chunk after the first (not at
/// a tested step, the eighth), so that the steps taken again were exercised.
fn mid_chunk(steps: &[u64]) -> bool {
    steps.iter().any(|k| *k >= 8 && k % 8 != 7)
}

/// Runs that overflow, runs the law refuses and runs whose law spends its budget, of 4
/// coordinates (where RK4 tests every step: a test of so few costs less than taking steps
/// again) and of 5 and 6 (where it tests one in 8): each kind of failure seen within the
/// untested steps.
fn unobserved_runs_end_as_observed_runs<T: Real>() -> Result<(), Error> {
    fn sizes<T: Real, const N: usize>() {
        let (k, limit) = (T::one(), Some(T::from_f64(30.0)));
        let mut seen = Seen::default();
        compare(|| Runaway::<T, N>::new(k, None, None), &mut seen);
        compare(|| Runaway::<T, N>::new(k, limit, None), &mut seen);
        compare(|| Runaway::<T, N>::new(k, None, Some(150)), &mut seen);
        for failed in [&seen.non_finite, &seen.refused, &seen.spent] {
            assert!(mid_chunk(failed), "N = {N}: {failed:?}");
        }
        assert!(seen.finished > 0);
    }
    sizes::<T, 4>();
    sizes::<T, 5>();
    sizes::<T, 6>();
    Ok(())
}

/// A step whose own time overflows (`t + dt` past the largest value) while the run's clock
/// stays finite: the run tested at every step refuses it (`finish` tests the step's time
/// before the clock's replaces it), and so must the unobserved run. From one ulp below the
/// largest value, steps of 0.625 ulp: the clock ends at `MAX + 0.25 ulp`, which rounds to
/// `MAX`, while the second step's own time is `MAX + 0.625 ulp`, which overflows.
fn a_step_whose_time_overflows<T: Real>(max: T, below: T) {
    let dt = (max - below) * T::from_f64(0.625);
    let at_rest = State::new(below, [T::zero(); 6], [T::zero(); 6]);
    let mechanism = Runaway::<T, 6>::new(T::one(), None, None);
    let observed = Rk4.integrate_with(&mechanism, &at_rest, dt, 2, |_| {});
    assert!(
        observed.is_err_and(|f| f.error == Error::NonFiniteState && f.step == 1),
        "{observed:?}"
    );
    let unobserved = Rk4.integrate(&mechanism, &at_rest, dt, 2);
    assert_eq!(format!("{unobserved:?}"), format!("{observed:?}"));
}

#[test]
fn a_step_whose_time_overflows_fails_unobserved_too() {
    a_step_whose_time_overflows(f64::MAX, f64::MAX.next_down());
    a_step_whose_time_overflows(f32::MAX, f32::MAX.next_down());
}

for_f32_and_f64!(unobserved_runs_end_as_observed_runs);
