//! [`CartPole`]: an inverted pendulum on a cart driven by a horizontal force.

use crate::small_solve::solve_sym2;
use lagrange_core::nalgebra::{Matrix2, SVector, Vector2};
use lagrange_core::{
    free_law_force, validate, Controlled, Error, Gather, GeneralizedForce, Lagrangian, Lanes,
    Mechanism, Real, Scalar, State,
};

/// The cart-pole: a cart of mass `M` on a frictionless horizontal track, driven by a horizontal
/// force `F`, carries a uniform pole of mass `m` and length `2 l` on a frictionless hinge, in
/// gravity `g`.
///
/// ```text
/// q = [x, th]   x: cart position, m; th: pole angle from the UPWARD vertical, rad (0 upright,
///               positive tipping towards +x); the pole's centre of mass is at
///               (x + l sin th, l cos th), its inertia about it m l^2 / 3
/// T = (M + m) x'^2 / 2 + m l cos th x' th' + (2/3) m l^2 th'^2
/// V = m g l cos th
/// Q = [F, 0]
///
/// M = | M + m         m l cos th   |      f = | m l sin th th'^2 |
///     | m l cos th    (4/3) m l^2  |          | m g l sin th     |
/// ```
///
/// These are the Barto-Sutton-Anderson cart-pole equations (without friction, in Florian's
/// corrected form):
///
/// ```text
/// th'' = (g sin th - cos th (F + m l th'^2 sin th) / (M + m)) / (l (4/3 - m cos^2 th / (M + m)))
/// x''  = (F + m l (th'^2 sin th - th'' cos th)) / (M + m)
/// ```
///
/// Parameters: cart and pole masses kg, pole half-length m, gravity m/s^2; the input force
/// ([`CartPole::set_force`]) N, held constant over a step and changed by the controller
/// between steps. `det M = m l^2 (4 (M + m) / 3 - m cos^2 th) > 0`: no singular configurations.
/// Energy `T + V` is conserved while `F = 0`; otherwise it changes by the work `F dx`.
///
/// ```
/// use lagrange_core::{Mechanism, State};
/// use lagrange_systems::CartPole;
/// let mut cp = CartPole::new(1.0, 0.1, 0.5, 9.8)?;
/// let upright = State::new(0.0, [0.0, 0.0], [0.0, 0.0]);
/// assert_eq!(cp.acceleration(&upright)?.as_slice(), &[0.0, 0.0]);
/// // Pushing the cart forwards tips the pole backwards.
/// cp.set_force(10.0)?;
/// let a = cp.acceleration(&upright)?;
/// assert!(a[0] > 0.0 && a[1] < 0.0);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CartPole<T: Real> {
    cart_mass: T,
    pole_mass: T,
    pole_half_length: T,
    gravity: T,
    force: T,
}

impl<T: Real> CartPole<T> {
    /// A cart of `cart_mass` (kg, > 0) carrying a pole of `pole_mass` (kg, > 0) and half-length
    /// `pole_half_length` (m, > 0), in `gravity` (m/s^2, >= 0), with no force applied.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first parameter out of range or not finite, or
    /// the one most responsible when a quantity formed from them leaves the range of `T`: the
    /// entries of the mass matrix, its determinant at its smallest and largest (the motion
    /// divides by it) and the weight terms `m g l`.
    pub fn new(cart_mass: T, pole_mass: T, pole_half_length: T, gravity: T) -> Result<Self, Error> {
        let cart_mass = validate::positive("cart_mass", cart_mass)?;
        let pole_mass = validate::positive("pole_mass", pole_mass)?;
        let pole_half_length = validate::positive("pole_half_length", pole_half_length)?;
        let gravity = validate::non_negative("gravity", gravity)?;
        let (mc, m, l, g) = (
            ("cart_mass", cart_mass, 1),
            ("pole_mass", pole_mass, 1),
            ("pole_half_length", pole_half_length, 1),
            ("gravity", gravity, 1),
        );
        let (m2, l2) = (
            ("pole_mass", pole_mass, 2),
            ("pole_half_length", pole_half_length, 2),
        );
        let total = validate::divisor(cart_mass + pole_mass, &[mc, m])?;
        let ml = validate::derived(pole_mass * pole_half_length, &[m, l])?;
        let m11 = validate::divisor(T::from_f64(4.0 / 3.0) * ml * pole_half_length, &[m, l2])?;
        validate::derived(ml * gravity, &[m, l, g])?;
        validate::derived(pole_mass * gravity * pole_half_length, &[m, g, l])?;
        // det M = total m11 - (ml cos)^2, smallest at cos^2 = 1: m l^2 (4/3 mc + m/3) > 0.
        let top = validate::derived(total * m11, &[mc, m2, l2])?;
        validate::divisor(top - ml * ml, &[mc, m2, l2])?;
        Ok(Self {
            cart_mass,
            pole_mass,
            pole_half_length,
            gravity,
            force: T::zero(),
        })
    }
    /// Cart mass, kg.
    #[must_use]
    pub fn cart_mass(&self) -> T {
        self.cart_mass
    }
    /// Pole mass, kg.
    #[must_use]
    pub fn pole_mass(&self) -> T {
        self.pole_mass
    }
    /// Half the pole's length (pivot to centre of mass), m.
    #[must_use]
    pub fn pole_half_length(&self) -> T {
        self.pole_half_length
    }
    /// Gravity, m/s^2.
    #[must_use]
    pub fn gravity(&self) -> T {
        self.gravity
    }
    /// The horizontal force on the cart, N.
    #[must_use]
    pub fn force(&self) -> T {
        self.force
    }
    /// Sets the horizontal force on the cart (N, any finite sign), used from the next
    /// evaluation on.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `force` when not finite (the force is left unchanged).
    pub fn set_force(&mut self, force: T) -> Result<(), Error> {
        self.force = validate::finite("force", force)?;
        Ok(())
    }

