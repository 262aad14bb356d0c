//! One acceleration law: every wrapper (a force added by `with_force`, the constrained wrapper,
//! both together) is right for explicit and implicit methods alike. The damped Cartesian
//! pendulum, a force wrapped around a constrained law, steps under Newton as the same pendulum
//! does in its one angle: as many iterations, the same motion to within the method's error.

use lagrange_core::{Constrained, Error, Forced, Mechanism, Projection, State, ViscousDamping};
use lagrange_integrators::{GaussLegendre2, ImplicitMidpoint, Integrator, Method, Projected};
use lagrange_systems::{CartesianPendulum, SimplePendulum};

const G: f64 = 9.81;

/// The Jacobian Newton uses on a constrained law wrapped by a force is the constrained law's:
/// a zero damping changes nothing (to the differences' rounding), where a Jacobian built from
/// the unconstrained equations is all zero for this free particle. Measured: the two agree to
/// 4e-9 of the entries' size (central differences of the same law at the same points, the
/// wrapper adding a zero); bound 1e-7.
#[test]
fn wrapped_constrained_jacobian_is_the_constrained_one() -> Result<(), Error> {
    let bare = Constrained::new(CartesianPendulum::new(1.0, 1.0, G)?);
    let wrapped = bare.with_force(ViscousDamping::uniform(0.0)?);
    for th in [0.3, 1.0, 2.5, -1.7] {
        let s = bare.parts().state_from_angle(0.0, th, 0.7);
        let (_, jb) = bare.acceleration_jacobian(&s)?;
        let (_, jw) = wrapped.acceleration_jacobian(&s)?;
        let size = jb
            .wrt_q
            .iter()
            .chain(jb.wrt_qd.iter())
            .fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(size > 1.0, "the constrained Jacobian is not zero: {jb:?}");
        let diff = (jb.wrt_q - jw.wrt_q)
            .iter()
            .chain((jb.wrt_qd - jw.wrt_qd).iter())
            .fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(diff < 1e-7 * size, "th {th}: {diff:e} of {size:e}");
    }
    Ok(())
}

/// What a run of an implicit method did: the angle at the end, and the Newton iterations per
/// step (largest, and the mean).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Run {
    angle: f64,
    most: u32,
    mean: f64,
}

/// The damped Cartesian pendulum: a force wrapped around a constrained law.
type Damped = Forced<Constrained<f64, 1, CartesianPendulum<f64>>, ViscousDamping<f64, 2>>;

/// `steps` steps of `dt` of a fresh `I` on `m` from `start` (projected onto `m`'s rows after
/// each step when `project`), the angle read by `angle`.
fn run<I, M>(
    m: &M,
    start: State<f64, 2>,
    dt: f64,
    steps: u64,
    angle: impl Fn(&State<f64, 2>) -> f64,
) -> Result<Run, Error>
where
    I: Default + Integrator<f64, 2, M>,
    M: Mechanism<f64, 2> + lagrange_core::Constraints<f64, 2, 1>,
{
    let mut stepper = Projected::new(I::default(), Projection::new(1e-13, 4)?);
    let (mut s, mut most, mut total) = (start, 0u32, 0u64);
    for _ in 0..steps {
        s = stepper.step(m, &s, dt)?;
        let k = stepper.last_step().iterations;
        most = most.max(k);
        total += u64::from(k);
    }
    Ok(Run {
        angle: angle(&s),
        most,
        mean: total as f64 / steps as f64,
    })
}

/// The angle form (minimal coordinates), the same pendulum as a damped constrained law, and
/// the bare constrained law with the damping given to the law as its extra force instead
/// (the two must be the same computation).
fn forms<I>(th0: f64, damping: f64, dt: f64, steps: u64) -> Result<[Run; 2], Error>
where
    I: Default + Integrator<f64, 1, SimplePendulum<f64>> + Integrator<f64, 2, Damped>,
{
    let angle_form = SimplePendulum::new(1.0, 1.0, G, damping)?;
    let mut minimal = I::default();
    let (mut s, mut most, mut total) = (State::at_rest([th0]), 0u32, 0u64);
    for _ in 0..steps {
        s = minimal.step(&angle_form, &s, dt)?;
        let k = minimal.last_step().iterations;
        most = most.max(k);
        total += u64::from(k);
    }
    let minimal = Run {
        angle: s.q[0],
        most,
        mean: total as f64 / steps as f64,
    };
    // A unit bob on a unit rod: the Cartesian damping c v has the torque c l^2 th'.
    let bare = Constrained::new(CartesianPendulum::new(1.0, 1.0, G)?);
    let damped: Damped = bare.with_force(ViscousDamping::uniform(damping)?);
    let start = bare.parts().state_from_angle(0.0, th0, 0.0);
    let angle = |s: &State<f64, 2>| bare.parts().angle(s).0;
    Ok([minimal, run::<I, _>(&damped, start, dt, steps, angle)?])
}

