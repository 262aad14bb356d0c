//! [`Clock`]: simulated time as a start plus a whole number of steps, exact to the last ulp
//! over runs of any length.

use lagrange_core::Real;

/// The time of a run of steps: `origin + n dt` for the `n` ticks of `dt` since the last change
/// of step, rounded once, so that it is within an ulp of the exact time however long the run.
///
/// Adding `dt` to `t` each step rounds every step: after 10^7 steps of 1/120 s an `f32` sum is
/// off by minutes, and a sum compensated in one extra float (Kahan) still drifts, by seconds,
/// once its correction term itself rounds. Here the product `n dt` is formed exactly instead:
///
/// ```text
/// dt = dt_hi + dt_lo            Veltkamp split: dt_hi with p - s significant bits,
///                               dt_lo with s (s = floor(p / 2): 12 in f32, 26 in f64)
/// n  = K + j,  j < 2^s          K a whole number of blocks of 2^s ticks
/// base = origin + K dt          a float pair (hi + lo), formed once per block from the
///                               s-bit digits of K, each digit times dt_hi and dt_lo exact
/// time = base.hi + j dt_hi + (j dt_lo + base.lo)     j dt_hi, j dt_lo exact; one rounding
/// ```
///
/// Each tick costs a counter increment and, for the time, two products and a two-sum (a few
/// float operations beside a step's accelerations, independent of them); every `2^s` ticks
/// the block's base is formed again. A tick of a different `dt` starts a new origin at the
/// time reached (a float pair, exact to twice the precision). After 10^8 `f32` steps of
/// 1/120 s the time is within an ulp of `n dt`.
///
/// A non-finite `dt` or origin gives a non-finite time (there is no error channel); the
/// drivers refuse such steps before they tick.
///
/// ```
/// use lagrange_integrators::Clock;
/// let dt = 1.0f32 / 120.0;
/// let mut clock = Clock::new(0.0f32);
/// for _ in 0..1_000_000 {
///     clock.tick(dt);
/// }
/// let exact = (1e6 * f64::from(dt)) as f32;
/// assert!((clock.time() - exact).abs() <= exact * f32::EPSILON);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clock<T> {
    /// Where the current step began to be counted, as a float pair `hi + lo`.
    origin: (T, T),
    /// The step being counted (zero before the first tick).
    dt: T,
    /// Its split `dt_hi + dt_lo`.
    dt_hi: T,
    dt_lo: T,
    /// Ticks of `dt` since the origin.
    n: u64,
    /// `origin + K dt` for the block `K = n - j` the count is in, as a float pair.
    base: (T, T),
    /// Ticks into the block, below `2^s`, counted in `T` (exact there).
    j: T,
}

impl<T: Real> Clock<T> {
    /// A clock at `t`.
    #[must_use]
    pub fn new(t: T) -> Self {
        Self {
            origin: (t, T::zero()),
            dt: T::zero(),
            dt_hi: T::zero(),
            dt_lo: T::zero(),
            n: 0,
            base: (t, T::zero()),
            j: T::zero(),
        }
    }

    /// Advances by `dt`.
    #[inline]
    pub fn tick(&mut self, dt: T) {
        if dt != self.dt {
            self.restart(dt);
        }
        self.n = self.n.wrapping_add(1);
        self.j += T::one();
        if self.n & ((1 << split_bits::<T>()) - 1) == 0 {
            self.base = self.block_base();
            self.j = T::zero();
        }
    }

    /// The time now, rounded once from its exact value (to within an ulp).
    #[inline]
    #[must_use]
    pub fn time(&self) -> T {
        let t = self.time_at(T::one());
        if t.is_finite() {
            t
        } else {
            // `j dt` may overflow where the time does not (a huge step towards a time far on
            // the other side of zero): the same at half scale, exact, doubled.
            self.time_at(T::HALF) * T::TWO
        }
    }

    /// The time now times `scale` (1 or 1/2: both exact).
    #[inline(always)]
    fn time_at(&self, scale: T) -> T {
        let j = self.j;
        let (s, e) = two_sum(self.base.0 * scale, j * (self.dt_hi * scale));
        s + (e + (j * (self.dt_lo * scale) + self.base.1 * scale))
    }

