//! Automatic Euler-Lagrange: write `T` and `V` once, generic over a [`Scalar`], and get the
//! equations of motion by differentiating them with nested [`Dual`] numbers.

use crate::mechanism::finite;
use crate::{
    central_difference_jacobian, solve_spd, Cholesky, Dual, Error, GeneralizedForce, Jacobian,
    Mechanism, Real, Scalar, State,
};
use nalgebra::{SMatrix, SVector};

/// A mechanism given by its Lagrangian `L = T - V`, written generic over the scalar so that it
/// can be both evaluated (`S = f64`) and differentiated (`S` a [`Dual`] number), and its
/// non-conservative forces `Q`.
///
/// This is where a mechanism's physics is written, once: its energies are these functions at
/// real scalars ([`Lagrangian::energy`]), [`EulerLagrange`] derives its equations of motion
/// from them, and every hand-derived [`Mechanism`] is one of these too (and is checked against
/// the automatic path). A scalar mixes with plain numbers on its right, so `T` and `V` read
/// like the formulas: `qd[0] * qd[0] * (0.5 * self.m)`. Do all math through [`Scalar`]'s
/// methods (`q[0].cos()`), so that `f32` and `f64` give the same bits on every target.
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
    /// a fixed frame), so that `d2L/dq'dt` is needed: one more dual evaluation per call.
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

/// First derivatives along `N` directions, over the scalar `S`.
type D1<S, const N: usize> = Dual<S, N>;
/// Second derivatives: an outer direction over an inner one.
type D2<S, const N: usize> = Dual<Dual<S, N>, N>;
/// One directional derivative: what the exact Jacobian seeds, one coordinate at a time.
type Directional<T> = Dual<T, 1>;

/// The [`Mechanism`] a [`Lagrangian`] defines, with
///
/// ```text
/// M   = d2T/dq'dq'
/// f   = dT/dq - dV/dq - (d2T/dq'dq) q' - d2T/dq'dt
/// ```
///
/// each entry exact to rounding, from forward-mode dual numbers: one nested evaluation of `T`
/// for `M`, one nested evaluation of `T` and one plain dual evaluation of `V` for `f` (and one
/// more of `T` when [`Lagrangian::EXPLICIT_TIME`]). No symbolic step, no heap. This is both the
/// general path for a user's own mechanism and the oracle the hand-derived systems are tested
/// against.
///
/// Its [`Mechanism::law_jacobian`] is exact too: differentiating `M q'' = f + Q + extra` gives
/// `M dq''/dx = d(f + Q + extra)/dx - (dM/dx) q''`, with `dM/dx` and `df/dx` from `M` and `f`
/// computed once more per coordinate and per velocity over a one-direction dual number (third
/// derivatives of `T`, `2 N` evaluations of `M` and `f` at about twice their plain cost, which
/// keeps the stack use of a long chain at that of `M` itself), then `2 N` mass solves. Only the
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

/// `x` as a second-order dual constant.
fn d2_constant<S: Scalar, const N: usize>(x: S) -> D2<S, N> {
    D2::constant(D1::constant(x))
}

/// `M = d2T/dq'dq'` evaluated over any scalar `S` (plain for the mass matrix, a dual number
/// for its derivatives).
fn mass_matrix_in<T, S, L, const N: usize>(
    l: &L,
    t: S,
    q: &SVector<S, N>,
    qd: &SVector<S, N>,
) -> SMatrix<S, N, N>
where
    T: Real,
    S: Scalar<Real = T>,
    L: Lagrangian<T, N>,
{
    // Velocities seeded in both the outer and the inner direction:
    // r.eps[k].eps[i] = d2T/dq'_k dq'_i.
    let q = q.map(d2_constant);
    let qd = SVector::<D2<S, N>, N>::from_fn(|k, _| D2::variable(D1::variable(qd[k], k), k));
    let r = l.kinetic(d2_constant(t), &q, &qd);
    SMatrix::from_fn(|i, k| r.eps[k].eps[i])
}

/// `f = dT/dq - dV/dq - (d2T/dq'dq) q' - d2T/dq'dt` over any scalar `S`.
fn rhs_in<T, S, L, const N: usize>(
    l: &L,
    t: S,
    q: &SVector<S, N>,
    qd: &SVector<S, N>,
) -> SVector<S, N>
where
    T: Real,
    S: Scalar<Real = T>,
    L: Lagrangian<T, N>,
{
    let v = l.potential(
        D1::constant(t),
        &SVector::<D1<S, N>, N>::from_fn(|k, _| D1::variable(q[k], k)),
    );
    let inner_qd = SVector::<D2<S, N>, N>::from_fn(|i, _| D2::constant(D1::variable(qd[i], i)));
    let mut f = if L::CONSTANT_MASS {
        // dT/dq = 0 and d2T/dq'dq = 0: nothing of T to differentiate.
        SVector::<S, N>::from_fn(|i, _| -v.eps[i])
    } else {
        // Outer direction k on q_k, inner direction i on q'_i: r.eps[k].re = dT/dq_k and
        // r.eps[k].eps[i] = d2T/dq_k dq'_i.
        let outer_q = SVector::<D2<S, N>, N>::from_fn(|k, _| D2::variable(D1::constant(q[k]), k));
        let r = l.kinetic(d2_constant(t), &outer_q, &inner_qd);
        SVector::<S, N>::from_fn(|i, _| {
            let mut fi = r.eps[i].re - v.eps[i];
            for k in 0..N {
                fi -= r.eps[k].eps[i] * qd[k];
            }
            fi
        })
    };

    if L::EXPLICIT_TIME {
        // Outer direction 0 on t: r.eps[0].eps[i] = d2T/dt dq'_i.
        let rt = l.kinetic(
            D2::variable(D1::constant(t), 0),
            &q.map(d2_constant),
            &inner_qd,
        );
        if let Some(dt) = rt.eps.first() {
            f -= SVector::<S, N>::from(dt.eps);
        }
    }
    f
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
            let m = mass_matrix_in(l, t, &q, &qd);
            let f = rhs_in(l, t, &q, &qd);
            let column = m.map(|x| x.eps[0]) * a - f.map(|x| x.eps[0]);
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
        rhs_in(&self.lagrangian, s.t, &s.q, &s.qd)
    }

    /// With the factor made once where the mass matrix is constant.
    fn solve_mass(&self, s: &State<T, N>, b: &SVector<T, N>) -> Result<SVector<T, N>, Error> {
        match &self.mass {
            Some(factor) => factor.as_ref().map(|c| c.solve(b)).map_err(|e| *e),
            None => solve_spd(&self.mass_matrix(s), b),
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
