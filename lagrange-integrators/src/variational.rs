//! [`VariationalMidpoint`]: the discrete Euler-Lagrange equations of the midpoint discrete
//! Lagrangian, with discrete forces (Lagrange-d'Alembert), in position-momentum form.

use crate::integrator::{
    check_run, check_run_step, check_signed, check_signed_run, check_step, continues, fail, Cost,
    Failure, Work,
};
use crate::newton::{self, BlockMatrix, Blocks, NewtonProblem, NewtonSettings, Start};
use crate::{Clock, Integrator, Method, SymmetricBase};
use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{
    all_finite, central_difference_jacobian, Dual, Error, Jacobian, Lagrangian, Mechanism, NoForce,
    Real, Scalar, State,
};

/// A state in position-momentum form: time, coordinates and the discrete momenta `p`
/// conjugate to them, which is what the variational integrator steps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseState<T: Real, const N: usize> {
    /// Time, s.
    pub t: T,
    /// Generalized coordinates `q`.
    pub q: SVector<T, N>,
    /// Momenta `p` (discrete momenta after a step; `dL/dq'` of a [`State`] at the start).
    pub p: SVector<T, N>,
}

impl<T: Real, const N: usize> PhaseState<T, N> {
    /// True when `t`, every coordinate and every momentum are finite.
    #[must_use]
    pub fn is_finite(&self) -> bool {
        self.t.is_finite() & all_finite(self.q.as_slice()) & all_finite(self.p.as_slice())
    }
}

#[cfg(feature = "defmt")]
impl<T: Real, const N: usize> defmt::Format for PhaseState<T, N> {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "PhaseState {{ t: {}, q: [", self.t.to_f64());
        for x in self.q.iter() {
            defmt::write!(f, "{} ", x.to_f64());
        }
        defmt::write!(f, "], p: [");
        for x in self.p.iter() {
            defmt::write!(f, "{} ", x.to_f64());
        }
        defmt::write!(f, "] }}");
    }
}

