//! Reverse mode over a recorded tape: the automatic path's second derivatives of a kinetic
//! energy without an `N x N` block in every value.
//!
//! A [`Taped`] number is a value and the index of the node that made it on a [`Tape`] that
//! lives on the stack for one evaluation of `T`. Each node keeps its (at most two) parents and
//! the first and second partial derivatives of its operation at the parents' values: that is
//! all [`sweep`] needs to get `M = d2T/dq'2`, `dT/dq` and the mixed term, from one reverse
//! and one forward pass over the nodes (see there). A value is two numbers (its value and a
//! scale, below), a reference and an index, so the user's `T` runs at about the speed of
//! plain arithmetic however large `N` is, where a [`Jet`](crate::jet::Jet) of a 20-link chain
//! is kilobytes.
//!
//! The tape holds at most `CAP` nodes; a `T` that needs more marks it full, and the caller
//! falls back to the jet. The tape's storage is not initialised ahead (`heapless::Vec`); the
//! sweep's work space is (arrays of `CAP` numbers and a pool of gradients), so a capacity
//! costs stack and the time to clear it: about 140 kB for the largest tape over `f64` at
//! `N = 20`, twice that over the dual numbers of the law's Jacobian. Only mechanisms of
//! [`FROM`] coordinates or more use a tape, none of the embedded targets' cases.

pub(crate) mod sweep;
pub(crate) mod terms;
mod trig;

use crate::scalar::{powi_by_squaring, Real, Scalar};
use core::cell::{Cell, Ref, RefCell};
use core::fmt;
use core::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};
use num_traits::{One, Zero};
use trig::TrigNodes;

/// From how many coordinates [`EulerLagrange`](crate::EulerLagrange) differentiates `T` over
/// a tape rather than a [`Jet`](crate::jet::Jet). A jet holds `N^2 + 3 N + 2` numbers and
/// every operation of `T` makes one; a tape costs about 20 ns a node over all its passes
/// whatever `N` is. Measured on the chain (the automatic-cost bench's `NLinkPendulum`): the
/// jet is faster up to ten links (3.4 against 4.2 us), the tape from twelve (5.3 against
/// 6.0 us; at twenty, 10.7 against 81 us).
pub(crate) const FROM: usize = 11;

/// The index of no node: a constant's, or a parent that is a constant.
pub(crate) const NONE: u16 = u16::MAX;

/// One operation on the tape: `v = phi(a, b)`, with `phi`'s partials at the parents' values.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Node<S> {
    /// First parent ([`NONE`] for an input, or where it is a constant).
    pub(crate) a: u16,
    /// Second parent ([`NONE`] for a unary operation, or where it is a constant).
    pub(crate) b: u16,
    /// `dphi/da`, `dphi/db`.
    pub(crate) pa: S,
    pub(crate) pb: S,
    /// `d2phi/da2`, `d2phi/dadb`, `d2phi/db2`: meaningful only where `curved`.
    pub(crate) haa: S,
    pub(crate) hab: S,
    pub(crate) hbb: S,
    /// False for an operation linear in its parents (sums, differences, inputs).
    pub(crate) curved: bool,
}

/// The nodes of one evaluation, at most `CAP` of them, in storage the caller owns (a
/// `heapless::Vec` kept in a `RefCell` of its own is zeroed whole when made, tens of
/// kilobytes each time; a local one is not).
pub(crate) struct Tape<'s, S, const CAP: usize> {
    nodes: RefCell<&'s mut heapless::Vec<Node<S>, CAP>>,
    /// Set when a node did not fit: the recording is then incomplete and must not be used.
    full: Cell<bool>,
    /// The sine and cosine nodes recorded so far, by angle.
    trig: TrigNodes<S>,
}

impl<'s, S: Scalar, const CAP: usize> Tape<'s, S, CAP> {
    /// An empty tape in `storage`.
    /// An empty tape in `storage`; with `remember`, an angle's sine or cosine taken again is
    /// the node recorded first (only for plain numbers: see [`TrigNodes`]).
    pub(crate) fn new(storage: &'s mut heapless::Vec<Node<S>, CAP>, remember: bool) -> Self {
        // Node indices are `u16`, `NONE` kept out of them.
        const { assert!(CAP < NONE as usize) };
        storage.clear();
        Self {
            nodes: RefCell::new(storage),
            full: Cell::new(false),
            trig: TrigNodes::new(remember),
        }
    }

