//! [`ImplicitRungeKutta`]: the one stepper behind implicit midpoint, Gauss-Legendre, backward
//! Euler and Radau IIA, each given by its Butcher tableau ([`ImplicitTableau`]).

use crate::integrator::{
    check_run_step, check_signed, check_signed_run, check_step, finish, step_loop, Cost, Failure,
    Work,
};
use crate::newton::{self, BlockMatrix, Blocks, NewtonProblem, NewtonSettings, Start};
use crate::{Integrator, Method, MidpointTableau, SymmetricBase};
use core::marker::PhantomData;
use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{Error, Jacobian, Mechanism, Real, State};

/// The Butcher tableau of an `S`-stage implicit Runge-Kutta method, as `f64` constants
/// rounded to the integrator's scalar when used.
pub trait ImplicitTableau<const S: usize> {
    /// Short name for tables and logs.
    const NAME: &'static str;
    /// Order of the global error.
    const ORDER: u32;
    /// The stage coefficients `a_ij`.
    const A: [[f64; S]; S];
    /// The weights `b_j`.
    const B: [f64; S];
    /// The nodes `c_i` (row sums of `A`).
    const C: [f64; S];
}

/// An implicit Runge-Kutta method applied to `y = (q, q')`, `y' = (q', q'')`:
///
/// ```text
/// V_i = q'0 + h sum_j a_ij K_j        Q_i = q0 + h sum_j a_ij V_j
/// K_i = q''(t0 + c_i h, Q_i, V_i)     (S N equations in the stage accelerations K)
/// q'1 = q'0 + h sum_j b_j K_j         q1  = q0 + h sum_j b_j V_j
/// ```
///
/// The stage equations are solved by simplified Newton ([`NewtonSettings`]): the Newton matrix
/// `I - h A (x) dq''/dq' - h^2 A^2 (x) dq''/dq` is built from the mechanism's
/// [`Mechanism::acceleration_jacobian`] at the start of the step (exact from dual numbers for
/// an [`EulerLagrange`](lagrange_core::EulerLagrange) mechanism, central differences otherwise),
/// factorised once, and rebuilt from the stages' own Jacobians only if convergence slows.
/// Converged means each component's update of a `K_i` is at most
/// `tolerance (|K_i| + |q'0| / |h|)`: the new velocity is settled to `tolerance` relative to
/// the motion.
///
/// Cost per step: one acceleration Jacobian, then `S` accelerations per Newton iteration
/// ([`Method::last_step`] tells how many the last step took; measured on a double
/// pendulum, the last iteration confirming convergence: 4 to 5 at `h = 1e-2`, 3 to 4 at
/// `h = 1e-3`; 2 for a linear mechanism).
///
/// Use the aliases: [`ImplicitMidpoint`](crate::ImplicitMidpoint),
/// [`GaussLegendre2`](crate::GaussLegendre2), [`BackwardEuler`](crate::BackwardEuler),
/// [`RadauIIA2`](crate::RadauIIA2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImplicitRungeKutta<T: Real, const S: usize, M> {
    newton: NewtonSettings<T>,
    work: Work,
    method: PhantomData<M>,
}

impl<T: Real, const S: usize, M> ImplicitRungeKutta<T, S, M> {
    /// The method, iterating with `newton`.
    #[must_use]
    pub fn new(newton: NewtonSettings<T>) -> Self {
        Self {
            newton,
            work: Work::default(),
            method: PhantomData,
        }
    }

    /// The Newton settings.
    #[must_use]
    pub fn newton(&self) -> &NewtonSettings<T> {
        &self.newton
    }
}

impl<T: Real, const S: usize, M> Default for ImplicitRungeKutta<T, S, M> {
    /// With [`NewtonSettings::default`].
    fn default() -> Self {
        Self::new(NewtonSettings::default())
    }
}

#[cfg(feature = "defmt")]
impl<T: Real + defmt::Format, const S: usize, M: ImplicitTableau<S>> defmt::Format
    for ImplicitRungeKutta<T, S, M>
{
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "{} {{ newton: {} }}", M::NAME, self.newton);
    }
}

