//! Classification of a result: finite or not ([`Finite`]), the parameter an error names
//! against the call's own ([`verdict`]), and drawing states.

use crate::harness::{lit, lits, Ctx, Verdict};
use crate::values::Kind;
use lagrange_core::constraints::ConstrainedAcceleration;
use lagrange_core::nalgebra::{SMatrix, SVector};
use lagrange_core::{Error, Jacobian, Real, State};
use lagrange_integrators::{Frame, PhaseState, Stop};

/// A result whose numbers can be checked: `Some(what)` names the first non-finite part.
pub trait Finite {
    fn non_finite(&self) -> Option<String>;
}

impl Finite for () {
    fn non_finite(&self) -> Option<String> {
        None
    }
}

/// A scalar result, as a vector the finiteness check reads.
pub fn num<T: Real>(x: T) -> SVector<T, 1> {
    SVector::<T, 1>::new(x)
}

/// A pair of scalars, likewise.
pub fn pair<T: Real>((a, b): (T, T)) -> SVector<T, 2> {
    SVector::<T, 2>::new(a, b)
}

impl<T: Real, const R: usize, const C: usize> Finite for SMatrix<T, R, C> {
    fn non_finite(&self) -> Option<String> {
        (!self.iter().all(|x| x.is_finite())).then(|| format!("{:?}", self.as_slice()))
    }
}

impl<T: Real, const N: usize> Finite for State<T, N> {
    fn non_finite(&self) -> Option<String> {
        (!self.is_finite()).then(|| format!("{self:?}"))
    }
}

impl<T: Real, const N: usize> Finite for PhaseState<T, N> {
    fn non_finite(&self) -> Option<String> {
        (!self.is_finite()).then(|| format!("{self:?}"))
    }
}

impl<T: Real, const N: usize> Finite for Jacobian<T, N> {
    fn non_finite(&self) -> Option<String> {
        (!self.is_finite()).then(|| format!("{self:?}"))
    }
}

impl<T: Real, const N: usize, const C: usize> Finite for ConstrainedAcceleration<T, N, C> {
    fn non_finite(&self) -> Option<String> {
        self.acceleration
            .non_finite()
            .or_else(|| self.multipliers.non_finite())
    }
}

impl<T: Real> Finite for Frame<T> {
    fn non_finite(&self) -> Option<String> {
        (!self.dropped.is_finite()).then(|| format!("{self:?}"))
    }
}

impl<T: Real, const N: usize> Finite for Stop<T, N> {
    fn non_finite(&self) -> Option<String> {
        self.state().non_finite()
    }
}

impl<A: Finite, B: Finite> Finite for (A, B) {
    fn non_finite(&self) -> Option<String> {
        self.0.non_finite().or_else(|| self.1.non_finite())
    }
}

impl<const C: usize> Finite for [bool; C] {
    fn non_finite(&self) -> Option<String> {
        None
    }
}

/// True when `name` is one of `params`, or an entry `p[i]` of one.
pub fn allowed(name: &str, params: &[&str]) -> bool {
    params.iter().any(|p| {
        name == *p
            || name
                .strip_prefix(p)
                .and_then(|rest| rest.strip_prefix('['))
                .and_then(|rest| rest.strip_suffix(']'))
                .is_some_and(|i| i.parse::<usize>().is_ok())
    })
}

/// The verdict of an error of a call whose parameters are `params`.
pub fn refused(e: Error, params: &[&str]) -> Verdict {
    match e {
        Error::InvalidParameter { name, .. } if !allowed(name, params) => {
            Verdict::WrongName(format!("{e:?}, the call's parameters are {params:?}"))
        }
        _ => Verdict::Error(e),
    }
}

/// The verdict of a result of a call whose parameters are `params`.
pub fn verdict<V: Finite>(r: &Result<V, Error>, params: &[&str]) -> Verdict {
    match r {
        Ok(v) => match v.non_finite() {
            Some(what) => Verdict::Silent(what),
            None => Verdict::Ok,
        },
        Err(e) => refused(*e, params),
    }
}

/// The value of a setup call (a constructor, whose parameters it checked), or an early return
/// with the verdict of its error: `let x = call!(r, &[..]);`
#[macro_export]
macro_rules! call {
    ($r:expr, $params:expr) => {{
        match $r {
            Ok(v) => v,
            Err(e) => return $crate::checks::refused(e, $params),
        }
    }};
}

/// A state of `N` coordinates drawn for a call, with its reproducer line `let s = ...;`.
pub fn state<T: Real, const N: usize>(ctx: &mut Ctx, var: &str) -> State<T, N> {
    let t = ctx.value::<T>(Kind::Time);
    let q = ctx.values::<T, N>(Kind::State);
    let qd = ctx.values::<T, N>(Kind::State);
    crate::say!(
        ctx,
        "let {var} = State::<{}, {N}>::new({}, {}, {});",
        crate::harness::ty::<T>(),
        lit(t),
        lits(&q),
        lits(&qd)
    );
    State::new(t, q, qd)
}

/// A vector of `N` values of `kind`, as an expression for the reproducer.
pub fn vector<T: Real, const N: usize>(ctx: &mut Ctx, kind: Kind) -> (SVector<T, N>, String) {
    let v = ctx.values::<T, N>(kind);
    (
        SVector::from(v),
        format!(
            "SVector::<{}, {N}>::from({})",
            crate::harness::ty::<T>(),
            lits(&v)
        ),
    )
}

impl<T: Real, const N: usize, const C: usize> Finite
    for lagrange_core::constraints::contact::Impact<T, N, C>
{
    fn non_finite(&self) -> Option<String> {
        self.state_before()
            .non_finite()
            .or_else(|| self.state_after().non_finite())
            .or_else(|| self.impulses.non_finite())
    }
}
