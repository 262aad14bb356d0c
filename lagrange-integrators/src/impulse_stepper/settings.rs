//! [`ImpulseSettings`]: the slop and the work caps of an [`ImpulseStepper`](super::ImpulseStepper).

use lagrange_core::{validate, Error, Real};

/// Most rounds a solve may be allowed: beyond a thousand a friction solve that has not
/// settled never will, and the cap bounds the cost of a step whatever is asked.
const MAX_ITERATIONS_CAP: u32 = 1000;

/// How deep a contact may rest and how much work a step of an
/// [`ImpulseStepper`](super::ImpulseStepper) may do.
///
/// ```text
/// slop            a contact may end a step this far below zero (gap units: m for a floor,
///                 rad for a joint limit); deeper, the position correction lifts it back to
///                 it. A little slop keeps a resting contact in touch from step to step
///                 (quiet, and warm-started); none makes every resting step lift it. Choose
///                 it above a step's free fall, dt^2 g (0.17 mm at 240 Hz, 2.7 mm at 60 Hz)
/// max_iterations  rounds of the plastic impulse solve, at most (each an exact solve of the
///                 normal rows, then a Gauss-Seidel sweep of the friction tangents; the last
///                 round sweeps until one changes nothing, at most this many); the solves
///                 after it (speculative rows, rebounds) share what it left, at least one
///                 round each: at most max_iterations + 3 rounds a step (max_rounds), the
///                 cap on a step's work
/// tolerance       a round whose first sweep changes no tangent's speed by more than this
///                 (gap units per second, plus the rounding of the speed) ends the solve
/// max_rows        rows in a step's solve, at most (default: every row of the set): the
///                 cap on a step's work in rows; more rows in contact is an error naming
///                 it, and open rows that would join beyond it (speculative, or taken below
///                 the slop by the drift correction) are left out, the deepest kept (the
///                 report's left_out)
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ImpulseSettings<T> {
    slop: T,
    max_iterations: u32,
    tolerance: T,
    max_rows: Option<u32>,
}

impl<T: Real> ImpulseSettings<T> {
    /// A slop of `slop` (gap units, >= 0, finite) and at most `max_iterations` (1 to 1000)
    /// rounds per solve, ending early below a tolerance of 1e-6 gap units per second.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `slop` when negative or not finite; `max_iterations` when
    /// zero or above 1000.
    pub fn new(slop: T, max_iterations: u32) -> Result<Self, Error> {
        if !(1..=MAX_ITERATIONS_CAP).contains(&max_iterations) {
            return Err(Error::InvalidParameter {
                name: "max_iterations",
                reason: "must be from 1 to 1000",
            });
        }
        Ok(Self {
            slop: validate::non_negative("slop", slop)?,
            max_iterations,
            tolerance: T::from_f64(1e-6),
            max_rows: None,
        })
    }

    /// The same settings with the rounds ending early at `tolerance` (gap units per second,
    /// > 0, finite).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `tolerance` when not positive and finite.
    pub fn with_tolerance(self, tolerance: T) -> Result<Self, Error> {
        Ok(Self {
            tolerance: validate::positive("tolerance", tolerance)?,
            ..self
        })
    }

    /// The same settings with at most `max_rows` (at least 1) rows in a step's solve: more
    /// in contact is an error, open rows beyond it do not join (see the type's docs).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `max_rows` when zero.
    pub fn with_max_rows(self, max_rows: u32) -> Result<Self, Error> {
        if max_rows == 0 {
            return Err(Error::InvalidParameter {
                name: "max_rows",
                reason: "must be at least 1",
            });
        }
        Ok(Self {
            max_rows: Some(max_rows),
            ..self
        })
    }

    /// The slop, gap units.
    #[must_use]
    pub fn slop(&self) -> T {
        self.slop
    }

    /// The most rounds of a step's plastic solve, and the most friction sweeps of a solve's
    /// last round (the others sweep once).
    #[must_use]
    pub fn max_iterations(&self) -> u32 {
        self.max_iterations
    }

    /// The most rounds a step takes: `max_iterations` for its plastic solve, then at most one
    /// for each of the three solves that may follow it (twice with speculative rows, once for
    /// rebounds), which share what the plastic solve left.
    #[must_use]
    pub fn max_rounds(&self) -> u32 {
        self.max_iterations + 3
    }

    /// The rounds' early-end tolerance, gap units per second.
    #[must_use]
    pub fn tolerance(&self) -> T {
        self.tolerance
    }

    /// The most rows in a step's solve, if capped below the contact set's size.
    #[must_use]
    pub fn max_rows(&self) -> Option<u32> {
        self.max_rows
    }
}