/// The variational integrator of the midpoint discrete Lagrangian, for any mechanism (its
/// [`Lagrangian`] is the discrete Lagrangian's; the forces its law applies besides `f`,
/// [`Mechanism::law_force`], are the discrete forces: damping, inputs, drives, and the
/// constraint forces of a constrained mechanism):
///
/// ```text
/// L_d(q0, q1, h) = h L(t0 + h/2, (q0 + q1)/2, (q1 - q0)/h)
/// F-  = F+ = h/2 Q(t0 + h/2, (q0 + q1)/2, (q1 - q0)/h)          discrete forces
///
/// p0 = -D1 L_d(q0, q1) - F-  =  dL/dq' - h/2 dL/dq - h/2 Q       solved for q1 (Newton)
/// p1 =  D2 L_d(q0, q1) + F+  =  p0 + h dL/dq + h Q               explicit
///                                 (all at the midpoint above)
/// ```
///
/// The first line of the position-momentum form is the discrete Euler-Lagrange equation
/// `D2 L_d(q_{k-1}, q_k) + D1 L_d(q_k, q_{k+1}) + F+ + F- = 0` (the discrete
/// Lagrange-d'Alembert principle when `Q` is not zero). The second is written as an impulse
/// (`D1 L_d + D2 L_d = h dL/dq`, `F- + F+ = h Q`; equal to `D2 L_d + F+` where the first
/// holds): then the momentum of a cyclic coordinate, which neither `L` nor `Q` changes, is
/// carried over unchanged, whatever the Newton tolerance and the rounding of `q1`.
///
/// Order 2, implicit (Newton on `N` unknowns: a first-order dual evaluation of `L` per
/// iteration for the residual, a second-order one for the exact Jacobian when it is
/// factorised, one more first-order evaluation for `p1`), fixed step.
/// Without forces the map `(q0, p0) -> (q1, p1)` is symplectic for any Lagrangian (a
/// configuration-dependent mass matrix included), so the energy error stays bounded with no
/// drift over very long runs, and it conserves exactly the discrete momentum of any cyclic
/// coordinate `q_i` (one that `L` does not contain, with no force on it): `p_i` is carried
/// from step to step unchanged, bit for bit. (By the discrete Noether theorem it conserves the
/// momentum map of any symmetry of `L`, there to the Newton tolerance.) With damping the
/// discrete forces remove energy at the rate the continuous ones do, to `O(h^2)`.
///
/// [`PhaseState`] carries the discrete momenta between steps; [`Integrator::step`] takes and
/// returns ordinary [`State`]s, converting with the Legendre transform `p = dL/dq'` (by
/// Newton on `dL/dq'(q, v) = p` for the velocities, exact in one iteration for a kinetic
/// energy quadratic in `q'`). A step from the state the last one returned continues from its
/// momenta, so a run of steps carries them exactly; [`Integrator::integrate`] stays in
/// position-momentum form throughout and converts only at the end. A constrained mechanism's
/// constraint forces enter as discrete forces (Lagrange-d'Alembert): the constraints then drift
/// by `O(h^2)`, which [`Projected`](crate::Projected) removes.
///
/// Cost per step, in evaluations of the Lagrangian in dual numbers counted as accelerations:
/// one first-order evaluation per Newton iteration, one second-order one per Newton matrix,
/// one more first-order one for `p1`, and the conversion to velocities (one iteration of the
/// same kind).
///
/// ```
/// use lagrange_core::prelude::*;
/// use lagrange_integrators::{Integrator, VariationalMidpoint};
/// use lagrange_systems::DoublePendulum;
/// let dp = EulerLagrange::new(DoublePendulum::new(1.0_f64, 1.0, 1.0, 1.0, 9.81)?);
/// let start = State::new(0.0, [0.6, -0.4], [0.5, 1.0]);
/// let end = VariationalMidpoint::default().integrate(&dp, &start, 1e-2, 1000)?;
/// assert!((dp.energy(&end) - dp.energy(&start)).abs() < 1e-3 * dp.energy(&start).abs());
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VariationalMidpoint<T: Real, const N: usize> {
    newton: NewtonSettings<T>,
    /// The state the last step returned and its position-momentum form: a step from it
    /// continues from those momenta.
    last: Option<(State<T, N>, PhaseState<T, N>)>,
    /// `(q1 - q0, h)` of the last step: the next step's first guess.
    motion: Option<(SVector<T, N>, T)>,
    work: Work,
}

impl<T: Real, const N: usize> Default for VariationalMidpoint<T, N> {
    /// With [`NewtonSettings::default`].
    fn default() -> Self {
        Self::new(NewtonSettings::default())
    }
}

#[cfg(feature = "defmt")]
impl<T: Real + defmt::Format, const N: usize> defmt::Format for VariationalMidpoint<T, N> {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "VariationalMidpoint {{ newton: {} }}", self.newton);
    }
}

/// `L = T - V` of `sys` at `(t, q, q')` in any scalar.
fn lagrangian<T, S, Sys, const N: usize>(
    sys: &Sys,
    t: S,
    q: &SVector<S, N>,
    qd: &SVector<S, N>,
) -> S
where
    T: Real,
    S: Scalar<Real = T>,
    Sys: Lagrangian<T, N>,
{
    sys.kinetic(t, q, qd) - sys.potential(t, q)
}

/// The discrete forces' generalized force at `state`: what the law applies besides `f`.
fn force<T: Real, M: Mechanism<T, N>, const N: usize>(
    m: &M,
    state: &State<T, N>,
) -> Result<SVector<T, N>, Error> {
    m.law_force(state, &NoForce)
}

