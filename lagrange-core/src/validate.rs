//! Parameter checks shared by every constructor, each naming the parameter it refuses: ranges
//! ([`positive`], [`non_negative`], [`finite`]), quantities formed from the parameters that must
//! stay in range ([`derived`], [`divisor`]), and the names of array entries ([`entry`]).

use crate::{Error, Real};

/// `x` when finite and strictly positive.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `name`.
pub fn positive<T: Real>(name: &'static str, x: T) -> Result<T, Error> {
    if x.is_finite() && x > T::zero() {
        Ok(x)
    } else {
        Err(Error::InvalidParameter {
            name,
            reason: "must be positive and finite",
        })
    }
}

/// `x` when finite and not negative.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `name`.
pub fn non_negative<T: Real>(name: &'static str, x: T) -> Result<T, Error> {
    if x.is_finite() && x >= T::zero() {
        Ok(x)
    } else {
        Err(Error::InvalidParameter {
            name,
            reason: "must be zero or positive, and finite",
        })
    }
}

/// `x` when finite.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `name`.
pub fn finite<T: Real>(name: &'static str, x: T) -> Result<T, Error> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(Error::InvalidParameter {
            name,
            reason: "must be finite",
        })
    }
}

/// `value`, a quantity a constructor forms from its parameters and keeps (a product such as
/// `m l^2`, a quotient such as `g / l`, a sum of masses), when it is finite: the rule that a
/// value the mechanism multiplies by stays in the range of `T` for every accepted parameter.
///
/// `factors` lists the parameters it is formed from, each with its power (`-1` for a divisor;
/// the terms of a sum each with power 1). When `value` overflows, the error names the factor
/// that pushes it furthest up: the one with the largest `power * log2 |x|`.
///
/// ```
/// use lagrange_core::{validate, Error};
/// let (m, l) = (1e200_f64, 1e60);
/// let refused = validate::derived(m * l * l, &[("mass", m, 1), ("length", l, 2)]);
/// assert!(matches!(refused, Err(Error::InvalidParameter { name: "mass", .. })));
/// assert_eq!(validate::derived(2.0 * 3.0, &[("mass", 2.0, 1), ("length", 3.0, 1)]), Ok(6.0));
/// ```
///
/// # Errors
/// [`Error::InvalidParameter`] naming the factor most responsible when `value` is not finite.
pub fn derived<T: Real>(value: T, factors: &[(&'static str, T, i32)]) -> Result<T, Error> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(blame(factors, Direction::Overflow))
    }
}

/// `value`, a quantity formed from the parameters that the mechanism divides by (or whose
/// reciprocal it keeps), when it and its reciprocal are finite and it is not zero: the rule
/// that a divisor neither overflows nor underflows to zero (or to a subnormal whose reciprocal
/// overflows).
///
/// `factors` as in [`derived`]. When `value` overflows, the error names the factor that pushes
/// it furthest up; when it underflows, the one that pulls it furthest down (the smallest
/// `power * log2 |x|`).
///
/// ```
/// use lagrange_core::{validate, Error};
/// let (m, l) = (1.0_f64, 1e-200);
/// let refused = validate::divisor(m * l * l, &[("mass", m, 1), ("length", l, 2)]);
/// assert!(matches!(refused, Err(Error::InvalidParameter { name: "length", .. })));
/// ```
///
/// # Errors
/// [`Error::InvalidParameter`] naming the factor most responsible.
pub fn divisor<T: Real>(value: T, factors: &[(&'static str, T, i32)]) -> Result<T, Error> {
    if !value.is_finite() {
        Err(blame(factors, Direction::Overflow))
    } else if value == T::zero() || !value.recip().is_finite() {
        Err(blame(factors, Direction::Underflow))
    } else {
        Ok(value)
    }
}

/// The error for a quantity formed from `factors` that overflowed where it was computed (a
/// phase `omega t`, a product inside a formula): [`Error::InvalidParameter`] naming the
/// factor that pushes it furthest up, as [`derived`] does.
///
/// ```
/// use lagrange_core::{validate, Error};
/// let e = validate::overflowed(&[("omega", 2.0_f64, 1), ("t", 1e308, 1)]);
/// assert!(matches!(e, Error::InvalidParameter { name: "t", .. }));
/// ```
#[must_use]
pub fn overflowed<T: Real>(factors: &[(&'static str, T, i32)]) -> Error {
    blame(factors, Direction::Overflow)
}

/// Which way a derived quantity left the range of `T`.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Direction {
    Overflow,
    Underflow,
}

/// The error naming the factor that moves a derived quantity furthest in `direction`, with a
/// reason that says which way the parameter is out of range.
fn blame<T: Real>(factors: &[(&'static str, T, i32)], direction: Direction) -> Error {
    // Each factor's share of log2 |value|; the error path only, so the logarithm costs nothing
    // on success.
    let share = |&(_, x, power): &(&'static str, T, i32)| {
        let l = x.abs().ln();
        if power >= 0 {
            l * T::from_f64(f64::from(power))
        } else {
            -(l * T::from_f64(f64::from(-power)))
        }
    };
    let mut worst: Option<(&(&'static str, T, i32), T)> = None;
    for f in factors {
        let s = share(f);
        let worse = match (worst, direction) {
            (None, _) => true,
            (Some((_, w)), Direction::Overflow) => s > w || w.partial_cmp(&s).is_none(),
            (Some((_, w)), Direction::Underflow) => s < w || w.partial_cmp(&s).is_none(),
        };
        if worse {
            worst = Some((f, s));
        }
    }
    let (name, power) = worst.map_or(("", 1), |(&(name, _, power), _)| (name, power));
    let reason = match (direction, power >= 0) {
        (Direction::Overflow, true) => "too large: a quantity formed from the parameters overflows",
        (Direction::Overflow, false) => {
            "too small: a quantity formed from the parameters (divided by it) overflows"
        }
        (Direction::Underflow, true) => {
            "too small: a quantity formed from the parameters that the motion divides by underflows"
        }
        (Direction::Underflow, false) => {
            "too large: a quantity formed from the parameters that the motion divides by underflows"
        }
    };
    Error::InvalidParameter { name, reason }
}

/// The name of entry `i` of an array parameter, from a table of entry names made by
/// [`entry_names!`](crate::entry_names) (`"masses[3]"`), or `whole` (`"masses"`) past the
/// table's end: an error then says which entry it refuses.
///
/// ```
/// use lagrange_core::{entry_names, validate};
/// const MASSES: [&str; 32] = entry_names!("masses");
/// assert_eq!(validate::entry(&MASSES, 3, "masses"), "masses[3]");
/// assert_eq!(validate::entry(&MASSES, 40, "masses"), "masses");
/// ```
#[must_use]
pub fn entry(names: &[&'static str], i: usize, whole: &'static str) -> &'static str {
    names.get(i).copied().unwrap_or(whole)
}

/// The names `"base[0]"` to `"base[31]"` of the first 32 entries of an array parameter, as a
/// `[&'static str; 32]`: the table [`validate::entry`](crate::validate::entry) reads, so that
/// an error can name the entry it refuses without allocating.
#[macro_export]
macro_rules! entry_names {
    ($base:literal) => {
        [
            concat!($base, "[0]"),
            concat!($base, "[1]"),
            concat!($base, "[2]"),
            concat!($base, "[3]"),
            concat!($base, "[4]"),
            concat!($base, "[5]"),
            concat!($base, "[6]"),
            concat!($base, "[7]"),
            concat!($base, "[8]"),
            concat!($base, "[9]"),
            concat!($base, "[10]"),
            concat!($base, "[11]"),
            concat!($base, "[12]"),
            concat!($base, "[13]"),
            concat!($base, "[14]"),
            concat!($base, "[15]"),
            concat!($base, "[16]"),
            concat!($base, "[17]"),
            concat!($base, "[18]"),
            concat!($base, "[19]"),
            concat!($base, "[20]"),
            concat!($base, "[21]"),
            concat!($base, "[22]"),
            concat!($base, "[23]"),
            concat!($base, "[24]"),
            concat!($base, "[25]"),
            concat!($base, "[26]"),
            concat!($base, "[27]"),
            concat!($base, "[28]"),
            concat!($base, "[29]"),
            concat!($base, "[30]"),
            concat!($base, "[31]"),
        ]
    };
}
