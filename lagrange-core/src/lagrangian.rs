//! Automatic Euler-Lagrange: write `T` and `V` once, generic over a [`Scalar`], and get the
//! equations of motion by differentiating them: below 11 coordinates `T` and `V` by forward
//! mode over the same second-order jets (which share their sines and cosines); from 11 on `T`
//! and `V` by reverse mode over one tape (on which `V`'s sines and cosines are `T`'s nodes).

use crate::jet::Jet;
use crate::mechanism::finite;
use crate::tape;
use crate::trig_memo::TrigMemo;
use crate::{
    central_difference_jacobian, solve_spd, Cholesky, Dual, Error, GeneralizedForce, Jacobian,
    Mechanism, Real, Scalar, State,
};
use core::any::TypeId;
use nalgebra::{ArrayStorage, SMatrix, SVector};

/// A mechanism given by its Lagrangian `L = T - V`, written generic over the scalar so that it
/// can be both evaluated (`S = f64`) and differentiated (`S` a [`Dual`] number), and its
/// non-conservative forces `Q`.
///
/// This is where a mechanism's physics is written, once: its energies are these functions at
/// real scalars ([`Lagrangian::energy`]), [`EulerLagrange`] derives its equations of motion
/// from them, and every hand-derived [`Mechanism`] is one of these too (and is checked against
/// the automatic path). A scalar mixes with plain numbers on its right, so `T` and `V` read
/// like the formulas: `qd[0] * qd[0] * (0.5 * self.m)`. Do all math through [`Scalar`]'s
/// methods (`q[0].cos()`), so that `f32` and `f64` give the same bits on every target, and
/// index the vectors rather than calling nalgebra's arithmetic on them (`qd.dot(qd)` asks for
/// a `'static` scalar, which the automatic path's need not be; see [`Scalar`]).
///
/// ```
/// use lagrange_core::prelude::*;
///
/// /// A pendulum of length `l` in gravity `g`, unit mass.
/// struct Pendulum { l: f64, g: f64 }
///
/// impl Lagrangian<f64, 1> for Pendulum {
///     fn kinetic<S: Scalar<Real = f64>>(&self, _t: S, _q: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
///         qd[0] * qd[0] * (0.5 * self.l * self.l)
///     }
///     fn potential<S: Scalar<Real = f64>>(&self, _t: S, q: &SVector<S, 1>) -> S {
///         -q[0].cos() * (self.g * self.l)
///     }
/// }
///
/// let m = EulerLagrange::new(Pendulum { l: 1.0, g: 9.81 });
/// let s = State::new(0.0, [0.5], [0.0]);
/// let a = m.acceleration(&s)?;
/// assert!((a[0] + 9.81 * 0.5f64.sin()).abs() < 1e-14);
/// assert!((m.energy(&s) + 9.81 * 0.5f64.cos()).abs() < 1e-15);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
pub trait Lagrangian<T: Real, const N: usize> {
    /// True when the kinetic energy depends on `t` explicitly (a driven mechanism written in
    /// a fixed frame), so that `d2L/dq'dt` is needed: [`EulerLagrange`] then moves time along
    /// with the coordinates in its one evaluation of `T` (no extra evaluation; with
    /// [`Lagrangian::CONSTANT_MASS`], one evaluation of `T` that it would otherwise skip).
    const EXPLICIT_TIME: bool = false;

    /// True when the mass matrix `d2T/dq'2` is the same at every state (masses and inertias
    /// times squared velocities of fixed coordinates: springs, particles, carts). The automatic
    /// path ([`EulerLagrange`]) then factors it once, when it is made, and its right-hand side
    /// skips differentiating `T` (which is then `-dV/dq`). A `T` that does depend on `q` or
    /// `t` must not claim it: its equations would be wrong.
    const CONSTANT_MASS: bool = false;

    /// True when the mechanism is driven from outside: time enters its equations, or its
    /// energy `T + V` is not conserved because something keeps moving it (a spinning hoop).
    /// A scene never puts a driven mechanism to sleep by default.
    const DRIVEN: bool = Self::EXPLICIT_TIME;

