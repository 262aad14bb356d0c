//! Every hand-derived constraint set agrees with the one dual numbers derive from `phi` or
//! `A` alone, and every constrained mechanism's accelerations and multipliers agree with the
//! fully automatic path (`Constrained` over `EulerLagrange` with `Holonomic` or `Pfaffian`), at
//! 500 random states each.

use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{
    Constrained, Constraints, Error, EulerLagrange, Holonomic, Lagrangian, Mechanism, Pfaffian,
    Real, State,
};
use lagrange_systems::{Branch, CartesianPendulum, FourBarLinkage, RollingDisk};
use lagrange_tests::{for_f32_and_f64, pick, Rng};

const STATES: usize = 500;

/// `|a - b|_inf / (|a|_inf + scale)`.
fn relative<T: Real>(
    a: impl IntoIterator<Item = T>,
    b: impl IntoIterator<Item = T>,
    scale: f64,
) -> f64 {
    let (mut diff, mut size) = (0.0f64, 0.0f64);
    for (x, y) in a.into_iter().zip(b) {
        diff = diff.max((x - y).abs().to_f64());
        size = size.max(x.abs().to_f64());
    }
    diff / (size + scale)
}

/// Both paths compute the same terms in a different order; the constrained solve then adds a
/// Schur complement and its Cholesky factor. Measured worst over the three systems: f64
/// 7.1e-16 (~3 ulps), f32 2.5e-7 (~2 ulps); bounds 3.5e-15 and 1.3e-6.
fn tolerance<T: Real>() -> f64 {
    pick::<T>(1.3e-6, 3.5e-15)
}

/// `hand` (the parts of a constrained mechanism: the unconstrained mechanism and its
/// constraints) against `auto_constraints`, and `Constrained::new(hand)` against
/// `EulerLagrange::new(hand).held_by(auto_constraints)`, at `states`; `scale` is a natural
/// size of the accelerations and multipliers.
fn agree<T, S, A, const N: usize, const C: usize>(
    hand: &S,
    auto_constraints: A,
    states: impl Iterator<Item = Result<State<T, N>, Error>>,
    scale: f64,
) -> Result<f64, Error>
where
    T: Real,
    S: Mechanism<T, N> + Constraints<T, N, C> + Lagrangian<T, N> + Clone,
    A: Constraints<T, N, C>,
{
    let constrained = Constrained::<T, C, S>::new(hand.clone());
    let auto = EulerLagrange::new(hand.clone()).held_by(auto_constraints);
    let tol = tolerance::<T>();
    let mut worst: f64 = 0.0;
    for s in states {
        let s = s?;
        let pairs: [(SVector<T, C>, SVector<T, C>); 2] = [
            (
                hand.position_residual(&s.q),
                auto.parts().rows().position_residual(&s.q),
            ),
            (
                hand.velocity_product(&s.q, &s.qd),
                auto.parts().rows().velocity_product(&s.q, &s.qd),
            ),
        ];
        for (a, b) in pairs {
            let e = relative(a.iter().copied(), b.iter().copied(), scale);
            worst = worst.max(e);
            assert!(e < tol, "at {s:?}: hand {a:?} auto {b:?} ({e:e})");
        }
        // The open chain's split form too (a solve_mass of its own can hide a wrong matrix).
        let free = EulerLagrange::new(hand.clone());
        let (ma, mb) = (hand.mass_matrix(&s), free.mass_matrix(&s));
        let e = relative(ma.iter().copied(), mb.iter().copied(), 1.0);
        worst = worst.max(e);
        assert!(
            e < tol,
            "mass matrix at {s:?}: hand {ma:?} auto {mb:?} ({e:e})"
        );
        let (ra, rb) = (hand.rhs(&s), free.rhs(&s));
        let e = relative(ra.iter().copied(), rb.iter().copied(), scale);
        worst = worst.max(e);
        assert!(e < tol, "rhs at {s:?}: hand {ra:?} auto {rb:?} ({e:e})");
        let (ja, jb): (SMatrix<T, C, N>, SMatrix<T, C, N>) =
            (hand.jacobian(&s.q), auto.parts().rows().jacobian(&s.q));
        let e = relative(ja.iter().copied(), jb.iter().copied(), 1.0);
        worst = worst.max(e);
        assert!(
            e < tol,
            "jacobian at {s:?}: hand {ja:?} auto {jb:?} ({e:e})"
        );
        let a = constrained.acceleration(&s)?;
        let b = auto.solve(&s)?;
        let e = relative(a.iter().copied(), b.acceleration.iter().copied(), scale);
        worst = worst.max(e);
        assert!(e < tol, "acceleration at {s:?}: {a:?} vs {b:?} ({e:e})");
    }
    Ok(worst)
}

