//! [`Block`]: up to [`LOCKS`] of one body's locked rows as one small system (see `locks`).

use lagrange_core::nalgebra::SVector;
use lagrange_core::Real;

/// The most own rows of one body locked in a step: a ragdoll lying on the floor holds two to
/// four of its joints at their limits.
pub(crate) const LOCKS: usize = 4;

/// One locked row (a body's own, so on its side 0): its Jacobian, its mobility and its
/// impulse in the phase under way.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Locked<T: Real, const N: usize> {
    pub(crate) j: SVector<T, N>,
    pub(crate) b: SVector<T, N>,
    pub(crate) impulse: T,
}

/// Up to [`LOCKS`] locked rows of one body by place, each `None` where there is none or it
/// was let go, and `W` among them (`W_pq = j_p . b_q`: positive definite, each row taken in
/// only where independent of the others).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Block<T: Real, const N: usize> {
    rows: [Option<Locked<T, N>>; LOCKS],
    w: [[T; LOCKS]; LOCKS],
}

impl<T: Real, const N: usize> Block<T, N> {
    /// No rows.
    pub(crate) fn none() -> Self {
        Self {
            rows: [None; LOCKS],
            w: [[T::zero(); LOCKS]; LOCKS],
        }
    }

    /// The rows `rows` in their places, taken to be independent (they were when locked).
    pub(crate) fn of(rows: impl Iterator<Item = Locked<T, N>>) -> Self {
        let mut block = Self::none();
        for (p, row) in rows.enumerate().take(LOCKS) {
            block.put(p, row);
        }
        block
    }

    /// The rows by place.
    pub(crate) fn rows(&self) -> &[Option<Locked<T, N>>; LOCKS] {
        &self.rows
    }

    /// Whether it has no row.
    pub(crate) fn is_empty(&self) -> bool {
        self.rows.iter().all(Option::is_none)
    }

    /// `row` taken in at the first free place where it is independent of the rows in it
    /// (its `W` with them held more than `sqrt(EPSILON)` of its own `W`); whether it was.
    pub(crate) fn push(&mut self, row: Locked<T, N>) -> bool {
        let Some(p) = self.rows.iter().position(Option::is_none) else {
            return false;
        };
        let held = self.mobility(&row.b, &self.impulses(&row.b));
        let (own, with) = (row.j.dot(&row.b), row.j.dot(&held));
        let independent = with > T::EPSILON.sqrt() * own && with.is_finite();
        if independent {
            self.put(p, row);
        }
        independent
    }

    /// The row at place `p` let go.
    pub(crate) fn let_go(&mut self, p: usize) {
        if let Some(r) = self.rows.get_mut(p) {
            *r = None;
        }
    }

    /// `mu = -W^-1 J b` over the rows in it (zero at the other places): the impulses that
    /// keep their speeds when a mobility `b` moves the body.
    pub(crate) fn impulses(&self, b: &SVector<T, N>) -> [T; LOCKS] {
        // Gaussian elimination of W, the places without a row the identity (their impulse
        // comes out zero).
        let mut a = [[T::zero(); LOCKS]; LOCKS];
        let mut y = [T::zero(); LOCKS];
        for (p, ((ap, yp), row)) in a.iter_mut().zip(&mut y).zip(&self.rows).enumerate() {
            match row {
                Some(r) => {
                    *ap = self.w.get(p).copied().unwrap_or([T::zero(); LOCKS]);
                    for (x, other) in ap.iter_mut().zip(&self.rows) {
                        if other.is_none() {
                            *x = T::zero();
                        }
                    }
                    *yp = -r.j.dot(b);
                }
                None => {
                    if let Some(d) = ap.get_mut(p) {
                        *d = T::one();
                    }
                }
            }
        }
        for k in 0..LOCKS {
            let (Some(&rk), Some(&yk)) = (a.get(k), y.get(k)) else {
                continue;
            };
            let pivot = rk.get(k).copied().unwrap_or(T::one());
            let positive = pivot > T::zero();
            if !positive {
                return [T::zero(); LOCKS];
            }
            for (ri, yi) in a.iter_mut().zip(&mut y).skip(k + 1) {
                let f = ri.get(k).copied().unwrap_or(T::zero()) / pivot;
                for (x, r) in ri.iter_mut().zip(rk).skip(k) {
                    *x -= f * r;
                }
                *yi -= f * yk;
            }
        }
        let mut mu = [T::zero(); LOCKS];
        for k in (0..LOCKS).rev() {
            let (Some(rk), Some(&yk)) = (a.get(k), y.get(k)) else {
                continue;
            };
            let known = rk
                .iter()
                .zip(&mu)
                .skip(k + 1)
                .fold(T::zero(), |s, (x, m)| s + *x * *m);
            let pivot = rk.get(k).copied().unwrap_or(T::one());
            if let Some(m) = mu.get_mut(k) {
                *m = (yk - known) / pivot;
            }
        }
        mu
    }

    /// `b + sum_p mu_p b_p` over the rows in it: a mobility with the impulses `mu` on them.
    pub(crate) fn mobility(&self, b: &SVector<T, N>, mu: &[T; LOCKS]) -> SVector<T, N> {
        self.rows
            .iter()
            .zip(mu)
            .fold(*b, |x, (r, m)| r.map_or(x, |r| x + r.b * *m))
    }

    /// `row` at place `p`, with its entries of `W`.
    fn put(&mut self, p: usize, row: Locked<T, N>) {
        for (q, other) in self.rows.iter().enumerate() {
            let Some(o) = other.as_ref().filter(|_| q != p) else {
                continue;
            };
            let (pq, qp) = (row.j.dot(&o.b), o.j.dot(&row.b));
            if let Some(x) = self.w.get_mut(p).and_then(|r| r.get_mut(q)) {
                *x = pq;
            }
            if let Some(x) = self.w.get_mut(q).and_then(|r| r.get_mut(p)) {
                *x = qp;
            }
        }
        if let Some(x) = self.w.get_mut(p).and_then(|r| r.get_mut(p)) {
            *x = row.j.dot(&row.b);
        }
        if let Some(r) = self.rows.get_mut(p) {
            *r = Some(row);
        }
    }
}
