//! [`NLinkPendulum`]: a planar chain of `N` point masses on massless rods, for every `N`.

use crate::small_solve::finite;
use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{
    free_law_force, validate, Error, GeneralizedForce, Lagrangian, Mechanism, Real, Scalar, State,
};

/// A planar chain of `N` point masses `m_j` on massless rods of lengths `l_j`: rod 1 hangs from
/// a fixed pivot, rod `j` from mass `j - 1`, in gravity `g`. One implementation for every
/// `N >= 1` (`N = 0` does not compile).
///
/// ```text
/// q = [th_1 .. th_N]   absolute angle of rod j from the downward vertical, rad;
///                      mass j at sum_{k<=j} l_k (sin th_k, -cos th_k)
/// mu_j = sum_{i>=j} m_i                 (the mass hanging from rod j)
/// T = 1/2 sum_{j,k} mu_max(j,k) l_j l_k cos(th_j - th_k) th_j' th_k'
/// V = -g sum_j mu_j l_j cos th_j
///
/// M_jk = mu_max(j,k) l_j l_k cos(th_j - th_k)
/// f_j  = -l_j sum_k mu_max(j,k) l_k sin(th_j - th_k) th_k'^2 - g mu_j l_j sin th_j
/// ```
///
/// Parameters: masses kg, lengths m, gravity m/s^2. `M = J^T diag(m) J` with `J` the Jacobian
/// of the mass positions, full rank for positive lengths: no singular configurations. Energy
/// `T + V` is conserved; for `N >= 2` the motion is chaotic at large energy.
///
/// Cost: [`Mechanism::mass_matrix`] is `O(N^2)` (`N` sine-cosine pairs, then
/// `cos(th_j - th_k) = cos th_j cos th_k + sin th_j sin th_k`), [`Mechanism::rhs`] `O(N)` (the
/// sums over `k` are prefix and suffix sums). [`Mechanism::acceleration`] and
/// [`Mechanism::solve_mass`] are `O(N)` and never form `M`: Newton's law for each mass with the
/// rod tensions `tau_j` as unknowns,
///
/// ```text
/// m_j a_j = -tau_j e_j + tau_{j+1} e_{j+1} + F_j,    e_j = (sin th_j, -cos th_j)
/// (a_j - a_{j-1}) . e_j = -l_j th_j'^2               (rod j keeps its length)
/// th_j'' = (a_j - a_{j-1}) . (cos th_j, sin th_j) / l_j
/// ```
///
/// gives a symmetric positive definite tridiagonal system for the tensions
/// (`K_jj = 1/m_j + 1/m_{j-1}`, `K_j,j+1 = -cos(th_j - th_j+1) / m_j`, no `1/m_0` term at the
/// pivot), solved by Thomas's algorithm. A generalized force `b` (conjugate to the angles)
/// enters as the Cartesian forces `F_j = G_j - G_{j+1}`, `G_j = (b_j / l_j)
/// (cos th_j, sin th_j)`, whose virtual work is `b . dth`; `solve_mass(b)` is the same
/// recursion with gravity and rates set to zero, so it returns `M^-1 b`. Against forming `M`
/// and `f` and solving by Cholesky (`O(N^3)`) it is about twice as fast at `N = 5` and four to
/// five times at `N = 20` (`cargo xtask demo` prints both), and in f32 it loses less to
/// rounding, since the tension system is far better conditioned than `M`.
///
/// ```
/// use lagrange_core::{Mechanism, State};
/// use lagrange_systems::NLinkPendulum;
/// let chain = NLinkPendulum::<f64, 5>::new([1.0; 5], [1.0; 5], 9.81)?;
/// let s = State::new(0.0, [0.3, 0.2, 0.1, 0.0, -0.1], [0.0; 5]);
/// let a = chain.acceleration(&s)?;
/// // The same accelerations as solving M q'' = f with the mass matrix.
/// let b = lagrange_core::solve_spd(&chain.mass_matrix(&s), &chain.rhs(&s))?;
/// assert!((a - b).amax() < 1e-13);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
///
/// A chain needs a link:
///
/// ```compile_fail
/// let none = lagrange_systems::NLinkPendulum::<f64, 0>::new([], [], 9.81);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct NLinkPendulum<T: Real, const N: usize> {
    masses: [T; N],
    lengths: [T; N],
    gravity: T,
    /// `mu_j`, the total mass hanging from rod `j`.
    mu: [T; N],
    /// `1 / m_j`.
    inv_masses: [T; N],
    /// `1 / l_j`.
    inv_lengths: [T; N],
}

