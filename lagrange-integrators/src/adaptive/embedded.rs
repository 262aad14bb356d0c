//! [`EmbeddedRungeKutta`]: one adaptive explicit Runge-Kutta engine for every embedded pair:
//! stages, error estimate, PI step-size control, and the stepping loops.

use super::controller::PiController;
use super::energy::{project, start_energy};
use super::nystrom::{position, Nystrom};
use super::sums::{combine, real, stage_sum, step_into, Hermite};
use super::AdaptiveSettings;
use crate::integrator::{check_step, continues, fail, Cost, Failure, Work};
use crate::{Integrator, Method};
use core::marker::PhantomData;
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, Mechanism, Real, State};

/// An embedded explicit Runge-Kutta pair with a continuous extension: the coefficients an
/// [`EmbeddedRungeKutta`] integrator runs on, as `f64` constants rounded to the integrator's
/// scalar when used.
///
/// `S` counts every stage: those of a step, the stage at `(t0 + h, y1)` whose derivative is
/// reused as the first stage of the next step (`FSAL`, its row of `A` holding the weights
/// `b`), and the extra stages of the dense output after it. `R` counts the rows of dense
/// coefficients beyond the three cubic-Hermite ones.
pub trait EmbeddedPair<const S: usize, const R: usize> {
    /// Short name for tables and logs.
    const NAME: &'static str;
    /// Order of the propagated solution.
    const ORDER: u32;
    /// `k` of the controller: the error estimate scales like `h^k`.
    const ERROR_EXPONENT: u32;
    /// Order of the dense output. More than one below [`EmbeddedPair::ORDER`] (the Nyström and
    /// Verner pairs), it is not trusted where a step is: [`Integrator::step`] lands on a
    /// frame's end by a step shortened to it, and an event is located again on steps of the
    /// pair.
    const DENSE_ORDER: u32;
    /// The nodes `c_i`.
    const C: [f64; S];
    /// The stage coefficients `a_ij`, strictly lower triangular.
    const A: [[f64; S]; S];
    /// Index of the stage at `(t0 + h, y1)`: `A[FSAL]` is `b`.
    const FSAL: usize;
    /// Weights of the error estimate: `err = h sum_j E_j k_j`.
    const E: [f64; S];
    /// Weights of a second, lower-order estimate combined with the first as in Hairer's
    /// DOP853 (`None` for a single estimate).
    const E3: Option<[f64; S]>;
    /// The dense-output rows beyond the cubic Hermite part: `d_r = h sum_j DENSE[r][j] k_j`.
    const DENSE: [[f64; S]; R];
    /// The position half of a Runge-Kutta-Nyström pair ([`Nystrom`]); `None`, the default,
    /// for a pair of the first-order system `y' = (q', q'')`.
    const NYSTROM: Option<Nystrom<S>> = None;
    /// Whether the dense output is the quintic Hermite interpolant through `q`, `q'` and
    /// `q''` at the step's two ends (for `q'`, its derivative), at no evaluation: order 4, for
    /// a pair without a continuous extension of its own. It takes two rows (`R = 2`), whose
    /// [`EmbeddedPair::DENSE`] entries are not read (a pair that sets it with another `R` does
    /// not compile). The default: `true` for the Nyström pairs.
    const HERMITE_DENSE: bool = Self::NYSTROM.is_some();
}

/// Work counts since the integrator was made or restarted.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Statistics {
    /// Accepted steps.
    pub accepted: u64,
    /// Rejected step attempts.
    pub rejected: u64,
    /// Acceleration evaluations.
    pub evaluations: u64,
}

