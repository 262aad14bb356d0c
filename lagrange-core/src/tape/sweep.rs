//! The second-order sweep over a recorded kinetic energy: `M = d2T/dq'2`, `dT/dq` and the
//! mixed term `d/de dT/dq'` along `e = (dq, dq', dt) = (q', 0, 1 or 0)`.
//!
//! For `T` made of nodes `v = phi_v(a, b)`, with `w_v = dT/dv` the adjoints of one reverse
//! pass and `g_x` the gradient of a node in whichever inputs are wanted, the second-order
//! chain rule gives the Hessian as a sum over the curved nodes:
//!
//! ```text
//! d2T = sum_v w_v (phi_aa g_a g_a^T + phi_ab (g_a g_b^T + g_b g_a^T) + phi_bb g_b g_b^T)
//! ```
//!
//! So one reverse pass (adjoints) and one forward pass (each node's gradient in `q'`, an
//! `N`-vector, and its tangent along `e`, a number) give `M` (the sum with velocity gradients
//! on both sides) and the mixed term (velocity gradients on one side, tangents on the other),
//! and the adjoints of the coordinates are `dT/dq`. Only curved nodes whose parents move with
//! `q'` add to `M`, each a rank-one or rank-two update (of both triangles: `M` is read whole).

use super::{Node, NONE};
use crate::Scalar;
use nalgebra::{SMatrix, SVector};

/// Where the inputs sit on the tape (its first nodes: time where it is one, then `q`, then
/// `q'`), and the direction `e` of the mixed term.
pub(crate) struct Inputs<'a, S, const N: usize> {
    /// The node of time, [`NONE`] where time is a constant (then `dt = 0` along `e`).
    pub(crate) time: u16,
    /// The node of `q[0]`; `q[k]` follows at `q + k`.
    pub(crate) q: u16,
    /// The node of `q'[0]`; `q'[k]` follows at `qd + k`.
    pub(crate) qd: u16,
    /// `q'`: the coordinates' rates along `e`.
    pub(crate) rates: &'a SVector<S, N>,
}

/// Where a node's gradient in `q'` is kept: entries `lo..hi` (the rest are zero) at `at..` of
/// the pool; an empty range for a node that does not move with `q'`. Coordinates enter a
/// mechanism's energy a few at a time (a chain's link `i` moves with the first `i + 1`
/// rates), and keeping only the range both saves copying `N`-vectors and keeps each update to
/// the entries it touches.
#[derive(Clone, Copy)]
struct Span {
    at: u32,
    lo: u16,
    hi: u16,
}

impl Span {
    /// No gradient: the node does not move with `q'`.
    const ZERO: Span = Span {
        at: 0,
        lo: 0,
        hi: 0,
    };

    /// True where the gradient is zero.
    fn is_zero(self) -> bool {
        self.lo >= self.hi
    }

    /// The range of entries that may be non-zero.
    fn range(self) -> core::ops::Range<usize> {
        usize::from(self.lo)..usize::from(self.hi)
    }

    /// The stored entries in `pool`.
    fn part<S>(self, pool: &[S]) -> &[S] {
        let at = self.at as usize;
        pool.get(at..at + self.range().len()).unwrap_or_default()
    }

    /// `x += c g` over the range.
    fn add_to<S: Scalar, const N: usize>(self, pool: &[S], x: &mut [S; N], c: S) {
        let xs = x.get_mut(self.range()).unwrap_or_default();
        for (e, y) in xs.iter_mut().zip(self.part(pool)) {
            *e += c * *y;
        }
    }
}

/// `pa ga + pb gb` appended to `pool`, or `None` where the pool is full. (The pool grows
/// by each gradient's length: clearing all of it ahead, 8 kB for the smaller tape, took more
/// time than writing the zeros of the gradients made.)
fn combine<S: Scalar, const POOL: usize>(
    pool: &mut heapless::Vec<S, POOL>,
    (pa, ga): (S, Span),
    (pb, gb): (S, Span),
) -> Option<Span> {
    let (lo, hi) = match (ga.is_zero(), gb.is_zero()) {
        (true, true) => return Some(Span::ZERO),
        (false, true) => (ga.lo, ga.hi),
        (true, false) => (gb.lo, gb.hi),
        (false, false) => (ga.lo.min(gb.lo), ga.hi.max(gb.hi)),
    };
    let at = pool.len();
    pool.resize(at + usize::from(hi - lo), S::zero()).ok()?;
    let (old, new) = pool.split_at_mut_checked(at)?;
    for (g, c) in [(ga, pa), (gb, pb)] {
        let from = usize::from(g.lo.saturating_sub(lo));
        let to = new.get_mut(from..).unwrap_or_default();
        for (x, y) in to.iter_mut().zip(g.part(old)) {
            *x += c * *y;
        }
    }
    Some(Span {
        at: u32::try_from(at).ok()?,
        lo,
        hi,
    })
}

/// The whole gradient `g` as an `N`-vector.
fn spread<S: Scalar, const N: usize>(g: Span, pool: &[S]) -> [S; N] {
    let mut full = [S::zero(); N];
    for (x, y) in full
        .get_mut(g.range())
        .unwrap_or_default()
        .iter_mut()
        .zip(g.part(pool))
    {
        *x = *y;
    }
    full
}

