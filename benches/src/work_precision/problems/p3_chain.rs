//! P3, the n-link chain: N unit point masses on N massless unit links, all links at 45 degrees
//! at rest, T = 5 s, for N = 5 and N = 20 (references from the published 1e-28 solves) and for
//! N = 10 and N = 40 (references from the tightest run of the library's DOP853, error
//! estimated); its equations written by hand for the peers ([`ChainRhs`]).

use crate::problem::{state_error, HandRhs, Problem, Reference};
use crate::real::BenchReal;
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, Real, Scalar, State};
use lagrange_integrators::{AdaptiveSettings, DormandPrince853};
use lagrange_systems::NLinkPendulum;

/// Gravity, m/s^2.
const G: f64 = 9.81;

/// The published final state for N = 5, angles then rates (shared/BENCH_PROBLEMS.md).
#[allow(clippy::excessive_precision)]
pub const N5: [f64; 10] = [
    0.16171700480933729845,
    0.11988465926932559420,
    0.041037883270398798882,
    0.020815219697576063429,
    0.0085999909042614160117,
    -0.82469393799034453939,
    -0.66395577859240348919,
    -1.4170308719963604309,
    -1.6953341610106654750,
    -2.6112056405099629554,
];

/// The published final state for N = 20, angles then rates (shared/BENCH_PROBLEMS.md, `p3n20`).
#[allow(clippy::excessive_precision)]
pub const N20: [f64; 40] = [
    -0.50525505565354309230,
    -0.50619063536176978075,
    -0.49891716656193269184,
    -0.48493096033196720509,
    -0.47520307551907189246,
    -0.45931907944892776016,
    -0.46281518777918218006,
    -0.46795254382254721408,
    -0.47055406218108493155,
    -0.48014674852501516624,
    -0.49237913419832614216,
    -0.50911720626121654025,
    -0.53008286998486060941,
    -0.55497132308517928891,
    -0.58211144106873582061,
    -0.61221650341829016937,
    -0.64323032501108449868,
    -0.67836786146133364712,
    -0.71500422609821760415,
    -0.76787054609638159379,
    0.25507655190555911783,
    0.41966949240474162165,
    0.71058598595553201266,
    0.62247708029932893021,
    0.47976263370701494830,
    0.32795841955897778388,
    0.51275360485011560886,
    0.40725408377490726349,
    0.49965270184581221189,
    0.54665557552786767502,
    0.56045905113149431817,
    0.58151960935314866862,
    0.58102920938735510606,
    0.57156631505347006853,
    0.54023740010545912646,
    0.49678101629312072958,
    0.44029315224618574515,
    0.36555911201321456599,
    0.28667417228480707576,
    0.11289006492739135073,
];

/// The chain mechanism the bench runs: the hand-derived `NLinkPendulum`.
pub type ChainMechanism<T, const N: usize> = NLinkPendulum<T, N>;

/// The chain of `N` unit masses on unit links in precision `T`.
///
/// # Errors
/// Never, for these parameters.
pub fn chain<T: Real, const N: usize>() -> Result<ChainMechanism<T, N>, Error> {
    NLinkPendulum::new([T::one(); N], [T::one(); N], T::from_f64(G))
}

/// Where a chain's reference comes from.
pub enum ChainReference<const N2: usize> {
    /// A published high-precision final state, angles then rates.
    Published([f64; N2]),
    /// The tightest run of the library's DOP853 (rtol = atol = [`TIGHT`]), its error taken as
    /// its distance to the run at ten times that tolerance.
    Tightest,
}

/// The tolerance of a computed chain reference (about 45 machine epsilons).
pub const TIGHT: f64 = 1e-14;

/// P3 with `N` links (`N2 = 2 N`) and its reference.
pub struct Chain<const N: usize, const N2: usize> {
    id: &'static str,
    title: &'static str,
    reference: ChainReference<N2>,
}

/// P3 with N = 5.
pub const CHAIN_5: Chain<5, 10> = Chain {
    id: "P3-N5",
    title: "n-link chain, N = 5: unit masses and links, all at 45 deg at rest, T = 5 s",
    reference: ChainReference::Published(N5),
};

/// P3 with N = 10.
pub const CHAIN_10: Chain<10, 20> = Chain {
    id: "P3-N10",
    title: "n-link chain, N = 10: unit masses and links, all at 45 deg at rest, T = 5 s",
    reference: ChainReference::Tightest,
};

