//! [`VariationalMidpoint`]: the discrete Euler-Lagrange equations of the midpoint discrete
//! Lagrangian, with discrete forces (Lagrange-d'Alembert), in position-momentum form.

use crate::integrator::check_dt;
use crate::newton::{self, BlockMatrix, Blocks, NewtonProblem, NewtonSettings, Start};
use crate::LagrangianSystem;
use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{Dual, Error, Real, State};

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
        self.t.is_finite()
            && self.q.iter().all(|x| x.is_finite())
            && self.p.iter().all(|x| x.is_finite())
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

/// The variational integrator of the midpoint discrete Lagrangian, for any
/// [`LagrangianSystem`] (any [`Lagrangian`](lagrange_core::Lagrangian) through
/// [`EulerLagrange`](lagrange_core::EulerLagrange), with forces added by `with_force`):
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
/// [`PhaseState`] carries the discrete momenta between steps; [`VariationalMidpoint::step`] and
/// [`VariationalMidpoint::integrate`] take and return ordinary [`State`]s, converting with the
/// Legendre transform `p = dL/dq'` at the ends (by Newton on `dL/dq'(q, v) = p` for the
/// velocities, exact in one iteration for a kinetic energy quadratic in `q'`).
///
/// ```
/// use lagrange_core::prelude::*;
/// use lagrange_integrators::VariationalMidpoint;
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
    /// `(q1, q1 - q0, h)` of the last step: the next step's first guess.
    last: Option<(SVector<T, N>, SVector<T, N>, T)>,
    iterations: u32,
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

/// First derivatives of `L` at `(t, q, q')` along the `N` directions `(sq e_i, e_i)` in
/// `(q, q')`: `dL/dq'_i + sq dL/dq_i`.
fn directional<T: Real, Sys: LagrangianSystem<T, N>, const N: usize>(
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
    SVector::from(sys.lagrangian(Dual::constant(t), &q, &qd).eps)
}

/// `dL/dq` at `(t, q, q')`.
fn coordinate_gradient<T: Real, Sys: LagrangianSystem<T, N>, const N: usize>(
    sys: &Sys,
    t: T,
    q: &SVector<T, N>,
    qd: &SVector<T, N>,
) -> SVector<T, N> {
    let q = SVector::<Dual<T, N>, N>::from_fn(|k, _| Dual::variable(q[k], k));
    let qd = qd.map(Dual::constant);
    SVector::from(sys.lagrangian(Dual::constant(t), &q, &qd).eps)
}

/// The derivative of [`directional`] along `(oq e_j, ov e_j)` in `(q, q')`, column `j`: one
/// evaluation of `L` in second-order duals.
#[allow(clippy::too_many_arguments)] // the point and the two seeds
fn directional_jacobian<T: Real, Sys: LagrangianSystem<T, N>, const N: usize>(
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
    let l = sys.lagrangian(Dual::constant(Dual::constant(t)), &qs, &qds);
    SMatrix::from_fn(|i, j| l.eps[j].eps[i])
}

/// The discrete Euler-Lagrange equation for `q1` given `(q0, p0)`.
struct DiscreteEulerLagrange<'a, T: Real, Sys, const N: usize> {
    sys: &'a Sys,
    start: &'a PhaseState<T, N>,
    h: T,
}

