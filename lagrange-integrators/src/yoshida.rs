//! Yoshida's order-4 composition (the triple jump; Forest-Ruth in kick-drift form) of a
//! symmetric second-order method.

use crate::integrator::{check_run_step, check_step, Cost, Work};
use crate::{Integrator, Method};
use lagrange_core::{Error, Mechanism, Real, State};

/// A symmetric (time-reversible) one-step method of order 2: what [`Yoshida4`] can raise to
/// order 4 (composing a non-symmetric method with these weights gives only order 3).
/// [`StormerVerlet`](crate::StormerVerlet), [`ImplicitMidpoint`](crate::ImplicitMidpoint) and
/// [`VariationalMidpoint`](crate::VariationalMidpoint) are.
pub trait SymmetricBase<T: Real, const N: usize, M: Mechanism<T, N>>: Integrator<T, N, M> {
    /// A step of `h`, which may be negative: a composition steps back in its middle substep.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `h` when not finite; [`Error::NonFiniteState`] for a
    /// non-finite `state` or result (a time `state.t + h` that overflows too);
    /// [`Error::StepSizeUnderflow`] when `state.t + h` rounds to `state.t` (`h = 0` too); as
    /// [`Integrator::step`] otherwise.
    fn signed_step(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        h: T,
    ) -> Result<State<T, N>, Error>;

    /// A signed substep of a run whose clock keeps the time ([`Integrator::run_step`]): as
    /// [`SymmetricBase::signed_step`], but an `h` below the resolution of `state.t` is taken.
    /// The default is [`SymmetricBase::signed_step`].
    ///
    /// # Errors
    /// As [`SymmetricBase::signed_step`], but for [`Error::StepSizeUnderflow`] where only the
    /// rounded time would not move.
    fn signed_run_step(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        h: T,
    ) -> Result<State<T, N>, Error> {
        self.signed_step(mechanism, state, h)
    }
}

/// The weights of the triple jump, `w1, w0, w1`:
///
/// ```text
/// w1 = 1 / (2 - 2^(1/3))       =  1.3512071919596575
/// w0 = -2^(1/3) / (2 - 2^(1/3)) = -1.7024143839193153
/// 2 w1 + w0 = 1 (consistency),  2 w1^3 + w0^3 = 0 (the h^3 error of a symmetric base cancels)
/// ```
pub const YOSHIDA4_WEIGHTS: [f64; 3] = [
    1.351_207_191_959_657_5,
    -1.702_414_383_919_315_3,
    1.351_207_191_959_657_5,
];

/// Yoshida's fourth-order composition: three steps of a symmetric second-order base method,
/// of `w1 h`, `w0 h` (negative: a step back) and `w1 h` ([`YOSHIDA4_WEIGHTS`]).
///
/// Order 4, fixed step, as explicit or implicit as its base; 3 base steps per step (6
/// acceleration evaluations over [`StormerVerlet`](crate::StormerVerlet) where the acceleration does not depend on
/// `q'`). Symmetric for any mechanism; symplectic wherever its base is (over
/// [`StormerVerlet`](crate::StormerVerlet): constant mass matrix and forces of `q` only, where it is Forest-Ruth's
/// method), with a bounded `O(h^4)` energy error and no drift there; on regular motion of
/// other conservative mechanisms (pendulum chains, polar coordinates) reversibility keeps the
/// energy error bounded too. The step back makes its error constant larger than RK4's at the
/// same cost on short runs; its point is the long run.
///
/// ```
/// use lagrange_core::prelude::*;
/// use lagrange_integrators::{Integrator, StormerVerlet, Yoshida4};
/// use lagrange_systems::SimplePendulum;
/// let p = SimplePendulum::new(1.0, 1.0, 9.81, 0.0)?;
/// let start = State::at_rest([0.5]);
/// let end = Yoshida4::<StormerVerlet<f64, 1>>::default().integrate(&p, &start, 1e-2, 10_000)?;
/// assert!((p.energy(&end) - p.energy(&start)).abs() < 1e-7);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Yoshida4<B> {
    base: B,
    work: Work,
}

impl<B> Yoshida4<B> {
    /// The composition of `base`.
    pub fn new(base: B) -> Self {
        Self {
            base,
            work: Work::default(),
        }
    }

    /// The base method.
    #[must_use]
    pub fn base(&self) -> &B {
        &self.base
    }
}

#[cfg(feature = "defmt")]
impl<B: defmt::Format> defmt::Format for Yoshida4<B> {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "Yoshida4 {{ base: {} }}", self.base);
    }
}

impl<B: Method> Method for Yoshida4<B> {
    const NAME: &'static str = B::YOSHIDA4_NAME;
    const ORDER: u32 = 4;
    const COST: Cost = Cost {
        fixed: 3 * B::COST.fixed,
        per_iteration: B::COST.per_iteration,
        jacobians: 3 * B::COST.jacobians,
    };

    /// The three substeps together (iterations summed over them).
    fn last_step(&self) -> Work {
        self.work
    }
}

impl<T, B, M, const N: usize> Integrator<T, N, M> for Yoshida4<B>
where
    T: Real,
    M: Mechanism<T, N>,
    B: SymmetricBase<T, N, M>,
{
    fn step(&mut self, m: &M, s: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        let dt = check_step(s, dt)?;
        self.compose(m, s, dt, false)
    }

    fn run_step(&mut self, m: &M, s: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        let dt = check_run_step(s, dt)?;
        self.compose(m, s, dt, true)
    }
}

impl<B> Yoshida4<B> {
    /// The three substeps of a step of `dt` (checked) from `s`: signed steps of the base, or
    /// signed steps of a run (`run`).
    fn compose<T, M, const N: usize>(
        &mut self,
        m: &M,
        s: &State<T, N>,
        dt: T,
        run: bool,
    ) -> Result<State<T, N>, Error>
    where
        T: Real,
        M: Mechanism<T, N>,
        B: SymmetricBase<T, N, M>,
    {
        let mut next = *s;
        let mut work = Work::default();
        for w in YOSHIDA4_WEIGHTS {
            // A substep that overflows (`w dt` near `T::MAX`) would end in a time that is not
            // finite, as `state.t + dt` past `T::MAX` would.
            let h = dt * T::from_f64(w);
            if !h.is_finite() {
                return Err(Error::NonFiniteState);
            }
            next = if run {
                self.base.signed_run_step(m, &next, h)?
            } else {
                self.base.signed_step(m, &next, h)?
            };
            let done = self.base.last_step();
            work.evaluations += done.evaluations;
            work.jacobians += done.jacobians;
            work.iterations += done.iterations;
        }
        work.steps = 1;
        self.work = work;
        // The substeps' times add up to dt only to rounding: land exactly.
        next.t = s.t + dt;
        Ok(next)
    }
}
