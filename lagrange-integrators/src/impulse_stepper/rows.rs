//! [`Workspace`]: the rows of one step (the normal rows' [`Delassus`], the friction
//! directions, each with its mobility through the mechanism's own mass solve), in storage
//! kept from step to step, and taken again by a step whose free step ends where the last
//! fill's did, to rounding ([`Workspace::reuse`]); and the rows' checks.

use lagrange_core::constraints::contact::{Contacts, Delassus};
use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{all_finite, Error, Mechanism, Real, State};

/// What a step fills and solves with, kept by the stepper so that a step neither makes nor
/// clears storage of `C^2` numbers (a ragdoll's is 19 kB in `f64`). A step reads what the
/// last one filled only where [`Workspace::reuse`] finds it filled at the same coordinates
/// (to their rounding) and mass matrix (bit for bit).
#[derive(Debug, Clone, Copy)]
pub(super) struct Workspace<T: Real, const N: usize, const C: usize> {
    /// The normal rows of the step (the candidates: in contact, or speculative).
    pub(super) normal: Delassus<T, N, C>,
    /// The tangents of the contacts with friction.
    pub(super) tangent: [Option<Direction<T, N>>; C],
    /// The rows' Jacobian at the step's free state, and their tangents (read where the
    /// contacts have friction): written in place by [`Contacts::jacobians`].
    pub(super) jacobian: SMatrix<T, C, N>,
    pub(super) tangents: SMatrix<T, C, N>,
    /// The columns handed to the mechanism's mass solve.
    jumps: SMatrix<T, N, C>,
    /// Where the rows were filled, while they are as filling left them.
    pub(super) filled: Option<Filled<T, N, C>>,
    /// The mass matrix where they were filled, where [`Filled::mass_known`] says (written
    /// only by a step that met the coordinates of the last fill: not by steps that move).
    mass: SMatrix<T, N, N>,
    /// The last coordinates a step's end was measured at, and the gaps there (see
    /// [`Measured::gaps`]).
    pub(super) ended: Measured<T, N, C>,
    /// The steps that took the rows again (what the tests count).
    #[cfg(test)]
    pub(super) reused: u32,
}

/// The gaps of a contact set at the coordinates they were last measured at: a body at rest
/// ends step after step at the same coordinates, bit for bit, and its gaps there are the
/// same numbers (a function of the coordinates alone).
#[derive(Debug, Clone, Copy)]
pub(super) struct Measured<T: Real, const N: usize, const C: usize> {
    last: Option<(SVector<T, N>, SVector<T, C>)>,
}

impl<T: Real, const N: usize, const C: usize> Measured<T, N, C> {
    /// The finite gaps of `contacts` at `q`: the last measured where `q` is theirs, bit for
    /// bit, else measured now (and kept).
    ///
    /// # Errors
    /// As [`finite_gaps`].
    pub(super) fn gaps<K: Contacts<T, N, C>>(
        &mut self,
        contacts: &K,
        q: &SVector<T, N>,
    ) -> Result<SVector<T, C>, Error> {
        if let Some((at, gaps)) = self.last {
            if same_bits(at.as_slice(), q.as_slice()) {
                return Ok(gaps);
            }
        }
        let gaps = finite_gaps(contacts.position_residual(q))?;
        self.last = Some((*q, gaps));
        Ok(gaps)
    }
}

/// Where a [`Workspace`]'s rows were filled: the free step's coordinates, whether the
/// workspace holds the mass matrix there (once a step has met those coordinates again: it
/// is not worked out for steps that move), whether the gaps came with the Jacobians, the
/// gaps and whether the tangents count.
#[derive(Debug, Clone, Copy)]
pub(super) struct Filled<T: Real, const N: usize, const C: usize> {
    pub(super) q: SVector<T, N>,
    pub(super) mass_known: bool,
    pub(super) rows_too: bool,
    pub(super) gaps: SVector<T, C>,
    pub(super) tangents: bool,
}

/// What [`Workspace::reuse`] found.
#[derive(Debug, Clone, Copy)]
pub(super) struct Reuse<T: Real, const N: usize, const C: usize> {
    /// The rows as filled: their gaps and whether their tangents count.
    pub(super) rows: Option<(SVector<T, C>, bool)>,
    /// Whether the workspace holds the mass matrix at `at` (the state came near the last
    /// fill's coordinates).
    pub(super) mass_known: bool,
    /// The coordinates of the step's rows: the last fill's where they are taken again, else
    /// the state's.
    pub(super) at: SVector<T, N>,
}

