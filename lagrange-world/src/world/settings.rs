//! [`WorldSettings`]: how a [`World`](super::World) handles its contacts.

use lagrange_core::constraints::contact::ContactModel;
use lagrange_core::{Error, Real};

/// How a [`World`](super::World) handles its contacts: the contact model (restitution, the
/// speed below which a contact rests rather than bounces, friction), the slop a contact may
/// rest within, the sweeps of its impulse solve (the cap on its work), the speculative
/// margin, and when its bodies fall asleep.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WorldSettings<T> {
    pub(crate) model: ContactModel<T>,
    pub(crate) slop: T,
    pub(crate) sweeps: u32,
    pub(crate) margin: T,
    pub(crate) sleep_speed: T,
    pub(crate) sleep_time: T,
}

impl<T: Real> WorldSettings<T> {
    /// `model`'s restitution, rest speed and friction (its time tolerance is the event
    /// stepper's and is not used), contacts resting within `slop` (m, > 0: the drift
    /// correction leaves a contact that deep, which keeps it in touch and quiet), `sweeps`
    /// sweeps of the impulse solve a step (>= 1; the drift correction's sweeps run again,
    /// up to four times as many in all, while a contact is left more than a slop deeper
    /// than it asks). A speculative margin of `4 slop` (bodies moving faster widen it by how
    /// far they move in the step); no sleeping.
    ///
    /// How many sweeps: a step's work grows with them, and a tall stack needs more, its
    /// weight carried down one row a sweep. A pyramid of 10 rows of boxes stands with 8
    /// (its top box 5 mm from its start after a minute); one of 20 rows falls apart with 8
    /// and stands with 12 (its top box 13 mm from its start after 10 s). A column of ten
    /// 1 m boxes placed by hand stands with 8; small boxes need more (ten 10 cm ones, 32).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `slop` unless positive and finite, `sweeps` when zero.
    pub fn new(model: ContactModel<T>, slop: T, sweeps: u32) -> Result<Self, Error> {
        if !(slop > T::zero() && slop.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "slop",
                reason: "must be positive and finite",
            });
        }
        if sweeps == 0 {
            return Err(Error::InvalidParameter {
                name: "sweeps",
                reason: "must be at least one",
            });
        }
        Ok(Self {
            model,
            slop,
            sweeps,
            margin: slop * T::from_f64(4.0),
            sleep_speed: T::zero(),
            sleep_time: T::INFINITY,
        })
    }

    /// The speculative margin: shapes this close (plus how far they move in a step) make
    /// contact rows that may close in the step but no further (m, >= `slop`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `margin` when below the slop or not finite.
    pub fn with_margin(self, margin: T) -> Result<Self, Error> {
        if !(margin >= self.slop && margin.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "margin",
                reason: "must be finite and at least the slop",
            });
        }
        Ok(Self { margin, ..self })
    }

    /// Islands whose every coordinate's rate stays below `speed` (> 0) for `time` s (> 0)
    /// fall asleep: they are not stepped, and wake when an awake body touches them.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `speed` or `time` unless positive and finite.
    pub fn with_sleep(self, speed: T, time: T) -> Result<Self, Error> {
        if !(speed > T::zero() && speed.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "speed",
                reason: "must be positive and finite",
            });
        }
        if !(time > T::zero() && time.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "time",
                reason: "must be positive and finite",
            });
        }
        Ok(Self {
            sleep_speed: speed,
            sleep_time: time,
            ..self
        })
    }

    /// The contact model.
    #[must_use]
    pub fn model(&self) -> ContactModel<T> {
        self.model
    }

    /// The slop, m.
    #[must_use]
    pub fn slop(&self) -> T {
        self.slop
    }

    /// The impulse solve's sweeps a step.
    #[must_use]
    pub fn sweeps(&self) -> u32 {
        self.sweeps
    }

    /// The speculative margin, m.
    #[must_use]
    pub fn margin(&self) -> T {
        self.margin
    }
}