/// An adaptive explicit Runge-Kutta integrator on the pair `P`: use the aliases
/// [`DormandPrince54`](crate::DormandPrince54), [`DormandPrince853`](crate::DormandPrince853),
/// [`Verner76`](crate::Verner76) and [`Verner98`](crate::Verner98), and for laws that do not
/// read the velocities the Runge-Kutta-Nyström
/// [`DormandPrinceNystrom64`](crate::DormandPrinceNystrom64),
/// [`DormandPrinceNystrom86`](crate::DormandPrinceNystrom86) and
/// [`DormandPrinceNystrom1210`](crate::DormandPrinceNystrom1210).
///
/// It advances by steps whose size a PI controller chooses from the embedded error estimate:
///
/// ```text
/// err      = RMS_i( est_i / (atol + rtol max(|y0_i|, |y1_i|)) )   over y = (q, q')
/// accepted when err <= 1, then
/// h_next   = h clamp(0.9 err^-(1/k - 0.75 beta) err_prev^beta, 0.2, 10),   beta = 0.04
/// rejected:  h <- h max(0.2, 0.9 err^(-1/k)), no growth on the next accepted step
/// ```
///
/// It is made from its settings alone; the mechanism and the state are given to each call,
/// which starts from that state:
///
/// - [`Integrator::step`] lands exactly on `state.t + dt` through the continuous extension
///   (dense output), so a frame loop ([`FixedTimestep`](crate::FixedTimestep), a scene) can
///   drive it with its own steps taken at the size the error control allows, not the frame's
///   (a pair whose dense output is more than an order below its steps, the Nyström and
///   Verner pairs', lands by a last step shortened to the frame's end instead);
/// - [`EmbeddedRungeKutta::integrate_to`] steps to an end time, its last step shortened to
///   land there;
/// - [`EmbeddedRungeKutta::next_step`] takes one step of the controller's choosing, and
///   [`EmbeddedRungeKutta::dense_output`] samples inside it;
/// - [`EmbeddedRungeKutta::integrate_until_event`] stops where a guard changes sign.
///
/// A call that starts from the state the last call returned continues the run: the derivative
/// at its end is reused by the next step (first same as last), the controller keeps its
/// history, and the steps a frame loop's landings interpolated between go on. A call from any
/// other state starts afresh there, trying first the step size the controller last proposed.
/// After changing the mechanism (an [`Input`](lagrange_core::Input), say), call
/// [`EmbeddedRungeKutta::restart`] so that the next call starts afresh from its state.
///
/// For a conservative mechanism on a long run (an orbit, a clock's pendulum), the settings'
/// [`AdaptiveSettings::with_energy_projection`] ends each step on the energy the run started
/// with, which stops the drift of energy, and of the phase with it, for one evaluation more
/// per step (none where the law does not read the velocities).
///
/// Steps stay bounded: a trial step is never above [`AdaptiveSettings::h_max`], never past
/// the end time of the call (the landing of [`Integrator::step`] is the exception: its steps
/// may run one step ahead), never above `T::MAX`; the controller grows a step at most tenfold
/// per step, so at an equilibrium (a zero error estimate) the step grows geometrically up to
/// the end time and no further. A call that fails (any error) leaves the integrator as it
/// found it, its work counters aside.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmbeddedRungeKutta<T: Real, const N: usize, const S: usize, const R: usize, P> {
    pub(super) settings: AdaptiveSettings<T>,
    /// Where the integration is: the end of the last accepted step (or the event that cut it).
    pub(super) state: State<T, N>,
    /// The state the last call returned: a call from it continues the run.
    pub(super) output: Option<State<T, N>>,
    /// The derivative `(q', q'')` at `state`, when known.
    pub(super) derivative: Option<(SVector<T, N>, SVector<T, N>)>,
    /// The stages of the last step and its dense coefficients.
    pub(super) stages: Stages<T, N, S, R>,
    /// The integrator as a failing call found it, saved before the call first changed it, so
    /// that a failure can put it back (see [`EmbeddedRungeKutta::call`]).
    backup: Option<(Run<T, N>, Stages<T, N, S, R>)>,
    /// Inside a public call: changes are to be saved first.
    guarded: bool,
    /// The next step size to try (zero before any).
    pub(super) h: T,
    pub(super) controller: PiController,
    /// The start of the last accepted step and its size (zero before any).
    pub(super) previous: State<T, N>,
    pub(super) h_last: T,
    /// The end of the interval the dense output may be sampled on (cut by an event).
    pub(super) dense_end: T,
    pub(super) stats: Statistics,
    /// The work of the last call.
    pub(super) work: Work,
    /// The energy the run holds, with [`AdaptiveSettings::with_energy_projection`].
    pub(super) energy: Option<T>,
    pub(super) pair: PhantomData<P>,
}

/// The stage derivatives of the last step and its dense coefficients: the large part of an
/// [`EmbeddedRungeKutta`], saved only when a call is about to change it.
#[derive(Debug, PartialEq)]
pub(super) struct Stages<T: Real, const N: usize, const S: usize, const R: usize> {
    /// Stage derivatives of the last step: `kq_i = V_i`, `kv_i = q''(stage i)`.
    pub(super) kq: [SVector<T, N>; S],
    pub(super) kv: [SVector<T, N>; S],
    /// Dense coefficients of the last step, when computed: the cubic Hermite part of `q` and
    /// of `q'`, then the rows.
    pub(super) hermite: Option<(Hermite<T, N>, Hermite<T, N>)>,
    pub(super) rows_q: [SVector<T, N>; R],
    pub(super) rows_v: [SVector<T, N>; R],
    /// The end of the last step where the energy projection moved it (the dense output ends
    /// there); `None` where the stages' own end is the step's.
    pub(super) end: Option<State<T, N>>,
}

impl<T: Real, const N: usize, const S: usize, const R: usize> Clone for Stages<T, N, S, R> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T: Real, const N: usize, const S: usize, const R: usize> Copy for Stages<T, N, S, R> {}

/// The rest of what a call may change, besides the [`Stages`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Run<T: Real, const N: usize> {
    state: State<T, N>,
    output: Option<State<T, N>>,
    derivative: Option<(SVector<T, N>, SVector<T, N>)>,
    h: T,
    controller: PiController,
    previous: State<T, N>,
    h_last: T,
    dense_end: T,
    energy: Option<T>,
}

