//! [`BenchReal`]: the two precisions the bench runs in, with what every runner needs of them.

use super::hand_rhs::HandRhs;
use super::hand_rk4;
use super::ode_peer::{self, OdeReal, Peer};
use super::outcome::{Observer, Outcome};
use lagrange_core::{Real, State};

/// `f32` or `f64`: a library scalar that `ode_solvers` also accepts, with the hand-written RK4
/// loops of its precision.
pub trait BenchReal: OdeReal {
    /// `"f32"` or `"f64"`.
    const LABEL: &'static str;

    /// `x` rounded to this precision (`from_f64` is ambiguous between the library's `Scalar`
    /// and `num_traits`' `FromPrimitive`, which `ode_solvers` needs).
    fn real(x: f64) -> Self {
        <Self as lagrange_core::Scalar>::from_f64(x)
    }

    /// Solves the hand-written equations `rhs` with `ode_solvers` in this precision (its
    /// solvers need `f64: From<Self>`, which only the concrete types can promise).
    fn ode_solve<R, const N: usize, const N2: usize>(
        peer: Peer,
        rhs: &R,
        start: &State<Self, N>,
        t_end: Self,
        tol: Self,
        observe: Observer<'_, Self, N>,
    ) -> Result<Outcome<Self, N>, String>
    where
        R: HandRhs<Self, N>;

    /// The hand-written RK4 loop for the pendulum `th'' = -(g/l) sin th`, in this precision:
    /// `steps` steps of `dt` from `(th, th')`.
    fn hand_rk4_pendulum(g_over_l: f64, y: [Self; 2], dt: Self, steps: u64) -> [Self; 2];

    /// The hand-written RK4 loop for the double pendulum with unit masses and lengths:
    /// `steps` steps of `dt` from `(th1, th2, th1', th2')`.
    fn hand_rk4_double(g: f64, y: [Self; 4], dt: Self, steps: u64) -> [Self; 4];
}

impl BenchReal for f64 {
    const LABEL: &'static str = "f64";
    fn ode_solve<R: HandRhs<f64, N>, const N: usize, const N2: usize>(
        peer: Peer,
        rhs: &R,
        start: &State<f64, N>,
        t_end: f64,
        tol: f64,
        observe: Observer<'_, f64, N>,
    ) -> Result<Outcome<f64, N>, String> {
        ode_peer::solve::<f64, R, N, N2>(peer, rhs, start, t_end, tol, observe)
    }
    fn hand_rk4_pendulum(g_over_l: f64, y: [f64; 2], dt: f64, steps: u64) -> [f64; 2] {
        hand_rk4::pendulum_f64(g_over_l, y, dt, steps)
    }
    fn hand_rk4_double(g: f64, y: [f64; 4], dt: f64, steps: u64) -> [f64; 4] {
        hand_rk4::double_f64(g, y, dt, steps)
    }
}

impl BenchReal for f32 {
    const LABEL: &'static str = "f32";
    fn ode_solve<R: HandRhs<f32, N>, const N: usize, const N2: usize>(
        peer: Peer,
        rhs: &R,
        start: &State<f32, N>,
        t_end: f32,
        tol: f32,
        observe: Observer<'_, f32, N>,
    ) -> Result<Outcome<f32, N>, String> {
        ode_peer::solve::<f32, R, N, N2>(peer, rhs, start, t_end, tol, observe)
    }
    #[allow(clippy::cast_possible_truncation)]
    fn hand_rk4_pendulum(g_over_l: f64, y: [f32; 2], dt: f32, steps: u64) -> [f32; 2] {
        hand_rk4::pendulum_f32(g_over_l as f32, y, dt, steps)
    }
    #[allow(clippy::cast_possible_truncation)]
    fn hand_rk4_double(g: f64, y: [f32; 4], dt: f32, steps: u64) -> [f32; 4] {
        hand_rk4::double_f32(g as f32, y, dt, steps)
    }
}

/// A state widened to `f64` (for errors and energies, always computed in `f64`).
pub fn widen<T: Real, const N: usize>(s: &State<T, N>) -> State<f64, N> {
    State {
        t: s.t.to_f64(),
        q: s.q.map(Real::to_f64),
        qd: s.qd.map(Real::to_f64),
    }
}

/// A state narrowed (rounded) to `T`.
pub fn narrow<T: Real, const N: usize>(s: &State<f64, N>) -> State<T, N> {
    State {
        t: T::from_f64(s.t),
        q: s.q.map(T::from_f64),
        qd: s.qd.map(T::from_f64),
    }
}

/// True when `a` and `b` hold the same bits in every coordinate and rate, the components that
/// errors and energies are measured on. The time is left out: a run observed step by step may
/// sum it in another order than one whole solve (the hand-written loops do).
pub fn same_bits<T: Real, const N: usize>(a: &State<T, N>, b: &State<T, N>) -> bool {
    let bits = |s: &State<T, N>| {
        let w = widen(s);
        w.q.iter()
            .chain(w.qd.iter())
            .map(|x| x.to_bits())
            .collect::<Vec<u64>>()
    };
    bits(a) == bits(b)
}
