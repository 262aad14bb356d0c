//! The sandbox: boxes, balls, a chain, pendulums and ragdolls in one `lagrange_world::World`,
//! each body stepped by its own law ([`OneOf`] makes them one type), contacts between all of
//! them, islands that fall asleep; the page draws its shapes, throws what is dragged, and
//! runs [`scripted`] to show that its bits are the host's.

use lagrange_core::constraints::contact::ContactModel;
use lagrange_core::nalgebra::SVector;
use lagrange_core::{Error, Real, State};
use lagrange_systems::{
    NLinkPendulum, Ragdoll, RagdollBody, RigidBody, SimplePendulum, ADULT_JOINT_LIMITS,
    RAGDOLL_COORDINATES,
};
use lagrange_world::{CoordinateLimits, HalfPlane, Limits, OneOf, Shape, World, WorldSettings};

/// Links of the chain.
const CHAIN: usize = 4;

/// Coordinates of a body of the sandbox: a ragdoll's, the most of any kind.
pub const COORDINATES: usize = RAGDOLL_COORDINATES;

/// A pendulum or the chain.
type Swing<T> = OneOf<SimplePendulum<T>, NLinkPendulum<T, CHAIN>, 1, CHAIN>;
/// A box or a ball (a rigid body), or a swing.
type Small<T> = OneOf<RigidBody<T>, Swing<T>, 3, CHAIN>;
/// A body of the sandbox: a ragdoll or a small one.
pub type Body<T> = OneOf<Ragdoll<T>, Small<T>, COORDINATES, CHAIN>;

/// Bodies, shapes and contact points the sandbox holds.
const BODIES: usize = 32;
const SHAPES: usize = 96;
/// The cap on contact points a step solves ([`World`]'s `K`): a step that finds more fails
/// (the page's test checks that no step comes near it).
pub const CONTACT_CAP: usize = 384;

/// A body's own rows: a ragdoll's joint limits where `on`, none for the others.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Joints {
    on: bool,
    limits: CoordinateLimits<9>,
}

impl<T: Real, const N: usize> Limits<T, N> for Joints {
    fn rows<F: FnMut(u32, T, SVector<T, N>)>(&self, q: &SVector<T, N>, visit: F) {
        if self.on {
            self.limits.rows(q, visit);
        }
    }
}

/// The sandbox's world.
type Sandbox3<T> = World<T, Body<T>, COORDINATES, BODIES, SHAPES, CONTACT_CAP, Joints>;

/// The fixed step, s.
pub const DT: f64 = 1.0 / 60.0;

/// Steps a frame may take at most (a slow frame is then slowed, not a spiral).
const MAX_STEPS_PER_FRAME: u32 = 4;

/// The floor and the walls' half-width, m.
const HALF_WIDTH: f64 = 4.0;

/// How a body is thrown: which kind it is.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    /// A box or a ball: its centre takes the velocity.
    Rigid,
    /// A pendulum of this length: its bob takes the velocity's part along its path.
    Pendulum(f64),
    /// The chain of links this long: each turns at the rate that gives its end the
    /// velocity's part along its path.
    Chain(f64),
    /// A ragdoll: its torso takes the velocity.
    Ragdoll,
}

/// The sandbox: its world, what kind each body is, the clock's leftover time.
pub struct Sandbox<T: Real> {
    world: Box<Sandbox3<T>>,
    kinds: Vec<(u32, Kind)>,
    leftover: f64,
    worst_contacts: u32,
}