/// `(dQ/dq, dQ/dq')` of [`force`] by central differences.
fn force_jacobian<T: Real, M: Mechanism<T, N>, const N: usize>(
    m: &M,
    state: &State<T, N>,
) -> Result<Jacobian<T, N>, Error> {
    let mut failure = None;
    let j = central_difference_jacobian(state, |s| {
        force(m, s).unwrap_or_else(|e| {
            failure = Some(e);
            SVector::zeros()
        })
    });
    failure.map_or(Ok(j), Err)
}

/// First derivatives of `L` at `(t, q, q')` along the `N` directions `(sq e_i, e_i)` in
/// `(q, q')`: `dL/dq'_i + sq dL/dq_i`.
fn directional<T: Real, Sys: Lagrangian<T, N>, const N: usize>(
    sys: &Sys,
    t: T,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
    sq: T,
) -> SVector<T, N> {
    let q = SVector::<Dual<T, N>, N>::from_fn(|k, _| {
        let mut d = Dual::constant(q[k]);
        if let Some(e) = d.eps.get_mut(k) {
            *e = sq;
        }
        d
    });
    let qd = SVector::<Dual<T, N>, N>::from_fn(|k, _| Dual::variable(qd[k], k));
    SVector::from(lagrangian(sys, Dual::constant(t), &q, &qd).eps)
}

/// `dL/dq` at `(t, q, q')`.
fn coordinate_gradient<T: Real, Sys: Lagrangian<T, N>, const N: usize>(
    sys: &Sys,
    t: T,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
) -> SVector<T, N> {
    let q = SVector::<Dual<T, N>, N>::from_fn(|k, _| Dual::variable(q[k], k));
    let qd = qd.map(Dual::constant);
    SVector::from(lagrangian(sys, Dual::constant(t), &q, &qd).eps)
}

/// The derivative of [`directional`] along `(oq e_j, ov e_j)` in `(q, q')`, column `j`: one
/// evaluation of `L` in second-order duals.
#[allow(clippy::too_many_arguments)] // the point and the two seeds
fn directional_jacobian<T: Real, Sys: Lagrangian<T, N>, const N: usize>(
    sys: &Sys,
    t: T,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
    sq: T,
    oq: T,
    ov: T,
) -> SMatrix<T, N, N> {
    let seed = |x: T, inner: T, outer: T, k: usize| {
        let mut re = Dual::<T, N>::constant(x);
        if let Some(e) = re.eps.get_mut(k) {
            *e = inner;
        }
        let mut d = Dual::<Dual<T, N>, N>::constant(re);
        if let Some(e) = d.eps.get_mut(k) {
            *e = Dual::constant(outer);
        }
        d
    };
    let qs = SVector::<Dual<Dual<T, N>, N>, N>::from_fn(|k, _| seed(q[k], sq, oq, k));
    let qds = SVector::<Dual<Dual<T, N>, N>, N>::from_fn(|k, _| seed(qd[k], T::one(), ov, k));
    let l = lagrangian(sys, Dual::constant(Dual::constant(t)), &qs, &qds);
    SMatrix::from_fn(|i, j| l.eps[j].eps[i])
}

/// The discrete Euler-Lagrange equation for `q1` given `(q0, p0)`.
struct DiscreteEulerLagrange<'a, T: Real, Sys, const N: usize> {
    sys: &'a Sys,
    start: &'a PhaseState<T, N>,
    h: T,
    /// Newton matrices evaluated.
    matrices: u32,
}

impl<T: Real, Sys: Mechanism<T, N>, const N: usize> DiscreteEulerLagrange<'_, T, Sys, N> {
    /// The midpoint state of the step to `q1`.
    fn midpoint(&self, q1: &SVector<T, N>) -> State<T, N> {
        State {
            t: self.start.t + self.h * T::HALF,
            q: (self.start.q + q1) * T::HALF,
            qd: (q1 - self.start.q) / self.h,
        }
    }
}