/// Sines and cosines of every angle.
fn sin_cos<T: Real, const N: usize>(q: &SVector<T, N>) -> ([T; N], [T; N]) {
    let mut sin = [T::zero(); N];
    let mut cos = [T::zero(); N];
    for ((s, c), th) in sin.iter_mut().zip(cos.iter_mut()).zip(q.iter()) {
        (*s, *c) = th.sin_cos();
    }
    (sin, cos)
}

/// Thomas's algorithm on the tension system `K tau = r` (`K` tridiagonal, symmetric: diagonal
/// `d`, overwritten by the pivots; super-diagonal `off`, `off[j] = K_j,j+1`): eliminates below
/// the diagonal keeping the inverse pivots, then back-substitutes.
///
/// The pivots are tested once, after the elimination, without a branch per pivot: a bad pivot
/// spoils only those after it, so the first one that fails is found by a scan that runs only
/// when one did.
///
/// # Errors
/// At the first pivot that fails: [`Error::NonFiniteState`] when it is not finite,
/// [`Error::SingularMassMatrix`] when it is not positive.
#[inline(always)]
fn thomas<T: Real, const N: usize>(
    d: &mut [T; N],
    off: &[T; N],
    mut r: [T; N],
) -> Result<[T; N], Error> {
    let mut inv_d = [T::zero(); N];
    let mut ok = true;
    for j in 0..N {
        if j > 0 {
            let factor = off[j - 1] * inv_d[j - 1];
            d[j] -= factor * off[j - 1];
            r[j] -= factor * r[j - 1];
        }
        // `>` is false for NaN; `is_finite` catches infinity. `&`: no branch.
        ok &= d[j].is_finite() & (d[j] > T::zero());
        inv_d[j] = d[j].recip();
    }
    if !ok {
        return Err(bad_pivot(d));
    }
    let mut tau = [T::zero(); N];
    let mut above = T::zero();
    for j in (0..N).rev() {
        tau[j] = (r[j] - above) * inv_d[j];
        if j > 0 {
            above = off[j - 1] * tau[j];
        }
    }
    Ok(tau)
}

/// The error for the first pivot in `d` that is not finite and positive (off the hot path).
#[cold]
#[inline(never)]
fn bad_pivot<T: Real, const N: usize>(d: &[T; N]) -> Error {
    for (j, dj) in d.iter().enumerate() {
        if !dj.is_finite() {
            return Error::NonFiniteState;
        }
        if *dj <= T::zero() {
            return Error::SingularMassMatrix { pivot: j };
        }
    }
    Error::NonFiniteState
}

