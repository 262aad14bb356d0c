//! [`OneOf`]: a body that is one of two kinds of mechanism, so that one [`World`](crate::World)
//! holds both (balls and the pendulums they strike, boxes and ragdolls).

use lagrange_core::links::{LinkPoint, Links, Pose};
use lagrange_core::nalgebra::{ArrayStorage, SMatrix, SVector};
use lagrange_core::{Error, GeneralizedForce, Lagrangian, Mechanism, Real, Scalar, State};

/// A mechanism of the kind `A` (`NA` coordinates) or `B` (`NB`), as one of `N` coordinates
/// with `N` at least the larger: its own coordinates first, the rest idle.
///
/// A [`World`](crate::World) holds bodies of one type; `OneOf` is that type for a world of
/// two kinds (nest it, `OneOf<A, OneOf<B, C, NB, NC>, NA, N>`, for more). Each body keeps its
/// own law, mass solve and links (a ball's constant mass, a ragdoll's articulated-body
/// recursion, their hand-derived point Jacobians): the variant is matched once per call.
///
/// The coordinates past a body's own are idle: unit mass, no force, no link moves with them,
/// so no contact acts on them and, started at rest (as [`OneOf::first_state`] and
/// [`OneOf::second_state`] place them), they stay at rest and add nothing to the energy.
/// What it costs: every body of the world carries `N` coordinates, and a world's rows,
/// mass solves and states are that wide (a world of balls and ragdolls steps its balls in
/// 12 coordinates rather than 3); a world of one kind is cheaper built on that kind alone.
///
/// `N` below `NA` or `NB` is refused when the program is compiled.
///
/// ```
/// use lagrange_core::{Mechanism, State};
/// use lagrange_systems::{RigidBody, SimplePendulum};
/// use lagrange_world::OneOf;
/// type Body = OneOf<SimplePendulum<f64>, RigidBody<f64>, 1, 3>;
/// let ball: Body = OneOf::Second(RigidBody::disk(1.0, 0.1, 9.81)?);
/// let s = Body::second_state::<f64, 3>(&State::at_rest([0.0, 2.0, 0.0]));
/// assert_eq!(ball.acceleration(&s)?.as_slice(), &[0.0, -9.81, 0.0]);
/// let bob: Body = OneOf::First(SimplePendulum::new(1.0, 1.0, 9.81, 0.0)?);
/// let s = Body::first_state::<f64, 3>(&State::at_rest([0.5]));
/// let a = bob.acceleration(&s)?;
/// assert_eq!((a[1], a[2]), (0.0, 0.0));
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum OneOf<A, B, const NA: usize, const NB: usize> {
    /// A body of the first kind: its coordinates are the first `NA`.
    First(A),
    /// A body of the second kind: its coordinates are the first `NB`.
    Second(B),
}

impl<A, B, const NA: usize, const NB: usize> OneOf<A, B, NA, NB> {
    /// `s`, a state of a body of the first kind, with the idle coordinates at zero and at
    /// rest: the state to give the world for it.
    #[must_use]
    pub fn first_state<T: Real, const N: usize>(s: &State<T, NA>) -> State<T, N> {
        widened(s)
    }

    /// `s`, a state of a body of the second kind, with the idle coordinates at zero and at
    /// rest.
    #[must_use]
    pub fn second_state<T: Real, const N: usize>(s: &State<T, NB>) -> State<T, N> {
        widened(s)
    }

    /// The state of a body of the first kind: the first `NA` coordinates of `s`.
    #[must_use]
    pub fn first_part<T: Real, const N: usize>(s: &State<T, N>) -> State<T, NA> {
        narrowed(s)
    }

    /// The state of a body of the second kind: the first `NB` coordinates of `s`.
    #[must_use]
    pub fn second_part<T: Real, const N: usize>(s: &State<T, N>) -> State<T, NB> {
        narrowed(s)
    }
}

/// The first `K` entries of `v` (`K <= N`, checked when compiled).
fn cut<S: Scalar, const K: usize, const N: usize>(v: &SVector<S, N>) -> SVector<S, K> {
    const { assert!(K <= N, "a OneOf of N coordinates holds kinds of at most N") };
    // Built from arrays: a scalar of the automatic path need not be 'static, which
    // nalgebra's constructors ask.
    let a: [S; K] = core::array::from_fn(|i| v[i]);
    SVector::from_array_storage(ArrayStorage([a]))
}