/// P3 with N = 20.
pub const CHAIN_20: Chain<20, 40> = Chain {
    id: "P3-N20",
    title: "n-link chain, N = 20: unit masses and links, all at 45 deg at rest, T = 5 s",
    reference: ChainReference::Published(N20),
};

/// P3 with N = 40.
pub const CHAIN_40: Chain<40, 80> = Chain {
    id: "P3-N40",
    title: "n-link chain, N = 40: unit masses and links, all at 45 deg at rest, T = 5 s",
    reference: ChainReference::Tightest,
};

/// The chain's equations by hand, as a user of another solver writes them: the same O(N)
/// recursion for the rod tensions as `NLinkPendulum`'s (Newton's law for each mass, a
/// tridiagonal system for the tensions solved by Thomas's algorithm), on plain arrays,
/// without its checks.
pub struct ChainRhs<T, const N: usize> {
    /// `1 / m_j`.
    inv_m: [T; N],
    /// `l_j`.
    l: [T; N],
    /// `1 / l_j`.
    inv_l: [T; N],
    /// Gravity, m/s^2.
    g: T,
}

impl<T: Real, const N: usize> ChainRhs<T, N> {
    /// The chain of `N` unit masses on unit links in gravity `g`.
    pub fn unit(g: T) -> Self {
        Self {
            inv_m: [T::one(); N],
            l: [T::one(); N],
            inv_l: [T::one(); N],
            g,
        }
    }
}

impl<T: Real, const N: usize> HandRhs<T, N> for ChainRhs<T, N> {
    /// Gravity `(0, -g)` on every mass: the differences of the external forces per unit mass
    /// vanish past the first rod, whose row carries `g cos th_1`.
    #[allow(clippy::needless_range_loop)] // the recursion reads like its formulas
    fn accelerations(&self, _t: T, q: &[T; N], qd: &[T; N], qdd: &mut [T; N]) {
        let (inv_m, l) = (&self.inv_m, &self.l);
        let mut sin = [T::zero(); N];
        let mut cos = [T::zero(); N];
        for j in 0..N {
            (sin[j], cos[j]) = Scalar::sin_cos(q[j]);
        }
        // K tau = r, K tridiagonal: diagonal d, super-diagonal off; sn[j] = sin(th_j+1 - th_j).
        let mut d = [T::zero(); N];
        let mut off = [T::zero(); N];
        let mut sn = [T::zero(); N];
        let mut r = [T::zero(); N];
        for j in 0..N {
            d[j] = inv_m[j];
            r[j] = l[j] * qd[j] * qd[j];
            if j == 0 {
                r[j] += self.g * cos[j];
            } else {
                d[j] += inv_m[j - 1];
            }
            if j + 1 < N {
                off[j] = -(cos[j] * cos[j + 1] + sin[j] * sin[j + 1]) * inv_m[j];
                sn[j] = sin[j + 1] * cos[j] - cos[j + 1] * sin[j];
            }
        }
        let mut inv_d = [T::zero(); N];
        for j in 0..N {
            if j > 0 {
                let factor = off[j - 1] * inv_d[j - 1];
                d[j] -= factor * off[j - 1];
                r[j] -= factor * r[j - 1];
            }
            inv_d[j] = d[j].recip();
        }
        let mut tau = [T::zero(); N];
        let mut above = T::zero();
        for j in (0..N).rev() {
            tau[j] = (r[j] - above) * inv_d[j];
            if j > 0 {
                above = off[j - 1] * tau[j];
            }
        }
        // th_j'' = (a_j - a_j-1) . n_j / l_j; gravity's own part cancels but on the first rod.
        for j in 0..N {
            let mut rel = if j == 0 { -self.g * sin[j] } else { T::zero() };
            if j + 1 < N {
                rel += tau[j + 1] * sn[j] * inv_m[j];
            }
            if j > 0 {
                rel -= tau[j - 1] * sn[j - 1] * inv_m[j - 1];
            }
            qdd[j] = rel * self.inv_l[j];
        }
    }
}

impl<const N: usize, const N2: usize> Problem<N, N2> for Chain<N, N2> {
    type Mech<T: BenchReal> = ChainMechanism<T, N>;
    type Hand<T: BenchReal> = ChainRhs<T, N>;