fn cartesian_pendulum_agrees<T: Real>() -> Result<(), Error> {
    let mut rng = Rng::new(61);
    let p = CartesianPendulum::new(
        rng.uniform(0.5, 2.0),
        rng.uniform(0.5, 2.0),
        T::from_f64(9.81),
    )?;
    // Anywhere but near the pivot, on the circle or off it.
    let states = (0..STATES).map(|_| {
        let r: T = rng.uniform(0.3, 3.0);
        let (s, c) = rng.uniform::<T>(-3.2, 3.2).sin_cos();
        Ok(State::new(
            T::zero(),
            [r * s, r * c],
            [rng.uniform(-5.0, 5.0), rng.uniform(-5.0, 5.0)],
        ))
    });
    let worst = agree(&p, Holonomic::new(p), states, 10.0)?;
    let multipliers = Constrained::new(p).solve(&State::new(
        T::zero(),
        [T::one(), T::zero()],
        [T::zero(); 2],
    ))?;
    assert!(multipliers.multipliers[0].abs() < T::EPSILON);
    println!("Cartesian pendulum: worst relative difference {worst:.1e}");
    Ok(())
}

fn four_bar_agrees<T: Real>() -> Result<(), Error> {
    let mut rng = Rng::new(62);
    let linkage = FourBarLinkage::new(
        [T::one(), T::from_f64(0.3), T::one(), T::from_f64(0.8)],
        [
            rng.uniform(0.5, 2.0),
            rng.uniform(0.5, 2.0),
            rng.uniform(0.5, 2.0),
        ],
        T::from_f64(9.81),
    )?;
    // Consistent states (a crank-rocker closes at every crank angle), both branches.
    let states = (0..STATES).map(|i| {
        let branch = if i % 2 == 0 {
            Branch::Left
        } else {
            Branch::Right
        };
        linkage.assemble(
            T::zero(),
            rng.uniform(-3.2, 3.2),
            rng.uniform(-8.0, 8.0),
            branch,
        )
    });
    let worst = agree(&linkage, Holonomic::new(linkage), states, 100.0)?;
    println!("four-bar linkage: worst relative difference {worst:.1e}");
    Ok(())
}

fn rolling_disk_agrees<T: Real>() -> Result<(), Error> {
    let mut rng = Rng::new(63);
    let disk = RollingDisk::new(rng.uniform(0.5, 2.0), rng.uniform(0.1, 1.0))?;
    // Any state: the rows need not be satisfied for the formulas to agree.
    let states = (0..STATES).map(|_| {
        Ok(State::new(
            T::zero(),
            core::array::from_fn(|_| rng.uniform(-3.2, 3.2)),
            core::array::from_fn(|_| rng.uniform(-5.0, 5.0)),
        ))
    });
    let worst = agree(&disk, Pfaffian::new(disk), states, 10.0)?;
    println!("rolling disk: worst relative difference {worst:.1e}");
    Ok(())
}

for_f32_and_f64!(
    cartesian_pendulum_agrees,
    four_bar_agrees,
    rolling_disk_agrees
);
