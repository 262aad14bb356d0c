//! P6, bodies under mutual gravity in the plane: a user's own mechanism ([`NBody`]: a
//! `Mechanism` with a diagonal mass matrix and a hand-written law, and a `Lagrangian` that
//! declares its mass matrix constant). N = 14: Hairer's Pleiades (seven stars, T = 3), against
//! the published reference; N = 28: a star and thirteen planets (T = 3), against the tightest
//! run of the library's DOP853.

use super::p3_chain::tight_reference;
use crate::problem::{HandRhs, Problem, Reference};
use crate::real::BenchReal;
use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{
    free_law_force, Error, GeneralizedForce, Lagrangian, Mechanism, Real, Scalar, State,
};

/// `B` point masses under mutual gravity (`G = 1`) in the plane: `N = 2 B` coordinates, body
/// `i` at `(q[2i], q[2i + 1])`.
///
/// ```text
/// T = sum_i m_i (x_i'^2 + y_i'^2) / 2         M = diag(m_1, m_1, m_2, m_2, ...), constant
/// V = -sum_{i<j} m_i m_j / r_ij               r_ij = |(x_j - x_i, y_j - y_i)|
/// x_i'' = sum_{j != i} m_j (x_j - x_i) / r_ij^3, and the same for y
/// ```
///
/// Its law is the sum over pairs written by hand ([`gravity`]); the same function is the
/// peers' right-hand side ([`HandRhs`]). As a [`Lagrangian`] it declares
/// [`Lagrangian::CONSTANT_MASS`], so that the automatic path factors `M` once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NBody<T, const B: usize, const N: usize> {
    /// Masses.
    m: [T; B],
}

impl<T: Real, const B: usize, const N: usize> NBody<T, B, N> {
    /// The bodies of masses `m`.
    pub fn new(m: [T; B]) -> Self {
        const { assert!(N == 2 * B, "N must be 2 B") };
        Self { m }
    }
}

/// The gravitational accelerations of bodies of masses `m` at `q` (`G = 1`): one pass over
/// the pairs, `r^3` and one division per pair.
#[inline(always)]
pub fn gravity<T: Real, const B: usize, const N: usize>(m: &[T; B], q: &[T; N], a: &mut [T; N]) {
    *a = [T::zero(); N];
    for i in 0..B {
        for j in i + 1..B {
            let (dx, dy) = (q[2 * j] - q[2 * i], q[2 * j + 1] - q[2 * i + 1]);
            let r2 = dx * dx + dy * dy;
            let inv_r3 = (r2 * r2.sqrt()).recip();
            let (fx, fy) = (dx * inv_r3, dy * inv_r3);
            a[2 * i] += fx * m[j];
            a[2 * i + 1] += fy * m[j];
            a[2 * j] -= fx * m[i];
            a[2 * j + 1] -= fy * m[i];
        }
    }
}

impl<T: Real, const B: usize, const N: usize> HandRhs<T, N> for NBody<T, B, N> {
    #[inline]
    fn accelerations(&self, _t: T, q: &[T; N], _qd: &[T; N], qdd: &mut [T; N]) {
        gravity(&self.m, q, qdd);
    }
}

impl<T: Real, const B: usize, const N: usize> Lagrangian<T, N> for NBody<T, B, N> {
    const CONSTANT_MASS: bool = true;
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, _q: &SVector<S, N>, qd: &SVector<S, N>) -> S {
        let mut t = S::zero();
        for (k, v) in qd.iter().enumerate() {
            t += *v * *v * (T::HALF * self.m[k / 2]);
        }
        t
    }
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, N>) -> S {
        let mut v = S::zero();
        for i in 0..B {
            for j in i + 1..B {
                let dx = q[2 * j] - q[2 * i];
                let dy = q[2 * j + 1] - q[2 * i + 1];
                v -= (dx * dx + dy * dy).sqrt().recip() * (self.m[i] * self.m[j]);
            }
        }
        v
    }
}

