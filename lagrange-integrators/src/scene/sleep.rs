//! Sleeping, chosen per bank as a type parameter: [`NeverSleeps`] (the plain loop) or the
//! rule [`Sleeps`] (rest at an equilibrium, over a count of steps).

use crate::Integrator;
use lagrange_core::nalgebra::SVector;
use lagrange_core::{validate, Error, Mechanism, Real, State};

/// Whether, and by which rule, a bank's instances fall asleep: [`NeverSleeps`] or
/// [`Sleeps`]. A bank takes it as a type parameter so that never sleeping compiles to the
/// plain loop.
pub trait Sleep<T: Real>: Copy {
    /// The rule, or `None` for a bank whose instances never sleep (then every sleep check
    /// compiles away).
    fn rule(&self) -> Option<&Sleeps<T>>;
}

/// Instances never fall asleep: a bank steps every instance every step, with no checks.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct NeverSleeps;

impl<T: Real> Sleep<T> for NeverSleeps {
    #[inline(always)]
    fn rule(&self) -> Option<&Sleeps<T>> {
        None
    }
}

/// Most steps between two rest checks by default ([`Sleeps::checked_every`]).
const DEFAULT_CHECK_INTERVAL: u32 = 8;

/// An instance falls asleep when it rests at an equilibrium it would stay in, over a count
/// of consecutive steps:
///
/// ```text
/// at rest  <=>  T(q, q') <= kinetic                       (it hardly moves)
///          and  max_i |q''_i(t, q, 0)| <= acceleration   (and, let go, it would stay)
///          and  nothing drives it: no explicit time dependence (Lagrangian::DRIVEN) and
///               no force at zero velocity, inputs included (Q(t, q, 0) = 0)
/// ```
///
/// The second condition is what keeps a swinging prop from freezing at the top of its
/// swing, where it stops for an instant but would fall back at once: looking at velocities
/// alone is the classic bug. The zero-velocity acceleration is the law the bank's integrator
/// steps ([`Integrator::law_acceleration`]): a constrained mechanism's, with its constraint
/// forces; a contact stepper's, with its resting contacts (a ball on the floor rests).
///
/// Rest is checked every [`Sleeps::interval`] steps (8 by default), on the awake instances
/// only, so that the check costs a fraction of a step; an instance falls asleep at the first
/// check at which it has been found at rest at every check over at least `steps` steps.
/// Falling asleep sets its velocities to zero, which changes its energy by its kinetic
/// energy: at most `kinetic`.
///
/// How long it takes, measured (tests/tests/scene_sleep.rs, `f32` and `f64` alike): a 1 m,
/// 1 kg pendulum damped at 3 N m s (decay rate 1.5/s) let go from 30 degrees at 120 Hz falls
/// asleep under `Sleeps::new(1e-6, 1e-3, 60)` 5.73 s after release, 9.7e-5 rad from the
/// bottom, its energy changed by 7.6e-12 J in falling asleep. The acceleration test decides:
/// the swing must shrink until `g |sin th| <= 1e-3` at its turning points. An undamped one
/// swinging from 30 degrees never sleeps (10^6 steps), not even under a kinetic threshold
/// loose enough to pass at every turning point.
///
/// By default a driven mechanism never sleeps; [`Sleeps::even_when_driven`] lets the two
/// thresholds alone decide (a cart held still by a constant push against a wall).
///
/// ```
/// use lagrange_integrators::scene::Sleeps;
/// // Asleep after 60 steps (half a second at 120 Hz) with T < 1e-6 J and |q''| < 1e-3.
/// let rule = Sleeps::new(1e-6_f32, 1e-3, 60)?;
/// assert_eq!(rule.interval(), 8);
/// assert!(Sleeps::new(-1.0_f32, 1e-3, 60).is_err());
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sleeps<T> {
    kinetic: T,
    acceleration: T,
    steps: u32,
    interval: u32,
    driven_too: bool,
}

impl<T: Real> Sleeps<T> {
    /// Asleep after `steps` (at least 1) consecutive steps at rest: kinetic energy at most
    /// `kinetic` (J, >= 0), every generalized acceleration at zero velocity at most
    /// `acceleration` in magnitude (>= 0, in the units of `q''`), checked every
    /// `min(steps, 8)` steps.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `kinetic` or `acceleration` when negative or not finite,
    /// `steps` when zero.
    pub fn new(kinetic: T, acceleration: T, steps: u32) -> Result<Self, Error> {
        if steps == 0 {
            return Err(Error::InvalidParameter {
                name: "steps",
                reason: "must be at least 1",
            });
        }
        Ok(Self {
            kinetic: validate::non_negative("kinetic", kinetic)?,
            acceleration: validate::non_negative("acceleration", acceleration)?,
            steps,
            interval: steps.min(DEFAULT_CHECK_INTERVAL),
            driven_too: false,
        })
    }

    /// The same rule, checking rest every `interval` steps (1 to `steps`): more often costs
    /// more, less often lets an instance sleep later.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `interval` when zero or above `steps`.
    pub fn checked_every(self, interval: u32) -> Result<Self, Error> {
        if interval == 0 || interval > self.steps {
            return Err(Error::InvalidParameter {
                name: "interval",
                reason: "must be at least 1 and at most steps",
            });
        }
        Ok(Self { interval, ..self })
    }

    /// The same rule, applied to driven mechanisms too (explicit time, a nonzero input):
    /// the thresholds alone decide.
    #[must_use]
    pub fn even_when_driven(self) -> Self {
        Self {
            driven_too: true,
            ..self
        }
    }

    /// The kinetic energy threshold, J.
    #[must_use]
    pub fn kinetic(&self) -> T {
        self.kinetic
    }

    /// The zero-velocity acceleration threshold.
    #[must_use]
    pub fn acceleration(&self) -> T {
        self.acceleration
    }

    /// Steps at rest before sleeping.
    #[must_use]
    pub fn steps(&self) -> u32 {
        self.steps
    }

    /// Steps between two rest checks.
    #[must_use]
    pub fn interval(&self) -> u32 {
        self.interval
    }

    /// Whether driven mechanisms may sleep.
    #[must_use]
    pub fn driven_too(&self) -> bool {
        self.driven_too
    }

    /// True when `state` of `mechanism`, stepped by `integrator`, is at rest by this rule
    /// (cheapest test first; a test that fails to evaluate says "not at rest").
    pub(crate) fn rests<const N: usize, M, I>(
        &self,
        mechanism: &M,
        integrator: &I,
        state: &State<T, N>,
    ) -> bool
    where
        M: Mechanism<T, N>,
        I: Integrator<T, N, M>,
    {
        if M::DRIVEN && !self.driven_too {
            return false;
        }
        let kinetic = mechanism.kinetic_energy(state);
        if !kinetic.is_finite() || kinetic > self.kinetic {
            return false;
        }
        let still = State {
            qd: SVector::zeros(),
            ..*state
        };
        if !self.driven_too
            && mechanism
                .non_conservative_force(&still)
                .iter()
                .any(|&f| f != T::zero())
        {
            return false;
        }
        integrator
            .law_acceleration(mechanism, &still)
            .is_ok_and(|a| a.iter().all(|&x| x.abs() <= self.acceleration))
    }
}

impl<T: Real> Sleep<T> for Sleeps<T> {
    #[inline(always)]
    fn rule(&self) -> Option<&Sleeps<T>> {
        Some(self)
    }
}