/// `x` in the integrator's scalar.
fn real<T: Real>(x: f64) -> T {
    T::from_f64(x)
}

/// The stage equations of one step.
struct Stages<'a, T: Real, Mech, const N: usize, const S: usize> {
    mechanism: &'a Mech,
    start: &'a State<T, N>,
    h: T,
    a: [[T; S]; S],
    a2: [[T; S]; S],
    c: [T; S],
    /// The Jacobian at the start, used for the first Newton matrix.
    start_jacobian: Option<Jacobian<T, N>>,
    /// `|q'0| / |h|`: the velocities in units of acceleration, added to `|K|` as the scale.
    velocity_scale: SVector<T, N>,
    /// Jacobians evaluated on refreshes (beyond the start's).
    refreshed: u32,
}

impl<T: Real, Mech: Mechanism<T, N>, const N: usize, const S: usize> Stages<'_, T, Mech, N, S> {
    /// The stage velocities `V_i` for stage accelerations `k`.
    fn velocities(&self, k: &Blocks<T, N, S>) -> Blocks<T, N, S> {
        core::array::from_fn(|i| {
            let mut v = self.start.qd;
            for (a, kj) in self.a[i].iter().zip(k.iter()) {
                v += kj * (self.h * *a);
            }
            v
        })
    }

    /// The stage states `(t0 + c_i h, Q_i, V_i)`.
    fn stage_states(&self, k: &Blocks<T, N, S>) -> [State<T, N>; S] {
        let v = self.velocities(k);
        core::array::from_fn(|i| {
            let mut q = self.start.q;
            for (a, vj) in self.a[i].iter().zip(v.iter()) {
                q += vj * (self.h * *a);
            }
            State {
                t: self.start.t + self.c[i] * self.h,
                q,
                qd: v[i],
            }
        })
    }
}

impl<T, Mech, const N: usize, const S: usize> NewtonProblem<T, N, S> for Stages<'_, T, Mech, N, S>
where
    T: Real,
    Mech: Mechanism<T, N>,
{
    fn residual(&mut self, k: &Blocks<T, N, S>) -> Result<Blocks<T, N, S>, Error> {
        let states = self.stage_states(k);
        let mut r = *k;
        for (ri, s) in r.iter_mut().zip(states.iter()) {
            *ri -= self.mechanism.acceleration(s)?;
        }
        Ok(r)
    }

    fn newton_matrix(&mut self, k: &Blocks<T, N, S>) -> Result<BlockMatrix<T, N, S>, Error> {
        // First the start's Jacobian for every stage; on a refresh each stage's own.
        let jacobians: [Jacobian<T, N>; S] = match self.start_jacobian.take() {
            Some(j) => [j; S],
            None => {
                let states = self.stage_states(k);
                self.refreshed += S as u32;
                let mut js = [Jacobian::zeros(); S];
                for (j, s) in js.iter_mut().zip(states.iter()) {
                    *j = self.mechanism.acceleration_jacobian(s)?.1;
                }
                js
            }
        };
        let (h, h2) = (self.h, self.h * self.h);
        Ok(BlockMatrix::from_blocks(|i, j| {
            let identity = if i == j {
                SMatrix::identity()
            } else {
                SMatrix::zeros()
            };
            identity
                - jacobians[i].wrt_qd * (h * self.a[i][j])
                - jacobians[i].wrt_q * (h2 * self.a2[i][j])
        }))
    }

    fn weights(&self, k: &Blocks<T, N, S>) -> Blocks<T, N, S> {
        k.map(|ki| ki.map(|x| x.abs()) + self.velocity_scale)
    }
}

