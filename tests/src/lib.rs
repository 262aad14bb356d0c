//! Shared helpers of the integration tests: a seeded generator, order fitting, error norms and
//! the macro that instantiates a test for `f32` and `f64`.

use lagrange_core::{Real, State};

mod agreement;

pub use agreement::{agrees_with_automatic, random_state, relative, Agreement, Scales};

/// A small, seeded, reproducible generator (SplitMix64), so that random-state tests are the
/// same on every run and every machine.
pub struct Rng(u64);

impl Rng {
    /// A generator from `seed`.
    #[must_use]
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `[lo, hi)`, rounded to `T`.
    pub fn uniform<T: Real>(&mut self, lo: f64, hi: f64) -> T {
        T::from_f64(lo + (hi - lo) * self.unit())
    }
}

/// Least-squares slope of `log(err)` against `log(dt)`: the measured order of convergence.
#[must_use]
pub fn fitted_order(dts: &[f64], errs: &[f64]) -> f64 {
    let n = dts.len() as f64;
    let xs: Vec<f64> = dts.iter().map(|d| d.ln()).collect();
    let ys: Vec<f64> = errs.iter().map(|e| e.ln()).collect();
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

/// `max_i |x_i - y_i|` over the coordinates and velocities of a state against `reference`
/// (coordinates first, then velocities), in `f64`.
#[must_use]
pub fn state_error<T: Real, const N: usize>(s: &State<T, N>, reference: &[f64]) -> f64 {
    s.q.iter()
        .chain(s.qd.iter())
        .zip(reference)
        .map(|(a, b)| (a.to_f64() - b).abs())
        .fold(0.0, f64::max)
}

/// The tolerance for `T`: `for_f32` when `T` is `f32`, `for_f64` when it is `f64`.
#[must_use]
pub fn pick<T: Real>(for_f32: f64, for_f64: f64) -> f64 {
    if T::EPSILON.to_f64() > 1e-10 {
        for_f32
    } else {
        for_f64
    }
}

/// Instantiates a generic test `fn name<T: Real>() -> Result<(), Error>` as the tests
/// `name::f32` and `name::f64`.
#[macro_export]
macro_rules! for_f32_and_f64 {
    ($($name:ident),* $(,)?) => {
        $(
            mod $name {
                #[test]
                fn f32() -> Result<(), lagrange_core::Error> {
                    super::$name::<f32>()
                }
                #[test]
                fn f64() -> Result<(), lagrange_core::Error> {
                    super::$name::<f64>()
                }
            }
        )*
    };
}

/// The README's example, compiled and run as a doc test.
#[cfg(doctest)]
#[doc = include_str!("../../README.md")]
pub struct ReadmeDoctests;

/// Each chapter of the guide (`guide/src/`) whose Rust blocks are compiled and run as doc
/// tests; `tests/tests/guide_blocks.rs` fails when a chapter is missing here or a block would
/// be skipped.
macro_rules! chapters {
    ($($name:ident => $file:literal),* $(,)?) => {
        $(
            #[cfg(doctest)]
            #[doc = include_str!(concat!("../../guide/src/", $file))]
            pub struct $name;
        )*
        /// The chapters included above, by file name.
        pub const GUIDE_CHAPTERS: &[&str] = &[$($file),*];
    };
}

chapters! {
    GuideIntroduction => "introduction.md",
    GuidePendulum => "pendulum.md",
    GuideOwnMechanism => "own-mechanism.md",
    GuideDerive => "derive.md",
    GuideIntegrators => "integrators.md",
    GuideConstraints => "constraints.md",
    GuideContacts => "contacts.md",
    GuideScenes => "scenes.md",
    GuideFirmware => "firmware.md",
    GuidePage => "page.md",
    GuideMechanisms => "mechanisms.md",
    GuidePerformance => "performance.md",
    GuideReliability => "reliability.md",
}

/// Problem P4's start: `mu = 1`, `e = 0.5`, `a = 1` (period `2 pi`, energy -1/2), at
/// periapsis: `r = 0.5`, `phi = 0`, `r' = 0`, `phi' = 2 sqrt(3)`.
#[must_use]
pub fn kepler_periapsis<T: Real>() -> State<T, 2> {
    State::new(
        T::zero(),
        [T::HALF, T::zero()],
        [T::zero(), T::from_f64(2.0 * 3.0f64.sqrt())],
    )
}