    /// Appends `node` and returns its index, or [`NONE`] (and marks the tape full) where it
    /// does not fit.
    fn push(&self, node: Node<S>) -> u16 {
        let Ok(mut nodes) = self.nodes.try_borrow_mut() else {
            self.full.set(true);
            return NONE;
        };
        // `CAP < NONE` (checked in `new`): an index that fits the storage fits a `u16`.
        let at = u16::try_from(nodes.len()).unwrap_or(NONE);
        if nodes.push(node).is_err() {
            self.full.set(true);
            return NONE;
        }
        at
    }

    /// An input: a node with no parents, its value `v`.
    pub(crate) fn input(&self, v: S) -> Taped<'_, 's, S, CAP> {
        let at = self.push(Node {
            a: NONE,
            b: NONE,
            pa: S::zero(),
            pb: S::zero(),
            haa: S::zero(),
            hab: S::zero(),
            hbb: S::zero(),
            curved: false,
        });
        Taped {
            v,
            tape: Some(self),
            at,
            scale: S::one(),
        }
    }

    /// The recorded nodes, or `None` where the recording did not fit. Borrowed in place: a
    /// tape moved is its whole capacity copied.
    pub(crate) fn nodes(&self) -> Option<Ref<'_, [Node<S>]>> {
        if self.full.get() {
            return None;
        }
        let nodes = self.nodes.try_borrow().ok()?;
        Some(Ref::map(nodes, |v| v.as_slice()))
    }
}

/// A number recorded on a [`Tape`]: its value, and the node it is a multiple of (none for a
/// constant): `v = scale x + shift` for the node's value `x`. Scalings and shifts by
/// constants (a parameter times a velocity, a sign, `T`'s `1/2`) make no node: they change
/// `scale` and `v` only, and the operation that takes the number folds `scale` into its
/// partials. A chain's kinetic energy has two such operations of twelve in each link.
#[derive(Clone, Copy)]
pub(crate) struct Taped<'t, 's, S, const CAP: usize> {
    v: S,
    tape: Option<&'t Tape<'s, S, CAP>>,
    at: u16,
    scale: S,
}

impl<S: Scalar, const CAP: usize> fmt::Debug for Taped<'_, '_, S, CAP> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "Taped({:?} = {:?} x node {})",
            self.v, self.scale, self.at
        )
    }
}

/// Equal values are equal, whichever node made them (as for a plain number).
impl<S: Scalar, const CAP: usize> PartialEq for Taped<'_, '_, S, CAP> {
    fn eq(&self, other: &Self) -> bool {
        self.v == other.v
    }
}

impl<S: Scalar, const CAP: usize> Taped<'_, '_, S, CAP> {
    /// A constant: no node.
    pub(crate) fn constant(v: S) -> Self {
        Self {
            v,
            tape: None,
            at: NONE,
            scale: S::zero(),
        }
    }

    /// The node's index ([`NONE`] for a constant), and the derivative of the value in it.
    pub(crate) fn node(self) -> (u16, S) {
        if self.tape.is_some() {
            (self.at, self.scale)
        } else {
            (NONE, S::zero())
        }
    }

    /// `f(self)` with value `v`, `f' = d`, `f'' = dd` (a function of one argument that is not
    /// linear: the linear ones are [`Taped::affine`], which makes no node).
    #[inline]
    fn unary(self, v: S, d: S, dd: S) -> Self {
        let Some(tape) = self.tape else {
            return Self::constant(v);
        };
        let z = S::zero();
        let s = self.scale;
        let at = tape.push(Node {
            a: self.at,
            b: NONE,
            pa: d * s,
            pb: z,
            haa: dd * s * s,
            hab: z,
            hbb: z,
            curved: true,
        });
        Self {
            v,
            tape: Some(tape),
            at,
            scale: S::one(),
        }
    }

    /// `phi(self, o)` with value `v`, first partials `p` and second partials
    /// `h = [d2/da2, d2/dadb, d2/db2]` (`curved` false where `phi` is linear). An operand
    /// that is a constant is no parent: its partials are zero, whatever `p` and `h` say
    /// (which may be infinite: a constant divisor of zero).
    #[inline]
    fn binary(self, o: Self, v: S, p: [S; 2], h: [S; 3], curved: bool) -> Self {
        let Some(tape) = self.tape.or(o.tape) else {
            return Self::constant(v);
        };
        let z = S::zero();
        let ((a, sa), (b, sb)) = (self.node(), o.node());
        let on = |node: u16, x: S| if node == NONE { z } else { x };
        let at = tape.push(Node {
            a,
            b,
            pa: on(a, p[0] * sa),
            pb: on(b, p[1] * sb),
            haa: on(a, h[0] * sa * sa),
            hab: on(a, on(b, h[1] * sa * sb)),
            hbb: on(b, h[2] * sb * sb),
            curved,
        });
        Self {
            v,
            tape: Some(tape),
            at,
            scale: S::one(),
        }
    }