    /// Whether `T` or `V` reads the time `t`: `true` unless the type says otherwise (the safe
    /// answer). Answer `false` only when [`Lagrangian::kinetic`] and
    /// [`Lagrangian::potential`] give the same at every `t` (then
    /// [`Lagrangian::EXPLICIT_TIME`] is `false` too); the library then knows that `dL/dt` at
    /// fixed `q` and `q'` is zero without evaluating it (an impulse stepper's energy guard
    /// evaluates `L` in dual numbers of `t` otherwise, twice in a step it acts in). A force
    /// that changes with time ([`Lagrangian::non_conservative_force`]) does not make `L` read
    /// it.
    const READS_TIME: bool = true;

    /// Every term of `L` that depends on the velocities: the kinetic energy `T(t, q, q')`.
    fn kinetic<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>, qd: &SVector<S, N>) -> S;

    /// The potential energy `V(t, q)`.
    fn potential<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>) -> S;

    /// Non-conservative generalized forces `Q` (damping, inputs); zero by default.
    fn non_conservative_force(&self, state: &State<T, N>) -> SVector<T, N> {
        let _ = state;
        SVector::zeros()
    }

    /// Kinetic energy `T` at `state` (computed only when asked, never inside a step).
    ///
    /// No error channel: for a state that is not finite, or a state and parameters so extreme
    /// that a term overflows, the result is NaN or an infinity (never a panic); check it with
    /// `is_finite` where it matters.
    fn kinetic_energy(&self, state: &State<T, N>) -> T {
        self.kinetic(state.t, &state.q, &state.qd)
    }

    /// Potential energy `V` at `state` (no error channel: NaN or an infinity for a state that
    /// is not finite or so extreme that a term overflows, never a panic).
    fn potential_energy(&self, state: &State<T, N>) -> T {
        self.potential(state.t, &state.q)
    }

    /// Total energy `T + V` at `state` (no error channel: NaN or an infinity for a state that
    /// is not finite or so extreme that a term overflows, never a panic).
    fn energy(&self, state: &State<T, N>) -> T {
        self.kinetic_energy(state) + self.potential_energy(state)
    }
}

/// One directional derivative: what the exact Jacobian seeds, one coordinate at a time.
type Directional<T> = Dual<T, 1>;

/// The [`Mechanism`] a [`Lagrangian`] defines, with
///
/// ```text
/// M   = d2T/dq'dq'
/// f   = dT/dq - dV/dq - (d2T/dq'dq) q' - d2T/dq'dt
/// ```
///
/// each entry exact to rounding, from automatic derivatives: one evaluation of `T` over a
/// second-order jet and one of `V` over the same jets (from 11 coordinates on, both on one
/// tape: below) give both. The jet carries `T`'s
/// gradients in `q` and `q'`, the upper half of its Hessian in `q'` (that is `M`), and the
/// derivative of its velocity gradient along `(dq, dt) = (q', 1)` (the mixed and time terms
/// at once, `O(N)` per operation instead of a second Hessian); parts that are exactly zero (a
/// parameter, a function of `q` alone, a value linear in `q'`) are skipped. `M q'' = f + Q`
/// is then solved by Cholesky ([`solve_spd`]). No symbolic step, no heap. This is both the general path for a
/// user's own mechanism and the oracle the hand-derived systems are tested against.
///
/// Cost: for a kinetic energy of `K` operations, up to `K N^2 / 2` for `M` (less where parts
/// are zero) and `K N` for `f`, plus `N^3 / 6` for the solve; a jet holds
/// `N^2 + 3 N + 2` numbers, which for a long chain (kilobytes at `N = 20`) makes copying them
/// a large part of the cost.
///
/// So from 11 coordinates on, `T` and then `V` are instead recorded on a tape on the stack
/// (each operation a node with its parents and partial derivatives; a sine or cosine of an
/// angle already taken is the node made for it) and swept: one reverse pass of `T - V` gives
/// `dT/dq - dV/dq`, one forward pass each node's gradient in `q'` (only over the coordinates
/// it depends on) and its rate along `(q', 1)`, and each node that is not linear in its
/// parents adds a rank-one or rank-two term to `M` and its share of the mixed term. The cost
/// is then about 20 ns a node plus the rank updates, whatever `N`: measured on a 20-link
/// chain, about 20 times the hand-derived law where the jet takes 170 times. A tape holds up
/// to 1,024 nodes (about 140 kB of stack at `N = 20`); a `T` that needs more is
/// differentiated by the jet, as below 11.
///
/// Its [`Mechanism::law_jacobian`] is exact too: differentiating `M q'' = f + Q + extra` gives
/// `M dq''/dx = d(f + Q + extra)/dx - (dM/dx) q''`, with `dM/dx` and `df/dx` from `M` and `f`
/// computed once more per coordinate and per velocity over a one-direction dual number (third
/// derivatives of `T`, `2 N` evaluations of the jet over `Dual<T, 1>` at about twice their
/// plain cost, which keeps the stack use of a long chain at about twice that of one
/// acceleration), then `2 N` mass solves. Only the
/// Lagrangian's [`Lagrangian::non_conservative_force`] is differentiated by central
/// differences, and an extra force by its own [`GeneralizedForce::jacobian`].
///
/// Where [`Lagrangian::CONSTANT_MASS`] holds, `M` is evaluated and factored once, when the
/// mechanism is made, and `f` is `-dV/dq` (plus the time term): the kinetic energy is then
/// never differentiated in a step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EulerLagrange<T: Real, const N: usize, L> {
    lagrangian: L,
    /// The factored constant mass matrix (or why it could not be factored), when
    /// [`Lagrangian::CONSTANT_MASS`] holds.
    mass: Option<Result<Cholesky<T, N>, Error>>,
}