impl<T: Real> Sandbox<T> {
    /// The scene: a floor between two walls, a pyramid of ten boxes, six balls, two pendulums,
    /// a chain of four links and two ragdolls, all dropped or hanging at rest.
    ///
    /// # Errors
    /// None for these values (the library's, should one be refused).
    pub fn new() -> Result<Self, Error> {
        let model = ContactModel::new(T::from_f64(0.2), T::from_f64(0.3), T::one())?
            .with_friction(T::from_f64(0.6))?;
        let settings = WorldSettings::new(model, T::from_f64(5e-3), 8)?
            .with_sleep(T::from_f64(0.05), T::HALF)?;
        let mut s = Self {
            world: Box::new(Sandbox3::new(settings)),
            kinds: Vec::new(),
            leftover: 0.0,
            worst_contacts: 0,
        };
        s.world.add_plane(1_000_000, HalfPlane::floor())?;
        let wall = T::from_f64(-HALF_WIDTH);
        s.world
            .add_plane(1_000_001, HalfPlane::new([T::one(), T::zero()], wall)?)?;
        s.world
            .add_plane(1_000_002, HalfPlane::new([-T::one(), T::zero()], wall)?)?;
        let adult = CoordinateLimits::new(core::array::from_fn(|j| j + 3), ADULT_JOINT_LIMITS)?;
        let free = Joints {
            on: false,
            limits: adult,
        };
        let mut key = 0;
        let mut add = |s: &mut Self,
                       body: Body<T>,
                       q: &[f64],
                       kind: Kind,
                       origin: [f64; 2],
                       shapes: &[(usize, Shape<T>)],
                       limits|
         -> Result<(), Error> {
            let state = State::new(
                T::zero(),
                core::array::from_fn(|i| T::from_f64(q.get(i).copied().unwrap_or(0.0))),
                [T::zero(); COORDINATES],
            );
            s.world
                .add_body_with(key, body, limits, state, origin.map(T::from_f64))?;
            for (k, &(link, shape)) in (0u32..).zip(shapes) {
                s.world.add_shape(100 * key + k, key, link, shape)?;
            }
            s.kinds.push((key, kind));
            key += 1;
            Ok(())
        };
        // A box or a ball at (x, y), at rest, with its one shape.
        let mut rigid = |s: &mut Self, body: RigidBody<T>, shape: Shape<T>, x: f64, y: f64| {
            let kind = small(OneOf::First(body));
            add(s, kind, &[x, y], Kind::Rigid, [0.0; 2], &[(0, shape)], free)
        };
        // A pyramid of four rows of 0.5 m boxes on the left.
        for row in 0..4u32 {
            for col in 0..(4 - row) {
                let x = -3.2 + 0.55 * f64::from(col) + 0.275 * f64::from(row);
                let y = 0.25 + 0.5 * f64::from(row);
                let crate_ = RigidBody::rectangle(T::one(), T::HALF, T::HALF, T::from_f64(9.81))?;
                rigid(&mut s, crate_, Shape::rectangle(T::HALF, T::HALF)?, x, y)?;
            }
        }
        // Six balls dropped in the middle.
        for k in 0..6u32 {
            let r = 0.12 + 0.02 * f64::from(k % 3);
            let ball = RigidBody::disk(T::from_f64(0.5), T::from_f64(r), T::from_f64(9.81))?;
            let x = -0.6 + 0.3 * f64::from(k);
            let y = 2.5 + 0.5 * f64::from(k % 2);
            rigid(&mut s, ball, Shape::circle(T::from_f64(r))?, x, y)?;
        }
        // Two pendulums hanging from the ceiling, one pulled aside.
        for (k, angle) in [(0u32, 0.0), (1, 0.9)] {
            let p = SimplePendulum::new(T::one(), T::one(), T::from_f64(9.81), T::zero())?;
            let bob = Shape::circle(T::from_f64(0.15))?.offset([T::zero(), -T::one()], T::zero());
            let pivot = [1.0 + 0.4 * f64::from(k), 4.5];
            add(
                &mut s,
                small(OneOf::Second(OneOf::First(p))),
                &[angle],
                Kind::Pendulum(1.0),
                pivot,
                &[(0, bob)],
                free,
            )?;
        }
        // A chain of four 0.35 m links hanging on the right.
        let link = 0.35;
        let chain = NLinkPendulum::new(
            [T::HALF; CHAIN],
            [T::from_f64(link); CHAIN],
            T::from_f64(9.81),
        )?;
        let rod = Shape::capsule(T::from_f64(link / 2.0), T::from_f64(0.05))?.offset(
            [T::zero(), T::from_f64(-link / 2.0)],
            T::from_f64(core::f64::consts::FRAC_PI_2),
        );
        let links: Vec<(usize, Shape<T>)> = (0..CHAIN).map(|k| (k, rod)).collect();
        add(
            &mut s,
            small(OneOf::Second(OneOf::Second(chain))),
            &[0.6, 0.3, 0.1, 0.0],
            Kind::Chain(link * CHAIN as f64),
            [3.0, 4.5],
            &links,
            free,
        )?;
        // Two ragdolls dropped from above.
        let doll = Ragdoll::new(RagdollBody::<T>::adult())?;
        let capsules = lagrange_cases::ragdoll_capsules(&doll)?;
        let limits = Joints {
            on: true,
            limits: adult,
        };
        let shapes: Vec<(usize, Shape<T>)> = capsules.into_iter().enumerate().collect();
        for (x, y, tilt) in [(-0.5, 3.5, 0.4), (1.8, 5.0, -0.8)] {
            add(
                &mut s,
                OneOf::First(doll),
                &[x, y, tilt],
                Kind::Ragdoll,
                [0.0; 2],
                &shapes,
                limits,
            )?;
        }
        Ok(s)
    }

