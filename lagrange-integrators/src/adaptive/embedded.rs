//! [`EmbeddedRungeKutta`]: one adaptive explicit Runge-Kutta engine for every embedded pair:
//! stages, error estimate, PI step-size control, and the stepping loops.

use super::controller::PiController;
use super::AdaptiveSettings;
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
    /// Order of the dense output.
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
}

/// Work counts since the last (re)start.
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

/// The cubic Hermite part of a dense output: `(y1 - y0, c3, c4)`.
pub(super) type Hermite<T, const N: usize> = [SVector<T, N>; 3];

/// An adaptive explicit Runge-Kutta integrator on the pair `P`: use the aliases
/// [`DormandPrince54`](crate::DormandPrince54) and
/// [`DormandPrince853`](crate::DormandPrince853).
///
/// It holds its current state (given to [`EmbeddedRungeKutta::new`] or
/// [`EmbeddedRungeKutta::restart`]) and advances it by steps whose size a PI controller
/// chooses from the embedded error estimate:
///
/// ```text
/// err      = RMS_i( est_i / (atol + rtol max(|y0_i|, |y1_i|)) )   over y = (q, q')
/// accepted when err <= 1, then
/// h_next   = h clamp(0.9 err^-(1/k - 0.75 beta) err_prev^beta, 0.2, 10),   beta = 0.04
/// rejected:  h <- h max(0.2, 0.9 err^(-1/k)), no growth on the next accepted step
/// ```
///
/// The mechanism is passed to every call and not stored. The derivative at the current state
/// is reused by the next step (first same as last); after changing the mechanism between
/// steps (an [`Input`](lagrange_core::Input), say) call [`EmbeddedRungeKutta::refresh`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmbeddedRungeKutta<T: Real, const N: usize, const S: usize, const R: usize, P> {
    pub(super) settings: AdaptiveSettings<T>,
    pub(super) state: State<T, N>,
    /// The derivative `(q', q'')` at `state`, when known.
    pub(super) derivative: Option<(SVector<T, N>, SVector<T, N>)>,
    /// Stage derivatives of the last step: `kq_i = V_i`, `kv_i = q''(stage i)`.
    pub(super) kq: [SVector<T, N>; S],
    pub(super) kv: [SVector<T, N>; S],
    /// The next step size to try.
    pub(super) h: T,
    pub(super) controller: PiController,
    /// The start of the last accepted step and its size (zero before any).
    pub(super) previous: State<T, N>,
    pub(super) h_last: T,
    /// The end of the interval the dense output may be sampled on (cut by an event).
    pub(super) dense_end: T,
    /// Dense coefficients of the last step, when computed: the cubic Hermite part of `q` and
    /// of `q'`, then the rows.
    pub(super) hermite: Option<(Hermite<T, N>, Hermite<T, N>)>,
    pub(super) rows_q: [SVector<T, N>; R],
    pub(super) rows_v: [SVector<T, N>; R],
    pub(super) stats: Statistics,
    pub(super) pair: PhantomData<P>,
}

/// `x` in the integrator's scalar.
pub(super) fn real<T: Real>(x: f64) -> T {
    T::from_f64(x)
}

/// `sum_j w_j k_j` over the first `w.len()` stages with a non-zero weight.
///
/// Always inlined: where `w` is a row of the pair's constant tableau at a constant index (the
/// stages of a step, see [`run_stages!`]), the loop unrolls and the zero weights fold away,
/// as in a hand-written stage.
#[inline(always)]
pub(super) fn combine<T: Real, const N: usize>(w: &[f64], k: &[SVector<T, N>]) -> SVector<T, N> {
    // Component by component, so that each sum stays in a register however large N is.
    SVector::from_fn(|i, _| {
        let mut acc = T::zero();
        for (wj, kj) in w.iter().zip(k) {
            if *wj != 0.0 {
                acc += kj[i] * real::<T>(*wj);
            }
        }
        acc
    })
}

/// Evaluates stages `1..=P::FSAL` of a step, each with a constant index (so that
/// [`combine`] sees constant rows): one line per possible stage, those past `FSAL` skipped at
/// compile time. Leaves the state of stage `FSAL`, `(t0 + h, y1)`, in `$last`.
macro_rules! run_stages {
    ($rk:ident, $m:ident, $y0:ident, $h:ident, $last:ident; $($i:literal)*) => {
        const { assert!(P::FSAL <= 12, "run_stages! covers pairs of up to 12 step stages") };
        $(
            if $i <= P::FSAL {
                $last = $rk.stage::<M, $i>($m, &$y0, $h)?;
            }
        )*
    };
}

