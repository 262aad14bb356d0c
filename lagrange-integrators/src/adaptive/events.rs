//! Dense output of the adaptive integrators (the continuous extension between the last two
//! accepted points) and event location by root finding on it.

use super::embedded::{check_end, EmbeddedPair, EmbeddedRungeKutta};
use super::hermite::quintic_rows;
use super::sums::{combine, real};
use crate::integrator::fail;
use crate::Failure;
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, Mechanism, Real, State};

/// Why [`EmbeddedRungeKutta::integrate_until_event`] stopped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stop<T: Real, const N: usize> {
    /// The guard changed sign: the state at the located time.
    Event(State<T, N>),
    /// The end time was reached without an event: the state there.
    End(State<T, N>),
}

impl<T: Real, const N: usize> Stop<T, N> {
    /// The state where the integration stopped, whatever the reason.
    #[must_use]
    pub fn state(&self) -> &State<T, N> {
        match self {
            Self::Event(s) | Self::End(s) => s,
        }
    }
}

#[cfg(feature = "defmt")]
impl<T: Real, const N: usize> defmt::Format for Stop<T, N> {
    fn format(&self, f: defmt::Formatter<'_>) {
        match self {
            Self::Event(s) => defmt::write!(f, "Event({})", s),
            Self::End(s) => defmt::write!(f, "End({})", s),
        }
    }
}

/// Root-finding iterations allowed per event (the Illinois method needs ~10 to rounding).
const MAX_ROOT_ITERATIONS: u32 = 200;

/// `g` when it is not NaN.
fn checked_guard<T: Real>(g: T) -> Result<T, Error> {
    if g.partial_cmp(&T::zero()).is_none() {
        Err(Error::InvalidParameter {
            name: "guard",
            reason: "returned NaN",
        })
    } else {
        Ok(g)
    }
}

/// True when `g` went from `g0` (not zero) to `g1` through zero.
fn crossed<T: Real>(g0: T, g1: T) -> bool {
    g0 != T::zero() && (g1 == T::zero() || (g0 < T::zero()) != (g1 < T::zero()))
}