impl<T: Real, const N: usize, L: Lagrangian<T, N>> EulerLagrange<T, N, L> {
    /// The mechanism of `lagrangian`.
    pub fn new(lagrangian: L) -> Self {
        let mass = L::CONSTANT_MASS.then(|| {
            let zero = SVector::zeros();
            Cholesky::factor(&mass_matrix_in(&lagrangian, T::zero(), &zero, &zero))
        });
        Self { lagrangian, mass }
    }
    /// The Lagrangian.
    #[must_use]
    pub fn lagrangian(&self) -> &L {
        &self.lagrangian
    }
}

#[cfg(feature = "defmt")]
impl<T: Real, const N: usize, L: defmt::Format> defmt::Format for EulerLagrange<T, N, L> {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "EulerLagrange({})", self.lagrangian);
    }
}

/// `M = d2T/dq'dq'` and `T`'s part of `f`, `dT/dq - (d2T/dq'dq) q' - d2T/dq'dt`, from `T` at
/// `(t, q, q')`, with `POTENTIAL` less `dV/dq` too (`V` over the same jets or on the same
/// tape as `T`): over a [`Jet`] below [`tape::FROM`] coordinates, over a tape from there on
/// (or where `T` does not fit the largest tape).
///
/// The one place that evaluates `T` for its derivatives, for every use (the law, `M` alone,
/// `f` alone, the time term). `M` is written to `m` and `f` returned: a matrix of a
/// tape-sized mechanism returned through the callers was copied at each (a 20-link chain's is
/// 3.2 kB).
fn kinetic_terms<T, S, L, const N: usize, const POTENTIAL: bool>(
    l: &L,
    t: S,
    (q, qd): (&SVector<S, N>, &SVector<S, N>),
    m: &mut SMatrix<S, N, N>,
) -> SVector<S, N>
where
    T: Real,
    S: Scalar<Real = T> + 'static,
    L: Lagrangian<T, N>,
{
    if N >= tape::FROM {
        if let Some(f) = tape::terms::kinetic::<T, S, L, N, POTENTIAL>(l, t, (q, qd), m) {
            return f;
        }
    }
    let (jm, f) = kinetic_jet::<T, S, L, N, POTENTIAL>(l, t, q, qd);
    *m = jm;
    f
}

