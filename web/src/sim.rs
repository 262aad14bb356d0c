//! [`Sim`]: one mechanism of the page in a scene (a bank of its instance and, for the chaotic
//! double pendulum, its twin) with one fixed-timestep clock, and what the page asks of it
//! ([`Panel`]): advance by a frame, points to draw, energy error, drags, inputs, resets.

use lagrange_core::nalgebra::{SVector, Vector2};
use lagrange_core::{Error, Mechanism, Real, State};
use lagrange_integrators::scene::{Bank, Id, Layout, OneByOne, Scene, Sleeps, Status};
use lagrange_integrators::Integrator;

/// The most fixed steps one frame may take: a slow frame (or a tiny dt) slows the motion
/// down instead of freezing the page.
pub const MAX_STEPS_PER_FRAME: u32 = 16;

/// What the page does with a mechanism, whatever its type, scalar and integrator.
pub trait Panel {
    /// Advances by `frame_time` seconds. An instance whose step fails is reset to its start
    /// and its error kept for [`Panel::error`].
    fn advance(&mut self, frame_time: f64);
    /// The points to draw, interpolated between the last two steps, world coordinates (m):
    /// first the main instance's, then (if any) the twin's, then (if any) the exact
    /// solution's. Every value is finite (a state that is not is never drawn).
    fn points(&self, out: &mut Vec<f64>) -> PointCounts;
    /// `(E - E0) / max(|E0|, scale)` of the main instance, `E0` its energy at the last start,
    /// drag or input change.
    fn energy_error(&self) -> f64;
    /// The main instance: 0 awake, 1 asleep, 2 set aside after a failed step.
    fn status(&self) -> u32;
    /// The scene's time, s.
    fn time(&self) -> f64;
    /// The fixed step, s.
    fn dt(&self) -> f64;
    /// A new fixed step: the scene is rebuilt around the current states.
    ///
    /// # Errors
    /// The library's refusal of `dt` (not positive and finite): the instance is then reset
    /// to its start with its default step, and the error kept.
    fn set_dt(&mut self, dt: f64) -> Result<(), Error>;
    /// Drags point `point` of the main instance: an impulse that gives it the velocity
    /// `(vx, vy)` (m/s), which wakes it.
    ///
    /// # Errors
    /// The library's refusal (a non-finite or overflowing impulse, a point that cannot move):
    /// the instance is then reset and the error kept.
    fn drag(&mut self, point: usize, vx: f64, vy: f64) -> Result<(), Error>;
    /// Sets the input (the cart-pole's force, N); others have none.
    ///
    /// # Errors
    /// The library's refusal of the value, or [`Error::InvalidParameter`] for a mechanism
    /// without an input.
    fn set_input(&mut self, input: f64) -> Result<(), Error>;
    /// Back to the start state and the default step.
    fn reset(&mut self);
    /// The last error, once: taken by the call.
    fn take_error(&mut self) -> Option<Error>;
    /// The worst work of any step since the page loaded, `[rows, rounds]` (zero for
    /// integrators that do not report it).
    fn work(&self) -> [u32; 2];
}

/// How many points of each group [`Panel::points`] wrote.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PointCounts {
    /// The main instance's.
    pub main: usize,
    /// The twin's (0 when there is none).
    pub twin: usize,
    /// The exact solution's (0 when there is none).
    pub exact: usize,
}

/// The points to draw of a mechanism at `q`, in f64 world coordinates.
pub type PointsFn<M, T, const N: usize> = fn(&M, &SVector<T, N>) -> Vec<[f64; 2]>;

/// The input of the mechanism, set on its bank.
pub type InputFn<T, const N: usize, M, I, Y = OneByOne> =
    fn(&mut Bank<T, N, 2, M, I, Sleeps<T>, Y>, Id, f64) -> Result<(), Error>;

/// The bank of a [`Sim`], laid out by `Y`: [`InLanes`](lagrange_integrators::scene::InLanes)
/// for the mechanisms that gather (the same bits as one by one).
type SimBank<T, const N: usize, M, I, Y> = Bank<T, N, 2, M, I, Sleeps<T>, Y>;

/// A scene over a [`SimBank`] and the ids of its instances (main, then twin). The scene is
/// boxed where it is made: a bank of two ragdoll impulse steppers in `f64` is 100 kB, and each
/// frame that moved it by value kept a copy (unoptimised, the page's tests overflowed a 2 MB
/// thread stack).
type Built<T, const N: usize, M, I, Y> = (Box<Scene<T, SimBank<T, N, M, I, Y>>>, Vec<Id>);