impl<T: Real, const B: usize, const N: usize> Mechanism<T, N> for NBody<T, B, N> {
    fn mass_matrix(&self, _s: &State<T, N>) -> SMatrix<T, N, N> {
        SMatrix::from_fn(|i, k| if i == k { self.m[i / 2] } else { T::zero() })
    }
    fn rhs(&self, s: &State<T, N>) -> SVector<T, N> {
        let mut a = [T::zero(); N];
        gravity(&self.m, &s.q.into(), &mut a);
        SVector::from_fn(|k, _| a[k] * self.m[k / 2])
    }
    fn solve_mass(&self, _s: &State<T, N>, b: &SVector<T, N>) -> Result<SVector<T, N>, Error> {
        Ok(SVector::from_fn(|k, _| b[k] / self.m[k / 2]))
    }
    /// The sum over pairs, plus `M^-1 (Q + extra)` where a force is added.
    #[inline(always)]
    fn law<F: GeneralizedForce<T, N>>(
        &self,
        s: &State<T, N>,
        extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        // In place: the coordinates read and the accelerations written as the vectors' own
        // arrays, not copies of them.
        let mut a = SVector::zeros();
        gravity(&self.m, &s.q.data.0[0], &mut a.data.0[0]);
        if F::IS_ZERO {
            Ok(a)
        } else {
            let b = extra.added_to(s, self.non_conservative_force(s));
            Ok(a + self.solve_mass(s, &b)?)
        }
    }
    fn law_force<F: GeneralizedForce<T, N>>(
        &self,
        s: &State<T, N>,
        extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        free_law_force(self, s, extra)
    }
    /// Never: gravity reads the positions only.
    fn reads_velocities(&self) -> bool {
        false
    }
}

/// The Pleiades' masses (star `i` weighs `i`).
const PLEIADES_MASSES: [f64; 7] = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0];

/// The published state of the Pleiades at t = 3 (Hairer, Norsett and Wanner, Solving ODEs I,
/// II.10; to 16 digits in the Test Set for IVP Solvers of Mazzia and Magherini, problem PLEI):
/// x_1..7, y_1..7, x'_1..7, y'_1..7.
#[allow(clippy::excessive_precision, clippy::unreadable_literal)]
const PLEIADES_AT_3: [f64; 28] = [
    0.3706139143970502,
    3.237284092057233,
    -3.222559032418324,
    0.6597091455775310,
    0.3425581707156584,
    1.562172101400631,
    -0.7003092922212495,
    -3.943437585517392,
    -3.271380973972550,
    5.225081843456543,
    -2.590612434977470,
    1.198213693392275,
    -0.2429682344935824,
    1.091449240428980,
    3.417003806314313,
    1.354584501625501,
    -2.590065597810775,
    2.025053734714242,
    -1.155815100160448,
    -0.8072988170223021,
    0.5952396354208710,
    -3.741244961234010,
    0.3773459685750630,
    0.9386858869551073,
    0.3667922227200571,
    -0.3474046353808490,
    2.344915448180937,
    -1.947020434263292,
];

/// Interleaves per-body `x, y` arrays into `q = [x_1, y_1, x_2, y_2, ...]`.
fn interleave<const B: usize, const N: usize>(x: &[f64; B], y: &[f64; B]) -> [f64; N] {
    core::array::from_fn(|k| if k % 2 == 0 { x[k / 2] } else { y[k / 2] })
}

/// P6 with N = 14: Hairer's Pleiades problem (PLEI), seven stars of masses 1..7 from the
/// published start, T = 3 (close encounters near t = 1.2 and 1.6 make the step sizes vary
/// over three decades).
pub struct Pleiades;

impl Problem<14, 28> for Pleiades {
    type Mech<T: BenchReal> = NBody<T, 7, 14>;
    type Hand<T: BenchReal> = NBody<T, 7, 14>;

    fn id(&self) -> &'static str {
        "P6-N14"
    }
    fn title(&self) -> &'static str {
        "N-body, N = 14: Hairer's Pleiades, seven stars of masses 1..7 under mutual gravity \
         (G = 1) in the plane, T = 3"
    }
    fn mechanism_note(&self) -> &'static str {
        "NBody (the bench's own: diagonal constant M, law by hand over the pairs)"
    }
    fn mechanism<T: BenchReal>(&self) -> Result<NBody<T, 7, 14>, Error> {
        Ok(NBody::new(PLEIADES_MASSES.map(T::real)))
    }
    fn hand<T: BenchReal>(&self) -> NBody<T, 7, 14> {
        NBody::new(PLEIADES_MASSES.map(T::real))
    }
    fn start(&self) -> State<f64, 14> {
        let x = [3.0, 3.0, -1.0, -3.0, 2.0, -2.0, 2.0];
        let y = [3.0, -3.0, 2.0, 0.0, 0.0, -4.0, 4.0];
        let vx = [0.0, 0.0, 0.0, 0.0, 0.0, 1.75, -1.5];
        let vy = [0.0, 0.0, 0.0, -1.25, 1.0, 0.0, 0.0];
        State::new(0.0, interleave(&x, &y), interleave(&vx, &vy))
    }
    fn t_end(&self) -> f64 {
        3.0
    }
    fn energy_datum(&self) -> Option<State<f64, 14>> {
        None
    }
    fn reference(&self) -> Result<Reference<14>, String> {
        let p = &PLEIADES_AT_3;
        let part = |k: usize| -> [f64; 7] { core::array::from_fn(|i| p[7 * k + i]) };
        Ok(Reference {
            state: State::new(
                self.t_end(),
                interleave(&part(0), &part(1)),
                interleave(&part(2), &part(3)),
            ),
            source: "published (Test Set for IVP Solvers, PLEI, 16 digits)".into(),
            error: 5e-15,
        })
    }
    fn coarsest_dt(&self) -> f64 {
        0.01
    }
    fn fastest_frequency(&self) -> f64 {
        fastest_pair::<7, 14>(&PLEIADES_MASSES, &self.start())
    }
}