/// [`kinetic_terms`] over a [`Jet`] (velocities seeded, coordinates seeded and moving at
/// `q'`, and time at unit rate where [`Lagrangian::EXPLICIT_TIME`], so that the jet's
/// directional parts give the mixed and time terms); with `POTENTIAL`, `f` less `dV/dq` too,
/// from `V` over the same jets.
///
/// For plain numbers the jets share one [`TrigMemo`], so that `V`'s sines and cosines of the
/// angles `T` has already taken (and repeats within either) are look-ups: the double
/// pendulum, the cart-pole, the acrobot and the chains take the same angles in both, and each
/// costs a sine and a cosine over a derivative type. (Over the law Jacobian's dual numbers
/// there is no memo: its key would be the whole dual number.)
///
/// Kept out of line, so that each scalar's `T` over a jet has this one caller: the compiler
/// may then inline it here, where every seed's flags are known, and fold the jet's tests of
/// them away. (Whether it does depends on the size of `T`; the automatic-cost bench measured
/// no difference from two callers on this machine.)
#[inline(never)]
pub(crate) fn kinetic_jet<T, S, L, const N: usize, const POTENTIAL: bool>(
    l: &L,
    t: S,
    q: &SVector<S, N>,
    qd: &SVector<S, N>,
) -> (SMatrix<S, N, N>, SVector<S, N>)
where
    T: Real,
    S: Scalar<Real = T> + 'static,
    L: Lagrangian<T, N>,
{
    let memo = TrigMemo::new();
    let memo = (TypeId::of::<S>() == TypeId::of::<T>()).then_some(&memo);
    let t = if L::EXPLICIT_TIME {
        Jet::time(t)
    } else {
        Jet::constant(t)
    }
    .remembering(memo);
    // From array storage: nalgebra's own constructors ask for a `'static` scalar.
    let jq = SVector::from_array_storage(ArrayStorage([core::array::from_fn(|k| {
        Jet::coordinate(q[k], k, qd[k]).remembering(memo)
    })]));
    let jqd = SVector::from_array_storage(ArrayStorage([core::array::from_fn(|k| {
        Jet::velocity(qd[k], k).remembering(memo)
    })]));
    let r = l.kinetic(t, &jq, &jqd);
    let mut f = SVector::from_fn(|i, _| r.gq[i] - r.dp[i]);
    if POTENTIAL {
        let v = l.potential(t, &jq);
        f -= SVector::from(v.gq);
    }
    (SMatrix::from_fn(|i, k| r.hessian(i, k)), f)
}

/// `dV/dq` over any scalar `S`, from one evaluation of `V` over `Dual<S, N>`: with
/// [`Lagrangian::CONSTANT_MASS`], where `T` is not differentiated (elsewhere `V` goes with `T`,
/// over its jets or on its tape), since `V` is a function of `q` alone and a dual number is
/// only `N + 1` numbers. (A tape of its own measured slower for `V`: its 20 ns or so a node
/// each way against a few ns an operation of the dual, on the N-body of the bench, 14 and 28
/// coordinates, 2.7 and 2.2 times. On `T`'s tape it is cheaper: its angles are `T`'s nodes.)
fn potential_gradient<T, S, L, const N: usize>(l: &L, t: S, q: &SVector<S, N>) -> SVector<S, N>
where
    T: Real,
    S: Scalar<Real = T> + 'static,
    L: Lagrangian<T, N>,
{
    // Seeded in place: built one by one (`from_fn`), each seed was copied by a call to
    // `memcpy`, 6% of a 20-link chain's acceleration.
    let mut seeds = [Dual::<S, N>::constant(S::zero()); N];
    for (k, (seed, &x)) in seeds.iter_mut().zip(q.iter()).enumerate() {
        seed.seed(x, k);
    }
    let v = l.potential(
        Dual::constant(t),
        &SVector::from_array_storage(ArrayStorage([seeds])),
    );
    SVector::from(v.eps)
}

/// `M = d2T/dq'dq'` over any scalar `S` (plain for the mass matrix, a dual number for its
/// derivatives), from one evaluation of `T` ([`kinetic_terms`]).
fn mass_matrix_in<T, S, L, const N: usize>(
    l: &L,
    t: S,
    q: &SVector<S, N>,
    qd: &SVector<S, N>,
) -> SMatrix<S, N, N>
where
    T: Real,
    S: Scalar<Real = T> + 'static,
    L: Lagrangian<T, N>,
{
    let mut m = SMatrix::from_element(S::zero());
    kinetic_terms::<T, S, L, N, false>(l, t, (q, qd), &mut m);
    m
}

