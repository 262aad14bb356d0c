//! Symmetric Stormer-Verlet: velocity Verlet made time-reversible for accelerations that
//! depend on the velocities, the base of the order-4 compositions.

use crate::integrator::{
    check_run_step, check_signed, check_signed_run, check_step, finish, Cost, Work,
};
use crate::newton::{self, BlockMatrix, Blocks, NewtonProblem, NewtonSettings, Start};
use crate::{Integrator, Method, SymmetricBase};
use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{Error, Mechanism, Real, State};

/// Stormer-Verlet in kick-drift-kick form, with the first half kick implicit:
///
/// ```text
/// v   = q'0 + h/2 q''(t0, q0, v)      implicit half kick (fixed point, Newton if needed)
/// q1  = q0 + h v                      drift
/// q'1 = v + h/2 q''(t0 + h, q1, v)    explicit half kick
/// ```
///
/// This is the composition of a first-order method with its adjoint, so it is symmetric
/// (time-reversible) for any mechanism, not only where the acceleration ignores `q'`: that is
/// what makes it a valid base for [`Yoshida4`](crate::Yoshida4), and what keeps the energy
/// error of regular motion bounded without drift where the mass matrix depends on `q` (a
/// pendulum chain). Where the acceleration does not depend on `q'` (constant mass matrix,
/// conservative forces), the implicit kick is explicit and this is exactly velocity Verlet:
/// symplectic, with a bounded `O(h^2)` energy error.
///
/// Order 2, fixed step. Cost: where the acceleration does not depend on `q'`, 2 acceleration
/// evaluations per step in a run of consecutive steps (the last kick's acceleration seeds the
/// next step and one evaluation confirms it), 3 for an isolated step. Where it does, the
/// implicit kick takes a fixed-point iteration, one evaluation each, contracting by
/// `h/2 |dq''/dq'|` per iteration (measured on a double pendulum: 5 to 6 iterations at
/// `h = 1e-2`, 4 at `h = 1e-3`), and switches to Newton with the mechanism's Jacobian where
/// that contraction is too slow (strong damping).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StormerVerlet<T: Real, const N: usize> {
    newton: NewtonSettings<T>,
    /// `(q1, q''(t1, q1, v))` of the last step: the next step's first guess.
    last: Option<(SVector<T, N>, SVector<T, N>)>,
    work: Work,
}

impl<T: Real, const N: usize> StormerVerlet<T, N> {
    /// The method, solving its implicit kick with `newton`.
    #[must_use]
    pub fn new(newton: NewtonSettings<T>) -> Self {
        Self {
            newton,
            last: None,
            work: Work::default(),
        }
    }
}

impl<T: Real, const N: usize> Default for StormerVerlet<T, N> {
    /// With [`NewtonSettings::default`].
    fn default() -> Self {
        Self::new(NewtonSettings::default())
    }
}

#[cfg(feature = "defmt")]
impl<T: Real + defmt::Format, const N: usize> defmt::Format for StormerVerlet<T, N> {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "StormerVerlet {{ newton: {} }}", self.newton);
    }
}

/// The implicit half kick `v = q'0 + h/2 q''(t0, q0, v)`.
struct HalfKick<'a, T: Real, M, const N: usize> {
    mechanism: &'a M,
    start: &'a State<T, N>,
    half: T,
    /// `|h/2 q''|` of the guess: added to `|v|` as the convergence scale.
    kick: SVector<T, N>,
    /// Jacobians evaluated (where the fixed point gave way to Newton).
    jacobians: u32,
}

impl<T: Real, M: Mechanism<T, N>, const N: usize> HalfKick<'_, T, M, N> {
    fn at(&self, v: &SVector<T, N>) -> State<T, N> {
        State {
            t: self.start.t,
            q: self.start.q,
            qd: *v,
        }
    }
}

impl<T: Real, M: Mechanism<T, N>, const N: usize> NewtonProblem<T, N, 1> for HalfKick<'_, T, M, N> {
    fn residual(&mut self, v: &Blocks<T, N, 1>) -> Result<Blocks<T, N, 1>, Error> {
        let kicked = self.start.qd + self.mechanism.acceleration(&self.at(&v[0]))? * self.half;
        Ok([v[0] - kicked])
    }

    fn newton_matrix(&mut self, v: &Blocks<T, N, 1>) -> Result<BlockMatrix<T, N, 1>, Error> {
        self.jacobians += 1;
        let j = self.mechanism.acceleration_jacobian(&self.at(&v[0]))?.1;
        Ok(BlockMatrix([[SMatrix::identity() - j.wrt_qd * self.half]]))
    }

    fn weights(&self, v: &Blocks<T, N, 1>) -> Blocks<T, N, 1> {
        [v[0].map(|x| x.abs()) + self.kick]
    }
}

impl<T: Real, const N: usize> StormerVerlet<T, N> {
    /// One step of `h` (either sign) from `s`, unchecked but for the result.
    fn advance<M: Mechanism<T, N>>(
        &mut self,
        m: &M,
        s: &State<T, N>,
        h: T,
    ) -> Result<State<T, N>, Error> {
        let half = h * T::HALF;
        let mut evaluations = 0;
        let guess = match self.last.take() {
            // Only a guess: a time-dependent mechanism's is a little off, and converges.
            Some((q, a)) if q == s.q => a,
            _ => {
                evaluations += 1;
                m.acceleration(s)?
            }
        };
        let mut kick = HalfKick {
            mechanism: m,
            start: s,
            half,
            kick: (guess * half).map(|x| x.abs()),
            jacobians: 0,
        };
        let mut v = [s.qd + guess * half];
        let iterations = newton::solve(&mut kick, &mut v, &self.newton, Start::FixedPoint)?;
        let [v] = v;
        let t = s.t + h;
        let q = s.q + v * h;
        let a = m.acceleration(&State { t, q, qd: v })?;
        self.last = Some((q, a));
        self.work = Work {
            evaluations: evaluations + iterations + 1,
            jacobians: kick.jacobians,
            iterations,
            steps: 1,
            rejected: 0,
        };
        finish(State {
            t,
            q,
            qd: v + a * half,
        })
    }
}

impl<T: Real, const N: usize> Method for StormerVerlet<T, N> {
    const NAME: &'static str = "Stormer-Verlet";
    const ORDER: u32 = 2;
    /// One acceleration per iteration of the implicit kick and one for the explicit kick (2
    /// per step where the acceleration does not depend on `q'`, in a run of steps; see the
    /// type's doc).
    const COST: Cost = Cost {
        fixed: 1,
        per_iteration: 1,
        jacobians: 0,
    };

    fn last_step(&self) -> Work {
        self.work
    }
}

impl<T: Real, const N: usize, M: Mechanism<T, N>> Integrator<T, N, M> for StormerVerlet<T, N> {
    fn step(&mut self, m: &M, s: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        let h = check_step(s, dt)?;
        self.advance(m, s, h)
    }

    fn run_step(&mut self, m: &M, s: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        let h = check_run_step(s, dt)?;
        self.advance(m, s, h)
    }
}

impl<T: Real, const N: usize, M: Mechanism<T, N>> SymmetricBase<T, N, M> for StormerVerlet<T, N> {
    fn signed_step(&mut self, m: &M, s: &State<T, N>, h: T) -> Result<State<T, N>, Error> {
        let h = check_signed(s, h)?;
        self.advance(m, s, h)
    }

    fn signed_run_step(&mut self, m: &M, s: &State<T, N>, h: T) -> Result<State<T, N>, Error> {
        let h = check_signed_run(s, h)?;
        self.advance(m, s, h)
    }
}
