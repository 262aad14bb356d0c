//! [`FallingParticle`]: a point mass in uniform gravity.

use crate::small_solve::finite;
use lagrange_core::nalgebra::{Matrix1, SMatrix, SVector, Vector1};
use lagrange_core::{
    free_law_force, validate, Error, Gather, GeneralizedForce, Lagrangian, Lanes, Mechanism, Real,
    Scalar, State,
};

/// A point mass `m` falling in uniform gravity `g` along -y.
///
/// ```text
/// q = [y]            height, m (up is positive)
/// L = m y'^2 / 2 - m g y
/// y'' = -g
/// ```
///
/// No singular configurations. The acceleration is constant, so RK4 and velocity Verlet are
/// exact to rounding.
///
/// ```
/// use lagrange_core::{Mechanism, State};
/// use lagrange_systems::FallingParticle;
/// let p = FallingParticle::new(2.0, 9.81)?;
/// assert_eq!(p.acceleration(&State::new(0.0, [10.0], [0.0]))?[0], -9.81);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FallingParticle<T: Real> {
    mass: T,
    gravity: T,
}

impl<T: Real> FallingParticle<T> {
    /// A particle of `mass` (kg, > 0) in `gravity` (m/s^2, >= 0).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `mass` or `gravity` when out of range or not finite,
    /// or the one most responsible when the weight `m g` overflows or `1 / m` does.
    pub fn new(mass: T, gravity: T) -> Result<Self, Error> {
        let mass = validate::positive("mass", mass)?;
        let gravity = validate::non_negative("gravity", gravity)?;
        validate::divisor(mass, &[("mass", mass, 1)])?;
        validate::derived(
            mass * gravity,
            &[("mass", mass, 1), ("gravity", gravity, 1)],
        )?;
        Ok(Self { mass, gravity })
    }
    /// Mass, kg.
    #[must_use]
    pub fn mass(&self) -> T {
        self.mass
    }
    /// Gravity, m/s^2.
    #[must_use]
    pub fn gravity(&self) -> T {
        self.gravity
    }
}

impl<T: Real> Gather<T, 1> for FallingParticle<T> {
    type Gathered<const L: usize> = FallingParticle<Lanes<T, L>>;
    /// Lane by lane: every parameter gathered.
    fn gather<const L: usize>(instances: [&Self; L]) -> Self::Gathered<L> {
        let lanes = |field: fn(&Self) -> T| Lanes::gather(&instances, field);
        FallingParticle {
            mass: lanes(|m| m.mass),
            gravity: lanes(|m| m.gravity),
        }
    }
    #[inline(always)] // see `Gather::window`
    fn window<const W: usize, const L: usize>(
        wide: &Self::Gathered<W>,
        at: usize,
    ) -> Self::Gathered<L> {
        FallingParticle {
            mass: wide.mass.window(at),
            gravity: wide.gravity.window(at),
        }
    }
    fn put<const L: usize>(&self, lanes: &mut Self::Gathered<L>, lane: usize) {
        lanes.mass.set(lane, self.mass);
        lanes.gravity.set(lane, self.gravity);
    }
}

impl<T: Real> Mechanism<T, 1> for FallingParticle<T> {
    fn mass_matrix(&self, _s: &State<T, 1>) -> SMatrix<T, 1, 1> {
        Matrix1::new(self.mass)
    }
    fn rhs(&self, _s: &State<T, 1>) -> SVector<T, 1> {
        Vector1::new(-self.mass * self.gravity)
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
    /// Never: the acceleration is `-g`.
    fn reads_velocities(&self) -> bool {
        false
    }
}

impl<T: Real> Lagrangian<T, 1> for FallingParticle<T> {
    const READS_TIME: bool = false;
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, _q: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
        S::from_real(T::HALF * self.mass) * qd[0] * qd[0]
    }
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 1>) -> S {
        S::from_real(self.mass * self.gravity) * q[0]
    }
}