/// `f = dT/dq - dV/dq - (d2T/dq'dq) q' - d2T/dq'dt` over any scalar `S`, and `M` written to
/// `m`, from one evaluation of `T` and one of `V`, over the same jets or on the same tape
/// ([`kinetic_terms`]). Where [`Lagrangian::CONSTANT_MASS`] holds, `f` skips `T` but for the
/// time term (`V` by [`potential_gradient`]), and `m` is left as it is (use the factor made
/// once).
#[inline(always)]
fn terms_in<T, S, L, const N: usize>(
    l: &L,
    t: S,
    (q, qd): (&SVector<S, N>, &SVector<S, N>),
    m: &mut SMatrix<S, N, N>,
) -> SVector<S, N>
where
    T: Real,
    S: Scalar<Real = T> + 'static,
    L: Lagrangian<T, N>,
{
    if L::CONSTANT_MASS {
        // dT/dq = 0 and d2T/dq'dq = 0: nothing of T to differentiate but the time term.
        let mut f = -potential_gradient(l, t, q);
        if L::EXPLICIT_TIME {
            // T's part is then -d2T/dq'dt alone (dT/dq = 0 and d2T/dq'dq = 0).
            f += kinetic_terms::<T, S, L, N, false>(l, t, (q, qd), m);
        }
        return f;
    }
    kinetic_terms::<T, S, L, N, true>(l, t, (q, qd), m)
}

/// `v` as one-direction duals, seeded along component `k` when `seed` is true.
fn seeded<T: Real, const N: usize>(
    v: &SVector<T, N>,
    k: usize,
    seed: bool,
) -> SVector<Directional<T>, N> {
    SVector::from_fn(|i, _| {
        if seed && i == k {
            Directional::variable(v[i], 0)
        } else {
            Directional::constant(v[i])
        }
    })
}

impl<T: Real, const N: usize, L: Lagrangian<T, N>> Lagrangian<T, N> for EulerLagrange<T, N, L> {
    const EXPLICIT_TIME: bool = L::EXPLICIT_TIME;
    const CONSTANT_MASS: bool = L::CONSTANT_MASS;
    const DRIVEN: bool = L::DRIVEN;
    const READS_TIME: bool = L::READS_TIME;
    fn kinetic<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>, qd: &SVector<S, N>) -> S {
        self.lagrangian.kinetic(t, q, qd)
    }
    fn potential<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>) -> S {
        self.lagrangian.potential(t, q)
    }
    fn non_conservative_force(&self, state: &State<T, N>) -> SVector<T, N> {
        self.lagrangian.non_conservative_force(state)
    }
}

/// `(d r/dq, d r/dq')` of the residual `r = M a - f` of `l` at `s` with `a` held fixed: exact,
/// from `M` and `f` over one-direction dual numbers.
fn residual_jacobian<T: Real, const N: usize, L: Lagrangian<T, N>>(
    l: &L,
    s: &State<T, N>,
    a: &SVector<T, N>,
) -> Jacobian<T, N> {
    let t = Directional::constant(s.t);
    let mut j = Jacobian::<T, N>::zeros();
    for k in 0..N {
        for velocity in [false, true] {
            let q = seeded(&s.q, k, !velocity);
            let qd = seeded(&s.qd, k, velocity);
            // With a constant mass matrix, dM/dx = 0.
            let mut m = SMatrix::from_element(Directional::constant(T::zero()));
            let f = terms_in(l, t, (&q, &qd), &mut m);
            let mut column = -f.map(|x| x.eps[0]);
            if !L::CONSTANT_MASS {
                column += m.map(|x| x.eps[0]) * a;
            }
            if velocity {
                j.wrt_qd.set_column(k, &column);
            } else {
                j.wrt_q.set_column(k, &column);
            }
        }
    }
    j
}

impl<T: Real, const N: usize, L: Lagrangian<T, N>> Mechanism<T, N> for EulerLagrange<T, N, L> {
    fn mass_matrix(&self, s: &State<T, N>) -> SMatrix<T, N, N> {
        mass_matrix_in(&self.lagrangian, s.t, &s.q, &s.qd)
    }

    fn rhs(&self, s: &State<T, N>) -> SVector<T, N> {
        terms_in(&self.lagrangian, s.t, (&s.q, &s.qd), &mut SMatrix::zeros())
    }

    /// With the factor made once where the mass matrix is constant.
    fn solve_mass(&self, s: &State<T, N>, b: &SVector<T, N>) -> Result<SVector<T, N>, Error> {
        match &self.mass {
            Some(factor) => factor.as_ref().map(|c| c.solve(b)).map_err(|e| *e),
            None => solve_spd(&self.mass_matrix(s), b),
        }
    }