/// The exact solution's points at time `t`, s.
pub type ExactFn = fn(f64) -> Vec<[f64; 2]>;

/// How a [`Sim`] is made: its mechanism, its start states, its integrator and rules.
pub struct Recipe<T: Real, const N: usize, M, I, Y: Layout<T, N, 2, M> = OneByOne> {
    /// The mechanism (parameters).
    pub mechanism: M,
    /// The main instance's start.
    pub start: State<T, N>,
    /// A twin's start, drawn faintly beside it.
    pub twin: Option<State<T, N>>,
    /// The integrator every instance is stepped by (a copy each).
    pub integrator: I,
    /// When the instances fall asleep.
    pub sleep: Sleeps<T>,
    /// The default fixed step, s.
    pub dt: f64,
    /// A natural energy, J: the energy error's floor of scale.
    pub energy_scale: f64,
    /// The points to draw.
    pub points: PointsFn<M, T, N>,
    /// The exact solution's points at time `t`, while the motion is the exact one's.
    pub exact: Option<ExactFn>,
    /// The input, for a mechanism that has one.
    pub input: Option<InputFn<T, N, M, I, Y>>,
    /// The worst work of the integrator's steps so far, `[rows, rounds]`, for one that
    /// reports it (a time-stepping contact solver).
    pub work: Option<fn(&I) -> [u32; 2]>,
}

/// One mechanism in its scene.
pub struct Sim<T: Real, const N: usize, M, I, Y: Layout<T, N, 2, M> = OneByOne> {
    recipe: Recipe<T, N, M, I, Y>,
    scene: Box<Scene<T, SimBank<T, N, M, I, Y>>>,
    ids: Vec<Id>,
    dt: f64,
    e0: f64,
    exact_valid: bool,
    error: Option<Error>,
    /// The worst work of any step since the page loaded (resets and rebuilds included).
    peak: [u32; 2],
}

/// A scene over a new bank of the recipe's instances at `states`, stepped by `dt`.
fn build<T, const N: usize, M, I, Y>(
    recipe: &Recipe<T, N, M, I, Y>,
    states: &[State<T, N>],
    dt: f64,
) -> Result<Built<T, N, M, I, Y>, Error>
where
    Y: Layout<T, N, 2, M>,
    T: Real,
    M: Mechanism<T, N> + Clone,
    I: Integrator<T, N, M> + Clone,
{
    let mut bank: SimBank<T, N, M, I, Y> = Bank::new(recipe.integrator.clone(), recipe.sleep)?;
    let mut ids = Vec::with_capacity(states.len());
    for s in states {
        ids.push(bank.add(recipe.mechanism.clone(), *s)?);
    }
    let scene = Box::new(Scene::new(bank, T::from_f64(dt), MAX_STEPS_PER_FRAME)?);
    Ok((scene, ids))
}

impl<T, const N: usize, M, I, Y> Sim<T, N, M, I, Y>
where
    Y: Layout<T, N, 2, M>,
    T: Real,
    M: Mechanism<T, N> + Clone,
    I: Integrator<T, N, M> + Clone,
{
    /// The mechanism of `recipe` at its start.
    ///
    /// # Errors
    /// The library's errors building the bank and the scene.
    pub fn new(recipe: Recipe<T, N, M, I, Y>) -> Result<Self, Error> {
        let (scene, ids) = build(&recipe, &Self::starts(&recipe), recipe.dt)?;
        let e0 = recipe.mechanism.energy(&recipe.start).to_f64();
        let dt = recipe.dt;
        let exact_valid = recipe.exact.is_some();
        Ok(Self {
            recipe,
            scene,
            ids,
            dt,
            e0,
            exact_valid,
            error: None,
            peak: [0; 2],
        })
    }

    /// The start states: main, then twin.
    fn starts(recipe: &Recipe<T, N, M, I, Y>) -> Vec<State<T, N>> {
        core::iter::once(recipe.start).chain(recipe.twin).collect()
    }

    /// The main instance's current state.
    fn main_state(&self) -> Result<State<T, N>, Error> {
        let id = *self.ids.first().ok_or(Error::NoSuchInstance)?;
        self.scene.banks().state(id)
    }

    /// Keeps `error` and resets.
    fn fail(&mut self, error: Error) -> Error {
        self.reset();
        self.error = Some(error);
        error
    }

    /// Rebuilds the scene around `states` at step `dt`.
    fn rebuild(&mut self, states: &[State<T, N>], dt: f64) -> Result<(), Error> {
        let (scene, ids) = build(&self.recipe, states, dt)?;
        self.scene = scene;
        self.ids = ids;
        self.dt = dt;
        Ok(())
    }
}