impl<T, const N: usize, const S: usize, const R: usize, P> EmbeddedRungeKutta<T, N, S, R, P>
where
    T: Real,
    P: EmbeddedPair<S, R>,
{
    /// Computes the dense coefficients of the last step, evaluating its extra stages.
    pub(super) fn prepare_dense<M: Mechanism<T, N>>(&mut self, m: &M) -> Result<(), Error> {
        if self.stages.hermite.is_some() {
            return Ok(());
        }
        self.protect();
        let (y0, h) = (self.previous, self.h_last);
        for i in P::FSAL + 1..S {
            let s = self.stage_state(&y0, h, i);
            self.stages.kq[i] = s.qd;
            self.stages.kv[i] = self.eval(m, &s)?;
        }
        // The step's end: where the energy projection moved it, else recomputed from the
        // stages (a state cut by an event is not it).
        let y1 = match self.stages.end {
            Some(end) => end,
            None => self.stage_state(&y0, h, P::FSAL),
        };
        let hermite = |dy: SVector<T, N>, k0: SVector<T, N>, k1: SVector<T, N>| {
            let c3 = k0 * h - dy;
            [dy, c3, dy - k1 * h - c3]
        };
        let f = P::FSAL;
        let k = &mut self.stages;
        k.hermite = Some((
            hermite(y1.q - y0.q, k.kq[0], k.kq[f]),
            hermite(y1.qd - y0.qd, k.kv[0], k.kv[f]),
        ));
        if P::HERMITE_DENSE {
            const { assert!(!P::HERMITE_DENSE || R == 2, "HERMITE_DENSE takes R = 2") };
            if let ([q4, q5], [v4, v5]) = (&mut k.rows_q[..], &mut k.rows_v[..]) {
                quintic_rows([q4, q5, v4, v5], &k.hermite, &k.kv, (&y0, &y1), h, f);
            }
            return Ok(());
        }
        for (r, row) in P::DENSE.iter().enumerate() {
            k.rows_q[r] = combine(row, &k.kq) * h;
            k.rows_v[r] = combine(row, &k.kv) * h;
        }
        Ok(())
    }

    /// The continuous extension at `t` (inside the last step), from prepared coefficients:
    ///
    /// ```text
    /// y(t0 + s h) = y0 + s (d1 + (1-s) (d2 + s (d3 + (1-s) (d4 + s (d5 + ...)))))
    /// ```
    pub(super) fn evaluate_dense(&self, t: T) -> State<T, N> {
        let (y0, h) = (self.previous, self.h_last);
        let s = (t - y0.t) / h;
        let s1 = T::one() - s;
        let weight = |i: usize| if i % 2 == 0 { s } else { s1 };
        let fold = |hermite: &[SVector<T, N>; 3], rows: &[SVector<T, N>; R]| {
            let mut acc = SVector::<T, N>::zeros();
            for (r, row) in rows.iter().enumerate().rev() {
                acc = (row + acc) * weight(r + 3);
            }
            for (i, c) in hermite.iter().enumerate().rev() {
                acc = (c + acc) * weight(i);
            }
            acc
        };
        match &self.stages.hermite {
            Some((hq, hv)) => State {
                t,
                q: y0.q + fold(hq, &self.stages.rows_q),
                qd: y0.qd + fold(hv, &self.stages.rows_v),
            },
            None => self.state,
        }
    }

    /// The interval `[t0, t1]` that [`EmbeddedRungeKutta::dense_output`] can sample: the
    /// last accepted step (up to an event that cut it short), when its continuous extension
    /// is prepared ([`EmbeddedRungeKutta::next_step`] prepares it); `None` otherwise.
    #[must_use]
    pub fn dense_interval(&self) -> Option<(T, T)> {
        (self.h_last > T::zero() && self.stages.hermite.is_some())
            .then_some((self.previous.t, self.dense_end))
    }

    /// The state at time `t` inside the last step taken by
    /// [`EmbeddedRungeKutta::next_step`] (from its start to its end), by the method's
    /// continuous extension (order 4 for Dormand-Prince 5(4), 7 for DOP853, 4 for the
    /// Nyström and Verner pairs).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `t` when outside [`EmbeddedRungeKutta::dense_interval`]
    /// (or there is none); [`Error::NonFiniteState`].
    pub fn dense_output(&self, t: T) -> Result<State<T, N>, Error> {
        match self.dense_interval() {
            Some((t0, t1)) if t >= t0 && t <= t1 => {
                let s = if t == t1 {
                    self.state
                } else {
                    self.evaluate_dense(t)
                };
                s.check_finite().map(|()| s)
            }
            _ => Err(Error::InvalidParameter {
                name: "t",
                reason: "must lie within the last step taken by next_step",
            }),
        }
    }

    /// Steps from `state` towards `t_end` until `guard(state)` changes sign, locates the time
    /// of the change on the dense output (the Illinois variant of regula falsi, to
    /// [`AdaptiveSettings::event_tolerance`](super::AdaptiveSettings::event_tolerance) or to
    /// rounding; for a pair whose dense output is more than an order below its steps, the
    /// Nyström and Verner pairs, again on steps of the pair from there), and stops there; a
    /// call from the state it returns continues the run.
    ///
    /// The guard is a function `g(t, q, q')` of the state. A sign change is a step from a
    /// non-zero value to zero or to the opposite sign; the located time is the first one known
    /// to be past the change (`g` there is zero or has the new sign), so continuing does not
    /// report the same event again. Events in which `g` touches zero or crosses twice within
    /// one step are not seen: bound the step ([`with_step_bounds`](super::AdaptiveSettings::with_step_bounds)) below
    /// the shortest interval between sign changes.
    ///
    /// # Errors
    /// As [`EmbeddedRungeKutta::integrate_to`]; [`Error::InvalidParameter`] `guard` when it
    /// returns NaN. A call that fails leaves the integrator as it found it.
    pub fn integrate_until_event<M, G>(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        t_end: T,
        guard: G,
    ) -> Result<Stop<T, N>, Failure<T, N>>
    where
        M: Mechanism<T, N>,
        G: FnMut(&State<T, N>) -> T,
    {
        self.call(|rk| rk.run_until_event(mechanism, state, t_end, guard))
    }

    /// The steps of [`EmbeddedRungeKutta::integrate_until_event`].
    fn run_until_event<M, G>(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        t_end: T,
        mut guard: G,
    ) -> Result<Stop<T, N>, Failure<T, N>>
    where
        M: Mechanism<T, N>,
        G: FnMut(&State<T, N>) -> T,
    {
        let t_end = check_end(state, t_end).map_err(|e| fail(e, 0, state))?;
        self.begin(mechanism, state)
            .map_err(|e| fail(e, 0, state))?;
        let mut g0 = checked_guard(guard(state)).map_err(|e| fail(e, 0, state))?;
        // Continuing from a landing that the last step passed: that step's rest first.
        if self.state.t > state.t {
            let g1 = checked_guard(guard(&self.state)).map_err(|e| fail(e, 0, state))?;
            if crossed(g0, g1) {
                return self
                    .stop_at_event(mechanism, &mut guard, (state.t, g0), g1)
                    .map_err(|e| fail(e, 0, state));
            }
            g0 = g1;
        }
        let mut steps = 0;
        while self.state.t < t_end {
            if steps == self.settings.max_steps() {
                return Err(fail(Error::TooManySteps { steps }, steps, &self.state));
            }
            let from = self.state;
            self.advance(mechanism, t_end)
                .map_err(|e| fail(e, steps, &from))?;
            steps += 1;
            let g1 = checked_guard(guard(&self.state)).map_err(|e| fail(e, steps, &from))?;
            if crossed(g0, g1) {
                let start = (self.previous.t, g0);
                return self
                    .stop_at_event(mechanism, &mut guard, start, g1)
                    .map_err(|e| fail(e, steps, &from));
            }
            g0 = g1;
        }
        self.output = Some(self.state);
        Ok(Stop::End(self.state))
    }

    /// The event inside the last step, where the guard went from `start = (t, g)` to `g1`
    /// at the step's end: the state there becomes the run's current one.
    ///
    /// The time is located on the dense output. Where that is more than an order below the
    /// steps (the Nyström and Verner pairs), it is located again on steps of the method itself
    /// from the step's start, the dense output's time tried first: the state returned is then
    /// as accurate as a step's, and the guard there is that state's.
    fn stop_at_event<M, G>(
        &mut self,
        m: &M,
        guard: &mut G,
        start: (T, T),
        g1: T,
    ) -> Result<Stop<T, N>, Error>
    where
        M: Mechanism<T, N>,
        G: FnMut(&State<T, N>) -> T,
    {
        self.protect();
        if g1 != T::zero() {
            self.prepare_dense(m)?;
            let end = (self.state.t, g1);
            let mut dense = |rk: &mut Self, t: T| checked_guard(guard(&rk.evaluate_dense(t)));
            let t = self.locate((start, end), None, &mut dense)?;
            self.state = if P::DENSE_ORDER + 1 < P::ORDER {
                // The guard's rate along the interpolant, for a Newton step from its time.
                let delta = (end.0 - start.0) * real::<T>(1e-3);
                let (lo, hi) = ((t - delta).max(start.0), (t + delta).min(end.0));
                let slope = (dense(self, hi)? - dense(self, lo)?) / (hi - lo);
                self.locate_by_steps(m, guard, (start, end), (t, slope))?
            } else {
                self.evaluate_dense(t)
            };
            self.state.check_finite()?;
            self.dense_end = self.state.t;
            self.derivative = None;
        }
        self.output = Some(self.state);
        Ok(Stop::Event(self.state))
    }

    /// The event located again on steps of the pair from the start of the last step, from
    /// the `guess` `(t, slope)` the dense output gave: the state there, the last step cut
    /// to it (its stages and dense output those of the step to it, so that the dense output
    /// ends on the state returned).
    fn locate_by_steps<M, G>(
        &mut self,
        m: &M,
        guard: &mut G,
        bracket: ((T, T), (T, T)),
        guess: (T, T),
    ) -> Result<State<T, N>, Error>
    where
        M: Mechanism<T, N>,
        G: FnMut(&State<T, N>) -> T,
    {
        let mut last = None;
        let stepped = |rk: &mut Self, t: T| {
            let s = rk.step_state(m, t)?;
            last = Some(s);
            checked_guard(guard(&s))
        };
        let t = self.locate(bracket, Some(guess), stepped)?;
        if t == self.state.t {
            // The step's own end: its dense output stands (prepared from its own stages).
            return Ok(self.state);
        }
        let s = match last {
            Some(s) if s.t == t => s,
            _ => self.step_state(m, t)?,
        };
        self.h_last = t - self.previous.t;
        self.stages.hermite = None;
        self.stages.end = None;
        self.prepare_dense(m)?;
        Ok(s)
    }

    /// The time of the sign change of the guard between `(a, g(a))` and `(b, g(b))`, by the
    /// Illinois variant of regula falsi on `g_at(t)`: the first time found past the change
    /// (`g` zero or of `g(b)`'s sign), to the event tolerance or to rounding.
    ///
    /// With a `guess` `(t, slope)`, `t` is tried first, then a Newton step from it on `slope`
    /// taken twice over, so that the root is bracketed about as tightly as the guess was
    /// close: from a good guess, a few trials instead of a regula falsi from the step's ends.
    fn locate(
        &mut self,
        ((mut a, mut ga), (mut b, mut gb)): ((T, T), (T, T)),
        mut guess: Option<(T, T)>,
        mut g_at: impl FnMut(&mut Self, T) -> Result<T, Error>,
    ) -> Result<T, Error> {
        let mut newton: Option<(T, T, T)> = None;
        // The times' scale: a few of its ulps are the default tolerance, and the trials keep
        // two off either end.
        let scale = T::EPSILON * a.abs().max(b.abs());
        let tolerance = self.settings.event_tolerance().max(real::<T>(4.0) * scale);
        let margin = real::<T>(2.0) * scale;
        // Which end moved last: the Illinois method halves the other end's value when the
        // same end moves twice, so both ends converge.
        let mut moved_b = None;
        for _ in 0..MAX_ROOT_ITERATIONS {
            if b - a <= tolerance {
                break;
            }
            let (mut c, slope) = match (guess.take(), newton.take()) {
                (Some((t, slope)), _) => (t, Some(slope)),
                (None, Some((t, g, slope))) => (t - real::<T>(2.0) * g / slope, None),
                (None, None) => (b - gb * (b - a) / (gb - ga), None),
            };
            // A step of NaN or infinity (equal values at both ends, a zero slope): the midpoint.
            if !c.is_finite() {
                c = a + (b - a) * T::HALF;
            }
            // Two ulps of the scale off either end, so strictly inside (the bracket is wider
            // than four): a root within rounding of one end, where regula falsi lands once
            // that end's value is tiny, is bracketed by the next trial, not approached by
            // halvings from the other end.
            c = c.max(a + margin).min(b - margin);
            let gc = g_at(self, c)?;
            if gc == T::zero() {
                return Ok(c);
            }
            newton = slope.map(|s| (c, gc, s));
            if (gc < T::zero()) == (gb < T::zero()) {
                b = c;
                gb = gc;
                if moved_b == Some(true) {
                    ga *= T::HALF;
                }
                moved_b = Some(true);
            } else {
                a = c;
                ga = gc;
                if moved_b == Some(false) {
                    gb *= T::HALF;
                }
                moved_b = Some(false);
            }
        }
        Ok(b)
    }
}