    /// `M` and `f` from one evaluation of `T` (or the factor made once).
    fn law<F: GeneralizedForce<T, N>>(
        &self,
        s: &State<T, N>,
        extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        let mut m = SMatrix::zeros();
        let f = terms_in(&self.lagrangian, s.t, (&s.q, &s.qd), &mut m);
        let b = extra.added_to(s, f + self.lagrangian.non_conservative_force(s));
        match &self.mass {
            Some(factor) => factor.as_ref().map(|c| c.solve(&b)).map_err(|e| *e),
            None => solve_spd(&m, &b),
        }
    }

    /// Exact: `M dq''/dx = d(f + Q + extra)/dx - (dM/dx) q''` (see the type's docs).
    fn law_jacobian<F: GeneralizedForce<T, N>>(
        &self,
        s: &State<T, N>,
        extra: &F,
    ) -> Result<(SVector<T, N>, Jacobian<T, N>), Error> {
        let qdd = finite(self.law(s, extra)?)?;
        let mut forces =
            central_difference_jacobian(s, |x| self.lagrangian.non_conservative_force(x));
        if !F::IS_ZERO {
            forces = forces + extra.jacobian(s);
        }
        let r = residual_jacobian(&self.lagrangian, s, &qdd) - forces;
        let mut j = Jacobian::<T, N>::zeros();
        for k in 0..N {
            // Each column solved is finite (solve_mass refuses anything else).
            let dq = self.solve_mass(s, &-r.wrt_q.column(k).into_owned())?;
            let dqd = self.solve_mass(s, &-r.wrt_qd.column(k).into_owned())?;
            j.wrt_q.set_column(k, &dq);
            j.wrt_qd.set_column(k, &dqd);
        }
        Ok((qdd, j))
    }

    /// `Q + extra` exactly: the law is unconstrained.
    fn law_force<F: GeneralizedForce<T, N>>(
        &self,
        s: &State<T, N>,
        extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        crate::free_law_force(&self.lagrangian, s, extra)
    }
}

/// Checks used by the tests of this module and by the doc example.
#[cfg(test)]
mod tests {
    use super::*;
    use crate::Error;

    /// A bead on a hoop spinning about the vertical, written in the fixed frame with an
    /// explicit time dependence that the time term must cancel exactly.
    struct TimeShifted;
    impl Lagrangian<f64, 1> for TimeShifted {
        const EXPLICIT_TIME: bool = true;
        fn kinetic<S: Scalar<Real = f64>>(
            &self,
            t: S,
            _q: &SVector<S, 1>,
            qd: &SVector<S, 1>,
        ) -> S {
            // T = (q' + t)^2 / 2: d/dt dT/dq' = q'' + 1, dT/dq = 0, so q'' = -1 - dV/dq.
            let v = qd[0] + t;
            S::from_f64(0.5) * v * v
        }
        fn potential<S: Scalar<Real = f64>>(&self, _t: S, q: &SVector<S, 1>) -> S {
            S::from_f64(0.5) * q[0] * q[0]
        }
    }

    #[test]
    fn explicit_time_term_enters() -> Result<(), Error> {
        let m = EulerLagrange::new(TimeShifted);
        let a = m.acceleration(&State::new(3.0, [2.0], [0.5]))?;
        assert!((a[0] - (-1.0 - 2.0)).abs() < 1e-15, "{a}");
        Ok(())
    }

    /// The bead of [`TimeShifted`] claiming a constant mass matrix (it is 1): the time term
    /// still enters, and `dV/dq` with its sign, on the path that skips `T` but for that term.
    struct TimeShiftedConstantMass;
    impl Lagrangian<f64, 1> for TimeShiftedConstantMass {
        const EXPLICIT_TIME: bool = true;
        const CONSTANT_MASS: bool = true;
        fn kinetic<S: Scalar<Real = f64>>(&self, t: S, q: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
            TimeShifted.kinetic(t, q, qd)
        }
        fn potential<S: Scalar<Real = f64>>(&self, t: S, q: &SVector<S, 1>) -> S {
            TimeShifted.potential(t, q)
        }
    }

