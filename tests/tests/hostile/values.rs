//! The generator of nasty values: NaN, infinities, the largest and smallest finite values,
//! subnormals, signed zeros, tiny and huge magnitudes, and ordinary values, drawn by what the
//! value is for (a parameter, a state component, a step, a tolerance, a time, a count), from a
//! seeded SplitMix64 so that every call of the campaign can be drawn again from its index.

use lagrange_core::Real;

/// SplitMix64: small, fast, seeded; the same sequence on every machine.
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    /// The generator of call `index` of entry point `entry` in the campaign of `seed`.
    pub fn for_call(seed: u64, entry: u64, index: u64) -> Self {
        let mut r = Self(seed ^ 0x6A09_E667_F3BC_C908);
        r.0 ^= r
            .next()
            .wrapping_add(entry.wrapping_mul(0x9E37_79B9_7F4A_7C15));
        r.0 ^= r
            .next()
            .wrapping_add(index.wrapping_mul(0xBF58_476D_1CE4_E5B9));
        Self(r.next())
    }

    /// The next 64 random bits.
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `0..n` (`n > 0`).
    pub fn below(&mut self, n: u64) -> u64 {
        self.next() % n.max(1)
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }

    /// Log-uniform in `[lo, hi]` (both positive).
    pub fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + (hi.ln() - lo.ln()) * self.unit()).exp()
    }
}

/// What a drawn value is for: each has its own mix of ordinary and nasty values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A physical parameter (mass, length, stiffness): ordinary values are positive, of
    /// order one.
    Param,
    /// A parameter that may be of either sign or zero (a spin rate, a force).
    Signed,
    /// A coordinate or velocity.
    State,
    /// A time.
    Time,
    /// A step size or frame time.
    Step,
    /// A tolerance, with the edges of its valid range.
    Tolerance,
}

/// The nasty values of `T`: the list every drawn value may come from.
pub fn nasty<T: Real>(rng: &mut Rng) -> f64 {
    let max = T::MAX.to_f64();
    let min_pos = T::MIN_POSITIVE.to_f64();
    let eps = T::EPSILON.to_f64();
    // The smallest subnormal of T, and a random subnormal.
    let (tiniest, subnormal) = if eps < 1e-10 {
        let x = f64::from_bits(1 + rng.below((1 << 52) - 1));
        (f64::from_bits(1), x)
    } else {
        let x = f32::from_bits(1 + rng.below((1 << 23) - 1) as u32);
        (f64::from(f32::from_bits(1)), f64::from(x))
    };
    let decades = max.log10().floor();
    let v = match rng.below(24) {
        0 => f64::NAN,
        1 => f64::INFINITY,
        2 => f64::NEG_INFINITY,
        3 => max,
        4 => -max,
        5 => min_pos,
        6 => -min_pos,
        7 => tiniest,
        8 => subnormal,
        9 => -subnormal,
        10 => 0.0,
        11 => -0.0,
        12 => eps,
        13 => 1.0 - eps / 2.0,
        14 => 1.0 + eps,
        // Tiny and huge magnitudes, either sign.
        15 => 10f64.powf(-(rng.unit() * decades)),
        16 => 10f64.powf(rng.unit() * decades),
        17 => -10f64.powf(rng.unit() * decades),
        18 => max.sqrt(),
        19 => 1.0 / max.sqrt(),
        // Large powers of two (a time where the step is an ulp).
        20 => 2f64.powi(rng.below(if eps < 1e-10 { 60 } else { 30 }) as i32 + 20),
        21 => max / 2.0,
        22 => -1.0,
        _ => 3.0e38_f64.min(max) * if rng.chance(0.5) { 1.0 } else { -1.0 },
    };
    round_to::<T>(v)
}

/// An ordinary value for `kind`.
fn ordinary<T: Real>(kind: Kind, rng: &mut Rng) -> f64 {
    let v = match kind {
        Kind::Param => rng.log_uniform(0.1, 10.0),
        Kind::Signed => rng.unit() * 20.0 - 10.0,
        Kind::State => rng.unit() * 6.0 - 3.0,
        Kind::Time => {
            if rng.chance(0.5) {
                0.0
            } else {
                rng.unit() * 100.0
            }
        }
        Kind::Step => rng.log_uniform(1e-4, 0.1),
        Kind::Tolerance => match rng.below(8) {
            0 => 10.0 * T::EPSILON.to_f64(),
            1 => T::EPSILON.to_f64(),
            2 => 1.0,
            3 => 0.0,
            4 => 1.0 - T::EPSILON.to_f64(),
            _ => rng.log_uniform(T::EPSILON.to_f64().sqrt(), 1e-2),
        },
    };
    round_to::<T>(v)
}

/// A value for `kind`: ordinary most of the time (so that calls get past their checks),
/// nasty otherwise; `hostility` multiplies the share of nasty values (a quarter of the calls
/// draw four times as many).
pub fn draw<T: Real>(kind: Kind, rng: &mut Rng, hostility: f64) -> f64 {
    let nasty_share = match kind {
        Kind::Param | Kind::Signed => 0.12,
        Kind::State | Kind::Time => 0.1,
        Kind::Step | Kind::Tolerance => 0.3,
    };
    if rng.chance((nasty_share * hostility).min(0.8)) {
        nasty::<T>(rng)
    } else {
        ordinary::<T>(kind, rng)
    }
}

/// A count (steps, iterations, a cap per frame): small mostly, with the edges.
pub fn count(rng: &mut Rng) -> u64 {
    match rng.below(12) {
        0 => 0,
        1 => 1,
        2 => 2,
        3 => u64::from(u32::MAX),
        4 => u64::MAX,
        5 => 1000,
        6 => 1001,
        _ => rng.below(20),
    }
}

/// `v` rounded to `T` and back (exact in `f64` either way), so that what is recorded is what
/// was used.
pub fn round_to<T: Real>(v: f64) -> f64 {
    T::from_f64(v).to_f64()
}