/// Where [`Workspace::mobilities`] put each tangent: `slot[i]`, the scratch column of
/// contact `i`'s; `overflow` where some found none.
#[derive(Debug, Clone, Copy)]
pub(super) struct Columns<const C: usize> {
    slot: [Option<usize>; C],
    overflow: bool,
}

impl<T: Real, const N: usize, const C: usize> Workspace<T, N, C> {
    /// Nothing filled.
    pub(super) fn empty() -> Self {
        Self {
            normal: Delassus::empty(),
            tangent: [None; C],
            jacobian: SMatrix::zeros(),
            tangents: SMatrix::zeros(),
            jumps: SMatrix::zeros(),
            filled: None,
            mass: SMatrix::zeros(),
            ended: Measured { last: None },
            #[cfg(test)]
            reused: 0,
        }
    }

    /// The rows filled at the free state `state`, where the last fill was at its coordinates
    /// to their rounding ([`close`]) and with the same mass matrix there, bit for bit, by the
    /// same route (`rows_too`, as [`Workspace::gaps`]) and nothing has joined the rows since:
    /// the gaps, Jacobians and tangents are functions of the coordinates, the mobilities of
    /// the mass matrix there (a mechanism at rest, whose velocities are the rounding of its
    /// last solve, finds them again). The normal rows keep the factor their last solve left
    /// (of the same `W`), so that the first pass of a resting step factors none of them. The
    /// record is taken: a step that fails after this leaves none ([`Workspace::keep`] makes
    /// it again) unless it fails before it fills rows ([`Workspace::put_back`]).
    pub(super) fn reuse<M: Mechanism<T, N>>(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        rows_too: bool,
    ) -> Reuse<T, N, C> {
        let none = Reuse {
            rows: None,
            mass_known: false,
            at: state.q,
        };
        let Some(f) = self.filled.take() else {
            return none;
        };
        if f.rows_too != rows_too || !close(&f.q, &state.q) {
            return none;
        }
        // Near the fill's coordinates: the mass matrix tells whether the mobilities are the
        // same (another mechanism, or one whose mass reads the time, gives another; one
        // that differs in its last place a unit away fills the rows again, rarely: the
        // thrown ragdoll takes rows again in 942 steps in f64 where it would in 947 with
        // the mass matrix worked out at the fill's coordinates).
        let mass = mechanism.mass_matrix(state);
        let same = f.mass_known && same_bits(self.mass.as_slice(), mass.as_slice());
        #[cfg(test)]
        {
            self.reused += u32::from(same);
        }
        if same {
            return Reuse {
                rows: Some((f.gaps, f.tangents)),
                mass_known: true,
                at: f.q,
            };
        }
        // Filled again here, with this state's mass matrix.
        self.mass = mass;
        Reuse {
            rows: None,
            mass_known: true,
            at: state.q,
        }
    }

    /// Nothing kept from the steps before: the next fills its rows and measures its gaps.
    #[cfg(test)]
    pub(super) fn forget(&mut self) {
        self.filled = None;
        self.ended.last = None;
    }

    /// After a step that failed before it filled its rows (a gap, Jacobian or tangent not
    /// finite, more rows in contact than `max_rows`, the mass solve of their mobilities:
    /// see `Setup::touch`), the record `prior` of the rows the last step left, as if the
    /// step had never run: the step wrote only the Jacobians and tangents over theirs
    /// (and the scratch columns), worked out here again at the record's coordinates by the record's route (the
    /// same bits: functions of the coordinates), so that the next step from the rest takes
    /// them again as an untouched stepper's would. Not where `reuse` wrote the mass matrix
    /// (the record would vouch for another's mobilities).
    pub(super) fn put_back<K: Contacts<T, N, C>>(
        &mut self,
        prior: Option<Filled<T, N, C>>,
        reuse: &Reuse<T, N, C>,
        contacts: &K,
    ) {
        let wrote_mass = reuse.rows.is_none() && reuse.mass_known;
        let Some(f) = prior.filter(|_| !wrote_mass) else {
            return;
        };
        let (jacobian, tangents) = (&mut self.jacobian, &mut self.tangents);
        if f.rows_too {
            let mut gaps = SVector::zeros();
            contacts.gaps_and_jacobians(&f.q, &mut gaps, jacobian, tangents);
        } else {
            contacts.jacobians(&f.q, jacobian, tangents);
        }
        // As they were filled, unless the contacts answer otherwise now.
        self.filled = finite_rows(&self.jacobian, &[true; C]).is_ok().then_some(f);
    }