    /// Advances the clock by `frame_time` s: as many fixed steps as it holds (at most four;
    /// the rest of a slow frame is dropped). The steps taken.
    ///
    /// # Errors
    /// A step's ([`World::step`]); the world is then as before that step.
    pub fn advance(&mut self, frame_time: f64) -> Result<u32, Error> {
        if !(frame_time.is_finite() && frame_time >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "frame_time",
                reason: "must be finite and not negative",
            });
        }
        self.leftover += frame_time;
        let mut steps = 0;
        while self.leftover >= DT && steps < MAX_STEPS_PER_FRAME {
            self.step()?;
            self.leftover -= DT;
            steps += 1;
        }
        if steps == MAX_STEPS_PER_FRAME {
            self.leftover = self.leftover.min(DT);
        }
        Ok(steps)
    }

    /// One fixed step.
    ///
    /// # Errors
    /// As [`Sandbox::advance`].
    pub fn step(&mut self) -> Result<(), Error> {
        let report = self.world.step(T::from_f64(DT))?;
        self.worst_contacts = self.worst_contacts.max(report.contacts);
        Ok(())
    }

    /// Writes every shape to `out` as `[asleep, radius, vertices, x0, y0, x1, y1, ...]` (world
    /// coordinates: a circle's one vertex is its centre, a capsule's two its ends); the
    /// number of shapes.
    pub fn shapes(&self, out: &mut Vec<f64>) -> usize {
        let mut count = 0;
        for p in self.world.placed_shapes() {
            let v = p.shape.vertices();
            out.extend([
                f64::from(u8::from(p.asleep)),
                p.shape.radius().to_f64(),
                v.len() as f64,
            ]);
            out.extend(v.iter().flat_map(|x| x.map(|c| c.to_f64())));
            count += 1;
        }
        count
    }

    /// The body whose shape holds the point `(x, y)`, if any.
    #[must_use]
    pub fn grab(&self, x: f64, y: f64) -> Option<u32> {
        let shape = self.world.shape_at([T::from_f64(x), T::from_f64(y)])?;
        self.world.placed_shapes().find(|p| p.key == shape)?.body
    }

    /// Throws body `key` at `(vx, vy)` m/s: a box, a ball or a ragdoll's torso takes that
    /// velocity, a pendulum's bob or the chain's end its part along their paths.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] `body` for no such body; [`Error::NonFiniteState`] for a
    /// velocity that is not finite.
    pub fn throw(&mut self, key: u32, vx: f64, vy: f64) -> Result<(), Error> {
        let kind = self
            .kinds
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, kind)| *kind);
        let (Some(kind), Some(mut s)) = (kind, self.world.state(key)) else {
            return Err(Error::InvalidParameter {
                name: "body",
                reason: "no body has that key",
            });
        };
        let along = |angle: f64| vx * angle.cos() + vy * angle.sin();
        let mut qd = SVector::<f64, COORDINATES>::zeros();
        match kind {
            Kind::Rigid | Kind::Ragdoll => (qd[0], qd[1]) = (vx, vy),
            Kind::Pendulum(length) => qd[0] = along(s.q[0].to_f64()) / length,
            Kind::Chain(length) => {
                for k in 0..CHAIN {
                    qd[k] = along(s.q[k].to_f64()) / length;
                }
            }
        }
        s.qd = qd.map(T::from_f64);
        self.world.set_state(key, s)
    }

    /// `[bodies, awake, contacts of the last step, the most of any step, the cap]`.
    #[must_use]
    pub fn info(&self) -> [u32; 5] {
        let r = self.world.report();
        [
            u32::try_from(self.kinds.len()).unwrap_or(u32::MAX),
            r.awake,
            r.contacts,
            self.worst_contacts,
            u32::try_from(CONTACT_CAP).unwrap_or(u32::MAX),
        ]
    }

    /// FNV-1a over every body's coordinates and velocities, bit for bit, and how many sleep.
    #[must_use]
    pub fn digest(&self) -> u64 {
        let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
        let mut mix = |w: u64| hash = (hash ^ w).wrapping_mul(0x0000_0100_0000_01b3);
        for (key, _) in &self.kinds {
            if let Some(s) = self.world.state(*key) {
                for x in s.q.iter().chain(s.qd.iter()) {
                    mix(x.to_f64().to_bits());
                }
            }
        }
        mix(u64::from(self.world.report().asleep));
        hash
    }
}

