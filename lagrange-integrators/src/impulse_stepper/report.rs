//! [`ImpulseReport`]: what one step of an [`ImpulseStepper`](super::ImpulseStepper) did.

/// What the last step of an [`ImpulseStepper`](super::ImpulseStepper) did: the counts its
/// work is bounded by (see the stepper's docs), and whether its solve settled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ImpulseReport {
    /// Normal rows solved (in contact, bilateral or speculative): at most the contact set's
    /// size.
    pub rows: u32,
    /// Of those, contacts still open that joined because the step's motion would close them.
    pub speculative: u32,
    /// Contacts with a tangent (friction).
    pub frictional: u32,
    /// Exact solves of the normal rows, each followed by friction sweeps: at most the
    /// settings' `max_iterations` per solve, and at most four solves (the plastic one, two
    /// more with speculative rows, the rebound).
    pub rounds: u32,
    /// Whether the friction sweeps settled before the cap (always without friction, and when
    /// no row was in contact). Where they did not, the impulses are those of the last round,
    /// the cone holds, and the step still never gains energy.
    pub settled: bool,
    /// Whether the drift correction moved the coordinates.
    pub corrected: bool,
    /// Whether the energy guard scaled the velocities down.
    pub energy_guard: bool,
}

impl ImpulseReport {
    /// The worse of the two, count by count and flag by flag.
    #[must_use]
    pub fn worst(&self, other: &Self) -> Self {
        Self {
            rows: self.rows.max(other.rows),
            speculative: self.speculative.max(other.speculative),
            frictional: self.frictional.max(other.frictional),
            rounds: self.rounds.max(other.rounds),
            settled: self.settled && other.settled,
            corrected: self.corrected || other.corrected,
            energy_guard: self.energy_guard || other.energy_guard,
        }
    }
}

impl Default for ImpulseReport {
    /// A step with no row in contact: no work, settled.
    fn default() -> Self {
        Self {
            rows: 0,
            speculative: 0,
            frictional: 0,
            rounds: 0,
            settled: true,
            corrected: false,
            energy_guard: false,
        }
    }
}