    /// Records that the rows were filled at `filled`, when the normal rows are still the
    /// `touching` ones filled (none joined since: speculative rows and the drift's add to
    /// them).
    pub(super) fn keep(&mut self, filled: Filled<T, N, C>, touching: &[bool; C]) {
        self.filled = (self.normal.candidates() == touching).then_some(filled);
    }

    /// The rows of `contacts` at `q` into [`Workspace::jacobian`] and
    /// [`Workspace::tangents`]: whether the tangents count (the contacts give them and
    /// `friction` is on).
    ///
    /// # Errors
    /// [`Error::NonFiniteRow`] for the first row whose Jacobian, or whose tangent where it
    /// counts and the row is in `frictional`, is not finite.
    pub(super) fn jacobians<K: Contacts<T, N, C>>(
        &mut self,
        contacts: &K,
        q: &SVector<T, N>,
        friction: bool,
        frictional: &[bool; C],
    ) -> Result<bool, Error> {
        let tangents = contacts.jacobians(q, &mut self.jacobian, &mut self.tangents);
        self.checked(tangents && friction, frictional)
    }

    /// The gaps of `contacts` at `q` and, where `rows_too` (a step that expects rows in
    /// contact), their Jacobians from the same call ([`Contacts::gaps_and_jacobians`]:
    /// a ragdoll's one pose), with whether the contacts gave tangents; else the gaps alone.
    ///
    /// # Errors
    /// [`Error::NonFiniteRow`] for the first gap that is not finite.
    pub(super) fn gaps<K: Contacts<T, N, C>>(
        &mut self,
        contacts: &K,
        q: &SVector<T, N>,
        rows_too: bool,
    ) -> Result<(SVector<T, C>, Option<bool>), Error> {
        if rows_too {
            let mut gaps = SVector::zeros();
            let tangents =
                contacts.gaps_and_jacobians(q, &mut gaps, &mut self.jacobian, &mut self.tangents);
            Ok((finite_gaps(gaps)?, Some(tangents)))
        } else {
            Ok((finite_gaps(contacts.position_residual(q))?, None))
        }
    }

    /// Whether the tangents count (`tangents`: the contacts gave them and friction is on),
    /// the Jacobian and (where they count) the tangents of `frictional` checked.
    ///
    /// # Errors
    /// As [`Workspace::jacobians`].
    pub(super) fn checked(&self, tangents: bool, frictional: &[bool; C]) -> Result<bool, Error> {
        finite_rows(&self.jacobian, &[true; C])?;
        if tangents {
            finite_rows(&self.tangents, frictional)?;
        }
        Ok(tangents)
    }

    /// The mobilities of a step's rows at `state` (the normal rows of the Jacobian in
    /// `touching`, and the tangents, with `tangents`, of the contacts in `frictional`) from
    /// one call of [`Mechanism::velocity_jumps`], into the scratch columns alone: each
    /// normal row in its own column, each tangent in one no normal row uses, where there is
    /// one ([`Columns`]; the others take a second call in [`Workspace::fill`]).
    ///
    /// # Errors
    /// The mass solve's.
    pub(super) fn mobilities<M: Mechanism<T, N>>(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        tangents: bool,
        touching: &[bool; C],
        frictional: &[bool; C],
    ) -> Result<Columns<C>, Error> {
        let jacobian = &self.jacobian;
        let tangents = tangents.then_some(&self.tangents);
        // Normal rows in their own columns; each tangent in a column no normal row uses.
        let mut slot = [None::<usize>; C];
        let mut spare = (0..C).filter(|&k| !touching[k]);
        let mut overflow = false;
        for ((k, column), &on) in self
            .jumps
            .as_mut_slice()
            .chunks_exact_mut(N)
            .enumerate()
            .zip(touching)
        {
            if on {
                put_row(column, jacobian, k);
            } else {
                column.fill(T::zero());
            }
        }
        if let Some(t) = tangents {
            for i in (0..C).filter(|&i| frictional[i]).map(within::<C>) {
                match spare.next().map(within::<C>) {
                    Some(k) => {
                        if let Some(column) = self.jumps.as_mut_slice().chunks_exact_mut(N).nth(k) {
                            put_row(column, t, i);
                        }
                        slot[i] = Some(k);
                    }
                    None => overflow = true,
                }
            }
        }
        mechanism.velocity_jumps(state, &mut self.jumps)?;
        Ok(Columns { slot, overflow })
    }

