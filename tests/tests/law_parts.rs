//! The parts a law is made of, each on its own: forces in pairs and their Jacobians, viscous
//! damping's exact Jacobian, a forced mechanism's own force plus the added one, an input set
//! and refused, the defaults of a hand-written `Mechanism` (the force its law applies, whether
//! it reads velocities, its Jacobian by differences and the refusal of one that is not finite),
//! and a constraint set's residual, the largest of its rows.

use lagrange_core::constraints::Constraints;
use lagrange_core::nalgebra::{SMatrix, SVector, Vector2};
use lagrange_core::{
    jacobian_by_differences, Controlled, Error, EulerLagrange, Forced, GeneralizedForce, Holonomic,
    HolonomicConstraints, Input, Lagrangian, Mechanism, Scalar, State, ViscousDamping,
};
use lagrange_systems::SimplePendulum;

/// Two masses on springs, coupled through their mass matrix, written by hand: a `Mechanism`
/// that keeps every default.
struct Coupled;

impl Lagrangian<f64, 2> for Coupled {
    fn kinetic<S: Scalar<Real = f64>>(&self, _t: S, _q: &SVector<S, 2>, v: &SVector<S, 2>) -> S {
        // M = [[2, 0.5], [0.5, 1]].
        v[0] * v[0] + v[1] * v[1] * 0.5 + v[0] * v[1] * 0.5
    }
    fn potential<S: Scalar<Real = f64>>(&self, _t: S, q: &SVector<S, 2>) -> S {
        q[0] * q[0] * 1.5 + q[1] * q[1]
    }
}

impl Mechanism<f64, 2> for Coupled {
    fn mass_matrix(&self, _s: &State<f64, 2>) -> SMatrix<f64, 2, 2> {
        SMatrix::<f64, 2, 2>::new(2.0, 0.5, 0.5, 1.0)
    }
    fn rhs(&self, s: &State<f64, 2>) -> SVector<f64, 2> {
        Vector2::new(-3.0 * s.q[0], -2.0 * s.q[1])
    }
}

/// A force of its own, `(sin q1, q0 q0')`.
fn pull(s: &State<f64, 2>) -> SVector<f64, 2> {
    Vector2::new(libm::sin(s.q[1]), s.q[0] * s.qd[0])
}

/// A state with every coordinate and velocity non-zero.
fn state() -> State<f64, 2> {
    State::new(0.25, [0.3, -0.8], [1.5, -2.0])
}

/// A pair of forces is their sum, and so is its Jacobian; viscous damping's Jacobian is
/// `-c` on the velocities exactly.
#[test]
fn forces_add_up() -> Result<(), Error> {
    let s = state();
    let damping = ViscousDamping::new([0.4, 1.5])?;
    let pair = (damping, pull);
    assert_eq!(pair.force(&s), damping.force(&s) + pull(&s));
    // -c q', to the rounding of 0.4 x 1.5.
    assert!((damping.force(&s) - Vector2::new(-0.6, 3.0)).abs().max() < 1e-15);
    let j = damping.jacobian(&s);
    assert_eq!(j.wrt_qd, SMatrix::<f64, 2, 2>::new(-0.4, 0.0, 0.0, -1.5));
    assert_eq!(j.wrt_q, SMatrix::<f64, 2, 2>::zeros());
    let both = pair.jacobian(&s);
    let sum = damping.jacobian(&s) + GeneralizedForce::jacobian(&pull, &s);
    assert_eq!((both.wrt_q, both.wrt_qd), (sum.wrt_q, sum.wrt_qd));
    // d pull / dq1 = cos q1, d pull / dq0' = q0, to the central differences' accuracy.
    assert!((both.wrt_q[(0, 1)] - libm::cos(-0.8)).abs() < 1e-9);
    assert!((both.wrt_qd[(1, 0)] - (0.3 - 0.0)).abs() < 1e-9);
    Ok(())
}

/// A forced mechanism's non-conservative force is its mechanism's own (the pendulum's
/// damping) plus the one added; an input is set, read back, and refused when not finite.
#[test]
fn forced_and_controlled() -> Result<(), Error> {
    let pendulum = SimplePendulum::new(1.0, 1.0, 9.81, 0.7)?;
    let s = State::new(0.0, [0.4], [2.0]);
    let push = |_: &State<f64, 1>| SVector::<f64, 1>::new(5.0);
    let forced = Forced::new(pendulum, push);
    let own = pendulum.non_conservative_force(&s);
    assert!(own[0] < 0.0, "the pendulum's damping: {own}");
    assert_eq!(forced.non_conservative_force(&s), own + push(&s));
    let mut driven = Forced::new(pendulum, Input::new([0.0]));
    driven.set_input(SVector::<f64, 1>::new(2.5))?;
    assert_eq!(driven.input()[0], 2.5);
    assert!(driven.set_input(SVector::<f64, 1>::new(f64::NAN)).is_err());
    assert_eq!(driven.input()[0], 2.5);
    Ok(())
}