/// `a^2 b` (both non-negative, or NaN), squaring without a square root unless `a^2` overflows
/// (a step near the largest finite time): then `(a sqrt(b))^2`, so that such a step with a
/// zero estimate is not taken for an infinite or NaN error.
#[inline(always)]
fn scaled_square<T: Real>(a: T, b: T) -> T {
    let a2 = a * a;
    if a2.is_finite() {
        a2 * b
    } else {
        let e = a * b.sqrt();
        e * e
    }
}

/// Zero for a finite `x`, NaN for an infinite or NaN one: added to a value, it makes that
/// value NaN exactly where `x` is not finite, without a branch.
#[inline(always)]
#[allow(clippy::eq_op)] // `x - x` is the point: NaN exactly where `x` is not finite
fn nan_unless_finite<T: Real>(x: T) -> T {
    x - x
}

/// Evaluates stages `1..=P::FSAL` of a step, each with a constant index (so that
/// [`combine`] sees constant rows): one line per possible stage, those past `FSAL` skipped at
/// compile time. Leaves the state of stage `FSAL`, `(t0 + h, y1)`, in `$last`.
macro_rules! run_stages {
    ($rk:ident, $m:ident, $y0:ident, $h:ident, $last:ident; $($i:literal)*) => {
        const { assert!(P::FSAL <= 17, "run_stages! covers pairs of up to 17 step stages") };
        $(
            if $i <= P::FSAL {
                $rk.stage::<M, $i>($m, &$y0, $h, &mut $last)?;
            }
        )*
    };
}