    /// The rows of a step at `state` (as [`Workspace::mobilities`]'s, which it takes
    /// `columns` from) written over the kept ones: the normal rows' `W`, the tangents'
    /// directions, and the mobilities of the tangents that found no free column (a second
    /// call of [`Mechanism::velocity_jumps`]).
    ///
    /// # Errors
    /// The mass solve's; [`Error::NonFiniteState`] when `W` is not finite.
    pub(super) fn fill<M: Mechanism<T, N>>(
        &mut self,
        mechanism: &M,
        state: &State<T, N>,
        tangents: bool,
        touching: &[bool; C],
        frictional: &[bool; C],
        Columns { slot, overflow }: Columns<C>,
    ) -> Result<(), Error> {
        let jacobian = &self.jacobian;
        let tangents = tangents.then_some(&self.tangents);
        let jumps = &self.jumps;
        self.normal.rebuild(
            jacobian,
            |m| {
                let from = jumps.as_slice().chunks_exact(N).zip(touching);
                for (to, (from, &on)) in m.as_mut_slice().chunks_exact_mut(N).zip(from) {
                    if on {
                        for (x, y) in to.iter_mut().zip(from) {
                            *x = *y;
                        }
                    }
                }
                Ok(())
            },
            touching,
        )?;
        // Each cleared in place (a new array of them is kilobytes written and copied).
        for t in &mut self.tangent {
            *t = None;
        }
        let Some(t) = tangents else {
            return Ok(());
        };
        for i in (0..C).filter(|&i| frictional[i]).map(within::<C>) {
            if let Some(k) = slot[i] {
                self.tangent[i] = Direction::new(t.row(i).transpose(), column(&self.jumps, k));
            }
        }
        if overflow {
            for i in (0..C).map(within::<C>) {
                if frictional[i] && slot[i].is_none() {
                    self.jumps.set_column(i, &t.row(i).transpose());
                } else {
                    self.jumps.column_mut(i).fill(T::zero());
                }
            }
            mechanism.velocity_jumps(state, &mut self.jumps)?;
            for i in (0..C)
                .filter(|&i| frictional[i] && slot[i].is_none())
                .map(within::<C>)
            {
                self.tangent[i] = Direction::new(t.row(i).transpose(), column(&self.jumps, i));
            }
        }
        Ok(())
    }
}

/// `i`, a row of a set of `C` counted here (so below `C`), clamped below `C`: a no-op that
/// tells the optimiser that no bounds check is needed (a bounds check is a panic path, which
/// the firmware's panic-free image refuses).
pub(super) fn within<const C: usize>(i: usize) -> usize {
    i.min(C.saturating_sub(1))
}

/// Row `i` of `rows` into `column` (a column of a matrix stored by columns), read entry by
/// entry (nalgebra's `set_column` from a row walks a strided iterator).
fn put_row<T: Real, const N: usize, const C: usize>(
    column: &mut [T],
    rows: &SMatrix<T, C, N>,
    i: usize,
) {
    for (c, x) in column.iter_mut().enumerate() {
        *x = rows[(within::<C>(i), c.min(N.saturating_sub(1)))];
    }
}

/// Column `k` of `m`, copied (nalgebra's `into_owned` keeps a length check, a panic path, in
/// optimised code).
fn column<T: Real, const N: usize, const C: usize>(
    m: &SMatrix<T, N, C>,
    k: usize,
) -> SVector<T, N> {
    let mut out = SVector::<T, N>::zeros();
    out.copy_from(&m.column(within::<C>(k)));
    out
}

/// One tangent direction: its Jacobian row `j`, its mobility `b = M^-1 j^T` (the velocity
/// change of a unit impulse, from the mechanism's velocity jump, which keeps a constrained
/// mechanism's own constraints), and `1 / (j b)`, the impulse that changes its speed by one.
#[derive(Debug, Clone, Copy)]
pub(super) struct Direction<T: Real, const N: usize> {
    pub(super) j: SVector<T, N>,
    pub(super) b: SVector<T, N>,
    pub(super) inverse: T,
}

