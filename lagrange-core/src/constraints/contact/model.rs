//! [`ContactModel`]: restitution, friction, the resting threshold and the event-location
//! tolerance of unilateral contacts.

use crate::{validate, Error, Real};

/// How contacts behave and how precisely their events are located.
///
/// ```text
/// restitution e   in [0, 1]: an impact sends the approach speed -w back as e (-w)
///                 (Newton's law, along each contact's gap gradient)
/// rest_speed      a contact whose rebound speed e |w| would be below this (m/s, or the
///                 gap's units per second) becomes resting: a bilateral constraint until
///                 its force would pull. This ends the infinite sequence of ever smaller
///                 bounces (Zeno) after finitely many events
/// time_tolerance  the bisection that locates a contact inside a step stops when the
///                 bracket is this short (s): the impact happens at most this early, at a
///                 gap of at most |w| time_tolerance
/// friction mu     Coulomb coefficient (>= 0, default 0) for contacts that give a tangent
///                 (see Contacts::tangent_jacobian)
/// ```
///
/// Choose `rest_speed` above the speed gravity gives in a couple of steps (`~ 2 g dt`), or
/// a resting body would register a new tiny impact every few steps.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ContactModel<T> {
    restitution: T,
    rest_speed: T,
    time_tolerance: T,
    friction: T,
}

impl<T: Real> ContactModel<T> {
    /// Frictionless contacts with restitution `restitution` (in `[0, 1]`), resting below
    /// `rest_speed` (> 0) and contact times located to `time_tolerance` (s, > 0).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `restitution` outside `[0, 1]` or not finite;
    /// `rest_speed` or `time_tolerance` not positive and finite.
    pub fn new(restitution: T, rest_speed: T, time_tolerance: T) -> Result<Self, Error> {
        let unit = restitution >= T::zero() && restitution <= T::one();
        if !unit {
            return Err(Error::InvalidParameter {
                name: "restitution",
                reason: "must be in [0, 1]",
            });
        }
        Ok(Self {
            restitution,
            rest_speed: validate::positive("rest_speed", rest_speed)?,
            time_tolerance: validate::positive("time_tolerance", time_tolerance)?,
            friction: T::zero(),
        })
    }

    /// The same model with Coulomb friction coefficient `friction` (>= 0).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `friction` when negative or not finite.
    pub fn with_friction(self, friction: T) -> Result<Self, Error> {
        Ok(Self {
            friction: validate::non_negative("friction", friction)?,
            ..self
        })
    }

    /// The coefficient of restitution.
    #[must_use]
    pub fn restitution(&self) -> T {
        self.restitution
    }
    /// The resting threshold on the rebound speed.
    #[must_use]
    pub fn rest_speed(&self) -> T {
        self.rest_speed
    }
    /// The event-location tolerance, s.
    #[must_use]
    pub fn time_tolerance(&self) -> T {
        self.time_tolerance
    }
    /// The Coulomb friction coefficient.
    #[must_use]
    pub fn friction(&self) -> T {
        self.friction
    }
}