impl<T: Real, const N: usize> NLinkPendulum<T, N> {
    /// A chain of `masses` (kg, each > 0) on rods of `lengths` (m, each > 0), mass `j` at the
    /// end of rod `j` counted from the pivot, in `gravity` (m/s^2, >= 0).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first entry out of range or not finite
    /// (`masses[j]`, `lengths[j]`; past the 32nd entry the whole array) or `gravity`, or the
    /// entry most responsible when a quantity formed from the parameters leaves the range of
    /// `T`: each `1/m_j` and `1/l_j` (the tension recursion divides by the masses and the
    /// lengths), the total mass and length, the diagonal `mu_j l_j^2` of the mass matrix (it
    /// bounds the rest), the weights `g mu_j l_j` and `g m_j`, and `g mu_1 sum l_j`, which
    /// bounds the potential energy.
    pub fn new(masses: [T; N], lengths: [T; N], gravity: T) -> Result<Self, Error> {
        const { assert!(N > 0, "an N-link pendulum needs at least one link") };
        const MASSES: [&str; 32] = lagrange_core::entry_names!("masses");
        const LENGTHS: [&str; 32] = lagrange_core::entry_names!("lengths");
        let mass_name = |j| validate::entry(&MASSES, j, "masses");
        let length_name = |j| validate::entry(&LENGTHS, j, "lengths");
        for (j, m) in masses.iter().enumerate() {
            validate::positive(mass_name(j), *m)?;
        }
        for (j, l) in lengths.iter().enumerate() {
            validate::positive(length_name(j), *l)?;
        }
        let gravity = validate::non_negative("gravity", gravity)?;
        let g = ("gravity", gravity, 1);
        // mu_j and its blame: the masses from j on.
        let mut mu = masses;
        let mut below = T::zero();
        for (j, (m, &length)) in mu.iter_mut().zip(&lengths).enumerate().rev() {
            below += *m;
            *m = below;
            // A sum overflows through its largest term.
            let (largest, largest_mass) = largest_from(&masses, j);
            let heaviest = (mass_name(largest), largest_mass, 1);
            validate::derived(below, &[heaviest])?;
            let l = (length_name(j), length, 2);
            validate::derived(below * length * length, &[heaviest, l])?;
            let l1 = (length_name(j), length, 1);
            validate::derived(gravity * below * length, &[g, heaviest, l1])?;
        }
        let mut total_length = T::zero();
        let (mut longest, mut longest_length) = (0, T::zero());
        let mut previous: Option<(usize, T)> = None;
        for (j, (m, l)) in masses.iter().zip(&lengths).enumerate() {
            validate::divisor(*m, &[(mass_name(j), *m, 1)])?;
            validate::divisor(*l, &[(length_name(j), *l, 1)])?;
            validate::derived(*m * gravity, &[(mass_name(j), *m, 1), g])?;
            if let Some((i, before)) = previous {
                let pair = [(mass_name(j), *m, -1), (mass_name(i), before, -1)];
                validate::derived(m.recip() + before.recip(), &pair)?;
            }
            previous = Some((j, *m));
            if *l > longest_length {
                (longest, longest_length) = (j, *l);
            }
            total_length += *l;
            validate::derived(total_length, &[(length_name(longest), longest_length, 1)])?;
        }
        let (heaviest, heaviest_mass) = largest_from(&masses, 0);
        validate::derived(
            gravity * below * total_length,
            &[
                g,
                (mass_name(heaviest), heaviest_mass, 1),
                (length_name(longest), longest_length, 1),
            ],
        )?;
        let inv_masses = masses.map(T::recip);
        let inv_lengths = lengths.map(T::recip);
        Ok(Self {
            masses,
            lengths,
            gravity,
            mu,
            inv_masses,
            inv_lengths,
        })
    }
    /// Masses, kg, from the pivot outwards.
    #[must_use]
    pub fn masses(&self) -> [T; N] {
        self.masses
    }
    /// Rod lengths, m, from the pivot outwards.
    #[must_use]
    pub fn lengths(&self) -> [T; N] {
        self.lengths
    }
    /// Gravity, m/s^2.
    #[must_use]
    pub fn gravity(&self) -> T {
        self.gravity
    }
    /// Positions `(x, y)` of the masses relative to the pivot, m, from the pivot outwards.
    /// (No error channel: NaN for angles that are not finite.)
    #[must_use]
    pub fn positions(&self, q: &SVector<T, N>) -> [(T, T); N] {
        let (sin, cos) = sin_cos(q);
        let (mut x, mut y) = (T::zero(), T::zero());
        core::array::from_fn(|j| {
            x += self.lengths[j] * sin[j];
            y -= self.lengths[j] * cos[j];
            (x, y)
        })
    }

    /// The tension recursion described on the type, for the chain in motion under gravity
    /// alone (`(px_j, py_j) = (0, -g)` on every mass), written out: the differences of the
    /// external forces per unit mass vanish past the first rod, so gravity enters the first
    /// row of the tension system (`g cos th_1`) and the first angle's acceleration
    /// (`-g sin th_1 / l_1`) only.
    #[inline(always)]
    fn falling(
        &self,
        (sin, cos): ([T; N], [T; N]),
        qd: &SVector<T, N>,
    ) -> Result<SVector<T, N>, Error> {
        let (l, inv_m) = (&self.lengths, &self.inv_masses);
        let mut d = [T::zero(); N];
        let mut off = [T::zero(); N];
        let mut sn = [T::zero(); N];
        let mut r = [T::zero(); N];
        for j in 0..N {
            d[j] = inv_m[j];
            r[j] = l[j] * qd[j] * qd[j];
            if j == 0 {
                r[j] += self.gravity * cos[j];
            } else {
                d[j] += inv_m[j - 1];
            }
            if j + 1 < N {
                off[j] = -(cos[j] * cos[j + 1] + sin[j] * sin[j + 1]) * inv_m[j];
                sn[j] = sin[j + 1] * cos[j] - cos[j + 1] * sin[j];
            }
        }
        let tau = thomas(&mut d, &off, r)?;
        let qdd = SVector::<T, N>::from_fn(|j, _| {
            let mut rel = if j == 0 {
                -self.gravity * sin[j]
            } else {
                T::zero()
            };
            if j + 1 < N {
                rel += tau[j + 1] * sn[j] * inv_m[j];
            }
            if j > 0 {
                rel -= tau[j - 1] * sn[j - 1] * inv_m[j - 1];
            }
            rel * self.inv_lengths[j]
        });
        finite(qdd, Error::NonFiniteState)
    }