/// A box, a ball or a swing as a body.
fn small<T: Real>(body: Small<T>) -> Body<T> {
    OneOf::Second(body)
}

/// Steps of the scripted run.
pub const SCRIPT_STEPS: u32 = 600;

/// The step of the scripted run at which it throws the first ragdoll and a box.
const THROW_AT: u32 = 240;

/// Step `i` of the scripted run: at [`THROW_AT`] the first ragdoll is thrown at (3, 6) m/s
/// and the pyramid's top box at (-4, 2) m/s, then the step.
///
/// # Errors
/// The step's.
pub fn script_step<T: Real>(sandbox: &mut Sandbox<T>, i: u32) -> Result<(), Error> {
    if i == THROW_AT {
        sandbox.throw(RAGDOLLS[0], 3.0, 6.0)?;
        sandbox.throw(TOP_BOX, -4.0, 2.0)?;
    }
    sandbox.step()
}

/// The keys of the two ragdolls (after 10 boxes, 6 balls, 2 pendulums and the chain).
const RAGDOLLS: [u32; 2] = [19, 20];

/// The key of the pyramid's top box.
const TOP_BOX: u32 = 9;

/// The scripted run's digest after `steps` steps: the pile the page builds, thrown into at
/// [`THROW_AT`].
///
/// # Errors
/// The sandbox's.
pub fn scripted<T: Real>(steps: u32) -> Result<u64, Error> {
    let mut sandbox = Sandbox::<T>::new()?;
    for i in 0..steps {
        script_step(&mut sandbox, i)?;
    }
    Ok(sandbox.digest())
}

/// A sandbox in the page's precision.
pub enum AnySandbox {
    /// In `f32`.
    Single(Sandbox<f32>),
    /// In `f64`.
    Double(Sandbox<f64>),
}

/// Calls the same method on either precision's sandbox.
macro_rules! either {
    ($s:expr, $x:ident => $call:expr) => {
        match $s {
            AnySandbox::Single($x) => $call,
            AnySandbox::Double($x) => $call,
        }
    };
}

impl AnySandbox {
    /// A new sandbox in `f64` (`double`) or `f32`.
    ///
    /// # Errors
    /// As [`Sandbox::new`].
    pub fn new(double: bool) -> Result<Self, Error> {
        Ok(if double {
            Self::Double(Sandbox::new()?)
        } else {
            Self::Single(Sandbox::new()?)
        })
    }

    /// [`Sandbox::advance`].
    ///
    /// # Errors
    /// As [`Sandbox::advance`].
    pub fn advance(&mut self, frame_time: f64) -> Result<u32, Error> {
        either!(self, s => s.advance(frame_time))
    }

    /// [`Sandbox::shapes`].
    pub fn shapes(&self, out: &mut Vec<f64>) -> usize {
        either!(self, s => s.shapes(out))
    }

    /// [`Sandbox::grab`].
    #[must_use]
    pub fn grab(&self, x: f64, y: f64) -> Option<u32> {
        either!(self, s => s.grab(x, y))
    }

    /// [`Sandbox::throw`].
    ///
    /// # Errors
    /// As [`Sandbox::throw`].
    pub fn throw(&mut self, key: u32, vx: f64, vy: f64) -> Result<(), Error> {
        either!(self, s => s.throw(key, vx, vy))
    }

    /// [`Sandbox::info`].
    #[must_use]
    pub fn info(&self) -> [u32; 5] {
        either!(self, s => s.info())
    }

    /// Step `i` of the scripted run ([`script_step`]).
    ///
    /// # Errors
    /// As [`script_step`].
    pub fn script_step(&mut self, i: u32) -> Result<(), Error> {
        either!(self, s => script_step(s, i))
    }

    /// [`Sandbox::digest`].
    #[must_use]
    pub fn digest(&self) -> u64 {
        either!(self, s => s.digest())
    }
}
