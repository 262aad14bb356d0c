//! Generated against hand-derived: where `lagrange-systems` has a mechanism written by hand and
//! `derive/specs/` the same one for SymPy (the pendulum, the double pendulum, the three-link
//! chain, the Cartesian pendulum), the two agree at random states (parameters away from the
//! defaults), in `f64` and `f32`: accelerations, mass matrices, right-hand sides, forces,
//! energies, the links' frames and the points on them (positions and Jacobians, the generated
//! ones by dual numbers from the spec's `links`, the hand-derived ones by hand), and for the
//! constrained one its rows, constrained accelerations and multipliers.

use lagrange_core::constraints::Constraints;
use lagrange_core::links::Links;
use lagrange_core::{Constrained, Error, Mechanism, Real, State};
use lagrange_generated as generated;
use lagrange_systems as hand;
use lagrange_tests::{for_f32_and_f64, pick, random_state, relative, Rng};

/// Random states compared per mechanism.
const STATES: usize = 1000;
/// Largest relative disagreement in `f64` (values compared relative to their size plus one).
const F64_TOLERANCE: f64 = 1e-12;
/// Largest relative disagreement in `f32`.
const F32_TOLERANCE: f64 = 1e-4;

/// `|a - b| / (|a| + 1)` over the entries must stay below the tolerance for `T`.
fn close<T: Real>(what: &str, s: &impl core::fmt::Debug, a: &[T], b: &[T]) {
    let e = relative(a.iter().copied(), b.iter().copied(), 1.0);
    let tolerance = pick::<T>(F32_TOLERANCE, F64_TOLERANCE);
    assert!(
        e < tolerance,
        "{what} at {s:?}: {a:?} against {b:?} ({e:e})"
    );
}

/// Accelerations, mass matrices, right-hand sides, forces and energies of two free mechanisms.
fn same_free<T: Real, const N: usize>(
    a: &impl Mechanism<T, N>,
    b: &impl Mechanism<T, N>,
    s: &State<T, N>,
) -> Result<(), Error> {
    close(
        "q''",
        s,
        a.acceleration(s)?.as_slice(),
        b.acceleration(s)?.as_slice(),
    );
    close(
        "M",
        s,
        a.mass_matrix(s).as_slice(),
        b.mass_matrix(s).as_slice(),
    );
    close("f", s, a.rhs(s).as_slice(), b.rhs(s).as_slice());
    close(
        "Q",
        s,
        a.non_conservative_force(s).as_slice(),
        b.non_conservative_force(s).as_slice(),
    );
    close("T", s, &[a.kinetic_energy(s)], &[b.kinetic_energy(s)]);
    close("V", s, &[a.potential_energy(s)], &[b.potential_energy(s)]);
    Ok(())
}

/// Every link's frame, and three points on each (their positions and Jacobians), of two
/// mechanisms with links.
fn same_links<T: Real, const N: usize>(
    a: &impl Links<T, N>,
    b: &impl Links<T, N>,
    s: &State<T, N>,
    links: usize,
) {
    for link in 0..links {
        let (pa, pb) = (a.pose(&s.q, link), b.pose(&s.q, link));
        close("link origin", s, &pa.origin, &pb.origin);
        close("link angle", s, &[pa.angle], &[pb.angle]);
        for local in [[0.0, 0.0], [0.0, -0.6], [0.25, -1.1]] {
            let local = local.map(T::from_f64);
            let (xa, xb) = (a.point(&s.q, link, local), b.point(&s.q, link, local));
            close("point", s, &xa.position, &xb.position);
            close(
                "point Jacobian",
                s,
                xa.jacobian.as_slice(),
                xb.jacobian.as_slice(),
            );
        }
    }
}

fn pendulum<T: Real>() -> Result<(), Error> {
    let p = [1.3, 0.7, 9.81, 0.2].map(T::from_f64);
    let g = generated::Pendulum::new(p[0], p[1], p[2], p[3])?;
    let h = hand::SimplePendulum::new(p[0], p[1], p[2], p[3])?;
    let mut rng = Rng::new(1);
    for _ in 0..STATES {
        let s = random_state(&mut rng, (-4.0, 4.0), (-5.0, 5.0));
        same_free(&g, &h, &s)?;
        same_links(&g, &h, &s, 1);
    }
    Ok(())
}

fn double_pendulum<T: Real>() -> Result<(), Error> {
    let p = [1.2, 0.8, 0.9, 1.1, 9.81].map(T::from_f64);
    let g = generated::DoublePendulum::new(p[0], p[1], p[2], p[3], p[4])?;
    let h = hand::DoublePendulum::new(p[0], p[1], p[2], p[3], p[4])?;
    let mut rng = Rng::new(2);
    for _ in 0..STATES {
        let s = random_state(&mut rng, (-4.0, 4.0), (-5.0, 5.0));
        same_free(&g, &h, &s)?;
        same_links(&g, &h, &s, 2);
    }
    Ok(())
}

fn triple_pendulum<T: Real>() -> Result<(), Error> {
    let m = [1.2, 0.8, 0.5].map(T::from_f64);
    let l = [0.9, 1.1, 0.7].map(T::from_f64);
    let g = T::from_f64(9.81);
    let generated = generated::TriplePendulum::new(m[0], m[1], m[2], l[0], l[1], l[2], g)?;
    let h = hand::NLinkPendulum::new(m, l, g)?;
    let mut rng = Rng::new(4);
    for _ in 0..STATES {
        let s = random_state(&mut rng, (-4.0, 4.0), (-5.0, 5.0));
        same_free(&generated, &h, &s)?;
        same_links(&generated, &h, &s, 3);
    }
    Ok(())
}

fn cartesian_pendulum<T: Real>() -> Result<(), Error> {
    let p = [0.9, 1.4, 9.81].map(T::from_f64);
    let g = generated::CartesianPendulum::new(p[0], p[1], p[2])?;
    let h = hand::CartesianPendulum::new(p[0], p[1], p[2])?;
    let (cg, ch) = (Constrained::new(g), Constrained::new(h));
    let mut rng = Rng::new(3);
    for _ in 0..STATES {
        // On the circle (the hand-derived helper places the bob), and anywhere in the plane.
        let th = rng.uniform::<T>(-3.0, 3.0);
        let thd = rng.uniform::<T>(-3.0, 3.0);
        let on = h.state_from_angle(T::zero(), th, thd);
        let off = random_state(&mut rng, (-2.0, 2.0), (-3.0, 3.0));
        for s in [on, off] {
            same_free(&g, &h, &s)?;
            close(
                "phi",
                &s,
                g.position_residual(&s.q).as_slice(),
                h.position_residual(&s.q).as_slice(),
            );
            close(
                "J",
                &s,
                g.jacobian(&s.q).as_slice(),
                h.jacobian(&s.q).as_slice(),
            );
            close(
                "J'q'",
                &s,
                g.velocity_product(&s.q, &s.qd).as_slice(),
                h.velocity_product(&s.q, &s.qd).as_slice(),
            );
            let (a, b) = (cg.solve(&s)?, ch.solve(&s)?);
            close(
                "constrained q''",
                &s,
                a.acceleration.as_slice(),
                b.acceleration.as_slice(),
            );
            close(
                "lambda",
                &s,
                a.multipliers.as_slice(),
                b.multipliers.as_slice(),
            );
        }
    }
    Ok(())
}

for_f32_and_f64!(
    pendulum,
    double_pendulum,
    triple_pendulum,
    cartesian_pendulum
);