/// Appends the finite points of `points` to `out` as x, y pairs; the count written (none
/// when any value is not finite: a state that is not finite is never drawn).
fn push_finite(out: &mut Vec<f64>, points: &[[f64; 2]]) -> usize {
    if points.iter().flatten().all(|x| x.is_finite()) {
        out.extend(points.iter().flatten());
        points.len()
    } else {
        0
    }
}

impl<T, const N: usize, M, I, Y> Panel for Sim<T, N, M, I, Y>
where
    Y: Layout<T, N, 2, M>,
    T: Real,
    M: Mechanism<T, N> + Clone,
    I: Integrator<T, N, M> + Clone,
{
    fn advance(&mut self, frame_time: f64) {
        let frame_time = if frame_time.is_finite() {
            frame_time.clamp(0.0, 0.25)
        } else {
            0.0
        };
        if let Err(e) = self.scene.advance(T::from_f64(frame_time)) {
            self.fail(e);
            return;
        }
        let failure = self
            .ids
            .iter()
            .find_map(|&id| match self.scene.banks().status(id) {
                Ok(Status::Failed(e)) => Some(e),
                Err(e) => Some(e),
                _ => None,
            });
        if let Some(e) = failure {
            self.fail(e);
        }
        if let Some(work) = self.recipe.work {
            for &id in &self.ids {
                if let Ok(i) = self.scene.banks().integrator(id) {
                    let [rows, rounds] = work(i);
                    self.peak = [self.peak[0].max(rows), self.peak[1].max(rounds)];
                }
            }
        }
    }

    fn work(&self) -> [u32; 2] {
        self.peak
    }

    fn points(&self, out: &mut Vec<f64>) -> PointCounts {
        let bank = self.scene.banks();
        let alpha = self.scene.alpha();
        let mut counts = PointCounts::default();
        for (k, &id) in self.ids.iter().enumerate() {
            let (Ok(s), Ok(m)) = (bank.interpolated(id, alpha), bank.mechanism(id)) else {
                continue;
            };
            let n = push_finite(out, &(self.recipe.points)(m, &s.q));
            if k == 0 {
                counts.main = n;
            } else {
                counts.twin = n;
            }
        }
        if let (true, Some(exact)) = (self.exact_valid, self.recipe.exact) {
            let t = (self.scene.time() + self.scene.alpha() * self.scene.dt()).to_f64();
            counts.exact = push_finite(out, &exact(t));
        }
        counts
    }

    fn energy_error(&self) -> f64 {
        let Ok(s) = self.main_state() else {
            return 0.0;
        };
        let e = self.recipe.mechanism.energy(&s).to_f64();
        let error = (e - self.e0) / self.e0.abs().max(self.recipe.energy_scale);
        if error.is_finite() {
            error
        } else {
            0.0
        }
    }

    fn status(&self) -> u32 {
        match self.ids.first().map(|&id| self.scene.banks().status(id)) {
            Some(Ok(Status::Awake)) => 0,
            Some(Ok(Status::Asleep)) => 1,
            _ => 2,
        }
    }

    fn time(&self) -> f64 {
        self.scene.time().to_f64()
    }

    fn dt(&self) -> f64 {
        self.dt
    }

    fn set_dt(&mut self, dt: f64) -> Result<(), Error> {
        let bank = self.scene.banks();
        let states: Result<Vec<State<T, N>>, Error> =
            self.ids.iter().map(|&id| bank.state(id)).collect();
        let rebuilt = states.and_then(|states| self.rebuild(&states, dt));
        rebuilt.map_err(|e| self.fail(e))?;
        // The exact solution no longer shares the clock's start.
        self.exact_valid = false;
        Ok(())
    }

    fn drag(&mut self, point: usize, vx: f64, vy: f64) -> Result<(), Error> {
        let pushed = self.impulse(point, vx, vy);
        pushed.map_err(|e| self.fail(e))
    }

    fn set_input(&mut self, input: f64) -> Result<(), Error> {
        let (Some(set), Some(&id)) = (self.recipe.input, self.ids.first()) else {
            return Err(Error::InvalidParameter {
                name: "input",
                reason: "this mechanism has no input",
            });
        };
        set(self.scene.banks_mut(), id, input).map_err(|e| self.fail(e))?;
        // The input does work: the energy is measured from here.
        if let Ok(s) = self.main_state() {
            self.e0 = self.recipe.mechanism.energy(&s).to_f64();
        }
        Ok(())
    }

    fn reset(&mut self) {
        let starts = Self::starts(&self.recipe);
        if self.rebuild(&starts, self.recipe.dt).is_err() {
            // The recipe built once; it builds again. Nothing else to do.
            return;
        }
        self.e0 = self.recipe.mechanism.energy(&self.recipe.start).to_f64();
        self.exact_valid = self.recipe.exact.is_some();
    }

    fn take_error(&mut self) -> Option<Error> {
        self.error.take()
    }
}