/// `v` in the first `K` entries and `rest`'s entries past them (`K <= N`, checked when
/// compiled).
fn widen<S: Scalar, const K: usize, const N: usize>(
    v: &SVector<S, K>,
    rest: &SVector<S, N>,
) -> SVector<S, N> {
    const { assert!(K <= N, "a OneOf of N coordinates holds kinds of at most N") };
    let a: [S; N] = core::array::from_fn(|i| if i < K { v[i] } else { rest[i] });
    SVector::from_array_storage(ArrayStorage([a]))
}

/// A state of `K` coordinates as one of `N`, the rest zero.
fn widened<T: Real, const K: usize, const N: usize>(s: &State<T, K>) -> State<T, N> {
    let zero = SVector::zeros();
    State {
        t: s.t,
        q: widen(&s.q, &zero),
        qd: widen(&s.qd, &zero),
    }
}

/// The first `K` coordinates of a state of `N`.
fn narrowed<T: Real, const K: usize, const N: usize>(s: &State<T, N>) -> State<T, K> {
    State {
        t: s.t,
        q: cut(&s.q),
        qd: cut(&s.qd),
    }
}

/// `½ |qd|²` over the idle coordinates past the first `K`.
fn idle_kinetic<S: Scalar, const K: usize, const N: usize>(qd: &SVector<S, N>) -> S {
    (K..N).fold(S::zero(), |sum, i| sum + qd[i] * qd[i] * S::from_f64(0.5))
}

/// `m` in the first `K` rows and columns, the identity past them.
fn block<T: Real, const K: usize, const N: usize>(m: &SMatrix<T, K, K>) -> SMatrix<T, N, N> {
    SMatrix::from_fn(|i, j| match (i < K, j < K) {
        (true, true) => m.get((i, j)).copied().unwrap_or_else(T::zero),
        _ if i == j => T::one(),
        _ => T::zero(),
    })
}

impl<T, A, B, const NA: usize, const NB: usize, const N: usize> Lagrangian<T, N>
    for OneOf<A, B, NA, NB>
where
    T: Real,
    A: Lagrangian<T, NA>,
    B: Lagrangian<T, NB>,
{
    const EXPLICIT_TIME: bool = A::EXPLICIT_TIME || B::EXPLICIT_TIME;
    const CONSTANT_MASS: bool = A::CONSTANT_MASS && B::CONSTANT_MASS;
    const DRIVEN: bool = A::DRIVEN || B::DRIVEN;
    const READS_TIME: bool = A::READS_TIME || B::READS_TIME;

    fn kinetic<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>, qd: &SVector<S, N>) -> S {
        match self {
            Self::First(a) => a.kinetic(t, &cut(q), &cut(qd)) + idle_kinetic::<S, NA, N>(qd),
            Self::Second(b) => b.kinetic(t, &cut(q), &cut(qd)) + idle_kinetic::<S, NB, N>(qd),
        }
    }

    fn potential<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>) -> S {
        match self {
            Self::First(a) => a.potential(t, &cut(q)),
            Self::Second(b) => b.potential(t, &cut(q)),
        }
    }

    fn non_conservative_force(&self, state: &State<T, N>) -> SVector<T, N> {
        let zero = SVector::zeros();
        match self {
            Self::First(a) => widen(&a.non_conservative_force(&narrowed(state)), &zero),
            Self::Second(b) => widen(&b.non_conservative_force(&narrowed(state)), &zero),
        }
    }
}

impl<T, A, B, const NA: usize, const NB: usize, const N: usize> Mechanism<T, N>
    for OneOf<A, B, NA, NB>