impl<T: Real, Sys: LagrangianSystem<T, N>, const N: usize> DiscreteEulerLagrange<'_, T, Sys, N> {
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
    Sys: LagrangianSystem<T, N>,
{
    fn residual(&mut self, q1: &Blocks<T, N, 1>) -> Result<Blocks<T, N, 1>, Error> {
        let m = self.midpoint(&q1[0]);
        let half = self.h * T::HALF;
        let p = directional(self.sys, m.t, &m.q, &m.qd, -half) - self.sys.force(&m) * half;
        Ok([p - self.start.p])
    }

    fn newton_matrix(&mut self, q1: &Blocks<T, N, 1>) -> Result<BlockMatrix<T, N, 1>, Error> {
        let m = self.midpoint(&q1[0]);
        let half = self.h * T::HALF;
        let dl = directional_jacobian(self.sys, m.t, &m.q, &m.qd, -half, T::HALF, self.h.recip());
        let dq = self.sys.force_jacobian(&m);
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
    Sys: LagrangianSystem<T, N>,
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
            iterations: 0,
        }
    }

    /// Newton iterations of the last step's discrete Euler-Lagrange equation.
    #[must_use]
    pub fn last_iterations(&self) -> u32 {
        self.iterations
    }

    /// The momenta `p = dL/dq'` at `state` (the continuous Legendre transform).
    pub fn momentum<Sys: LagrangianSystem<T, N>>(
        &self,
        sys: &Sys,
        state: &State<T, N>,
    ) -> SVector<T, N> {
        directional(sys, state.t, &state.q, &state.qd, T::zero())
    }

    /// `state` in position-momentum form.
    pub fn phase_state<Sys: LagrangianSystem<T, N>>(
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
    pub fn velocity_state<Sys: LagrangianSystem<T, N>>(
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

    /// One step of `dt` in position-momentum form: `(q0, p0) -> (q1, p1)`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `dt` when zero or not finite; [`Error::NonFiniteState`] for
    /// a non-finite start or result; [`Error::NoConvergence`] or [`Error::SingularJacobian`]
    /// from Newton on the discrete Euler-Lagrange equation.
    pub fn step_phase<Sys: LagrangianSystem<T, N>>(
        &mut self,
        sys: &Sys,
        phase: &PhaseState<T, N>,
        dt: T,
    ) -> Result<PhaseState<T, N>, Error> {
        let guess = match self.last.take() {
            Some((q, dq, h)) if q == phase.q => phase.q + dq * (dt / h),
            _ => phase.q,
        };
        self.step_from(sys, phase, dt, guess)
    }

    /// [`VariationalMidpoint::step_phase`] from the guess `q1`.
    fn step_from<Sys: LagrangianSystem<T, N>>(
        &mut self,
        sys: &Sys,
        phase: &PhaseState<T, N>,
        dt: T,
        q1: SVector<T, N>,
    ) -> Result<PhaseState<T, N>, Error> {
        if !phase.is_finite() {
            return Err(Error::NonFiniteState);
        }
        let h = check_dt(dt)?;
        let mut problem = DiscreteEulerLagrange {
            sys,
            start: phase,
            h,
        };
        let mut x = [q1];
        self.iterations = newton::solve(&mut problem, &mut x, &self.newton, Start::Newton)?;
        let [q1] = x;
        let m = problem.midpoint(&q1);
        let p1 = phase.p + (coordinate_gradient(sys, m.t, &m.q, &m.qd) + sys.force(&m)) * h;
        let next = PhaseState {
            t: phase.t + h,
            q: q1,
            p: p1,
        };
        if !next.is_finite() {
            return Err(Error::NonFiniteState);
        }
        self.last = Some((q1, q1 - phase.q, h));
        Ok(next)
    }

    /// One step of `dt` from a [`State`], converting to and from momenta.
    ///
    /// # Errors
    /// As [`VariationalMidpoint::step_phase`] and [`VariationalMidpoint::velocity_state`].
    pub fn step<Sys: LagrangianSystem<T, N>>(
        &mut self,
        sys: &Sys,
        state: &State<T, N>,
        dt: T,
    ) -> Result<State<T, N>, Error> {
        state.check_finite()?;
        let z = self.phase_state(sys, state);
        let next = self.step_from(sys, &z, dt, state.q + state.qd * dt)?;
        self.velocity_state(sys, &next, &((next.q - z.q) / dt))
    }

    /// `steps` steps of `dt` from `state`, in position-momentum form throughout, converting
    /// only at the ends.
    ///
    /// # Errors
    /// The first error of any step.
    pub fn integrate<Sys: LagrangianSystem<T, N>>(
        &mut self,
        sys: &Sys,
        state: &State<T, N>,
        dt: T,
        steps: u64,
    ) -> Result<State<T, N>, Error> {
        self.integrate_phase(sys, state, dt, steps, |_| Ok(()))
    }

    /// As [`VariationalMidpoint::integrate`], calling `observe` with every new state (which
    /// costs a conversion to velocities per step) and its position-momentum form.
    ///
    /// # Errors
    /// The first error of any step or conversion.
    pub fn integrate_with<Sys, F>(
        &mut self,
        sys: &Sys,
        state: &State<T, N>,
        dt: T,
        steps: u64,
        mut observe: F,
    ) -> Result<State<T, N>, Error>
    where
        Sys: LagrangianSystem<T, N>,
        F: FnMut(&State<T, N>, &PhaseState<T, N>),
    {
        let newton = self.newton;
        let mut previous = state.q;
        self.integrate_phase(sys, state, dt, steps, |z| {
            let s = Self::new(newton).velocity_state(sys, z, &((z.q - previous) / dt))?;
            previous = z.q;
            observe(&s, z);
            Ok(())
        })
    }

    /// The stepping loop of [`VariationalMidpoint::integrate`] and
    /// [`VariationalMidpoint::integrate_with`].
    fn integrate_phase<Sys, F>(
        &mut self,
        sys: &Sys,
        state: &State<T, N>,
        dt: T,
        steps: u64,
        mut each: F,
    ) -> Result<State<T, N>, Error>
    where
        Sys: LagrangianSystem<T, N>,
        F: FnMut(&PhaseState<T, N>) -> Result<(), Error>,
    {
        state.check_finite()?;
        let mut z = self.phase_state(sys, state);
        let mut guess = state.q + state.qd * dt;
        let mut before = z.q;
        for _ in 0..steps {
            before = z.q;
            z = self.step_from(sys, &z, dt, guess)?;
            guess = z.q + (z.q - before);
            each(&z)?;
        }
        if steps == 0 {
            return Ok(*state);
        }
        self.velocity_state(sys, &z, &((z.q - before) / dt))
    }
}