impl<T: Real, const N: usize> Direction<T, N> {
    /// The direction `j` with its mobility `b`; `None` where `j` moves nothing (a zero row:
    /// a joint limit has no tangent; or one the mechanism's own constraints hold).
    pub(super) fn new(j: SVector<T, N>, b: SVector<T, N>) -> Option<Self> {
        let d = j.dot(&b);
        // A direction whose own inverse mass is below the rounding of its terms moves nothing.
        let size = j
            .iter()
            .zip(b.iter())
            .fold(T::zero(), |s, (x, y)| s + (*x * *y).abs());
        (d > T::from_f64(64.0) * T::EPSILON * size).then(|| Self {
            j,
            b,
            inverse: d.recip(),
        })
    }
}

/// [`Error::NonFiniteRow`] naming the first of the rows marked `used` with an entry that is
/// not finite.
fn finite_rows<T: Real, const N: usize, const C: usize>(
    rows: &SMatrix<T, C, N>,
    used: &[bool; C],
) -> Result<(), Error> {
    // All finite, the common case, read in storage order without stopping early (lanes of
    // SIMD: a row of a matrix stored by columns is read with a stride, an entry at a time).
    if all_finite(rows.as_slice()) {
        return Ok(());
    }
    match (0..C).find(|&i| used[i] && !rows.row(i).iter().all(|x| x.is_finite())) {
        Some(row) => Err(Error::NonFiniteRow { row }),
        None => Ok(()),
    }
}

/// Whether the coordinates `b` are the coordinates `a` to their rounding: no coordinate
/// apart by more than a unit of the last place of the largest of `a` (and of 1: a
/// coordinate near zero rounds on the others' scale in every sum it meets). The rows at
/// `b` are those at `a` to the rounding they are worked out with; a mechanism at rest moves
/// by less, step after step (its velocities are the rounding of the last solve: 1e-15 in
/// f64 moves a coordinate by 4e-18 at 1/240 s), a mechanism that moves by more.
fn close<T: Real, const N: usize>(a: &SVector<T, N>, b: &SVector<T, N>) -> bool {
    let scale = a.iter().fold(T::one(), |m, x| m.max(x.abs()));
    let allowed = T::EPSILON * scale;
    a.iter()
        .zip(b.iter())
        .all(|(x, y)| (*x - *y).abs() <= allowed)
}

/// Whether `a` and `b` hold the same numbers bit for bit (zero's sign too).
fn same_bits<T: Real>(a: &[T], b: &[T]) -> bool {
    // Widened to f64, which keeps every f32 apart.
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| x.to_f64().to_bits() == y.to_f64().to_bits())
}

/// `gaps` when every gap is finite, else [`Error::NonFiniteRow`] naming the first that is not.
fn finite_gaps<T: Real, const C: usize>(gaps: SVector<T, C>) -> Result<SVector<T, C>, Error> {
    if all_finite(gaps.as_slice()) {
        return Ok(gaps);
    }
    match (0..C).find(|&i| !gaps[i].is_finite()) {
        Some(row) => Err(Error::NonFiniteRow { row }),
        None => Ok(gaps),
    }
}

#[cfg(test)]
mod tests {
    use super::close;
    use lagrange_core::nalgebra::SVector;

    /// Coordinates are close within a unit of the last place of the largest of the first
    /// (1000 here), or of 1 where all are smaller: 0.9 units apart are, 1.1 are not.
    #[test]
    fn close_is_within_a_unit_of_the_largest_coordinate() {
        let unit = f64::EPSILON;
        for (scale, a) in [(1000.0, [1000.0, 0.5]), (1.0, [0.25, 0.0])] {
            let a = SVector::<f64, 2>::new(a[0], a[1]);
            let by = |units: f64| a + SVector::<f64, 2>::new(0.0, units * unit * scale);
            assert!(close(&a, &by(0.9)) && close(&a, &by(-0.9)), "{a}");
            assert!(!close(&a, &by(1.1)) && !close(&a, &by(-1.1)), "{a}");
        }
        assert!(!close(
            &SVector::<f64, 2>::zeros(),
            &SVector::<f64, 2>::new(f64::NAN, 0.0)
        ));
    }
}