    #[test]
    fn explicit_time_term_enters_with_a_constant_mass() -> Result<(), Error> {
        let m = EulerLagrange::new(TimeShiftedConstantMass);
        let a = m.acceleration(&State::new(3.0, [2.0], [0.5]))?;
        // q'' = -1 - q, exactly in f64 at q = 2.
        assert_eq!(a[0], -3.0);
        Ok(())
    }

    /// Two coupled coordinates with a mass matrix that depends on `q`, a non-conservative
    /// force of their own, and energies through the trait's defaults.
    struct Coupled;
    impl Lagrangian<f64, 2> for Coupled {
        fn kinetic<S: Scalar<Real = f64>>(
            &self,
            _t: S,
            q: &SVector<S, 2>,
            qd: &SVector<S, 2>,
        ) -> S {
            // M = [[2 + cos q1, 0.5], [0.5, 1]].
            let m00 = q[1].cos() + 2.0;
            (m00 * qd[0] * qd[0] + qd[1] * qd[1]) * 0.5 + qd[0] * qd[1] * 0.5
        }
        fn potential<S: Scalar<Real = f64>>(&self, _t: S, q: &SVector<S, 2>) -> S {
            q[0] * q[0] + q[0] * q[1] * 0.5 + q[1] * q[1] * 1.5
        }
        fn non_conservative_force(&self, s: &State<f64, 2>) -> SVector<f64, 2> {
            SVector::<f64, 2>::new(-0.4 * s.qd[0] * s.q[1], -0.2 * s.qd[1].powi(3))
        }
    }

    /// The defaults: `T`, `V` and their sum at a state, against the formulas.
    #[test]
    fn default_energies_are_the_formulas() {
        let s = State::new(0.0, [0.3, -0.8], [1.5, -2.0]);
        let t = 0.5 * ((2.0 + libm::cos(-0.8)) * 2.25 + 4.0) + 0.5 * 1.5 * -2.0;
        let v = 0.09 + 0.5 * 0.3 * -0.8 + 1.5 * 0.64;
        // The same operations in another order: a few ulps.
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-15 * (1.0 + b.abs());
        assert!(close(Coupled.kinetic_energy(&s), t));
        assert!(close(Coupled.potential_energy(&s), v));
        assert!(close(Coupled.energy(&s), t + v));
    }

    /// The exact law Jacobian with the mechanism's own force and an extra force against
    /// central differences of the law: both forces enter, each with its sign.
    #[test]
    fn law_jacobian_takes_both_forces() -> Result<(), Error> {
        let m = EulerLagrange::new(Coupled);
        let extra = |s: &State<f64, 2>| SVector::<f64, 2>::new(libm::sin(s.q[1]), s.qd[0] * s.q[0]);
        let s = State::new(0.0, [0.3, -0.8], [1.5, -2.0]);
        let (a, j) = m.law_jacobian(&s, &extra)?;
        assert_eq!(a, m.law(&s, &extra)?);
        let differences = central_difference_jacobian(&s, |x| {
            m.law(x, &extra)
                .unwrap_or_else(|_| SVector::from_element(f64::NAN))
        });
        // Central differences are good to about EPSILON^(2/3) ~ 4e-11 of the scale (entries
        // of order one here); each force's Jacobian is of order 0.5 to 4.
        for (exact, near) in [(j.wrt_q, differences.wrt_q), (j.wrt_qd, differences.wrt_qd)] {
            let worst = (exact - near).abs().max();
            assert!(worst < 1e-7, "{exact} {near}");
        }
        Ok(())
    }

    /// `Error` must not be constructed out of nothing: a zero kinetic energy is singular.
    struct Massless;
    impl Lagrangian<f64, 2> for Massless {
        fn kinetic<S: Scalar<Real = f64>>(
            &self,
            _t: S,
            _q: &SVector<S, 2>,
            qd: &SVector<S, 2>,
        ) -> S {
            qd[0] * qd[0]
        }
        fn potential<S: Scalar<Real = f64>>(&self, _t: S, q: &SVector<S, 2>) -> S {
            q[1]
        }
    }

    #[test]
    fn singular_mass_matrix_is_reported() {
        let m = EulerLagrange::new(Massless);
        assert_eq!(
            m.acceleration(&State::new(0.0, [0.0, 0.0], [1.0, 1.0])),
            Err(Error::SingularMassMatrix { pivot: 1 })
        );
    }
}