/// The defaults of a hand-written mechanism: the force its law applies is the extra force
/// (`M q'' - f`), it says it reads velocities, and its Jacobian by differences is that of its
/// law, refused when the law is not finite near the state.
#[test]
fn a_mechanism_with_every_default() -> Result<(), Error> {
    let s = state();
    let force = Coupled.law_force(&s, &pull)?;
    // M q'' - f against the force: the rounding of a 2 x 2 solve and product.
    assert!((force - pull(&s)).abs().max() < 1e-14, "{force}");
    assert!(Coupled.reads_velocities());
    assert!(EulerLagrange::new(Coupled).reads_velocities());
    let (a, j) = jacobian_by_differences(&Coupled, &s, &pull)?;
    assert_eq!(a, Coupled.law(&s, &pull)?);
    // The law is linear in q but for the force: dq''/dq0 = M^-1 (-3, q0') + ...; checked
    // against the exact law Jacobian of the automatic path, to the differences' accuracy.
    let (_, exact) = EulerLagrange::new(Coupled).law_jacobian(&s, &pull)?;
    assert!((j.wrt_q - exact.wrt_q).abs().max() < 1e-8);
    assert!((j.wrt_qd - exact.wrt_qd).abs().max() < 1e-8);
    // A force that jumps by 3e308 across the state (+-1.5e308 on either side of q0, finite
    // everywhere): the law is finite at every state the differences take, its Jacobian is
    // not.
    let here = s;
    let jump = move |x: &State<f64, 2>| {
        let side = (x.q[0] - here.q[0]).signum();
        if x == &here {
            pull(x)
        } else {
            Vector2::new(1.5e308 * side, 0.0)
        }
    };
    let mut beside = s;
    beside.q[0] += 1e-3;
    assert!(Coupled.law(&beside, &jump)?.iter().all(|a| a.is_finite()));
    beside.q[0] -= 2e-3;
    assert!(Coupled.law(&beside, &jump)?.iter().all(|a| a.is_finite()));
    assert_eq!(
        jacobian_by_differences(&Coupled, &s, &jump).map(|_| ()),
        Err(Error::NonFiniteState)
    );
    Ok(())
}

/// The unit circle and a line through it, as two rows.
struct CircleAndLine;

impl HolonomicConstraints<f64, 2, 2> for CircleAndLine {
    fn phi<S: Scalar<Real = f64> + 'static>(&self, q: &SVector<S, 2>) -> SVector<S, 2> {
        Vector2::new(q[0] * q[0] + q[1] * q[1] - S::one(), q[0] - q[1] * 2.0)
    }
}

/// A set's residual is the largest row's, position and velocity, whichever row it is; a
/// non-finite row makes it non-finite.
#[test]
fn the_residual_is_the_largest_row() {
    let rows = Holonomic::new(CircleAndLine);
    // phi = (0.25 + 0.01 - 1, 0.5 - 0.2) = (-0.74, 0.3); J q' = (2 x x' + 2 y y', x' - 2 y').
    let s = State::new(0.0, [0.5, 0.1], [0.2, 0.3]);
    let r = rows.residual(&s);
    assert!((r.position - 0.74).abs() < 1e-15, "{r:?}");
    // J q' = (0.2 + 0.06, 0.2 - 0.6) = (0.26, -0.4): the second row's.
    assert!((r.velocity - 0.4).abs() < 1e-15, "{r:?}");
    let nan = State::new(0.0, [f64::NAN, 0.1], [0.2, 0.3]);
    assert!(rows.residual(&nan).position.is_nan());
}

/// A state is finite only when its time, every coordinate and every velocity are: any one of
/// them not finite makes it not finite.
#[test]
fn a_state_is_finite_in_every_part() {
    let s = state();
    assert!(s.is_finite());
    for bad in [f64::NAN, f64::INFINITY] {
        let (mut t, mut q, mut qd) = (s, s, s);
        t.t = bad;
        q.q[1] = bad;
        qd.qd[0] = bad;
        for x in [t, q, qd] {
            assert!(!x.is_finite(), "{x:?}");
            assert_eq!(x.check_finite(), Err(Error::NonFiniteState));
        }
    }
}

/// A quantity that overflows or underflows blames the parameter with the largest share of
/// its logarithm, `power ln |x|`, and says which way it went wrong: a large factor and a
/// large power (1e80 squared beats 1e100), a small divisor (1e-100 squared, divided by,
/// beats 1e150), and the underflow of a divisor.
#[test]
fn errors_blame_the_largest_share() {
    use lagrange_core::validate::{derived, divisor};
    let blamed = |e: Result<f64, Error>| match e {
        Err(Error::InvalidParameter { name, reason }) => Some((name, reason)),
        _ => None,
    };
    let inf = f64::INFINITY;
    assert_eq!(
        blamed(derived(inf, &[("a", 1e100, 1), ("b", 1e80, 2)])),
        Some((
            "b",
            "too large: a quantity formed from the parameters overflows"
        ))
    );
    assert_eq!(
        blamed(derived(inf, &[("x", 1e150, 1), ("m", 1e-100, -2)])),
        Some((
            "m",
            "too small: a quantity formed from the parameters (divided by it) overflows"
        ))
    );
    assert_eq!(
        blamed(divisor(0.0, &[("k", 1e-200, 1), ("m", 1e-150, 1)])),
        Some((
            "k",
            "too small: a quantity formed from the parameters that the motion divides by underflows"
        ))
    );
}