where
    T: Real,
    A: Mechanism<T, NA>,
    B: Mechanism<T, NB>,
{
    fn mass_matrix(&self, state: &State<T, N>) -> SMatrix<T, N, N> {
        match self {
            Self::First(a) => block(&a.mass_matrix(&narrowed(state))),
            Self::Second(b) => block(&b.mass_matrix(&narrowed(state))),
        }
    }

    fn rhs(&self, state: &State<T, N>) -> SVector<T, N> {
        let zero = SVector::zeros();
        match self {
            Self::First(a) => widen(&a.rhs(&narrowed(state)), &zero),
            Self::Second(b) => widen(&b.rhs(&narrowed(state)), &zero),
        }
    }

    /// The body's own mass solve; an idle coordinate's unit mass leaves its entry as it is.
    fn solve_mass(&self, state: &State<T, N>, b: &SVector<T, N>) -> Result<SVector<T, N>, Error> {
        Ok(match self {
            Self::First(m) => widen(&m.solve_mass(&narrowed(state), &cut(b))?, b),
            Self::Second(m) => widen(&m.solve_mass(&narrowed(state), &cut(b))?, b),
        })
    }

    /// The body's own batched solve (one factorisation for all the columns where it has
    /// one); the idle coordinates' entries left as they are, as in `solve_mass`.
    fn velocity_jumps<const K: usize>(
        &self,
        state: &State<T, N>,
        impulses: &mut SMatrix<T, N, K>,
    ) -> Result<(), Error> {
        match self {
            Self::First(m) => jumps_of(m, state, impulses),
            Self::Second(m) => jumps_of(m, state, impulses),
        }
    }

    /// The body's own law, with the extra force's first entries; an idle coordinate
    /// accelerates by its entry of the extra force (unit mass).
    fn law<F: GeneralizedForce<T, N>>(
        &self,
        state: &State<T, N>,
        extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        let f = extra.added_to(state, SVector::zeros());
        Ok(match self {
            Self::First(a) => {
                let own: SVector<T, NA> = cut(&f);
                widen(&a.law(&narrowed(state), &move |_: &State<T, NA>| own)?, &f)
            }
            Self::Second(b) => {
                let own: SVector<T, NB> = cut(&f);
                widen(&b.law(&narrowed(state), &move |_: &State<T, NB>| own)?, &f)
            }
        })
    }

    fn reads_velocities(&self) -> bool {
        match self {
            Self::First(a) => a.reads_velocities(),
            Self::Second(b) => b.reads_velocities(),
        }
    }
}

impl<T, A, B, const NA: usize, const NB: usize, const N: usize> Links<T, N> for OneOf<A, B, NA, NB>
where
    T: Real,
    A: Links<T, NA>,
    B: Links<T, NB>,
{
    /// The larger kind's. A shape on a link past a body's own is placed where the body puts
    /// a link out of its range (some pose, never a panic: the [`Links`] contract): give each
    /// body shapes on its own links.
    const LINKS: usize = if A::LINKS > B::LINKS {
        A::LINKS
    } else {
        B::LINKS
    };

    fn pose<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, N>, link: usize) -> Pose<S> {
        match self {
            Self::First(a) => a.pose(&cut(q), link),
            Self::Second(b) => b.pose(&cut(q), link),
        }
    }

    /// The body's own poses (from one pass where it shares them).
    fn poses(&self, q: &SVector<T, N>, poses: &mut [Pose<T>]) {
        match self {
            Self::First(a) => a.poses(&cut(q), poses),
            Self::Second(b) => b.poses(&cut(q), poses),
        }
    }

    /// The body's own point (its hand-derived Jacobian where it has one), with zero columns
    /// for the idle coordinates.
    fn point(&self, q: &SVector<T, N>, link: usize, local: [T; 2]) -> LinkPoint<T, N> {
        let (position, jacobian) = match self {
            Self::First(a) => {
                let p = a.point(&cut(q), link, local);
                (p.position, columns(&p.jacobian))
            }
            Self::Second(b) => {
                let p = b.point(&cut(q), link, local);
                (p.position, columns(&p.jacobian))
            }
        };
        LinkPoint { position, jacobian }
    }
}

/// `mechanism`'s [`Mechanism::velocity_jumps`] of the first `NM` rows of `impulses`, the
/// rows past them left as they are.
fn jumps_of<T: Real, M: Mechanism<T, NM>, const NM: usize, const N: usize, const K: usize>(
    mechanism: &M,
    state: &State<T, N>,
    impulses: &mut SMatrix<T, N, K>,
) -> Result<(), Error> {
    let mut own = SMatrix::<T, NM, K>::from_fn(|i, k| impulses[(i, k)]);
    mechanism.velocity_jumps(&narrowed(state), &mut own)?;
    for k in 0..K {
        for i in 0..NM {
            impulses[(i, k)] = own[(i, k)];
        }
    }
    Ok(())
}

/// `j`'s `K` columns, then zero columns up to `N`.
fn columns<T: Real, const K: usize, const N: usize>(j: &SMatrix<T, 2, K>) -> SMatrix<T, 2, N> {
    SMatrix::from_fn(|r, c| j.get((r, c)).copied().unwrap_or_else(T::zero))
}