    /// The mass matrix and right-hand side together, sharing one `sin_cos(th)`.
    fn terms(&self, s: &State<T, 2>) -> (Matrix2<T>, Vector2<T>) {
        let (sin, cos) = s.q[1].sin_cos();
        let (m, l) = (self.pole_mass, self.pole_half_length);
        let ml = m * l;
        let coupling = ml * cos;
        let mass = Matrix2::new(
            self.cart_mass + m,
            coupling,
            coupling,
            T::from_f64(4.0 / 3.0) * ml * l,
        );
        let thd = s.qd[1];
        let f = Vector2::new(ml * sin * thd * thd, ml * self.gravity * sin);
        (mass, f)
    }
}

/// The input is the horizontal force on the cart, N.
impl<T: Real> Controlled<T> for CartPole<T> {
    type Input = T;
    fn input(&self) -> T {
        self.force()
    }
    /// # Errors
    /// [`Error::InvalidParameter`] `input` when not finite (the force is left unchanged).
    fn set_input(&mut self, input: T) -> Result<(), Error> {
        self.set_force(validate::finite("input", input)?)
    }
}

impl<T: Real> Gather<T, 2> for CartPole<T> {
    type Gathered<const L: usize> = CartPole<Lanes<T, L>>;
    /// Lane by lane: every parameter gathered.
    fn gather<const L: usize>(instances: [&Self; L]) -> Self::Gathered<L> {
        let lanes = |field: fn(&Self) -> T| Lanes::gather(&instances, field);
        CartPole {
            cart_mass: lanes(|m| m.cart_mass),
            pole_mass: lanes(|m| m.pole_mass),
            pole_half_length: lanes(|m| m.pole_half_length),
            gravity: lanes(|m| m.gravity),
            force: lanes(|m| m.force),
        }
    }
    #[inline(always)] // see `Gather::window`
    fn window<const W: usize, const L: usize>(
        wide: &Self::Gathered<W>,
        at: usize,
    ) -> Self::Gathered<L> {
        CartPole {
            cart_mass: wide.cart_mass.window(at),
            pole_mass: wide.pole_mass.window(at),
            pole_half_length: wide.pole_half_length.window(at),
            gravity: wide.gravity.window(at),
            force: wide.force.window(at),
        }
    }
    fn put<const L: usize>(&self, lanes: &mut Self::Gathered<L>, lane: usize) {
        lanes.cart_mass.set(lane, self.cart_mass);
        lanes.pole_mass.set(lane, self.pole_mass);
        lanes.pole_half_length.set(lane, self.pole_half_length);
        lanes.gravity.set(lane, self.gravity);
        lanes.force.set(lane, self.force);
    }
}

impl<T: Real> Mechanism<T, 2> for CartPole<T> {
    fn mass_matrix(&self, s: &State<T, 2>) -> Matrix2<T> {
        self.terms(s).0
    }
    fn rhs(&self, s: &State<T, 2>) -> Vector2<T> {
        self.terms(s).1
    }
    fn solve_mass(&self, s: &State<T, 2>, b: &Vector2<T>) -> Result<Vector2<T>, Error> {
        solve_sym2(&self.mass_matrix(s), b)
    }
    /// The closed form.
    fn law<F: GeneralizedForce<T, 2>>(
        &self,
        s: &State<T, 2>,
        extra: &F,
    ) -> Result<SVector<T, 2>, Error> {
        let (mass, f) = self.terms(s);
        solve_sym2(
            &mass,
            &extra.added_to(s, f + self.non_conservative_force(s)),
        )
    }
    fn law_force<F: GeneralizedForce<T, 2>>(
        &self,
        s: &State<T, 2>,
        extra: &F,
    ) -> Result<SVector<T, 2>, Error> {
        free_law_force(self, s, extra)
    }
}

impl<T: Real> Lagrangian<T, 2> for CartPole<T> {
    const READS_TIME: bool = false;
    /// The cart's `M x'^2 / 2`, the pole's `m |v_c|^2 / 2` with the Cartesian velocity of its
    /// centre of mass, and its spin `(m l^2 / 3) th'^2 / 2`.
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 2>, qd: &SVector<S, 2>) -> S {
        let (xd, thd) = (qd[0], qd[1]);
        let (sin, cos) = q[1].sin_cos();
        let (m, l) = (self.pole_mass, self.pole_half_length);
        let l_s = S::from_real(l);
        let vx = xd + l_s * cos * thd;
        let vy = -l_s * sin * thd;
        let half = S::from_f64(0.5);
        half * S::from_real(self.cart_mass) * xd * xd
            + half * S::from_real(m) * (vx * vx + vy * vy)
            + half * S::from_real(m * l * l / T::from_f64(3.0)) * thd * thd
    }
    /// `m g y_c` with `y_c = l cos th`.
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 2>) -> S {
        S::from_real(self.pole_mass * self.gravity * self.pole_half_length) * q[1].cos()
    }
    fn non_conservative_force(&self, _s: &State<T, 2>) -> Vector2<T> {
        Vector2::new(self.force, T::zero())
    }
}
