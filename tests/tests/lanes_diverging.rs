//! A law that branches differently in different lanes: the divergence is counted and a bank
//! steps its instances one by one, with the bits of each alone. (A test binary of its own:
//! the divergence count is per process, and the other lane tests assert it does not move.)

use lagrange_core::nalgebra::SVector;
use lagrange_core::{
    divergences, Error, Gather, GeneralizedForce, Lagrangian, Lanes, Mechanism, Real, Scalar, State,
};
use lagrange_integrators::scene::{Bank, InLanes, NeverSleeps, Scene, LANES};
use lagrange_integrators::{FixedTimestep, Rk4};
use lagrange_tests::for_f32_and_f64;

/// Lanes per group (the scene's width on x86_64).
const L: usize = 8;

/// A spring whose stiffness doubles where `x < 0`: a law that branches on the state, so that
/// lanes on both sides of zero take different branches.
#[derive(Debug, Clone, Copy, PartialEq)]
struct KinkedSpring<T> {
    k: T,
}

impl<T: Real> Lagrangian<T, 1> for KinkedSpring<T> {
    fn kinetic<S: Scalar<Real = T>>(&self, _t: S, _q: &SVector<S, 1>, qd: &SVector<S, 1>) -> S {
        qd[0] * qd[0] * T::HALF
    }
    fn potential<S: Scalar<Real = T>>(&self, _t: S, q: &SVector<S, 1>) -> S {
        let k = if q[0].value() < T::zero() {
            self.k * T::TWO
        } else {
            self.k
        };
        q[0] * q[0] * (k * T::HALF)
    }
}

impl<T: Real> Mechanism<T, 1> for KinkedSpring<T> {
    fn mass_matrix(&self, _s: &State<T, 1>) -> lagrange_core::nalgebra::SMatrix<T, 1, 1> {
        lagrange_core::nalgebra::SMatrix::identity()
    }
    fn rhs(&self, s: &State<T, 1>) -> SVector<T, 1> {
        let k = if s.q[0] < T::zero() {
            self.k * T::TWO
        } else {
            self.k
        };
        SVector::from([-k * s.q[0]])
    }
    fn law<F: GeneralizedForce<T, 1>>(
        &self,
        s: &State<T, 1>,
        extra: &F,
    ) -> Result<SVector<T, 1>, Error> {
        Ok(extra.added_to(s, self.rhs(s)))
    }
}

impl<T: Real> Gather<T, 1> for KinkedSpring<T> {
    type Gathered<const W: usize> = KinkedSpring<Lanes<T, W>>;
    fn gather<const W: usize>(instances: [&Self; W]) -> KinkedSpring<Lanes<T, W>> {
        KinkedSpring {
            k: Lanes::gather(&instances, |m| m.k),
        }
    }
    fn window<const W: usize, const V: usize>(
        wide: &KinkedSpring<Lanes<T, W>>,
        at: usize,
    ) -> KinkedSpring<Lanes<T, V>> {
        KinkedSpring {
            k: wide.k.window(at),
        }
    }
    fn put<const W: usize>(&self, lanes: &mut KinkedSpring<Lanes<T, W>>, lane: usize) {
        lanes.k.set(lane, self.k);
    }
}

/// Springs swinging through their kink: their lanes diverge, the divergence is counted, and a
/// bank steps them one by one: every instance equals its `FixedTimestep` run bit for bit.
fn diverging_lanes_fall_back<T: Real>() -> Result<(), Error> {
    const K: usize = 2 * L;
    let dt = T::from_f64(1e-2);
    let mut bank: Bank<T, 1, K, KinkedSpring<T>, Rk4, NeverSleeps, InLanes> =
        Bank::new(Rk4, NeverSleeps)?;
    let mut alone = Vec::new();
    for i in 0..K {
        // Stiffnesses of their own: a kinked spring's period does not depend on its
        // amplitude, so equal springs would cross the kink together.
        let m = KinkedSpring {
            k: T::from_f64(4.0 + 0.37 * i as f64),
        };
        let s = State::new(T::zero(), [T::from_f64(0.1 * i as f64 - 0.75)], [T::zero()]);
        let id = bank.add(m, s)?;
        alone.push((id, m, FixedTimestep::new(Rk4, dt, 1, s)?));
    }
    let mut scene = Scene::new(bank, dt, 1)?;
    let before = divergences();
    for _ in 0..500 {
        scene.advance(dt)?;
        for (id, m, clock) in &mut alone {
            clock.advance(m, dt)?;
            assert_eq!(scene.banks().state(*id)?.q, clock.current().q);
        }
    }
    if LANES > 1 {
        assert_ne!(divergences(), before, "the kink never split the lanes");
    }
    Ok(())
}

/// A branch on finiteness counts a divergence where the lanes disagree (unlike the tests of
/// results, [`lagrange_core::check_finite`], whose failure ends the computation): a law may
/// choose between two formulas by it.
fn a_branch_on_finiteness_counts<T: Real>() -> Result<(), Error> {
    let mixed = Lanes::<T, L>::from_fn(|i| if i == 3 { T::INFINITY } else { T::one() });
    let before = divergences();
    assert!(!mixed.is_finite());
    if cfg!(target_has_atomic = "32") {
        assert_ne!(divergences(), before, "a disagreement went uncounted");
    }
    assert!(Lanes::<T, L>::splat(T::one()).is_finite());
    assert!(!Lanes::<T, L>::splat(T::INFINITY).is_finite());
    Ok(())
}

/// A comparison the lanes disagree on is false (an ordering, none) and counts a divergence,
/// each; so does reading lanes that differ as one plain number (the first lane's).
fn a_split_comparison_is_false_and_counts<T: Real>() -> Result<(), Error> {
    let x = Lanes::<T, L>::from_fn(|i| T::from_f64(i as f64));
    let mid = Lanes::<T, L>::splat(T::from_f64(3.5));
    let counting = cfg!(target_has_atomic = "32");
    let mut count = divergences().unwrap_or(0);
    let mut check = |answer: bool, what: &str| {
        assert!(!answer, "{what}");
        let now = divergences().unwrap_or(0);
        if counting {
            assert!(now > count, "{what} went uncounted");
        }
        count = now;
    };
    check(x < mid, "<");
    check(x <= mid, "<=");
    check(x > mid, ">");
    check(x >= mid, ">=");
    check(
        x == Lanes::from_fn(|i| T::from_f64(if i == 2 { 9.0 } else { i as f64 })),
        "==",
    );
    check(x.partial_cmp(&mid).is_some(), "partial_cmp");
    check(x.to_f64() != 0.0, "to_f64 (the first lane)");
    Ok(())
}

for_f32_and_f64!(
    diverging_lanes_fall_back,
    a_branch_on_finiteness_counts,
    a_split_comparison_is_false_and_counts
);