    /// The tension recursion described on the type, at rest: `q''` of the chain at angles
    /// with sines `sin` and cosines `cos`, not moving, under external forces per unit mass
    /// `(px_j, py_j)` on each mass. (The chain in motion under gravity is [`Self::falling`].)
    fn tension_solve(
        &self,
        (sin, cos): ([T; N], [T; N]),
        (px, py): ([T; N], [T; N]),
    ) -> Result<SVector<T, N>, Error> {
        let inv_m = &self.inv_masses;
        // K tau = r, K tridiagonal: diagonal `d`, super-diagonal `off` (off[j] = K_j,j+1).
        // e_j = (sin, -cos), n_j = (cos, sin); sn[j] = e_{j+1} . n_j = sin(th_{j+1} - th_j).
        // Row j: r_j = (p_j - p_{j-1}) . e_j, with p_{-1} = 0 at the pivot (and no
        // centripetal term l_j th_j'^2: at rest).
        let mut d = [T::zero(); N];
        let mut off = [T::zero(); N];
        let mut sn = [T::zero(); N];
        let mut r = [T::zero(); N];
        for j in 0..N {
            let (mut dpx, mut dpy) = (px[j], py[j]);
            d[j] = inv_m[j];
            if j > 0 {
                dpx -= px[j - 1];
                dpy -= py[j - 1];
                d[j] += inv_m[j - 1];
            }
            r[j] = dpx * sin[j] - dpy * cos[j];
            if j + 1 < N {
                off[j] = -(cos[j] * cos[j + 1] + sin[j] * sin[j + 1]) * inv_m[j];
                sn[j] = sin[j + 1] * cos[j] - cos[j + 1] * sin[j];
            }
        }
        let tau = thomas(&mut d, &off, r)?;
        // th_j'' = (a_j - a_{j-1}) . n_j / l_j with m_j a_j = -tau_j e_j + tau_{j+1} e_{j+1} + F_j.
        let qdd = SVector::<T, N>::from_fn(|j, _| {
            let mut rel = px[j] * cos[j] + py[j] * sin[j];
            if j + 1 < N {
                rel += tau[j + 1] * sn[j] * inv_m[j];
            }
            if j > 0 {
                rel -=
                    tau[j - 1] * sn[j - 1] * inv_m[j - 1] + px[j - 1] * cos[j] + py[j - 1] * sin[j];
            }
            rel * self.inv_lengths[j]
        });
        finite(qdd, Error::NonFiniteState)
    }
}

impl<T: Real, const N: usize> Mechanism<T, N> for NLinkPendulum<T, N> {
    fn mass_matrix(&self, s: &State<T, N>) -> SMatrix<T, N, N> {
        let (sin, cos) = sin_cos(&s.q);
        let l = &self.lengths;
        SMatrix::from_fn(|j, k| {
            self.mu[j.max(k)] * l[j] * l[k] * (cos[j] * cos[k] + sin[j] * sin[k])
        })
    }