impl<T, const N: usize, const S: usize, const R: usize, P> EmbeddedRungeKutta<T, N, S, R, P>
where
    T: Real,
    P: EmbeddedPair<S, R>,
{
    /// The integrator with `settings`; the first call starts where it is told.
    #[must_use]
    pub fn new(settings: AdaptiveSettings<T>) -> Self {
        let nowhere = State {
            t: T::zero(),
            q: SVector::zeros(),
            qd: SVector::zeros(),
        };
        Self {
            settings,
            state: nowhere,
            output: None,
            derivative: None,
            stages: Stages {
                kq: [SVector::zeros(); S],
                kv: [SVector::zeros(); S],
                hermite: None,
                rows_q: [SVector::zeros(); R],
                rows_v: [SVector::zeros(); R],
                end: None,
            },
            backup: None,
            guarded: false,
            h: T::zero(),
            controller: PiController::new(P::ERROR_EXPONENT),
            previous: nowhere,
            h_last: T::zero(),
            dense_end: T::zero(),
            stats: Statistics::default(),
            work: Work::default(),
            energy: None,
            pair: PhantomData,
        }
    }

    /// Forgets the run, so that the next call starts afresh from its state (after the
    /// mechanism changed between calls): the derivative kept for the next step, the
    /// controller's history and the dense output go, and the energy held
    /// ([`AdaptiveSettings::with_energy_projection`]) is the new start's; the proposed step
    /// size stays as the first step to try.
    pub fn restart(&mut self) {
        self.output = None;
    }

    /// The step size the next step will try (zero before any).
    #[must_use]
    pub fn step_size(&self) -> T {
        self.h
    }

    /// The settings.
    #[must_use]
    pub fn settings(&self) -> &AdaptiveSettings<T> {
        &self.settings
    }

    /// Work done since the integrator was made or the run started afresh.
    #[must_use]
    pub fn statistics(&self) -> Statistics {
        self.stats
    }

    /// Continues the run when `state` is what the last call returned; otherwise starts afresh
    /// there: the derivative, and the first step (the controller's last proposal, else
    /// Hairer's estimate).
    pub(super) fn begin<M: Mechanism<T, N>>(
        &mut self,
        m: &M,
        state: &State<T, N>,
    ) -> Result<(), Error> {
        if P::NYSTROM.is_some() && m.reads_velocities() {
            return Err(Error::InvalidParameter {
                name: "mechanism",
                reason: "reads the velocities: a Nyström pair steps only laws q'' = f(t, q)",
            });
        }
        state.check_finite()?;
        if self.output.is_some_and(|out| continues(&out, state)) {
            return Ok(());
        }
        self.protect();
        self.state = *state;
        self.output = Some(*state);
        self.stats = Statistics::default();
        self.controller.reset();
        self.h_last = T::zero();
        self.stages.hermite = None;
        self.previous = *state;
        self.dense_end = state.t;
        self.derivative = None;
        self.energy = if self.settings.energy_projection() {
            Some(start_energy(m, state)?)
        } else {
            None
        };
        let (q, v) = self.derivative_at_state(m)?;
        if let Some(h) = self.settings.h_initial() {
            self.h = h;
        } else if self.h <= T::zero() || !self.h.is_finite() {
            self.h = self.initial_step(m, &q, &v)?;
        }
        self.h = self.h.min(self.settings.h_max());
        Ok(())
    }

    /// One evaluation of the acceleration, counted.
    pub(super) fn eval<M: Mechanism<T, N>>(
        &mut self,
        m: &M,
        s: &State<T, N>,
    ) -> Result<SVector<T, N>, Error> {
        self.stats.evaluations += 1;
        // Counted apart from the statistics, which a fresh start zeroes midway through a call.
        self.work.evaluations = self.work.evaluations.saturating_add(1);
        m.acceleration(s)
    }

    /// The derivative at the current state, evaluated if not kept.
    fn derivative_at_state<M: Mechanism<T, N>>(
        &mut self,
        m: &M,
    ) -> Result<(SVector<T, N>, SVector<T, N>), Error> {
        if let Some(d) = self.derivative {
            return Ok(d);
        }
        let s = self.state;
        let d = (s.qd, self.eval(m, &s)?);
        self.derivative = Some(d);
        Ok(d)
    }

    /// Hairer's initial step estimate (`hinit` of DOPRI5 and DOP853), one evaluation. A
    /// non-finite intermediate (a state so large that its scale overflows) falls back to a
    /// small first step, which the controller then grows.
    fn initial_step<M: Mechanism<T, N>>(
        &mut self,
        m: &M,
        fq: &SVector<T, N>,
        fv: &SVector<T, N>,
    ) -> Result<T, Error> {
        let s = self.state;
        let (rtol, atol) = (self.settings.rtol(), self.settings.atol());
        let rms = |q: &SVector<T, N>, v: &SVector<T, N>| {
            let mut sum = T::zero();
            for (x, y) in q.iter().zip(s.q.iter()).chain(v.iter().zip(s.qd.iter())) {
                let r = *x / (atol + rtol * y.abs());
                sum += r * r;
            }
            (sum / T::from_f64(2.0 * N as f64)).sqrt()
        };
        let fallback = real::<T>(1e-6);
        let (d0, d1) = (rms(&s.q, &s.qd), rms(fq, fv));
        let small = real::<T>(1e-5);
        let mut h0 = if !(d0 >= small && d1 >= small) {
            fallback
        } else {
            real::<T>(0.01) * d0 / d1
        };
        if !(h0.is_finite() && h0 > T::zero()) {
            h0 = fallback;
        }
        h0 = h0.min(self.settings.h_max());
        let explicit_euler = State {
            t: s.t + h0,
            q: s.q + fq * h0,
            qd: s.qd + fv * h0,
        };
        if !explicit_euler.is_finite() {
            return Ok(fallback.min(self.settings.h_max()));
        }
        let a1 = self.eval(m, &explicit_euler)?;
        let d2 = rms(&(explicit_euler.qd - fq), &(a1 - fv)) / h0;
        let d = d1.max(d2);
        let h1 = if d <= real(1e-15) {
            real::<T>(1e-6).max(h0 * real(1e-3))
        } else {
            (real::<T>(0.01) / d).powf(real::<T>(1.0) / T::from_f64(f64::from(P::ORDER)))
        };
        let h = (h0 * real(100.0)).min(h1).min(self.settings.h_max());
        Ok(if h.is_finite() && h > T::zero() {
            h
        } else {
            fallback.min(self.settings.h_max())
        })
    }

    /// The square of the error norm of a step of `h` from `y0 = self.state` to `y1`, from the
    /// stages; NaN when `y1` is not finite. Squared: the test against 1 and the controller
    /// (which takes a logarithm) need no square root, whose latency sat on the chain from one
    /// step's last stage to the next step's first.
    #[inline(always)]
    fn error_norm_sq(&self, h: T, y1: &State<T, N>) -> T {
        let (rtol, atol) = (self.settings.rtol(), self.settings.atol());
        let y0 = &self.state;
        // The weights 1 / (atol + rtol max(|y0|, |y1|)), divided once for both estimates.
        // Each weight is poisoned by `y1`'s component ([`nan_unless_finite`]), so that a new
        // state that is not finite makes the error NaN and the step is rejected: the check
        // rides on the weights, computed beside the estimate, instead of a test of `y1` whose
        // branch changed how the whole step was compiled and cost a third of a
        // Dormand-Prince step of a Kepler orbit.
        let weight =
            |a: T, b: T| (atol + rtol * a.abs().max(b.abs())).recip() + nan_unless_finite(b);
        let wq = SVector::<T, N>::from_fn(|i, _| weight(y0.q[i], y1.q[i]));
        let wv = SVector::<T, N>::from_fn(|i, _| weight(y0.qd[i], y1.qd[i]));
        // The time too, on the factor `|h|`, which is known before the estimate.
        let h = h.abs() + nan_unless_finite(y1.t);
        let n = T::from_f64(2.0 * N as f64);
        let err5 = self.weighted_sum_sq(&P::E[..=P::FSAL], h, &wq, &wv);
        match P::E3 {
            None => scaled_square(h, err5 / n),
            Some(e3) => {
                let err3 = self.weighted_sum_sq(&e3[..=P::FSAL], h, &wq, &wv);
                let mut deno = err5 + real::<T>(0.01) * err3;
                if deno <= T::zero() {
                    deno = T::one();
                }
                scaled_square(h * err5, (deno * n).recip())
            }
        }
    }

    /// `|W_q e_q|^2 + |W_v e_v|^2` for the estimate `e = sum_j w_j k_j` (of a Nyström pair:
    /// `e_q = h sum_j E[j] kv_j`, see [`Nystrom`]), to be scaled by `h^2`.
    #[inline(always)]
    fn weighted_sum_sq(&self, w: &[f64], h: T, wq: &SVector<T, N>, wv: &SVector<T, N>) -> T {
        let eq = match P::NYSTROM {
            None => combine(w, &self.stages.kq),
            Some(ny) => combine(&ny.e[..w.len()], &self.stages.kv) * h,
        }
        .component_mul(wq);
        let ev = combine(w, &self.stages.kv).component_mul(wv);
        eq.dot(&eq) + ev.dot(&ev)
    }

    /// Evaluates stage `I` of a step of `h` from `y0`, its state written into `s` (whose other
    /// components it leaves alone).
    #[inline(always)]
    fn stage<M: Mechanism<T, N>, const I: usize>(
        &mut self,
        m: &M,
        y0: &State<T, N>,
        h: T,
        s: &mut State<T, N>,
    ) -> Result<(), Error> {
        let (row, c) = (&P::A[I][..I], P::C[I]);
        s.t = y0.t + h * real::<T>(c);
        if let Some(ny) = P::NYSTROM {
            position(&mut s.q, y0, &ny.abar[I][..I], c, &self.stages.kv, h);
            s.qd = y0.qd;
            self.stages.kv[I] = self.eval(m, s)?;
            step_into(&mut s.qd, &y0.qd, &P::A[I][..=I], &self.stages.kv, h);
            self.stages.kq[I] = s.qd;
            return Ok(());
        }
        step_into(&mut s.q, &y0.q, row, &self.stages.kq, h);
        // The stage's q' is its derivative of q too: written to both in the same loop, not
        // copied after.
        let kq = self.stages.kq[I].as_mut_slice();
        for (i, (v, k)) in s.qd.as_mut_slice().iter_mut().zip(kq).enumerate() {
            *v = y0.qd.as_slice()[i] + stage_sum(row, &self.stages.kv, i) * h;
            *k = *v;
        }
        self.stages.kv[I] = self.eval(m, s)?;
        Ok(())
    }

    /// The state at stage `i` of a step of `h` from `y0`, from the stages before it.
    #[inline(always)]
    pub(super) fn stage_state(&self, y0: &State<T, N>, h: T, i: usize) -> State<T, N> {
        let mut s = *y0;
        self.stage_state_into(y0, h, i, &mut s);
        s
    }

    /// [`Self::stage_state`] written into `s`.
    #[inline(always)]
    fn stage_state_into(&self, y0: &State<T, N>, h: T, i: usize, s: &mut State<T, N>) {
        // A is strictly lower triangular: stage i combines the stages before it.
        let (row, c) = (&P::A[i][..i], P::C[i]);
        s.t = y0.t + h * real::<T>(c);
        if let Some(ny) = P::NYSTROM {
            // The stage's own evaluation is known here (a stage after the step's).
            position(&mut s.q, y0, &ny.abar[i][..i], c, &self.stages.kv, h);
            step_into(&mut s.qd, &y0.qd, &P::A[i][..=i], &self.stages.kv, h);
            return;
        }
        step_into(&mut s.q, &y0.q, row, &self.stages.kq, h);
        step_into(&mut s.qd, &y0.qd, row, &self.stages.kv, h);
    }

    /// One accepted step from the current state, at most to `t_end` (landing on it when the
    /// step reaches it): tries, rejects and shrinks until the error estimate passes.
    ///
    /// The last step to `t_end` is stretched by up to 1% rather than leave a sliver, but never
    /// after a rejection: a rejected last step shrinks like any other, so that a step which
    /// cannot move the clock fails with [`Error::StepSizeUnderflow`] instead of retrying the
    /// same stretched step for ever. A step whose new state is not finite counts as rejected.
    ///
    /// Every trial step is finite (at most `h_max`, at most the distance to `t_end`, never
    /// above `T::MAX`) and each rejection shrinks it by at least the controller's 0.9, so the
    /// loop ends: accepted, or [`Error::StepSizeUnderflow`] once `t + h` rounds to `t`, or
    /// to the step just rejected (below two ulps of the time, 0.9 of a step rounds back up to
    /// it: the same trial, rejected again, for ever).
    ///
    /// Never inlined: a step is a chain of dependent stages, and merged into a caller's loop
    /// (the bench's timed closure) it was compiled with a longer chain, 15% slower per step
    /// on a Kepler orbit; a call per step costs nothing measurable beside six evaluations.
    #[inline(never)]
    pub(super) fn advance<M: Mechanism<T, N>>(&mut self, m: &M, t_end: T) -> Result<(), Error> {
        self.protect();
        let (fq, fv) = self.derivative_at_state(m)?;
        self.stages.kq[0] = fq;
        self.stages.kv[0] = fv;
        let y0 = self.state;
        let mut h = self.h.min(self.settings.h_max()).min(T::MAX);
        // A first trial below the resolution of the time (a large t) is raised to the
        // smallest step that moves it: the error test decides whether that step is good.
        // After a rejection it is not raised again.
        if y0.t + h == y0.t {
            h = h.max(y0.t.abs() * T::EPSILON).min(self.settings.h_max());
        }
        let mut stretch = real::<T>(1.01);
        // The last trial rejected: a trial the clock rounds back up to it (a step below an
        // ulp of the time, rounded to one) cannot shrink any further.
        let mut rejected = T::INFINITY;
        loop {
            // An end too far to be reached in one finite step (t_end - t overflows) is not
            // a last step.
            let remaining = t_end - y0.t;
            let last = remaining.is_finite() && h * stretch >= remaining;
            if last {
                h = remaining;
            }
            if y0.t + h == y0.t || (!last && h < self.settings.h_min()) {
                return Err(Error::StepSizeUnderflow);
            }
            if !last {
                // The step the clock takes (t + h rounds to a multiple of t's ulp; the
                // difference is exact): the state moves by as much time as its clock, or a
                // late run (an f32 clock after an hour, an ulp of 2.4e-4 s) drifts in phase.
                h = (y0.t + h) - y0.t;
                if h >= rejected {
                    return Err(Error::StepSizeUnderflow);
                }
            }
            let mut y1 = y0;
            run_stages!(self, m, y0, h, y1; 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17);
            if last {
                y1.t = t_end;
            }
            // A blown-up stage, or a new state that is not finite, makes the error NaN:
            // rejected.
            let err_sq = self.error_norm_sq(h, &y1);
            if err_sq <= T::one() {
                // (A run that holds no energy never sets `stages.end`: nothing to clear here.)
                if let Some(e0) = self.energy {
                    self.hold_energy(m, &mut y1, e0)?;
                }
                let rejected_last = self.controller.rejected_last();
                // Grows at most tenfold, and never past the largest finite step.
                let factor = self.controller.accept(err_sq.to_f32());
                let proposal = (h * T::from_f32(factor)).min(T::MAX);
                // A last step shortened to land on t_end says nothing against the proposal
                // it was shortened from.
                self.h = if last && !rejected_last {
                    self.h.max(proposal)
                } else {
                    proposal
                };
                self.previous = y0;
                self.h_last = h;
                self.dense_end = y1.t;
                self.stages.hermite = None;
                self.state = y1;
                self.derivative = Some((self.stages.kq[P::FSAL], self.stages.kv[P::FSAL]));
                self.stats.accepted += 1;
                self.work.steps += 1;
                return Ok(());
            }
            rejected = h;
            h *= T::from_f32(self.controller.reject(err_sq.to_f32()));
            stretch = T::one();
            self.stats.rejected += 1;
            self.work.rejected += 1;
        }
    }

    /// Projects the end `y1` of an accepted step onto the energy `e0`
    /// ([`AdaptiveSettings::with_energy_projection`]), its derivative with it: the law is
    /// evaluated again where it reads the velocities (the acceleration of a law that does not
    /// read them is the stages' own, the coordinates being unchanged).
    fn hold_energy<M: Mechanism<T, N>>(
        &mut self,
        m: &M,
        y1: &mut State<T, N>,
        e0: T,
    ) -> Result<(), Error> {
        project(m, y1, e0)?;
        if P::NYSTROM.is_none() && m.reads_velocities() {
            self.stages.kv[P::FSAL] = self.eval(m, y1)?;
        }
        self.stages.kq[P::FSAL] = y1.qd;
        self.stages.end = Some(*y1);
        Ok(())
    }

    /// The state one step of the method from the start of the last accepted step to `t`
    /// inside it (for events located on steps, [`Self::stop_at_event`]): its stages overwrite
    /// the last step's from the second on; the first, the derivative at the start, is kept.
    pub(super) fn step_state<M: Mechanism<T, N>>(
        &mut self,
        m: &M,
        t: T,
    ) -> Result<State<T, N>, Error> {
        let y0 = self.previous;
        let h = t - y0.t;
        let mut y1 = y0;
        run_stages!(self, m, y0, h, y1; 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17);
        y1.t = t;
        y1.check_finite()?;
        Ok(y1)
    }

    /// Runs one public call `f`, with its work counted ([`Method::last_step`]); a call that
    /// fails leaves the integrator as it found it (the run, the controller, the step size,
    /// the dense output), so that the caller can go on from its last good state as if the
    /// call had not been made. Only the work counters ([`EmbeddedRungeKutta::statistics`],
    /// [`Method::last_step`]) keep the failed call's work.
    ///
    /// The integrator is saved only when the call first changes it
    /// ([`EmbeddedRungeKutta::protect`]): a landing inside the last step, the common call
    /// from a frame loop, copies nothing.
    pub(super) fn call<V, E>(&mut self, f: impl FnOnce(&mut Self) -> Result<V, E>) -> Result<V, E> {
        self.work = Work::default();
        self.guarded = true;
        let result = f(self);
        self.guarded = false;
        if let Some((run, stages)) = self.backup.take() {
            if result.is_err() {
                self.state = run.state;
                self.output = run.output;
                self.derivative = run.derivative;
                self.h = run.h;
                self.controller = run.controller;
                self.previous = run.previous;
                self.h_last = run.h_last;
                self.dense_end = run.dense_end;
                self.energy = run.energy;
                self.stages = stages;
            }
        }
        result
    }

    /// Saves the integrator before a call first changes it (once per call; the work counters
    /// and `output`, which a call sets only on success, aside).
    #[inline(always)]
    pub(super) fn protect(&mut self) {
        if self.guarded && self.backup.is_none() {
            let run = Run {
                state: self.state,
                output: self.output,
                derivative: self.derivative,
                h: self.h,
                controller: self.controller,
                previous: self.previous,
                h_last: self.h_last,
                dense_end: self.dense_end,
                energy: self.energy,
            };
            self.backup = Some((run, self.stages));
        }
    }

    /// One accepted step from `state`, of the size the controller chooses but not past
    /// `t_end`; returns the new state. Its dense output is prepared, so that
    /// [`EmbeddedRungeKutta::dense_output`] can sample inside it (3 more evaluations for
    /// DOP853's order-7 extension; none for Dormand-Prince 5(4)).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `t_end` when not after `state.t` or not finite;
    /// [`Error::StepSizeUnderflow`] when the error test needs a step below the minimum (or
    /// below the resolution of `t`); [`Error::NonFiniteState`] for a non-finite `state`;
    /// whatever the mechanism's law returns.
    pub fn next_step<M: Mechanism<T, N>>(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        t_end: T,
    ) -> Result<State<T, N>, Error> {
        let t_end = check_end_after(state, t_end)?;
        self.call(|rk| rk.next_step_from(mechanism, state, t_end))
    }

    fn next_step_from<M: Mechanism<T, N>>(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        t_end: T,
    ) -> Result<State<T, N>, Error> {
        self.begin(mechanism, state)?;
        if self.state.t >= t_end {
            if self.previous.t < t_end {
                // Continuing from a landing that the last step already passed: the end is
                // inside that step, whose dense interval is this call's.
                self.prepare_dense(mechanism)?;
                let s = self.landing(mechanism, t_end)?;
                self.output = Some(s);
                return Ok(s);
            }
            // The run continued is already at the end (a state handed back an ulp or two
            // early, no step behind it): a step is promised, so the run starts afresh.
            self.output = None;
            self.begin(mechanism, state)?;
        }
        self.advance(mechanism, t_end)?;
        self.prepare_dense(mechanism)?;
        self.output = Some(self.state);
        Ok(self.state)
    }

    /// The state a call returns at `t` inside the last accepted step: the continuous
    /// extension's, projected onto the energy where the run holds it (the run itself goes on
    /// from the step's end).
    fn landing<M: Mechanism<T, N>>(&mut self, m: &M, t: T) -> Result<State<T, N>, Error> {
        let mut s = self.interpolate(m, t)?;
        if let Some(e0) = self.energy {
            project(m, &mut s, e0)?;
        }
        Ok(s)
    }

    /// The state at `t` inside the last accepted step, by the continuous extension.
    pub(super) fn interpolate<M: Mechanism<T, N>>(
        &mut self,
        m: &M,
        t: T,
    ) -> Result<State<T, N>, Error> {
        if t == self.state.t {
            return Ok(self.state);
        }
        self.prepare_dense(m)?;
        let s = self.evaluate_dense(t);
        s.check_finite().map(|()| s)
    }

    /// Steps from `state` until the time is `t_end` exactly (the last step is shortened to
    /// land on it); returns the state there. An end equal to `state.t` takes no step and
    /// returns `state` (a run of length zero; [`EmbeddedRungeKutta::next_step`], which
    /// promises a step, refuses it).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `t_end` before `state.t` or not finite;
    /// [`Error::TooManySteps`] after [`AdaptiveSettings::max_steps`] steps; as
    /// [`EmbeddedRungeKutta::next_step`]; each with the steps taken and the last good state
    /// ([`Failure`]).
    pub fn integrate_to<M: Mechanism<T, N>>(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        t_end: T,
    ) -> Result<State<T, N>, Failure<T, N>> {
        self.call(|rk| rk.run_to(mechanism, state, t_end, true))
    }

    /// The steps of [`EmbeddedRungeKutta::integrate_to`]; with `exact_end` false the end is
    /// reached by the continuous extension when a step passes it (the landing of
    /// [`Integrator::step`]), else by a last step shortened to it.
    fn run_to<M: Mechanism<T, N>>(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        t_end: T,
        exact_end: bool,
    ) -> Result<State<T, N>, Failure<T, N>> {
        let t_end = check_end(state, t_end).map_err(|e| fail(e, 0, state))?;
        self.begin(mechanism, state)
            .map_err(|e| fail(e, 0, state))?;
        let mut steps = 0;
        while self.state.t < t_end {
            if steps == self.settings.max_steps() {
                return Err(fail(Error::TooManySteps { steps }, steps, &self.state));
            }
            let horizon = if exact_end { t_end } else { T::INFINITY };
            let from = self.state;
            self.advance(mechanism, horizon)
                .map_err(|e| fail(e, steps, &from))?;
            steps += 1;
        }
        let out = if self.state.t == t_end {
            self.state
        } else {
            self.landing(mechanism, t_end)
                .map_err(|e| fail(e, steps, &self.previous))?
        };
        self.output = Some(out);
        Ok(out)
    }
}

