//! [`SpringMassDamper`]: a mass on a linear spring with a linear viscous damper.

use crate::small_solve::finite;
use lagrange_core::nalgebra::{Matrix1, SMatrix, SVector, Vector1};
use lagrange_core::{
    free_law_force, validate, Error, Gather, GeneralizedForce, Lagrangian, Lanes, Mechanism, Real,
    Scalar, State,
};

/// A mass `m` on a linear spring of stiffness `k` and a viscous damper `c`, no gravity.
///
/// ```text
/// q = [x]      displacement from the spring's rest position, m
/// L = m x'^2 / 2 - k x^2 / 2
/// Q = -c x'
/// m x'' = -k x - c x'
/// ```
///
/// Under-damped for `c^2 < 4 k m`, critically damped at equality, over-damped above;
/// [`exact::damped_oscillator`](crate::exact::damped_oscillator) gives the exact motion in every
/// case. No singular configurations; a non-finite state gives [`Error::NonFiniteState`]. Energy
/// `T + V` is conserved when `c = 0` and never increases otherwise.
///
/// ```
/// use lagrange_core::{Mechanism, State};
/// use lagrange_systems::SpringMassDamper;
/// let smd = SpringMassDamper::<f64>::new(2.0, 8.0, 0.5)?;
/// let a = smd.acceleration(&State::new(0.0, [0.1], [1.0]))?;
/// assert!((a[0] - (-8.0 * 0.1 - 0.5 * 1.0) / 2.0).abs() < 1e-15);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SpringMassDamper<T: Real> {
    mass: T,
    stiffness: T,
    damping: T,
}

impl<T: Real> SpringMassDamper<T> {
    /// A `mass` (kg, > 0) on a spring of `stiffness` (N/m, >= 0) with `damping` (N s/m, >= 0).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first parameter out of range or not finite, or
    /// `mass` when `1 / m` overflows.
    pub fn new(mass: T, stiffness: T, damping: T) -> Result<Self, Error> {
        let mass = validate::positive("mass", mass)?;
        let stiffness = validate::non_negative("stiffness", stiffness)?;
        let damping = validate::non_negative("damping", damping)?;
        validate::divisor(mass, &[("mass", mass, 1)])?;
        Ok(Self {
            mass,
            stiffness,
            damping,
        })
    }
    /// Mass, kg.
    #[must_use]
    pub fn mass(&self) -> T {
        self.mass
    }
    /// Stiffness, N/m.
    #[must_use]
    pub fn stiffness(&self) -> T {
        self.stiffness
    }
    /// Damping, N s/m.
    #[must_use]
    pub fn damping(&self) -> T {
        self.damping
    }
}

impl<T: Real> Gather<T, 1> for SpringMassDamper<T> {
    type Gathered<const L: usize> = SpringMassDamper<Lanes<T, L>>;
    /// Lane by lane: every parameter gathered.
    fn gather<const L: usize>(instances: [&Self; L]) -> Self::Gathered<L> {
        let lanes = |field: fn(&Self) -> T| Lanes::gather(&instances, field);
        SpringMassDamper {
            mass: lanes(|m| m.mass),
            stiffness: lanes(|m| m.stiffness),
            damping: lanes(|m| m.damping),
        }
    }
    #[inline(always)] // see `Gather::window`
    fn window<const W: usize, const L: usize>(
        wide: &Self::Gathered<W>,
        at: usize,
    ) -> Self::Gathered<L> {
        SpringMassDamper {
            mass: wide.mass.window(at),
            stiffness: wide.stiffness.window(at),
            damping: wide.damping.window(at),
        }
    }
    fn put<const L: usize>(&self, lanes: &mut Self::Gathered<L>, lane: usize) {
        lanes.mass.set(lane, self.mass);
        lanes.stiffness.set(lane, self.stiffness);
        lanes.damping.set(lane, self.damping);
    }
}

impl<T: Real> Mechanism<T, 1> for SpringMassDamper<T> {
    fn mass_matrix(&self, _s: &State<T, 1>) -> SMatrix<T, 1, 1> {
        Matrix1::new(self.mass)
    }
    fn rhs(&self, s: &State<T, 1>) -> SVector<T, 1> {
        Vector1::new(-self.stiffness * s.q[0])
    }
    fn solve_mass(&self, _s: &State<T, 1>, b: &SVector<T, 1>) -> Result<SVector<T, 1>, Error> {
        finite(b / self.mass, Error::NonFiniteState)
    }
    fn law_force<F: GeneralizedForce<T, 1>>(
        &self,
        s: &State<T, 1>,
        extra: &F,
    ) -> Result<SVector<T, 1>, Error> {
        free_law_force(self, s, extra)
    }
    /// Only through the damping.
    fn reads_velocities(&self) -> bool {
        self.damping != T::zero()
    }
}

impl<T: Real> Lagrangian<T, 1> for SpringMassDamper<T> {
    const READS_TIME: bool = false;
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, _q: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
        S::from_real(T::HALF * self.mass) * qd[0] * qd[0]
    }
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 1>) -> S {
        S::from_real(T::HALF * self.stiffness) * q[0] * q[0]
    }
    fn non_conservative_force(&self, s: &State<T, 1>) -> SVector<T, 1> {
        Vector1::new(-self.damping * s.qd[0])
    }
}
