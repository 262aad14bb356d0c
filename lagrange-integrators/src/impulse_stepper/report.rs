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
    /// Contacts still open that would have joined (speculative, or taken below the slop by
    /// the drift correction) but for which the settings' `max_rows` left no room: `rows`
    /// never exceeds the cap. Zero without one.
    pub left_out: u32,
    /// Contacts with a tangent (friction).
    pub frictional: u32,
    /// Exact solves of the normal rows, each followed by a friction sweep: at most the
    /// settings' `max_iterations` for the plastic solve, and one more for each of the three
    /// that may follow it (two with speculative rows, the rebound), which share what it left:
    /// at most `ImpulseSettings::max_rounds`.
    pub rounds: u32,
    /// Whether the friction sweeps settled before the cap (always without friction, and when
    /// no row was in contact). Where they did not, the impulses are those of the last round,
    /// the cone holds, and the step still never gains energy.
    pub settled: bool,
    /// Whether the drift correction moved the coordinates.
    pub corrected: bool,
    /// Corrections of the drift on the gaps the first one left (the gaps are not linear in
    /// the coordinates: a link turned in the step), each one exact solve of the rows: at most
    /// three.
    pub drift_rounds: u32,
    /// Whether the drift correction could not bring every contact within the slop in its
    /// rounds (a link turned by a large part of a radian in one step), so that the
    /// coordinates stayed where the step began (the velocities are the impulses').
    pub held_back: bool,
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
            left_out: self.left_out.max(other.left_out),
            frictional: self.frictional.max(other.frictional),
            rounds: self.rounds.max(other.rounds),
            settled: self.settled && other.settled,
            corrected: self.corrected || other.corrected,
            drift_rounds: self.drift_rounds.max(other.drift_rounds),
            held_back: self.held_back || other.held_back,
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
            left_out: 0,
            frictional: 0,
            rounds: 0,
            settled: true,
            corrected: false,
            drift_rounds: 0,
            held_back: false,
            energy_guard: false,
        }
    }
}