impl<T: Real, const S: usize, Tab: ImplicitTableau<S>> ImplicitRungeKutta<T, S, Tab> {
    /// One step of `h` (either sign) from `s`, unchecked but for the result.
    fn advance<Mech: Mechanism<T, N>, const N: usize>(
        &mut self,
        m: &Mech,
        s: &State<T, N>,
        h: T,
    ) -> Result<State<T, N>, Error> {
        let a: [[T; S]; S] = Tab::A.map(|row| row.map(real));
        let a2 = core::array::from_fn(|i| {
            core::array::from_fn(|j| (0..S).fold(T::zero(), |acc, l| acc + a[i][l] * a[l][j]))
        });
        let (qdd, jacobian) = m.acceleration_jacobian(s)?;
        let mut problem = Stages {
            mechanism: m,
            start: s,
            h,
            a,
            a2,
            c: Tab::C.map(real),
            start_jacobian: Some(jacobian),
            velocity_scale: s.qd.map(|v| v.abs() / h.abs()),
            refreshed: 0,
        };
        let mut k = [qdd; S];
        let iterations = newton::solve(&mut problem, &mut k, &self.newton, Start::Newton)?;
        self.work = Work {
            evaluations: S as u32 * iterations,
            jacobians: 1 + problem.refreshed,
            iterations,
            steps: 1,
            rejected: 0,
        };

        let v = problem.velocities(&k);
        let mut q = s.q;
        let mut qd = s.qd;
        for ((b, kj), vj) in Tab::B.iter().zip(k.iter()).zip(v.iter()) {
            let hb = h * real::<T>(*b);
            qd += kj * hb;
            q += vj * hb;
        }
        finish(State { t: s.t + h, q, qd })
    }
}

/// `sum_j b_j c_j`.
const fn position_share<const S: usize>(b: &[f64; S], c: &[f64; S]) -> f64 {
    let mut sum = 0.0;
    let mut j = 0;
    while j < S {
        sum += b[j] * c[j];
        j += 1;
    }
    sum
}

impl<T: Real, Tab: ImplicitTableau<S>, const S: usize> Method for ImplicitRungeKutta<T, S, Tab> {
    const NAME: &'static str = Tab::NAME;
    const YOSHIDA4_NAME: &'static str = "Yoshida 4 (midpoint)";
    const ORDER: u32 = Tab::ORDER;
    /// `sum_j b_j c_j`: the stages' velocities `q'0 + h c_j a`, weighted (1 for backward
    /// Euler, 1/2 for the others, which are exact on a constant acceleration).
    const POSITION_SHARE: f64 = position_share(&Tab::B, &Tab::C);
    /// `S` accelerations per Newton iteration and one Jacobian (its accelerations are not
    /// counted apart: the first iteration starts from them).
    const COST: Cost = Cost {
        fixed: 0,
        per_iteration: S as u32,
        jacobians: 1,
    };

    fn last_step(&self) -> Work {
        self.work
    }
}

impl<T, Tab, Mech, const N: usize, const S: usize> Integrator<T, N, Mech>
    for ImplicitRungeKutta<T, S, Tab>
where
    T: Real,
    Tab: ImplicitTableau<S>,
    Mech: Mechanism<T, N>,
{
    fn step(&mut self, m: &Mech, s: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        let h = check_step(s, dt)?;
        self.advance(m, s, h)
    }

    fn run_step(&mut self, m: &Mech, s: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        let h = check_run_step(s, dt)?;
        self.advance(m, s, h)
    }

    /// As the default, with `dt` and the start checked once rather than at every step (each
    /// step's end is checked, so the next step's start is known finite).
    fn integrate_with<F: FnMut(&State<T, N>)>(
        &mut self,
        m: &Mech,
        state: &State<T, N>,
        dt: T,
        steps: u64,
        observe: F,
    ) -> Result<State<T, N>, Failure<T, N>> {
        step_loop(state, dt, steps, |s| self.advance(m, s, dt), observe)
    }
}

/// The implicit midpoint rule is symmetric and of order 2: a base for [`Yoshida4`](crate::Yoshida4).
impl<T, Mech, const N: usize> SymmetricBase<T, N, Mech>
    for ImplicitRungeKutta<T, 1, MidpointTableau>
where
    T: Real,
    Mech: Mechanism<T, N>,
{
    fn signed_step(&mut self, m: &Mech, s: &State<T, N>, h: T) -> Result<State<T, N>, Error> {
        let h = check_signed(s, h)?;
        self.advance(m, s, h)
    }

    fn signed_run_step(&mut self, m: &Mech, s: &State<T, N>, h: T) -> Result<State<T, N>, Error> {
        let h = check_signed_run(s, h)?;
        self.advance(m, s, h)
    }
}