    /// The sine (`SIN`) and the cosine (`COS`) of `self`: the nodes recorded for the same
    /// angle before where there are (see [`TrigNodes`]), else new ones (a function not asked
    /// for is the constant zero).
    #[inline]
    fn sin_cos_nodes<const SIN: bool, const COS: bool>(self) -> (Self, Self) {
        let Some(tape) = self.tape else {
            let (s, c) = self.v.sin_cos();
            return (Self::constant(s), Self::constant(c));
        };
        let mut found = tape.trig.find(self.at, self.scale, self.v);
        let (s, c) = found.values;
        let recorded = found.nodes;
        // The node recorded for the function where there is one, else a new node (value `v`,
        // derivatives `d`, `dd`), which is then the one recorded.
        let take = |node: &mut u16, (v, d, dd): (S, S, S)| {
            let r = if *node == NONE {
                self.unary(v, d, dd)
            } else {
                Self {
                    v,
                    tape: Some(tape),
                    at: *node,
                    scale: S::one(),
                }
            };
            *node = r.at;
            r
        };
        let zero = Self::constant(S::zero());
        let sin = if SIN {
            take(&mut found.nodes.0, (s, c, -s))
        } else {
            zero
        };
        let cos = if COS {
            take(&mut found.nodes.1, (c, -s, -c))
        } else {
            zero
        };
        if found.nodes != recorded {
            tape.trig.keep(self.at, self.scale, self.v, found);
        }
        (sin, cos)
    }

    /// A linear function of `self` with slope `c` and value `v`: no node.
    #[inline]
    fn affine(self, c: S, v: S) -> Self {
        if self.tape.is_none() {
            return Self::constant(v);
        }
        Self {
            v,
            scale: self.scale * c,
            ..self
        }
    }
}

impl<S: Scalar, const CAP: usize> Add for Taped<'_, '_, S, CAP> {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        let (one, z) = (S::one(), S::zero());
        match (self.tape, o.tape) {
            (_, None) => self.affine(one, self.v + o.v),
            (None, _) => o.affine(one, self.v + o.v),
            _ => self.binary(o, self.v + o.v, [one, one], [z; 3], false),
        }
    }
}

impl<S: Scalar, const CAP: usize> Sub for Taped<'_, '_, S, CAP> {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        let (one, z) = (S::one(), S::zero());
        match (self.tape, o.tape) {
            (_, None) => self.affine(one, self.v - o.v),
            (None, _) => o.affine(-one, self.v - o.v),
            _ => self.binary(o, self.v - o.v, [one, -one], [z; 3], false),
        }
    }
}

impl<S: Scalar, const CAP: usize> Mul for Taped<'_, '_, S, CAP> {
    type Output = Self;
    #[inline]
    fn mul(self, o: Self) -> Self {
        let v = self.v * o.v;
        // By a constant (a parameter): a scaling, linear, with one parent.
        match (self.tape, o.tape) {
            (_, None) => self.affine(o.v, v),
            (None, _) => o.affine(self.v, v),
            _ => {
                let z = S::zero();
                self.binary(o, v, [o.v, self.v], [z, S::one(), z], true)
            }
        }
    }
}

impl<S: Scalar, const CAP: usize> Div for Taped<'_, '_, S, CAP> {
    type Output = Self;
    #[inline]
    fn div(self, o: Self) -> Self {
        let inv = o.v.recip();
        let v = self.v * inv;
        if o.tape.is_none() {
            return self.affine(inv, v);
        }
        let pb = -v * inv;
        let hab = -inv * inv;
        let hbb = -(pb * inv + pb * inv);
        self.binary(o, v, [inv, pb], [S::zero(), hab, hbb], true)
    }
}

impl<S: Scalar, const CAP: usize> Neg for Taped<'_, '_, S, CAP> {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        self.affine(-S::one(), -self.v)
    }
}

/// The compound assignments of an operator, through the operator.
macro_rules! assign_through {
    ($assign:ident, $fa:ident, $op:ident, $f:ident, $rhs:ty) => {
        impl<S: Scalar<Real = R>, R: Real, const CAP: usize> $assign<$rhs>
            for Taped<'_, '_, S, CAP>
        {
            #[inline]
            fn $fa(&mut self, o: $rhs) {
                *self = $op::$f(*self, o);
            }
        }
    };
}