impl<T, Sys, const N: usize> NewtonProblem<T, N, 1> for DiscreteEulerLagrange<'_, T, Sys, N>
where
    T: Real,
    Sys: Mechanism<T, N>,
{
    fn residual(&mut self, q1: &Blocks<T, N, 1>) -> Result<Blocks<T, N, 1>, Error> {
        let m = self.midpoint(&q1[0]);
        let half = self.h * T::HALF;
        let p = directional(self.sys, m.t, &m.q, &m.qd, -half) - force(self.sys, &m)? * half;
        Ok([p - self.start.p])
    }

    fn newton_matrix(&mut self, q1: &Blocks<T, N, 1>) -> Result<BlockMatrix<T, N, 1>, Error> {
        let m = self.midpoint(&q1[0]);
        let half = self.h * T::HALF;
        let dl = directional_jacobian(self.sys, m.t, &m.q, &m.qd, -half, T::HALF, self.h.recip());
        self.matrices += 1;
        let dq = force_jacobian(self.sys, &m)?;
        // d/dq1 of h/2 Q(midpoint): h/2 (dQ/dq / 2 + dQ/dq' / h).
        let force = dq.wrt_q * (half * T::HALF) + dq.wrt_qd * T::HALF;
        Ok(BlockMatrix([[dl - force]]))
    }

    fn weights(&self, q1: &Blocks<T, N, 1>) -> Blocks<T, N, 1> {
        [q1[0].map(|x| x.abs()) + (q1[0] - self.start.q).map(|x| x.abs())]
    }
}

/// The inverse Legendre transform: `dL/dq'(t, q, v) = p` for `v`.
struct Legendre<'a, T: Real, Sys, const N: usize> {
    sys: &'a Sys,
    phase: &'a PhaseState<T, N>,
}

impl<T, Sys, const N: usize> NewtonProblem<T, N, 1> for Legendre<'_, T, Sys, N>
where
    T: Real,
    Sys: Lagrangian<T, N>,
{
    fn residual(&mut self, v: &Blocks<T, N, 1>) -> Result<Blocks<T, N, 1>, Error> {
        let z = self.phase;
        Ok([directional(self.sys, z.t, &z.q, &v[0], T::zero()) - z.p])
    }

    fn newton_matrix(&mut self, v: &Blocks<T, N, 1>) -> Result<BlockMatrix<T, N, 1>, Error> {
        let z = self.phase;
        let m = directional_jacobian(self.sys, z.t, &z.q, &v[0], T::zero(), T::zero(), T::one());
        Ok(BlockMatrix([[m]]))
    }

    fn weights(&self, v: &Blocks<T, N, 1>) -> Blocks<T, N, 1> {
        // The solve mixes the velocities through the mass matrix, so each one's rounding is
        // relative to the largest: a link nearly at rest beside a fast one (a chain falling
        // from rest) has no relative precision of its own to converge to.
        let largest = v[0].iter().fold(T::zero(), |m, x| m.max(x.abs()));
        [v[0].map(|x| x.abs() + largest)]
    }
}

impl<T: Real, const N: usize> VariationalMidpoint<T, N> {
    /// The integrator, solving its implicit equations with `newton`.
    #[must_use]
    pub fn new(newton: NewtonSettings<T>) -> Self {
        Self {
            newton,
            last: None,
            motion: None,
            work: Work::default(),
        }
    }

    /// The momenta `p = dL/dq'` at `state` (the continuous Legendre transform). No error
    /// channel: NaN or infinite for a state that is not finite or so extreme that it
    /// overflows; [`VariationalMidpoint::step_phase`] refuses such a phase state.
    pub fn momentum<Sys: Lagrangian<T, N>>(&self, sys: &Sys, state: &State<T, N>) -> SVector<T, N> {
        directional(sys, state.t, &state.q, &state.qd, T::zero())
    }

    /// `state` in position-momentum form.
    pub fn phase_state<Sys: Lagrangian<T, N>>(
        &self,
        sys: &Sys,
        state: &State<T, N>,
    ) -> PhaseState<T, N> {
        PhaseState {
            t: state.t,
            q: state.q,
            p: self.momentum(sys, state),
        }
    }

