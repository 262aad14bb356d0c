//! Parameter checks shared by every constructor, each naming the parameter it refuses.

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