    /// The time of a clock started at `t` after `n` ticks of `dt`, without ticking.
    pub(crate) fn after(t: T, dt: T, n: u64) -> T {
        let mut c = Self::new(t);
        c.restart(dt);
        let block = 1u64 << split_bits::<T>();
        c.n = n - n % block;
        c.base = c.block_base();
        c.n = n;
        c.j = T::from_f64((n % block) as f64);
        c.time()
    }

    /// Starts counting steps of `dt` from the time reached.
    #[cold]
    fn restart(&mut self, dt: T) {
        let now = self.exact();
        self.origin = now;
        self.base = now;
        self.dt = dt;
        (self.dt_hi, self.dt_lo) = split(dt);
        self.n = 0;
        self.j = T::zero();
    }

    /// The time now as a float pair (before rounding).
    fn exact(&self) -> (T, T) {
        let pair = |scale: T| {
            let j = self.j;
            let (s, e) = two_sum(self.base.0 * scale, j * (self.dt_hi * scale));
            add(
                (s, e),
                (j * (self.dt_lo * scale) + self.base.1 * scale, T::zero()),
            )
        };
        doubled_if_needed(pair)
    }

    /// `origin + n dt` for the count `n`, a whole number of blocks, as a float pair: the
    /// `s`-bit digits of `n`, highest first, each times `dt_hi` and `dt_lo` exactly, scaled by
    /// its power of two, summed in a pair. (The base lies between the origin and the time
    /// reached, so it is finite when they are, though `n dt` may not be.)
    #[cold]
    fn block_base(&self) -> (T, T) {
        doubled_if_needed(|scale| {
            let s = split_bits::<T>();
            let radix = T::from_f64(f64::from(1u32 << s));
            let digits = 64u32.div_ceil(s);
            let mut acc = (T::zero(), T::zero());
            for i in (0..digits).rev() {
                let d = (self.n >> (i * s)) & ((1u64 << s) - 1);
                if d == 0 {
                    continue;
                }
                let mut power = scale;
                for _ in 0..i {
                    power *= radix;
                }
                let d = T::from_f64(d as f64);
                acc = add(acc, (d * self.dt_hi * power, T::zero()));
                acc = add(acc, (d * self.dt_lo * power, T::zero()));
            }
            add((self.origin.0 * scale, self.origin.1 * scale), acc)
        })
    }
}

/// `s = floor(p / 2)` for the `p` significant bits of `T`: the split that makes `j dt_hi` and
/// `j dt_lo` exact for `j < 2^s`.
fn split_bits<T: Real>() -> u32 {
    // EPSILON = 2^(1 - p).
    let exponent = ((T::EPSILON.to_f64().to_bits() >> 52) & 0x7ff) as u32;
    let p = 1 + 1023 - exponent;
    p / 2
}

/// Veltkamp's split of `x` into `hi + lo`, `hi` with `p - s` significant bits and `lo` with at
/// most `s`; `(x, 0)` where the split would overflow (a step near `T::MAX`, whose product
/// is then rounded).
fn split<T: Real>(x: T) -> (T, T) {
    let factor = T::from_f64(f64::from(1u32 << split_bits::<T>()) + 1.0);
    let c = factor * x;
    let hi = c - (c - x);
    let lo = x - hi;
    if hi.is_finite() && lo.is_finite() {
        (hi, lo)
    } else {
        (x, T::zero())
    }
}

/// `f(1)`, or `2 f(1/2)` when `f(1)` is not finite: a pair computed at half scale (exact) when
/// an intermediate product overflows at full scale.
fn doubled_if_needed<T: Real>(f: impl Fn(T) -> (T, T)) -> (T, T) {
    let (hi, lo) = f(T::one());
    if hi.is_finite() && lo.is_finite() {
        (hi, lo)
    } else {
        let (hi, lo) = f(T::HALF);
        (hi * T::TWO, lo * T::TWO)
    }
}

/// Knuth's two-sum: `a + b = s + e` exactly, `s` the rounded sum.
#[inline]
fn two_sum<T: Real>(a: T, b: T) -> (T, T) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// The sum of two float pairs, as a float pair.
fn add<T: Real>(a: (T, T), b: (T, T)) -> (T, T) {
    let (s, e) = two_sum(a.0, b.0);
    let e = e + a.1 + b.1;
    two_sum(s, e)
}