/// Bodies of the star and planets of P6 with N = 28.
const PLANETS: usize = 13;

/// P6 with N = 28: a star of mass 100 and thirteen planets of masses 0.5 to 1.7 on nearly
/// circular orbits of radii 2 to 9.2 (golden-angle phases, the star moving so that the total
/// momentum is zero), T = 3: every pair interacts, no close encounter.
pub struct StarAndPlanets;

impl StarAndPlanets {
    /// Masses: the star, then the planets.
    fn masses() -> [f64; PLANETS + 1] {
        core::array::from_fn(|i| if i == 0 { 100.0 } else { 0.4 + 0.1 * i as f64 })
    }
}

impl Problem<28, 56> for StarAndPlanets {
    type Mech<T: BenchReal> = NBody<T, 14, 28>;
    type Hand<T: BenchReal> = NBody<T, 14, 28>;

    fn id(&self) -> &'static str {
        "P6-N28"
    }
    fn title(&self) -> &'static str {
        "N-body, N = 28: a star (mass 100) and thirteen planets (0.5..1.7) on near-circular \
         orbits of radii 2..9.2 under mutual gravity (G = 1) in the plane, T = 3"
    }
    fn mechanism_note(&self) -> &'static str {
        "NBody (the bench's own: diagonal constant M, law by hand over the pairs)"
    }
    fn mechanism<T: BenchReal>(&self) -> Result<NBody<T, 14, 28>, Error> {
        Ok(NBody::new(Self::masses().map(T::real)))
    }
    fn hand<T: BenchReal>(&self) -> NBody<T, 14, 28> {
        NBody::new(Self::masses().map(T::real))
    }
    fn start(&self) -> State<f64, 28> {
        let m = Self::masses();
        let (mut x, mut y, mut vx, mut vy) = ([0.0; 14], [0.0; 14], [0.0; 14], [0.0; 14]);
        let (mut px, mut py) = (0.0, 0.0);
        for k in 1..=PLANETS {
            let r = 2.0 + 0.6 * (k - 1) as f64;
            let phase = 2.399_963_229_728_653 * k as f64;
            let v = (m[0] / r).sqrt();
            (x[k], y[k]) = (r * phase.cos(), r * phase.sin());
            (vx[k], vy[k]) = (-v * phase.sin(), v * phase.cos());
            px += m[k] * vx[k];
            py += m[k] * vy[k];
        }
        (vx[0], vy[0]) = (-px / m[0], -py / m[0]);
        State::new(0.0, interleave(&x, &y), interleave(&vx, &vy))
    }
    fn t_end(&self) -> f64 {
        3.0
    }
    fn energy_datum(&self) -> Option<State<f64, 28>> {
        None
    }
    fn reference(&self) -> Result<Reference<28>, String> {
        tight_reference(
            &self.mechanism::<f64>().map_err(|e| e.to_string())?,
            &self.start(),
            3.0,
        )
    }
    fn coarsest_dt(&self) -> f64 {
        0.05
    }
    fn fastest_frequency(&self) -> f64 {
        fastest_pair::<14, 28>(&Self::masses(), &self.start())
    }
}

/// The fastest pair rate at `s`: the largest `sqrt((m_i + m_j) / r_ij^3)` (the angular rate
/// of a circular orbit of the pair at its distance).
fn fastest_pair<const B: usize, const N: usize>(m: &[f64; B], s: &State<f64, N>) -> f64 {
    let mut w: f64 = 0.0;
    for i in 0..B {
        for j in i + 1..B {
            let dx = s.q[2 * j] - s.q[2 * i];
            let dy = s.q[2 * j + 1] - s.q[2 * i + 1];
            let r = dx.hypot(dy);
            w = w.max(((m[i] + m[j]) / (r * r * r)).sqrt());
        }
    }
    w
}