/// `t_end` when it is finite and after `state.t`: the end of one step, which must move.
fn check_end_after<T: Real, const N: usize>(state: &State<T, N>, t_end: T) -> Result<T, Error> {
    if t_end.is_finite() && t_end > state.t {
        Ok(t_end)
    } else {
        Err(Error::InvalidParameter {
            name: "t_end",
            reason: "must be finite and after the state's time",
        })
    }
}

/// `t_end` when it is finite and not before `state.t`: the end of a run, which may be empty.
pub(super) fn check_end<T: Real, const N: usize>(
    state: &State<T, N>,
    t_end: T,
) -> Result<T, Error> {
    if t_end.is_finite() && t_end >= state.t {
        Ok(t_end)
    } else {
        Err(Error::InvalidParameter {
            name: "t_end",
            reason: "must be finite and not before the state's time",
        })
    }
}

impl<T, P, const N: usize, const S: usize, const R: usize> Method
    for EmbeddedRungeKutta<T, N, S, R, P>
where
    T: Real,
    P: EmbeddedPair<S, R>,
{
    const NAME: &'static str = P::NAME;
    const ORDER: u32 = P::ORDER;
    /// Per internal step accepted (`fixed`, with the first stage of the next step reused), and
    /// per rejected attempt (`per_iteration`: a rejection is an iteration of the step-size
    /// search); [`Method::last_step`] reports both counts of a call. Holding the energy
    /// ([`AdaptiveSettings::with_energy_projection`]) costs one more per accepted step where
    /// the law reads the velocities, which `last_step` counts and this constant does not.
    const COST: Cost = Cost {
        fixed: P::FSAL as u32,
        per_iteration: P::FSAL as u32,
        jacobians: 0,
    };

    fn last_step(&self) -> Work {
        self.work
    }
}