    /// The [`State`] whose momenta `dL/dq'` are `phase.p`, by Newton from the velocity
    /// `guess` (exact in one iteration when the kinetic energy is quadratic in `q'`).
    ///
    /// # Errors
    /// [`Error::NonFiniteState`] for a non-finite `phase`; [`Error::SingularJacobian`] where
    /// the mass matrix is singular; [`Error::NoConvergence`].
    pub fn velocity_state<Sys: Lagrangian<T, N>>(
        &self,
        sys: &Sys,
        phase: &PhaseState<T, N>,
        guess: &SVector<T, N>,
    ) -> Result<State<T, N>, Error> {
        if !phase.is_finite() {
            return Err(Error::NonFiniteState);
        }
        let mut v = [*guess];
        newton::solve(
            &mut Legendre { sys, phase },
            &mut v,
            &self.newton,
            Start::Newton,
        )?;
        let [qd] = v;
        Ok(State {
            t: phase.t,
            q: phase.q,
            qd,
        })
    }

    /// One step of `dt` (positive) in position-momentum form: `(q0, p0) -> (q1, p1)`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `dt` when not positive and finite;
    /// [`Error::StepSizeUnderflow`] when `phase.t + dt` rounds to `phase.t`;
    /// [`Error::NonFiniteState`] for a non-finite start or result (a time that overflows
    /// too); [`Error::NoConvergence`] or
    /// [`Error::SingularJacobian`] from Newton on the discrete Euler-Lagrange equation.
    pub fn step_phase<M: Mechanism<T, N>>(
        &mut self,
        m: &M,
        phase: &PhaseState<T, N>,
        dt: T,
    ) -> Result<PhaseState<T, N>, Error> {
        let dt = crate::integrator::check_dt(dt)?;
        if !phase.is_finite() {
            return Err(Error::NonFiniteState);
        }
        crate::integrator::advances(phase.t, dt)?;
        let guess = self.guess(&phase.q, dt);
        self.step_from(m, phase, dt, guess)
    }

    /// The first guess of `q1` for a step of `h` from `q0`: the last step's motion, scaled.
    fn guess(&self, q0: &SVector<T, N>, h: T) -> SVector<T, N> {
        match self.motion {
            Some((dq, h_last)) => q0 + dq * (h / h_last),
            None => *q0,
        }
    }

    /// A step of `h` (either sign, checked by the caller: it may be below the resolution of
    /// the time in a run) from `phase` with the guess `q1`.
    fn step_from<M: Mechanism<T, N>>(
        &mut self,
        m: &M,
        phase: &PhaseState<T, N>,
        h: T,
        q1: SVector<T, N>,
    ) -> Result<PhaseState<T, N>, Error> {
        if !phase.is_finite() {
            return Err(Error::NonFiniteState);
        }
        let mut problem = DiscreteEulerLagrange {
            sys: m,
            start: phase,
            h,
            matrices: 0,
        };
        let mut x = [q1];
        let iterations = newton::solve(&mut problem, &mut x, &self.newton, Start::Newton)?;
        let [q1] = x;
        let mid = problem.midpoint(&q1);
        let p1 = phase.p + (coordinate_gradient(m, mid.t, &mid.q, &mid.qd) + force(m, &mid)?) * h;
        let next = PhaseState {
            t: phase.t + h,
            q: q1,
            p: p1,
        };
        if !next.is_finite() {
            return Err(Error::NonFiniteState);
        }
        self.motion = Some((q1 - phase.q, h));
        self.work = Work {
            evaluations: iterations + 1,
            jacobians: problem.matrices,
            iterations,
            steps: 1,
            rejected: 0,
        };
        Ok(next)
    }