impl<T, const N: usize, M, I, Y> Sim<T, N, M, I, Y>
where
    Y: Layout<T, N, 2, M>,
    T: Real,
    M: Mechanism<T, N> + Clone,
    I: Integrator<T, N, M> + Clone,
{
    /// The generalized impulse `p = J^T lambda` that sets the velocity of point `point` to
    /// `(vx, vy)`: `J` its Jacobian (central differences of the drawing's points), `lambda`
    /// from `(J M^-1 J^T) lambda = v* - J q'`, `M^-1 J^T` by the mechanism's own velocity
    /// jump (a constrained mechanism keeps its constraints). Applied to the bank: it wakes.
    fn impulse(&mut self, point: usize, vx: f64, vy: f64) -> Result<(), Error> {
        let id = *self.ids.first().ok_or(Error::NoSuchInstance)?;
        let s = self.main_state()?;
        let m = self.scene.banks().mechanism(id)?.clone();
        let at = |q: &SVector<T, N>| -> Result<[f64; 2], Error> {
            (self.recipe.points)(&m, q)
                .get(point)
                .copied()
                .ok_or(Error::InvalidParameter {
                    name: "point",
                    reason: "no such point on this mechanism",
                })
        };
        let h = if T::EPSILON.to_f64() > 1e-10 {
            1e-3
        } else {
            1e-6
        };
        let mut jx = SVector::<T, N>::zeros();
        let mut jy = SVector::<T, N>::zeros();
        for i in 0..N {
            let mut plus = s.q;
            plus[i] += T::from_f64(h);
            let mut minus = s.q;
            minus[i] -= T::from_f64(h);
            let (a, b) = (at(&plus)?, at(&minus)?);
            jx[i] = T::from_f64((a[0] - b[0]) / (2.0 * h));
            jy[i] = T::from_f64((a[1] - b[1]) / (2.0 * h));
        }
        let ux = m.velocity_jump(&s, &jx)?;
        let uy = m.velocity_jump(&s, &jy)?;
        let a = [
            [jx.dot(&ux).to_f64(), jx.dot(&uy).to_f64()],
            [jy.dot(&ux).to_f64(), jy.dot(&uy).to_f64()],
        ];
        let dv = [vx - jx.dot(&s.qd).to_f64(), vy - jy.dot(&s.qd).to_f64()];
        // A point the mechanism cannot move in some direction (a pivot, a rod's length)
        // makes `a` singular: regularised, the impulse then moves it as far as it can.
        let ridge = 1e-9 * (a[0][0].abs() + a[1][1].abs()) + 1e-300;
        let (a00, a11) = (a[0][0] + ridge, a[1][1] + ridge);
        let det = a00 * a11 - a[0][1] * a[1][0];
        let lambda = Vector2::new(
            (a11 * dv[0] - a[0][1] * dv[1]) / det,
            (a00 * dv[1] - a[1][0] * dv[0]) / det,
        );
        let p = jx * T::from_f64(lambda[0]) + jy * T::from_f64(lambda[1]);
        self.scene.banks_mut().apply_impulse(id, &p)?;
        // The drag does work: the energy is measured from here, and the exact solution no
        // longer applies.
        self.e0 = self.recipe.mechanism.energy(&self.main_state()?).to_f64();
        self.exact_valid = false;
        Ok(())
    }
}