/// Both forms, and each form's own error at `dt` estimated from its run at `dt / 2`
/// (Richardson, order `p`; the method is not invariant under the change of coordinates, so
/// the two forms err differently): they must agree to within the sum of their errors (twice
/// it, plus the projection tolerance). Returns the two runs.
fn agree<I>(name: &str, order: u32, th0: f64, dt: f64, steps: u64) -> Result<[Run; 2], Error>
where
    I: Default + Integrator<f64, 1, SimplePendulum<f64>> + Integrator<f64, 2, Damped>,
{
    let [minimal, cartesian] = forms::<I>(th0, 0.3, dt, steps)?;
    let [minimal_half, cartesian_half] = forms::<I>(th0, 0.3, dt / 2.0, 2 * steps)?;
    let richardson = |coarse: f64, fine: f64| {
        let scale = f64::from(2u32.pow(order));
        (coarse - fine).abs() * scale / (scale - 1.0)
    };
    let error = richardson(minimal.angle, minimal_half.angle)
        + richardson(cartesian.angle, cartesian_half.angle);
    let difference = (minimal.angle - cartesian.angle).abs();
    println!(
        "{name} from {th0} rad at dt = {dt}: angle form {:.12}, Cartesian {:.12}, difference \
         {difference:.1e} (errors summed ~{error:.1e}); Newton iterations per step: angle \
         form at most {} (mean {:.2}), Cartesian at most {} (mean {:.2})",
        minimal.angle, cartesian.angle, minimal.most, minimal.mean, cartesian.most, cartesian.mean
    );
    assert!(
        difference <= 2.0 * error + 1e-12,
        "{name}: {difference:e} against {error:e}"
    );
    Ok([minimal, cartesian])
}

/// Gauss-Legendre 2 and the implicit midpoint rule on the pendulum damped at 0.3 from 2.5 rad,
/// in its angle and as a damped constrained law, projected:
///
/// - at dt = 1e-3 Newton needs as many iterations in both forms, within one (measured, angle
///   form against Cartesian: GL2 at most 3 against 4, means 2.75 against 3.49; midpoint at
///   most 3 against 4, means 2.73 against 3.37), and the two runs agree to within the
///   methods' errors;
/// - at dt = 1e-2 and at the large step dt = 0.2 (where a Newton matrix without the constraint
///   forces failed to converge at the third step) both converge and agree. The Cartesian
///   form's constraint force grows with the square of the velocity, so its stage accelerations
///   change more over a step and Newton takes more iterations from the same first guess
///   (measured means, angle form against Cartesian: GL2 3.02 against 5.02 at 1e-2, 4.70
///   against 6.75 at 0.2; midpoint 5.00 against 7.90 at 0.2, at most 18): asserted below
///   20, the default limit.
#[test]
fn implicit_methods_on_a_damped_constrained_pendulum() -> Result<(), Error> {
    for (dt, steps) in [(1e-3, 2000), (1e-2, 300), (0.2, 20)] {
        let gl = agree::<GaussLegendre2<f64>>(GaussLegendre2::<f64>::NAME, 4, 2.5, dt, steps)?;
        let mid = agree::<ImplicitMidpoint<f64>>(ImplicitMidpoint::<f64>::NAME, 2, 2.5, dt, steps)?;
        for [minimal, cartesian] in [gl, mid] {
            assert!(cartesian.most < 20, "{cartesian:?}");
            if dt <= 1e-3 {
                assert!(
                    cartesian.most <= minimal.most + 1,
                    "{cartesian:?} vs {minimal:?}"
                );
                assert!(
                    (cartesian.mean - minimal.mean).abs() <= 1.0,
                    "{cartesian:?} vs {minimal:?}"
                );
            }
        }
    }
    Ok(())
}

/// The damping added by wrapping the constrained law, and the same damping handed to the bare
/// law as its extra force at each evaluation, are one computation: Newton takes the same
/// iterations and ends in the same bits.
#[test]
fn a_wrapped_force_is_the_law_with_that_extra_force() -> Result<(), Error> {
    let damping = ViscousDamping::uniform(0.3)?;
    let bare = Constrained::new(CartesianPendulum::new(1.0, 1.0, G)?);
    let damped: Damped = bare.with_force(damping);
    let s = bare.parts().state_from_angle(0.0, 2.5, -1.0);
    assert_eq!(
        damped.acceleration(&s)?,
        bare.acceleration_with(&s, &damping)?
    );
    let (a, ja) = damped.acceleration_jacobian(&s)?;
    let (b, jb) = bare.law_jacobian(&s, &damping)?;
    assert_eq!((a, ja), (b, jb));
    Ok(())
}