impl<T, const N: usize, const S: usize, const R: usize, P> EmbeddedRungeKutta<T, N, S, R, P>
where
    T: Real,
    P: EmbeddedPair<S, R>,
{
    /// The integrator with `settings`, started at `state`: evaluates the derivative there
    /// and chooses the first step (Hairer's estimate, one more evaluation, unless
    /// [`AdaptiveSettings::with_initial_step`] gave it).
    ///
    /// # Errors
    /// [`Error::NonFiniteState`] for a non-finite `state`; whatever
    /// [`Mechanism::acceleration`] returns.
    pub fn new<M: Mechanism<T, N>>(
        settings: AdaptiveSettings<T>,
        mechanism: &M,
        state: &State<T, N>,
    ) -> Result<Self, Error> {
        let mut s = Self {
            settings,
            state: *state,
            derivative: None,
            kq: [SVector::zeros(); S],
            kv: [SVector::zeros(); S],
            h: T::zero(),
            controller: PiController::new(P::ERROR_EXPONENT),
            previous: *state,
            h_last: T::zero(),
            dense_end: state.t,
            hermite: None,
            rows_q: [SVector::zeros(); R],
            rows_v: [SVector::zeros(); R],
            stats: Statistics::default(),
            pair: PhantomData,
        };
        s.restart(mechanism, state)?;
        Ok(s)
    }

    /// Starts again from `state`, as [`EmbeddedRungeKutta::new`] does, keeping the settings.
    ///
    /// # Errors
    /// As [`EmbeddedRungeKutta::new`].
    pub fn restart<M: Mechanism<T, N>>(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
    ) -> Result<(), Error> {
        state.check_finite()?;
        self.state = *state;
        self.stats = Statistics::default();
        self.controller.reset();
        self.h_last = T::zero();
        self.hermite = None;
        self.previous = *state;
        self.dense_end = state.t;
        self.derivative = None;
        let (q, v) = self.derivative_at_state(mechanism)?;
        self.h = match self.settings.h_initial() {
            Some(h) => h,
            None => self.initial_step(mechanism, &q, &v)?,
        }
        .min(self.settings.h_max());
        Ok(())
    }

    /// Drops the derivative kept from the last step, so that the next step evaluates it anew:
    /// call after changing the mechanism between steps.
    pub fn refresh(&mut self) {
        self.derivative = None;
    }

    /// The current state.
    #[must_use]
    pub fn state(&self) -> &State<T, N> {
        &self.state
    }

    /// The step size the next step will try.
    #[must_use]
    pub fn step_size(&self) -> T {
        self.h
    }

    /// The settings.
    #[must_use]
    pub fn settings(&self) -> &AdaptiveSettings<T> {
        &self.settings
    }

    /// Work done since the last (re)start.
    #[must_use]
    pub fn statistics(&self) -> Statistics {
        self.stats
    }

    /// One evaluation of the acceleration, counted.
    pub(super) fn eval<M: Mechanism<T, N>>(
        &mut self,
        m: &M,
        s: &State<T, N>,
    ) -> Result<SVector<T, N>, Error> {
        self.stats.evaluations += 1;
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

    /// Hairer's initial step estimate (`hinit` of DOPRI5 and DOP853), one evaluation.
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
        let d0 = rms(&s.q, &s.qd);
        let d1 = rms(fq, fv);
        let small = real::<T>(1e-5);
        let mut h0 = if d0 < small || d1 < small {
            real(1e-6)
        } else {
            real::<T>(0.01) * d0 / d1
        };
        h0 = h0.min(self.settings.h_max());
        let explicit_euler = State {
            t: s.t + h0,
            q: s.q + fq * h0,
            qd: s.qd + fv * h0,
        };
        let a1 = self.eval(m, &explicit_euler)?;
        let d2 = rms(&(explicit_euler.qd - fq), &(a1 - fv)) / h0;
        let d = d1.max(d2);
        let h1 = if d <= real(1e-15) {
            real::<T>(1e-6).max(h0 * real(1e-3))
        } else {
            (real::<T>(0.01) / d).powf(real::<T>(1.0) / T::from_f64(f64::from(P::ORDER)))
        };
        let h = (h0 * real(100.0)).min(h1).min(self.settings.h_max());
        if h.is_finite() && h > T::zero() {
            Ok(h)
        } else {
            Err(Error::NonFiniteState)
        }
    }

    /// The error norm of a step of `h` from `y0 = self.state` to `y1`, from the stages.
    #[inline(always)]
    fn error_norm(&self, h: T, y1: &State<T, N>) -> T {
        let (rtol, atol) = (self.settings.rtol(), self.settings.atol());
        let y0 = &self.state;
        // The weights 1 / (atol + rtol max(|y0|, |y1|)), divided once for both estimates.
        let weight = |a: T, b: T| (atol + rtol * a.abs().max(b.abs())).recip();
        let wq = SVector::<T, N>::from_fn(|i, _| weight(y0.q[i], y1.q[i]));
        let wv = SVector::<T, N>::from_fn(|i, _| weight(y0.qd[i], y1.qd[i]));
        let n = T::from_f64(2.0 * N as f64);
        let err5 = self.weighted_sum_sq(&P::E[..=P::FSAL], &wq, &wv);
        match P::E3 {
            None => h.abs() * (err5 / n).sqrt(),
            Some(e3) => {
                let err3 = self.weighted_sum_sq(&e3[..=P::FSAL], &wq, &wv);
                let mut deno = err5 + real::<T>(0.01) * err3;
                if deno <= T::zero() {
                    deno = T::one();
                }
                h.abs() * err5 / (deno * n).sqrt()
            }
        }
    }

    /// `|W_q e_q|^2 + |W_v e_v|^2` for the estimate `e = sum_j w_j k_j`.
    #[inline(always)]
    fn weighted_sum_sq(&self, w: &[f64], wq: &SVector<T, N>, wv: &SVector<T, N>) -> T {
        let eq = combine(w, &self.kq).component_mul(wq);
        let ev = combine(w, &self.kv).component_mul(wv);
        eq.dot(&eq) + ev.dot(&ev)
    }

    /// Evaluates stage `I` of a step of `h` from `y0`; returns its state.
    #[inline(always)]
    fn stage<M: Mechanism<T, N>, const I: usize>(
        &mut self,
        m: &M,
        y0: &State<T, N>,
        h: T,
    ) -> Result<State<T, N>, Error> {
        let s = self.stage_state(y0, h, I);
        self.kq[I] = s.qd;
        self.kv[I] = self.eval(m, &s)?;
        Ok(s)
    }

    /// The state at stage `i` of a step of `h` from `y0`, from the stages before it.
    #[inline(always)]
    pub(super) fn stage_state(&self, y0: &State<T, N>, h: T, i: usize) -> State<T, N> {
        // A is strictly lower triangular: stage i combines the stages before it.
        let (row, c) = (&P::A[i][..i], P::C[i]);
        State {
            t: y0.t + h * real::<T>(c),
            q: y0.q + combine(row, &self.kq) * h,
            qd: y0.qd + combine(row, &self.kv) * h,
        }
    }

    /// One accepted step from the current state, at most to `t_end`: tries, rejects and
    /// shrinks until the error estimate passes.
    pub(super) fn advance<M: Mechanism<T, N>>(
        &mut self,
        m: &M,
        t_end: Option<T>,
    ) -> Result<(), Error> {
        let (fq, fv) = self.derivative_at_state(m)?;
        self.kq[0] = fq;
        self.kv[0] = fv;
        let y0 = self.state;
        let mut h = self.h.min(self.settings.h_max());
        loop {
            let mut last = false;
            if let Some(te) = t_end {
                // Stretch by up to 1% rather than leave a sliver of a step.
                if y0.t + h * real(1.01) >= te {
                    h = te - y0.t;
                    last = true;
                }
            }
            if !last && (h < self.settings.h_min() || y0.t + h == y0.t) {
                return Err(Error::StepSizeUnderflow);
            }
            let mut y1 = y0;
            run_stages!(self, m, y0, h, y1; 1 2 3 4 5 6 7 8 9 10 11 12);
            if let (true, Some(te)) = (last, t_end) {
                y1.t = te;
            }
            let err = self.error_norm(h, &y1);
            if err <= T::one() {
                let rejected_last = self.controller.rejected_last();
                let proposal = h * T::from_f32(self.controller.accept(err.to_f32()));
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
                self.hermite = None;
                self.state = y1;
                self.derivative = Some((self.kq[P::FSAL], self.kv[P::FSAL]));
                self.stats.accepted += 1;
                return Ok(());
            }
            // Rejected (a NaN error estimate from a blown-up stage counts as rejected).
            h *= T::from_f32(self.controller.reject(err.to_f32()));
            self.stats.rejected += 1;
        }
    }

    /// One accepted step, of whatever size the controller chooses; returns the new state.
    ///
    /// # Errors
    /// [`Error::StepSizeUnderflow`] when the error test needs a step below the minimum (or
    /// below the resolution of `t`); whatever [`Mechanism::acceleration`] returns.
    pub fn step<M: Mechanism<T, N>>(&mut self, mechanism: &M) -> Result<State<T, N>, Error> {
        self.advance(mechanism, None)?;
        Ok(self.state)
    }

    /// `t_end` when it is finite and not before the current time.
    pub(super) fn check_end(&self, t_end: T) -> Result<T, Error> {
        if t_end.is_finite() && t_end >= self.state.t {
            Ok(t_end)
        } else {
            Err(Error::InvalidParameter {
                name: "t_end",
                reason: "must be finite and not before the current time",
            })
        }
    }

    /// Steps until the current time is `t_end` exactly (the last step is shortened to land
    /// on it); returns the state there.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `t_end` before the current time or not finite;
    /// [`Error::TooManySteps`] after [`AdaptiveSettings::max_steps`] steps; as
    /// [`EmbeddedRungeKutta::step`].
    pub fn integrate_to<M: Mechanism<T, N>>(
        &mut self,
        mechanism: &M,
        t_end: T,
    ) -> Result<State<T, N>, Error> {
        let t_end = self.check_end(t_end)?;
        let mut steps = 0;
        while self.state.t < t_end {
            if steps == self.settings.max_steps() {
                return Err(Error::TooManySteps { steps });
            }
            self.advance(mechanism, Some(t_end))?;
            steps += 1;
        }
        Ok(self.state)
    }
}