    fn rhs(&self, s: &State<T, N>) -> SVector<T, N> {
        let (sin, cos) = sin_cos(&s.q);
        let l = &self.lengths;
        // sum_k mu_max(j,k) x_k = mu_j sum_{k<=j} x_k + sum_{k>j} mu_k x_k for
        // x_k = l_k cos th_k th_k'^2 and l_k sin th_k th_k'^2.
        let mut after_c = [T::zero(); N];
        let mut after_s = [T::zero(); N];
        let (mut acc_c, mut acc_s) = (T::zero(), T::zero());
        for k in (0..N).rev() {
            after_c[k] = acc_c;
            after_s[k] = acc_s;
            let w2 = l[k] * s.qd[k] * s.qd[k];
            acc_c += self.mu[k] * w2 * cos[k];
            acc_s += self.mu[k] * w2 * sin[k];
        }
        let (mut upto_c, mut upto_s) = (T::zero(), T::zero());
        SVector::from_fn(|j, _| {
            let w2 = l[j] * s.qd[j] * s.qd[j];
            upto_c += w2 * cos[j];
            upto_s += w2 * sin[j];
            let sum_c = self.mu[j] * upto_c + after_c[j];
            let sum_s = self.mu[j] * upto_s + after_s[j];
            -l[j] * (sin[j] * sum_c - cos[j] * sum_s) - self.gravity * self.mu[j] * l[j] * sin[j]
        })
    }

    /// `M^-1 b` by the tension recursion at rest without gravity, `b` realised as the Cartesian
    /// forces `G_j - G_{j+1}`, `G_j = (b_j / l_j) (cos th_j, sin th_j)`.
    fn solve_mass(&self, s: &State<T, N>, b: &SVector<T, N>) -> Result<SVector<T, N>, Error> {
        let (sin, cos) = sin_cos(&s.q);
        let g = |j: usize| -> (T, T) {
            match b.get(j) {
                Some(bj) => {
                    let k = *bj * self.inv_lengths[j];
                    (k * cos[j], k * sin[j])
                }
                None => (T::zero(), T::zero()),
            }
        };
        let mut px = [T::zero(); N];
        let mut py = [T::zero(); N];
        let mut next = g(0);
        for j in 0..N {
            let here = next;
            next = g(j + 1);
            px[j] = (here.0 - next.0) * self.inv_masses[j];
            py[j] = (here.1 - next.1) * self.inv_masses[j];
        }
        self.tension_solve((sin, cos), (px, py))
    }

    /// The closed form: the tension recursion under gravity alone (`falling`), plus
    /// `M^-1` of the extra force when there is one.
    #[inline]
    fn law<F: GeneralizedForce<T, N>>(
        &self,
        s: &State<T, N>,
        extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        let free = self.falling(sin_cos(&s.q), &s.qd)?;
        if F::IS_ZERO {
            Ok(free)
        } else {
            finite(
                free + self.solve_mass(s, &extra.force(s))?,
                Error::NonFiniteState,
            )
        }
    }
    fn law_force<F: GeneralizedForce<T, N>>(
        &self,
        s: &State<T, N>,
        extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        free_law_force(self, s, extra)
    }
}

impl<T: Real, const N: usize> Lagrangian<T, N> for NLinkPendulum<T, N> {
    const READS_TIME: bool = false;
    /// `sum_i m_i |v_i|^2 / 2` with the Cartesian velocity `v_i` of each mass.
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, N>, qd: &SVector<S, N>) -> S {
        let (mut vx, mut vy, mut t) = (S::zero(), S::zero(), S::zero());
        for (j, (th, w)) in q.iter().zip(qd.iter()).enumerate() {
            let (sin, cos) = th.sin_cos();
            let u = S::from_real(self.lengths[j]) * *w;
            vx += u * cos;
            vy += u * sin;
            t += S::from_real(T::HALF * self.masses[j]) * (vx * vx + vy * vy);
        }
        t
    }
    /// `g sum_i m_i y_i` with the height `y_i` of each mass.
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, N>) -> S {
        let (mut y, mut v) = (S::zero(), S::zero());
        for (j, th) in q.iter().enumerate() {
            y -= S::from_real(self.lengths[j]) * th.cos();
            v += S::from_real(self.masses[j] * self.gravity) * y;
        }
        v
    }
}

/// The largest of `values[from..]` (positive) and its index, the first of equals: by
/// iteration, so that a constructor holds no bounds check (the panic-free firmware image).
fn largest_from<T: Real>(values: &[T], from: usize) -> (usize, T) {
    values
        .iter()
        .enumerate()
        .skip(from)
        .fold(
            (from, T::zero()),
            |(a, va), (i, &v)| {
                if v > va {
                    (i, v)
                } else {
                    (a, va)
                }
            },
        )
}