    /// One step of `h` (either sign) from a [`State`]: from the momenta kept by the last step
    /// when `state` is what it returned, converting otherwise; then back to velocities.
    fn advance<M: Mechanism<T, N>>(
        &mut self,
        m: &M,
        state: &State<T, N>,
        h: T,
    ) -> Result<State<T, N>, Error> {
        let (z, guess) = match self.last.take() {
            // The driver's clock is the time.
            Some((out, z)) if continues(&out, state) => {
                (PhaseState { t: state.t, ..z }, self.guess(&state.q, h))
            }
            _ => (self.phase_state(m, state), state.q + state.qd * h),
        };
        let next = self.step_from(m, &z, h, guess)?;
        let out = self.velocity_state(m, &next, &((next.q - z.q) / h))?;
        self.work.evaluations += 1;
        self.last = Some((out, next));
        Ok(out)
    }
}

impl<T: Real, const N: usize> Method for VariationalMidpoint<T, N> {
    const NAME: &'static str = "variational midpoint";
    const YOSHIDA4_NAME: &'static str = "Yoshida 4 (variational)";
    const ORDER: u32 = 2;
    /// Lagrangian evaluations in dual numbers, counted as accelerations: one first-order per
    /// Newton iteration, one for `p1` and one for the velocities; one second-order per Newton
    /// matrix.
    const COST: Cost = Cost {
        fixed: 2,
        per_iteration: 1,
        jacobians: 1,
    };

    fn last_step(&self) -> Work {
        self.work
    }
}

impl<T: Real, const N: usize, M: Mechanism<T, N>> Integrator<T, N, M>
    for VariationalMidpoint<T, N>
{
    fn step(&mut self, m: &M, s: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        let h = check_step(s, dt)?;
        self.advance(m, s, h)
    }

    fn run_step(&mut self, m: &M, s: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        let h = check_run_step(s, dt)?;
        self.advance(m, s, h)
    }

    /// In position-momentum form throughout, converting to velocities only at the end (the
    /// default would convert after every step).
    fn integrate(
        &mut self,
        m: &M,
        state: &State<T, N>,
        dt: T,
        steps: u64,
    ) -> Result<State<T, N>, Failure<T, N>> {
        let dt = check_run(state, dt, steps).map_err(|e| fail(e, 0, state))?;
        if steps == 0 {
            return Ok(*state);
        }
        // The last step's momenta and motion only where this run continues from its end.
        let (mut z, mut guess) = match self.last.take() {
            Some((out, z)) if continues(&out, state) => {
                (PhaseState { t: state.t, ..z }, self.guess(&state.q, dt))
            }
            _ => (self.phase_state(m, state), state.q + state.qd * dt),
        };
        let mut clock = Clock::new(state.t);
        let mut before = z;
        for k in 0..steps {
            before = z;
            z = self.step_from(m, &z, dt, guess).map_err(|e| {
                // The last good state in velocities, when it can be had.
                let last = self.velocity_state(m, &before, &state.qd).unwrap_or(*state);
                fail(e, k, &last)
            })?;
            clock.tick(dt);
            z.t = clock.time();
            guess = z.q + (z.q - before.q);
        }
        let out = self
            .velocity_state(m, &z, &((z.q - before.q) / dt))
            .map_err(|e| fail(e, steps, state))?;
        self.last = Some((out, z));
        Ok(out)
    }
}

/// The variational midpoint rule is symmetric and of order 2: a base for
/// [`Yoshida4`](crate::Yoshida4), which makes an order-4 method symplectic for any Lagrangian.
impl<T: Real, const N: usize, M: Mechanism<T, N>> SymmetricBase<T, N, M>
    for VariationalMidpoint<T, N>
{
    fn signed_step(&mut self, m: &M, s: &State<T, N>, h: T) -> Result<State<T, N>, Error> {
        let h = check_signed(s, h)?;
        self.advance(m, s, h)
    }

    fn signed_run_step(&mut self, m: &M, s: &State<T, N>, h: T) -> Result<State<T, N>, Error> {
        let h = check_signed_run(s, h)?;
        self.advance(m, s, h)
    }
}