/// `h += c a a^T` over the square block of `a`'s range (both triangles: the matrix is
/// read whole). Rows of one length per call, which the compiler vectorises; a triangle's rows
/// of varying length measured slower for the chain's short ranges.
fn add_square<S: Scalar, const N: usize>(h: &mut [[S; N]; N], pool: &[S], c: S, a: Span) {
    let part = a.part(pool);
    let rows = h.get_mut(a.range()).unwrap_or_default();
    for (row, ai) in rows.iter_mut().zip(part) {
        let cai = c * *ai;
        let block = row.get_mut(a.range()).unwrap_or_default();
        for (e, aj) in block.iter_mut().zip(part) {
            *e += cai * *aj;
        }
    }
}

/// `h += c a a^T + d b b^T` for gradients `a`, `b` of one range, in one pass over the block.
fn add_two_squares<S: Scalar, const N: usize>(
    h: &mut [[S; N]; N],
    pool: &[S],
    (c, a): (S, Span),
    (d, b): (S, Span),
) {
    let (pa, pb) = (a.part(pool), b.part(pool));
    let rows = h.get_mut(a.range()).unwrap_or_default();
    for ((row, ai), bi) in rows.iter_mut().zip(pa).zip(pb) {
        let (cai, dbi) = (c * *ai, d * *bi);
        let block = row.get_mut(a.range()).unwrap_or_default();
        for ((e, aj), bj) in block.iter_mut().zip(pa).zip(pb) {
            *e += cai * *aj + dbi * *bj;
        }
    }
}

/// `M`'s rank-one squares, held back one at a time so that two of one range (a chain's
/// `vx^2 + vy^2`) go in one pass over their block: the updates of `M` were row overhead as
/// much as arithmetic.
struct Squares<'h, S, const N: usize> {
    h: &'h mut [[S; N]; N],
    held: Option<(S, Span)>,
}

impl<S: Scalar, const N: usize> Squares<'_, S, N> {
    /// `h += c a a^T`, now or with the next square.
    fn add(&mut self, pool: &[S], c: S, a: Span) {
        if let Some((d, b)) = self.held {
            if b.range() == a.range() {
                self.held = None;
                add_two_squares(self.h, pool, (d, b), (c, a));
                return;
            }
        }
        self.flush(pool);
        self.held = Some((c, a));
    }

    /// Adds the square held, if any.
    fn flush(&mut self, pool: &[S]) {
        if let Some((c, a)) = self.held.take() {
            add_square(self.h, pool, c, a);
        }
    }
}

/// `h += c (a b^T + b a^T)`, in the rows of the ranges: whole rows of the fixed length `N`
/// (the two ranges differ, and a loop of known length vectorises).
fn add_outer<S: Scalar, const N: usize>(h: &mut [[S; N]; N], pool: &[S], c: S, a: Span, b: Span) {
    let (fa, fb) = (spread::<S, N>(a, pool), spread::<S, N>(b, pool));
    add_rows(h, c, (a, &fa), &fb);
    add_rows(h, c, (b, &fb), &fa);
}

/// `h += c x y^T` in the rows of `x`'s range, `x` with its range, both spread out.
fn add_rows<S: Scalar, const N: usize>(
    h: &mut [[S; N]; N],
    c: S,
    (xs, x): (Span, &[S; N]),
    y: &[S; N],
) {
    let rows = h.get_mut(xs.range()).unwrap_or_default();
    for (row, xi) in rows.iter_mut().zip(x.get(xs.range()).unwrap_or_default()) {
        let cxi = c * *xi;
        for (e, yj) in row.iter_mut().zip(y) {
            *e += cxi * *yj;
        }
    }
}

/// The adjoints `w_v = dT/dv` of the value recorded in `nodes` (a multiple `out.1` of the
/// node `out.0`), by one reverse pass, and which nodes the curved terms need the gradient and
/// tangent of: the parents of curved nodes with a non-zero adjoint, and everything they are
/// made of (a node made only of such, like `T`'s running sum, needs neither).
fn reverse<S: Scalar, const CAP: usize>(
    nodes: &[Node<S>],
    out: (u16, S),
) -> ([S; CAP], [bool; CAP]) {
    let z = S::zero();
    // Plain arrays, not `heapless::Vec`s: a push stores the length to memory, and a loop of
    // pushes waits on that store each time (measured: most of the sweep's time).
    let mut adj = [z; CAP];
    let mut needed = [false; CAP];
    if let Some(w) = adj.get_mut(usize::from(out.0)) {
        *w = out.1;
    }
    for (v, node) in nodes.iter().enumerate().rev() {
        let w = adj.get(v).copied().unwrap_or(z);
        let live = !w.is_zero();
        if (node.curved && live) || needed.get(v).copied().unwrap_or(false) {
            for p in [node.a, node.b] {
                if let Some(x) = needed.get_mut(usize::from(p)) {
                    *x = true;
                }
            }
        }
        if !live {
            continue;
        }
        if let Some(x) = adj.get_mut(usize::from(node.a)) {
            *x += node.pa * w;
        }
        if let Some(x) = adj.get_mut(usize::from(node.b)) {
            *x += node.pb * w;
        }
    }
    (adj, needed)
}

