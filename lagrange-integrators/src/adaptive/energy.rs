//! The energy projection of the adaptive pairs
//! ([`AdaptiveSettings::with_energy_projection`](super::AdaptiveSettings::with_energy_projection)):
//! the velocities at the end of a step scaled back onto the energy the run started with.

use super::settings::ENERGY_PROJECTION_LIMIT;
use super::sums::real;
use lagrange_core::{Error, Mechanism, Real, State};

/// The energy `T + V` a run starting at `state` holds.
///
/// # Errors
/// [`Error::InvalidParameter`] `mechanism` for a driven mechanism, whose `T + V` is not
/// conserved; [`Error::NonFiniteState`] where the energy is not finite.
pub(super) fn start_energy<T, M, const N: usize>(m: &M, state: &State<T, N>) -> Result<T, Error>
where
    T: Real,
    M: Mechanism<T, N>,
{
    if M::DRIVEN {
        return Err(Error::InvalidParameter {
            name: "mechanism",
            reason: "is driven: its energy T + V is not conserved, and cannot be projected onto",
        });
    }
    // T and V apart, as `project` takes them.
    let e0 = m.kinetic_energy(state) + m.potential_energy(state);
    if e0.is_finite() {
        Ok(e0)
    } else {
        Err(Error::NonFiniteState)
    }
}

/// Scales the velocities of `y` by `a = sqrt((e0 - V) / T)`, which makes its energy `e0`
/// again (`T` being quadratic in them), with `a` kept within [`ENERGY_PROJECTION_LIMIT`] of 1:
/// where the exact factor is further (a state near rest, whose kinetic energy cannot carry the
/// correction, or a run that drifted before), the speed changes by the limit, towards `e0`. A
/// state at rest, or whose energies are not numbers, is left as it is.
///
/// # Errors
/// [`Error::InvalidParameter`] `mechanism` where a non-conservative force acts at `y`.
pub(super) fn project<T, M, const N: usize>(m: &M, y: &mut State<T, N>, e0: T) -> Result<(), Error>
where
    T: Real,
    M: Mechanism<T, N>,
{
    if m.non_conservative_force(y).iter().any(|x| *x != T::zero()) {
        return Err(Error::InvalidParameter {
            name: "mechanism",
            reason: "has a non-conservative force (damping, an input): its energy is not held",
        });
    }
    let kinetic = m.kinetic_energy(y);
    // The square of the exact factor: the kinetic energy wanted over the one there is.
    let ratio = (e0 - m.potential_energy(y)) / kinetic;
    // At rest (or a kinetic energy that is not a number), or energies that are not numbers.
    let moving = kinetic.partial_cmp(&T::zero()) == Some(core::cmp::Ordering::Greater);
    if !moving || ratio.partial_cmp(&T::zero()).is_none() {
        return Ok(());
    }
    let limit = real::<T>(ENERGY_PROJECTION_LIMIT);
    let (low, high) = (T::one() - limit, T::one() + limit);
    y.qd *= if ratio < low * low {
        low
    } else if ratio > high * high {
        high
    } else {
        ratio.sqrt()
    };
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::{project, start_energy};
    use lagrange_core::{Error, Lagrangian, State};
    use lagrange_systems::{BeadOnRotatingHoop, SimplePendulum};

    /// The pendulum of unit mass and length under g = 1: `T = w^2 / 2`.
    fn pendulum(damping: f64) -> Result<SimplePendulum<f64>, Error> {
        SimplePendulum::new(1.0, 1.0, 1.0, damping)
    }

    /// Scaled onto the energy to rounding where the speed changes by at most 1%; by 1%
    /// towards it beyond (the exact factors 1/1.02 and 1/0.98, about 45,000 near rest, and
    /// none where the potential energy alone is above the target); left alone at rest.
    #[test]
    fn scales_onto_the_energy_or_by_the_limit_towards_it() -> Result<(), Error> {
        let p = pendulum(0.0)?;
        // The energy of unit speed at the bottom.
        let e0 = p.energy(&State::new(0.0, [0.0], [1.0]));
        let mut near = State::new(0.0, [0.0], [1.005]);
        project(&p, &mut near, e0)?;
        assert!((near.qd[0] - 1.0).abs() <= 1e-15, "{near:?}");
        let raised = p.energy(&State::at_rest([0.3])) + 1e-3;
        let lowered = p.energy(&State::at_rest([0.3])) - 1e-3;
        for (s, target, factor) in [
            (State::new(0.0, [0.0], [1.02]), e0, 0.99),
            (State::new(0.0, [0.0], [0.98]), e0, 1.01),
            (State::new(0.0, [0.3], [1e-6]), raised, 1.01),
            (State::new(0.0, [0.3], [1e-6]), lowered, 0.99),
            (State::at_rest([0.3]), raised, 1.0),
        ] {
            let mut moved = s;
            project(&p, &mut moved, target)?;
            assert_eq!(moved.qd[0], s.qd[0] * factor, "{s:?}");
            assert_eq!((moved.t, moved.q), (s.t, s.q));
        }
        Ok(())
    }

    /// A non-conservative force where the projection is asked is an error (none acts on a
    /// damped pendulum at rest); a driven mechanism has no energy to hold.
    #[test]
    fn refuses_what_does_not_conserve_its_energy() -> Result<(), Error> {
        let damped = pendulum(0.1)?;
        let mut moving = State::new(0.0, [0.0], [1.0]);
        let refused = Err(Error::InvalidParameter {
            name: "mechanism",
            reason: "has a non-conservative force (damping, an input): its energy is not held",
        });
        assert_eq!(project(&damped, &mut moving, 0.5), refused);
        assert_eq!(project(&damped, &mut State::at_rest([0.2]), 0.5), Ok(()));
        let bead = BeadOnRotatingHoop::new(1.0, 1.0, 2.0, 9.81)?;
        assert!(matches!(
            start_energy(&bead, &State::at_rest([0.1])),
            Err(Error::InvalidParameter {
                name: "mechanism",
                ..
            })
        ));
        Ok(())
    }
}
