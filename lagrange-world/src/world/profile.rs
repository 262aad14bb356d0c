//! [`Profile`]: where a [`World`](super::World)'s step spent its time, read from a clock the
//! user gives ([`World::set_clock`](super::World::set_clock)): a cycle counter on a
//! microcontroller, nanoseconds on a desktop. The library reads no clock of its own (it has
//! none in `no_std`); without one every figure is zero and the step reads nothing.

/// A clock: its ticks now, counting up, never wrapping within a step (widen a 32-bit cycle
/// counter to `u64` before it wraps).
pub type Clock = fn() -> u64;

/// The ticks of the world's clock a step spent in each of its parts, in the order it runs
/// them (all zero without a clock).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Profile {
    /// The awake bodies' free steps (each body's own law).
    pub free: u64,
    /// The broad phase: every shape's box, and the pairs whose boxes overlap.
    pub broad: u64,
    /// The narrow phase: each pair's manifold, the half-planes', the bodies' own rows, and
    /// every contact's rows (Jacobians, mobilities through the mass solve).
    pub narrow: u64,
    /// The impulses: the sweeps over the contacts, the energy guard, and whether they sent
    /// a body where its contacts were not looked for (a second phase's detection goes to
    /// `broad` and `narrow`, its sweeps here).
    pub solve: u64,
    /// The drift correction and the move of the coordinates.
    pub drift: u64,
    /// Islands, sleep, contact events.
    pub sleep: u64,
}

impl Profile {
    /// The whole step: the sum of its parts.
    #[must_use]
    pub fn total(&self) -> u64 {
        [
            self.free,
            self.broad,
            self.narrow,
            self.solve,
            self.drift,
            self.sleep,
        ]
        .iter()
        .fold(0, |s, &x| s.saturating_add(x))
    }

    /// `other`'s figures added to these (a run's totals).
    #[must_use]
    pub fn plus(&self, other: &Self) -> Self {
        Self {
            free: self.free.saturating_add(other.free),
            broad: self.broad.saturating_add(other.broad),
            narrow: self.narrow.saturating_add(other.narrow),
            solve: self.solve.saturating_add(other.solve),
            drift: self.drift.saturating_add(other.drift),
            sleep: self.sleep.saturating_add(other.sleep),
        }
    }
}

/// Laps of a clock, or of none (every lap zero, no clock read).
#[derive(Debug, Clone, Copy)]
pub(super) struct Stopwatch {
    clock: Option<Clock>,
    last: u64,
}

impl Stopwatch {
    /// Started now.
    pub(super) fn start(clock: Option<Clock>) -> Self {
        Self {
            last: clock.map_or(0, |c| c()),
            clock,
        }
    }

    /// The ticks since the last lap (or the start); zero without a clock, or where the clock
    /// went back.
    pub(super) fn lap(&mut self) -> u64 {
        let Some(clock) = self.clock else {
            return 0;
        };
        let now = clock();
        let lap = now.saturating_sub(self.last);
        self.last = now;
        lap
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::sync::atomic::{AtomicU64, Ordering};

    static TICKS: AtomicU64 = AtomicU64::new(100);

    /// A clock that advances by 7 each time it is read.
    fn ticking() -> u64 {
        TICKS.fetch_add(7, Ordering::Relaxed)
    }

    #[test]
    fn laps_are_the_ticks_between_reads() {
        let mut watch = Stopwatch::start(Some(ticking));
        assert_eq!(watch.lap(), 7);
        assert_eq!(watch.lap(), 7);
        let mut none = Stopwatch::start(None);
        assert_eq!(none.lap(), 0);
    }

    #[test]
    fn a_profile_sums_its_parts() {
        let p = Profile {
            free: 1,
            broad: 2,
            narrow: 4,
            solve: 8,
            drift: 16,
            sleep: 32,
        };
        assert_eq!(p.total(), 63);
        assert_eq!(p.plus(&p).total(), 126);
        assert_eq!(p.plus(&Profile::default()), p);
        let full = Profile {
            free: u64::MAX,
            ..p
        };
        assert_eq!(full.total(), u64::MAX);
    }
}