/// `dT/dq - d/de dT/dq'` of the `T` recorded in `nodes`, its value a multiple `out.1` of
/// the node `out.0`, and `M` added to `m` (zero on entry; whole: both triangles); `None`
/// where the pool (`POOL` numbers of gradients) is too small.
#[inline(never)]
pub(crate) fn second_order<
    S: Scalar + 'static,
    const N: usize,
    const CAP: usize,
    const POOL: usize,
>(
    nodes: &[Node<S>],
    out: (u16, S),
    inputs: &Inputs<'_, S, N>,
    m: &mut SMatrix<S, N, N>,
) -> Option<SVector<S, N>> {
    let z = S::zero();
    let (adj, needed) = reverse::<S, CAP>(nodes, out);

    // Forward: tangents along e, velocity gradients (only for the nodes that need them), and
    // the curved nodes' terms.
    let mut tangent = [z; CAP];
    let mut span = [Span::ZERO; CAP];
    let mut pool = heapless::Vec::<S, POOL>::new();
    // Row `i` of `h` is column `i` of `m`: the same numbers, `M` being symmetric.
    let mut h = Squares {
        h: &mut m.data.0,
        held: None,
    };
    let mut dp = [z; N];
    let (time, q0, qd0) = (
        usize::from(inputs.time),
        usize::from(inputs.q),
        usize::from(inputs.qd),
    );
    for (v, node) in nodes.iter().enumerate() {
        let w = adj.get(v).copied().unwrap_or(z);
        let curved = node.curved && !w.is_zero();
        let need = needed.get(v).copied().unwrap_or(false);
        if !curved && !need {
            continue;
        }
        // A parent that is not a node (NONE) has no tangent and no gradient.
        let ta = tangent.get(usize::from(node.a)).copied().unwrap_or(z);
        let tb = tangent.get(usize::from(node.b)).copied().unwrap_or(z);
        let ga = span.get(usize::from(node.a)).copied().unwrap_or(Span::ZERO);
        let gb = span.get(usize::from(node.b)).copied().unwrap_or(Span::ZERO);
        if curved {
            curved_terms(&mut h, &mut dp, &pool, w, node, (ga, ta), (gb, tb));
        }
        if !need {
            continue;
        }
        // The inputs are the first nodes, by index (see `Inputs`).
        let (t, g) = if v == time {
            (S::one(), Span::ZERO)
        } else if (q0..q0 + N).contains(&v) {
            (inputs.rates.get(v - q0).copied().unwrap_or(z), Span::ZERO)
        } else if (qd0..qd0 + N).contains(&v) {
            let at = u32::try_from(pool.len()).ok()?;
            pool.push(S::one()).ok()?;
            let k = u16::try_from(v - qd0).ok()?;
            (
                z,
                Span {
                    at,
                    lo: k,
                    hi: k + 1,
                },
            )
        } else {
            let g = combine(&mut pool, (node.pa, ga), (node.pb, gb))?;
            let mut t = z;
            if node.a != NONE {
                t += node.pa * ta;
            }
            if node.b != NONE {
                t += node.pb * tb;
            }
            (t, g)
        };
        *tangent.get_mut(v)? = t;
        *span.get_mut(v)? = g;
    }

    h.flush(&pool);
    let gq = SVector::from_fn(|i, _| adj.get(q0 + i).copied().unwrap_or(z));
    Some(gq - SVector::from(dp))
}

/// A curved node's share of `M` (upper triangle `h`) and of the mixed term `dp`, its adjoint
/// `w`, each parent with its velocity gradient (none where it does not move with `q'`) and
/// its tangent.
fn curved_terms<S: Scalar, const N: usize>(
    h: &mut Squares<'_, S, N>,
    dp: &mut [S; N],
    pool: &[S],
    w: S,
    node: &Node<S>,
    (ga, ta): (Span, S),
    (gb, tb): (Span, S),
) {
    let (caa, cab, cbb) = (w * node.haa, w * node.hab, w * node.hbb);
    if !ga.is_zero() {
        if !caa.is_zero() {
            h.add(pool, caa, ga);
            ga.add_to(pool, dp, caa * ta);
        }
        if !cab.is_zero() {
            ga.add_to(pool, dp, cab * tb);
        }
    }
    if !gb.is_zero() {
        if !cbb.is_zero() {
            h.add(pool, cbb, gb);
            gb.add_to(pool, dp, cbb * tb);
        }
        if !cab.is_zero() {
            gb.add_to(pool, dp, cab * ta);
        }
    }
    if !ga.is_zero() && !gb.is_zero() && !cab.is_zero() {
        if node.a == node.b {
            // x x: a square, 2 c g g^T.
            h.add(pool, cab + cab, ga);
        } else {
            add_outer(h.h, pool, cab, ga, gb);
        }
    }
}