assign_through!(AddAssign, add_assign, Add, add, Self);
assign_through!(SubAssign, sub_assign, Sub, sub, Self);
assign_through!(MulAssign, mul_assign, Mul, mul, Self);
assign_through!(DivAssign, div_assign, Div, div, Self);

impl<S: Scalar<Real = R>, R: Real, const CAP: usize> Add<R> for Taped<'_, '_, S, CAP> {
    type Output = Self;
    #[inline]
    fn add(self, x: R) -> Self {
        self.affine(S::one(), self.v + x)
    }
}

impl<S: Scalar<Real = R>, R: Real, const CAP: usize> Sub<R> for Taped<'_, '_, S, CAP> {
    type Output = Self;
    #[inline]
    fn sub(self, x: R) -> Self {
        self.affine(S::one(), self.v - x)
    }
}

impl<S: Scalar<Real = R>, R: Real, const CAP: usize> Mul<R> for Taped<'_, '_, S, CAP> {
    type Output = Self;
    #[inline]
    fn mul(self, x: R) -> Self {
        self.affine(S::from_real(x), self.v * x)
    }
}

impl<S: Scalar<Real = R>, R: Real, const CAP: usize> Div<R> for Taped<'_, '_, S, CAP> {
    type Output = Self;
    #[inline]
    fn div(self, x: R) -> Self {
        self.affine(S::from_real(x).recip(), self.v / x)
    }
}

assign_through!(AddAssign, add_assign, Add, add, R);
assign_through!(SubAssign, sub_assign, Sub, sub, R);
assign_through!(MulAssign, mul_assign, Mul, mul, R);
assign_through!(DivAssign, div_assign, Div, div, R);

impl<S: Scalar, const CAP: usize> Zero for Taped<'_, '_, S, CAP> {
    fn zero() -> Self {
        Self::constant(S::zero())
    }
    fn is_zero(&self) -> bool {
        self.tape.is_none() && self.v.is_zero()
    }
}

impl<S: Scalar, const CAP: usize> One for Taped<'_, '_, S, CAP> {
    fn one() -> Self {
        Self::constant(S::one())
    }
}

impl<S: Scalar<Real = R>, R: Real, const CAP: usize> Scalar for Taped<'_, '_, S, CAP> {
    type Real = R;

    fn from_real(x: R) -> Self {
        Self::constant(S::from_real(x))
    }
    fn from_f64(x: f64) -> Self {
        Self::constant(S::from_f64(x))
    }
    fn value(self) -> R {
        self.v.value()
    }
    fn sin(self) -> Self {
        self.sin_cos_nodes::<true, false>().0
    }
    fn cos(self) -> Self {
        self.sin_cos_nodes::<false, true>().1
    }
    fn sin_cos(self) -> (Self, Self) {
        self.sin_cos_nodes::<true, true>()
    }
    fn tan(self) -> Self {
        let t = self.v.tan();
        let d = S::one() + t * t;
        self.unary(t, d, (t + t) * d)
    }
    fn sqrt(self) -> Self {
        let r = self.v.sqrt();
        let d = (r + r).recip();
        // d/dx (1 / 2r) = -1 / (4 r^3) = -2 d^3.
        let d3 = d * d * d;
        self.unary(r, d, -(d3 + d3))
    }
    fn exp(self) -> Self {
        let e = self.v.exp();
        self.unary(e, e, e)
    }
    fn ln(self) -> Self {
        let inv = self.v.recip();
        self.unary(self.v.ln(), inv, -(inv * inv))
    }
    fn powi(self, n: i32) -> Self {
        powi_by_squaring(self, n)
    }
    fn abs(self) -> Self {
        if self.v.value() < R::zero() {
            -self
        } else {
            self
        }
    }
    fn atan2(self, x: Self) -> Self {
        // self = y: d/dy = x / r2, d/dx = -y / r2; second partials over r2^2.
        let (y, xv) = (self.v, x.v);
        let inv = (xv * xv + y * y).recip();
        let inv2 = inv * inv;
        let xy = xv * y;
        let hyy = -(xy + xy) * inv2;
        let hxy = (y * y - xv * xv) * inv2;
        self.binary(x, y.atan2(xv), [xv * inv, -y * inv], [hyy, hxy, -hyy], true)
    }
    fn recip(self) -> Self {
        let r = self.v.recip();
        let r2 = r * r;
        self.unary(r, -r2, (r2 + r2) * r)
    }
}
