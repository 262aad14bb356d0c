//! [`Pair`]: two mechanisms as one, their coordinates side by side, so that contacts between
//! them are rows of one mechanism that the contact steppers already solve.

use lagrange_core::links::{Links, Pose};
use lagrange_core::nalgebra::{ArrayStorage, SMatrix, SVector};
use lagrange_core::{Error, GeneralizedForce, Lagrangian, Mechanism, Real, Scalar, State};

/// Two mechanisms `a` (`NA` coordinates) and `b` (`NB`) as one of `N = NA + NB` coordinates,
/// `q = [q_a, q_b]`: their kinetic and potential energies add, the mass matrix is
/// block-diagonal, and each one's law is its own (`a`'s accelerations are `a.law` of its half
/// of the state). Their links are `a`'s, then `b`'s ([`Links`]), so that a contact between a
/// shape on each (`ShapePairs`) is a row through both mechanisms' point Jacobians: an impulse
/// on it changes both halves of `q'`, equal and opposite on the bodies.
///
/// `N` must be `NA + NB`: any other is refused when the program is compiled.
///
/// ```
/// use lagrange_core::{Mechanism, State};
/// use lagrange_systems::RigidBody;
/// use lagrange_world::Pair;
/// let ball = RigidBody::disk(1.0, 0.1, 9.81)?;
/// let two = Pair::<_, _, 3, 3>::new(ball, ball);
/// let s = State::<f64, 6>::new(0.0, [0.0; 6], [0.0; 6]);
/// assert_eq!(two.acceleration(&s)?.as_slice(), &[0.0, -9.81, 0.0, 0.0, -9.81, 0.0]);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Pair<A, B, const NA: usize, const NB: usize> {
    a: A,
    b: B,
}

impl<A, B, const NA: usize, const NB: usize> Pair<A, B, NA, NB> {
    /// `a` and `b` side by side.
    pub fn new(a: A, b: B) -> Self {
        Self { a, b }
    }
    /// The first mechanism.
    pub fn first(&self) -> &A {
        &self.a
    }
    /// The second mechanism.
    pub fn second(&self) -> &B {
        &self.b
    }
}

/// `v`'s first `NA` entries and its next `NB` (`N = NA + NB`, checked when compiled).
fn split<S: Scalar, const NA: usize, const NB: usize, const N: usize>(
    v: &SVector<S, N>,
) -> (SVector<S, NA>, SVector<S, NB>) {
    const {
        assert!(
            N == NA + NB,
            "a Pair of NA and NB coordinates has N = NA + NB"
        )
    };
    // Built from arrays: a scalar of the automatic path need not be 'static, which
    // nalgebra's constructors ask.
    let a: [S; NA] = core::array::from_fn(|i| v[i]);
    let b: [S; NB] = core::array::from_fn(|i| v[NA + i]);
    (
        SVector::from_array_storage(ArrayStorage([a])),
        SVector::from_array_storage(ArrayStorage([b])),
    )
}

/// `a` then `b`.
fn join<S: Scalar, const NA: usize, const NB: usize, const N: usize>(
    a: &SVector<S, NA>,
    b: &SVector<S, NB>,
) -> SVector<S, N> {
    const {
        assert!(
            N == NA + NB,
            "a Pair of NA and NB coordinates has N = NA + NB"
        )
    };
    let v: [S; N] = core::array::from_fn(|i| if i < NA { a[i] } else { b[i - NA] });
    SVector::from_array_storage(ArrayStorage([v]))
}

/// The halves of a state.
fn halves<T: Real, const NA: usize, const NB: usize, const N: usize>(
    s: &State<T, N>,
) -> (State<T, NA>, State<T, NB>) {
    let ((qa, qb), (va, vb)) = (split(&s.q), split(&s.qd));
    (
        State {
            t: s.t,
            q: qa,
            qd: va,
        },
        State {
            t: s.t,
            q: qb,
            qd: vb,
        },
    )
}

impl<T, A, B, const NA: usize, const NB: usize, const N: usize> Lagrangian<T, N>
    for Pair<A, B, NA, NB>
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
        let ((qa, qb), (va, vb)) = (split::<S, NA, NB, N>(q), split::<S, NA, NB, N>(qd));
        self.a.kinetic(t, &qa, &va) + self.b.kinetic(t, &qb, &vb)
    }

    fn potential<S: Scalar<Real = T>>(&self, t: S, q: &SVector<S, N>) -> S {
        let (qa, qb) = split::<S, NA, NB, N>(q);
        self.a.potential(t, &qa) + self.b.potential(t, &qb)
    }

    fn non_conservative_force(&self, state: &State<T, N>) -> SVector<T, N> {
        let (sa, sb) = halves(state);
        join(
            &self.a.non_conservative_force(&sa),
            &self.b.non_conservative_force(&sb),
        )
    }
}

impl<T, A, B, const NA: usize, const NB: usize, const N: usize> Mechanism<T, N>
    for Pair<A, B, NA, NB>
where
    T: Real,
    A: Mechanism<T, NA>,
    B: Mechanism<T, NB>,
{
    fn mass_matrix(&self, state: &State<T, N>) -> SMatrix<T, N, N> {
        let (sa, sb) = halves(state);
        let (ma, mb) = (self.a.mass_matrix(&sa), self.b.mass_matrix(&sb));
        SMatrix::from_fn(|i, j| match (i < NA, j < NA) {
            (true, true) => ma[(i, j)],
            (false, false) => mb[(i - NA, j - NA)],
            _ => T::zero(),
        })
    }

    fn rhs(&self, state: &State<T, N>) -> SVector<T, N> {
        let (sa, sb) = halves(state);
        join(&self.a.rhs(&sa), &self.b.rhs(&sb))
    }

    fn solve_mass(&self, state: &State<T, N>, b: &SVector<T, N>) -> Result<SVector<T, N>, Error> {
        let (sa, sb) = halves(state);
        let (ba, bb) = split(b);
        Ok(join(
            &self.a.solve_mass(&sa, &ba)?,
            &self.b.solve_mass(&sb, &bb)?,
        ))
    }

    /// Each mechanism's own law on its half of the state, the extra force split the same way.
    fn law<F: GeneralizedForce<T, N>>(
        &self,
        state: &State<T, N>,
        extra: &F,
    ) -> Result<SVector<T, N>, Error> {
        let (sa, sb) = halves(state);
        let (fa, fb) = split(&extra.added_to(state, SVector::zeros()));
        let qa = self.a.law(&sa, &move |_: &State<T, NA>| fa)?;
        let qb = self.b.law(&sb, &move |_: &State<T, NB>| fb)?;
        Ok(join(&qa, &qb))
    }

    fn reads_velocities(&self) -> bool {
        self.a.reads_velocities() || self.b.reads_velocities()
    }
}

impl<T, A, B, const NA: usize, const NB: usize, const N: usize> Links<T, N> for Pair<A, B, NA, NB>
where
    T: Real,
    A: Links<T, NA>,
    B: Links<T, NB>,
{
    /// `a`'s links, then `b`'s.
    const LINKS: usize = A::LINKS + B::LINKS;

    fn pose<S: Scalar<Real = T> + 'static>(&self, q: &SVector<S, N>, link: usize) -> Pose<S> {
        let (qa, qb) = split::<S, NA, NB, N>(q);
        if link < A::LINKS {
            self.a.pose(&qa, link)
        } else {
            self.b.pose(&qb, link - A::LINKS)
        }
    }
}