impl<T, M, P, const N: usize, const S: usize, const R: usize> Integrator<T, N, M>
    for EmbeddedRungeKutta<T, N, S, R, P>
where
    T: Real,
    M: Mechanism<T, N>,
    P: EmbeddedPair<S, R>,
{
    /// Lands on `state.t + dt` through the continuous extension, the internal steps as long
    /// as the tolerance allows (they run ahead of the landing; the next call from this one's
    /// result continues from them). A pair whose dense output is more than one order below
    /// its own (quintic Hermite under the orders 6 to 12 of the Nyström and Verner
    /// pairs) lands by a last step shortened to `state.t + dt` instead, so that a frame is as
    /// accurate as a step.
    fn step(&mut self, m: &M, state: &State<T, N>, dt: T) -> Result<State<T, N>, Error> {
        let dt = check_step(state, dt)?;
        let exact_end = P::DENSE_ORDER + 1 < P::ORDER;
        self.call(|rk| rk.run_to(m, state, state.t + dt, exact_end))
            .map_err(|f| f.error)
    }
}

#[cfg(test)]
mod tests {
    use super::scaled_square;

    /// `a^2 b`, and where `a^2` overflows (a step near the largest finite time) the same
    /// through `(a sqrt b)^2`: finite, not infinity times a small estimate.
    #[test]
    fn scaled_square_survives_overflow() {
        assert_eq!(scaled_square(3.0f64, 2.0), 18.0);
        // (1e200 sqrt(1e-300))^2 = (1e50)^2 = 1e100, to a few roundings.
        let big = scaled_square(1e200f64, 1e-300);
        assert!((big / 1e100 - 1.0).abs() < 1e-14, "{big:e}");
        let big32 = scaled_square(1e20f32, 1e-30);
        assert!((big32 / 1e10 - 1.0).abs() < 1e-6, "{big32:e}");
        // A zero estimate is a zero error however long the step; NaN stays NaN.
        assert_eq!(scaled_square(1e200f64, 0.0), 0.0);
        assert!(scaled_square(f64::NAN, 1.0).is_nan());
        assert!(scaled_square(1e200f64, f64::NAN).is_nan());
    }
}