    fn id(&self) -> &'static str {
        self.id
    }
    fn title(&self) -> &'static str {
        self.title
    }
    fn mechanism_note(&self) -> &'static str {
        "NLinkPendulum (hand-derived)"
    }
    fn mechanism<T: BenchReal>(&self) -> Result<ChainMechanism<T, N>, Error> {
        chain()
    }
    fn hand<T: BenchReal>(&self) -> ChainRhs<T, N> {
        ChainRhs::unit(T::real(G))
    }
    fn start(&self) -> State<f64, N> {
        State::at_rest([std::f64::consts::FRAC_PI_4; N])
    }
    fn t_end(&self) -> f64 {
        5.0
    }
    fn energy_datum(&self) -> Option<State<f64, N>> {
        Some(State::at_rest([0.0; N]))
    }
    fn reference(&self) -> Result<Reference<N>, String> {
        let p = match &self.reference {
            ChainReference::Published(p) => p,
            ChainReference::Tightest => return self.tightest(),
        };
        Ok(Reference {
            state: State {
                t: self.t_end(),
                q: SVector::from_fn(|i, _| p[i]),
                qd: SVector::from_fn(|i, _| p[N + i]),
            },
            source: "published high-precision solve (shared/BENCH_PROBLEMS.md)".into(),
            error: 1e-28,
        })
    }
    fn coarsest_dt(&self) -> f64 {
        0.05
    }
    fn fastest_frequency(&self) -> f64 {
        fastest_small_oscillation::<N>()
    }
}

impl<const N: usize, const N2: usize> Chain<N, N2> {
    /// The tightest run of the library's DOP853 (rtol = atol = [`TIGHT`]) and its distance to
    /// the run at ten times that tolerance as its error.
    fn tightest(&self) -> Result<Reference<N>, String> {
        let m = chain::<f64, N>().map_err(|e| e.to_string())?;
        tight_reference(&m, &self.start(), self.t_end())
    }
}

/// The state at `t_end` from `start` by the library's DOP853 at rtol = atol = [`TIGHT`], with
/// its distance to the run at ten times that tolerance as its error.
///
/// # Errors
/// Either run failing.
pub fn tight_reference<M: lagrange_core::Mechanism<f64, N>, const N: usize>(
    m: &M,
    start: &State<f64, N>,
    t_end: f64,
) -> Result<Reference<N>, String> {
    let run = |tol: f64| {
        AdaptiveSettings::new(tol, tol)
            .and_then(|s| s.with_max_steps(100_000_000))
            .map_err(|e| e.to_string())
            .and_then(|s| {
                DormandPrince853::<f64, N>::new(s)
                    .integrate_to(m, start, t_end)
                    .map_err(|e| e.to_string())
            })
    };
    let fine = run(TIGHT)?;
    let coarse = run(10.0 * TIGHT)?;
    let error = state_error(&fine, &coarse);
    Ok(Reference {
        state: fine,
        source: format!(
            "tightest run of the library's DOP853, rtol = atol = {TIGHT:.0e}; error: its \
             distance to the run at {:.0e}",
            10.0 * TIGHT
        ),
        error,
    })
}

/// The fastest small-oscillation frequency of the hanging unit chain of `N` links: the largest
/// `w` with `K x = w^2 M0 x`, `M0_jk = mu_max(j,k)`, `K = g diag(mu_j)`, by power iteration on
/// `M0^-1 K` (its eigenvalues are real and positive, and the largest is well separated).
fn fastest_small_oscillation<const N: usize>() -> f64 {
    use lagrange_core::nalgebra::SMatrix;
    let mu = |j: usize| (N - j) as f64;
    let m0 = SMatrix::<f64, N, N>::from_fn(|j, k| mu(j.max(k)));
    let k = SVector::<f64, N>::from_fn(|j, _| G * mu(j));
    let mut x = SVector::<f64, N>::from_fn(|j, _| if j % 2 == 0 { 1.0 } else { -1.0 });
    let mut w2 = 0.0;
    for _ in 0..500 {
        let Ok(y) = lagrange_core::solve_spd(&m0, &k.component_mul(&x)) else {
            return f64::NAN;
        };
        let norm = y.dot(&y).sqrt();
        w2 = norm / x.dot(&x).sqrt();
        x = y / norm;
    }
    w2.sqrt()
}
