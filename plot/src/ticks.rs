//! Tick generation: an axis's bounds, its labelled ticks (1, 2 or 5 x 10^k on a linear axis,
//! decades on a log axis) and their labels, from the data it shows.

/// How an axis places values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// Linear.
    Linear,
    /// Base-10 logarithmic; values at or below zero are not drawn.
    Log,
}

impl Scale {
    /// True when `v` can be placed on an axis of this scale.
    #[must_use]
    pub fn drawable(self, v: f64) -> bool {
        v.is_finite() && (self == Self::Linear || v > 0.0)
    }
}

/// Most labelled ticks on a linear axis.
const LINEAR_MAX_TICKS: usize = 7;
/// Most labelled ticks on a log axis.
const LOG_MAX_TICKS: usize = 9;
/// Most labelled ticks on any axis (a log axis may have the most).
pub const MAX_TICKS: usize = LOG_MAX_TICKS;

/// The mantissas of a linear axis's tick step, and of a log axis's step in decades.
const MANTISSAS: [i64; 3] = [1, 2, 5];

/// An axis laid out for a range of data: bounds, labelled ticks and unlabelled minor ticks.
///
/// Every labelled tick is an integer multiple of the step `m x 10^e` (`m` = 1, 2 or 5), and
/// its label is written from that integer, so that no rounding shows in it (`0.3`, not
/// `0.30000000000000004`; `0`, not `-0.001`). On a log axis the labelled ticks are decades
/// (every 1, 2 or 5 decades, as they fit), labelled `1e-6`.
#[derive(Debug, Clone, PartialEq)]
pub struct Ticks {
    scale: Scale,
    lo: f64,
    hi: f64,
    /// Linear: the step's mantissa and exponent. Log: the step in decades (mantissa) and 0.
    step: (i64, i32),
    /// Labelled ticks: the integer multiples `k` of the step (log: the exponents).
    major: Vec<i64>,
    /// Unlabelled ticks, as values.
    minor: Vec<f64>,
}

impl Ticks {
    /// The axis for `values` (those the scale cannot draw are left out): a linear axis from the
    /// multiple of the step at or below the smallest value to the one at or above the largest;
    /// a log axis over whole decades.
    #[must_use]
    pub fn new(scale: Scale, values: impl IntoIterator<Item = f64>) -> Self {
        let (lo, hi) = values
            .into_iter()
            .filter(|v| scale.drawable(*v))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        match scale {
            Scale::Linear => Self::linear(lo, hi),
            Scale::Log => Self::log(lo, hi),
        }
    }

    /// A linear axis over `[lo, hi]` (empty when `lo > hi`).
    fn linear(lo: f64, hi: f64) -> Self {
        let (lo, hi) = if lo > hi {
            (0.0, 1.0)
        } else if hi - lo <= f64::EPSILON * lo.abs().max(hi.abs()) {
            // A constant: a tenth of its size either side, or a unit at zero.
            let pad = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
            (lo - pad, hi + pad)
        } else {
            (lo, hi)
        };
        let exponent = ((hi - lo) / LINEAR_MAX_TICKS as f64).log10().floor() as i32;
        let (mut first, mut last, mut step) = (0, 0, (1, exponent));
        // The finest step whose ticks, bounds included, fit LINEAR_MAX_TICKS.
        'search: for e in exponent..exponent + 3 {
            for m in MANTISSAS {
                let size = m as f64 * 10f64.powi(e);
                // A bound a rounding away from a multiple is on it.
                let (k0, k1) = ((lo / size + 1e-9).floor(), (hi / size - 1e-9).ceil());
                if k1 - k0 < LINEAR_MAX_TICKS as f64 {
                    (first, last, step) = (k0 as i64, k1 as i64, (m, e));
                    break 'search;
                }
            }
        }
        let size = step.0 as f64 * 10f64.powi(step.1);
        Self {
            scale: Scale::Linear,
            lo: first as f64 * size,
            hi: last as f64 * size,
            step,
            major: (first..=last).collect(),
            minor: Vec::new(),
        }
    }

    /// A log axis over the whole decades around `[lo, hi]` (empty when `lo > hi`).
    fn log(lo: f64, hi: f64) -> Self {
        let (mut d0, mut d1) = if lo > hi {
            (0, 1)
        } else {
            (lo.log10().floor() as i64, hi.log10().ceil() as i64)
        };
        if d1 <= d0 {
            (d0, d1) = (d0 - 1, d1 + 1);
        }
        // Every 1, 2, 5, 10, 20, ... decades, as many as fit.
        let every = (0..)
            .flat_map(|e| MANTISSAS.map(|m| m * 10i64.pow(e)))
            .find(|&n| d1.div_euclid(n) - (d0 + n - 1).div_euclid(n) < LOG_MAX_TICKS as i64)
            .unwrap_or(1);
        let major: Vec<i64> = (d0..=d1).filter(|d| d.rem_euclid(every) == 0).collect();
        let minor = if every > 1 {
            (d0..=d1)
                .filter(|d| d.rem_euclid(every) != 0)
                .map(|d| 10f64.powi(d as i32))
                .collect()
        } else if d1 - d0 <= 4 {
            (d0..d1)
                .flat_map(|d| (2..10).map(move |m| f64::from(m) * 10f64.powi(d as i32)))
                .collect()
        } else {
            Vec::new()
        };
        Self {
            scale: Scale::Log,
            lo: 10f64.powi(d0 as i32),
            hi: 10f64.powi(d1 as i32),
            step: (every, 0),
            major,
            minor,
        }
    }

    /// The scale.
    #[must_use]
    pub fn scale(&self) -> Scale {
        self.scale
    }

    /// The axis's bounds.
    #[must_use]
    pub fn bounds(&self) -> (f64, f64) {
        (self.lo, self.hi)
    }

    /// Where `v` falls between the bounds: 0 at the lower, 1 at the upper (NaN where the scale
    /// cannot draw it).
    #[must_use]
    pub fn fraction(&self, v: f64) -> f64 {
        match self.scale {
            Scale::Linear => (v - self.lo) / (self.hi - self.lo),
            Scale::Log if v > 0.0 => {
                (v.log10() - self.lo.log10()) / (self.hi.log10() - self.lo.log10())
            }
            Scale::Log => f64::NAN,
        }
    }

    /// The labelled ticks, as values.
    #[must_use]
    pub fn major(&self) -> Vec<f64> {
        self.major.iter().map(|&k| self.value(k)).collect()
    }

    /// The unlabelled ticks, as values.
    #[must_use]
    pub fn minor(&self) -> &[f64] {
        &self.minor
    }

    /// The labels of the labelled ticks, in order.
    #[must_use]
    pub fn labels(&self) -> Vec<String> {
        self.major.iter().map(|&k| self.text(k)).collect()
    }

    /// The label of the labelled tick nearest `v` (what a plotting backend asks for by value).
    #[must_use]
    pub fn label(&self, v: f64) -> String {
        let near = self.major.iter().copied().min_by(|&a, &b| {
            let (da, db) = (self.distance(a, v), self.distance(b, v));
            da.total_cmp(&db)
        });
        near.map_or_else(String::new, |k| self.text(k))
    }

    /// How far tick `k` is from `v`, in axis fractions.
    fn distance(&self, k: i64, v: f64) -> f64 {
        (self.fraction(self.value(k)) - self.fraction(v)).abs()
    }

    /// The value of tick `k`.
    fn value(&self, k: i64) -> f64 {
        match self.scale {
            Scale::Linear => (k * self.step.0) as f64 * 10f64.powi(self.step.1),
            Scale::Log => 10f64.powi(k as i32),
        }
    }

    /// The label of tick `k`: the integer `k m` times `10^e`, in plain decimals where the
    /// exponent is moderate, else as `m'e<exponent>`; decades as `1e<k>` (`1` for 10^0).
    fn text(&self, k: i64) -> String {
        match self.scale {
            Scale::Log if k == 0 => "1".into(),
            Scale::Log => format!("1e{k}"),
            Scale::Linear => {
                let (mantissa, mut e) = (k * self.step.0, self.step.1);
                if mantissa == 0 {
                    return "0".into();
                }
                if (-4..=5).contains(&e) {
                    let decimals = usize::try_from(-e).unwrap_or(0);
                    return format!("{:.decimals$}", mantissa as f64 * 10f64.powi(e));
                }
                // d.ddd x 10^exponent, from the digits of the integer mantissa.
                let sign = if mantissa < 0 { "-" } else { "" };
                let digits = mantissa.unsigned_abs().to_string();
                e += i32::try_from(digits.len()).unwrap_or(0) - 1;
                let digits = digits.trim_end_matches('0');
                let (lead, rest) = digits.split_at(1);
                if rest.is_empty() {
                    format!("{sign}{lead}e{e}")
                } else {
                    format!("{sign}{lead}.{rest}e{e}")
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{Scale, Ticks, MAX_TICKS};

    /// The labels of a linear axis over `[lo, hi]`.
    fn linear(lo: f64, hi: f64) -> Vec<String> {
        Ticks::new(Scale::Linear, [lo, hi]).labels()
    }

    /// True when `x` is `m` (1, 2 or 5) times an integer power of ten, up to rounding.
    fn nice_step(x: f64) -> bool {
        let e = x.log10().floor();
        let m = x / 10f64.powf(e);
        [1.0, 2.0, 5.0, 10.0].iter().any(|n| (m - n).abs() < 1e-9)
    }

    #[test]
    fn linear_ticks_are_round_multiples_of_one_two_or_five() {
        assert_eq!(linear(0.001, 9.991), ["0", "2", "4", "6", "8", "10"]);
        assert_eq!(
            linear(-0.545, 0.545),
            ["-0.6", "-0.4", "-0.2", "0", "0.2", "0.4", "0.6"]
        );
        assert_eq!(linear(0.0, 1.0), ["0", "0.2", "0.4", "0.6", "0.8", "1.0"]);
        assert_eq!(
            linear(-9.3, -9.1),
            ["-9.30", "-9.25", "-9.20", "-9.15", "-9.10"]
        );
        assert_eq!(
            linear(0.0, 3e-6),
            ["0", "5e-7", "1e-6", "1.5e-6", "2e-6", "2.5e-6", "3e-6"]
        );
        assert_eq!(
            linear(-2e7, 1e7),
            ["-2e7", "-1.5e7", "-1e7", "-5e6", "0", "5e6", "1e7"]
        );
        // A constant series still gets an axis around it.
        assert_eq!(linear(2.0, 2.0), ["1.8", "1.9", "2.0", "2.1", "2.2"]);
        assert_eq!(linear(0.0, 0.0), ["-1.0", "-0.5", "0", "0.5", "1.0"]);
    }

    #[test]
    fn every_axis_has_few_round_ticks_that_cover_the_data() {
        let ranges = [
            (0.001, 9.991),
            (-0.545, 0.545),
            (-1e-3, 2.7),
            (3.0, 1234.5),
            (-7e-9, 4e-9),
            (-250.0, -3.0),
            (0.17, 0.18),
        ];
        for (lo, hi) in ranges {
            let t = Ticks::new(Scale::Linear, [lo, hi]);
            let ticks = t.major();
            let (a, b) = t.bounds();
            assert!(a <= lo && b >= hi, "{lo}..{hi}: bounds {a}..{b}");
            assert!(
                (3..=MAX_TICKS).contains(&ticks.len()),
                "{lo}..{hi}: {ticks:?}"
            );
            let step = ticks[1] - ticks[0];
            assert!(nice_step(step), "{lo}..{hi}: step {step}");
            for (v, label) in ticks.iter().zip(t.labels()) {
                let read: f64 = label.parse().unwrap_or(f64::NAN);
                assert!((read - v).abs() <= 1e-9 * step, "{label} for {v}");
                assert!(
                    label != "-0" && !label.contains("e-0") && label.len() <= 8,
                    "{label}"
                );
            }
        }
    }

    #[test]
    fn log_ticks_are_decades_labelled_as_powers_of_ten() {
        let t = Ticks::new(Scale::Log, [3.2e-5, 7.7e-5]);
        assert_eq!(t.labels(), ["1e-5", "1e-4"]);
        assert_eq!(t.minor().len(), 8, "2..9 x 1e-5 between the decades");
        let t = Ticks::new(Scale::Log, [1e-6, 1e-3, 0.0, -1.0, f64::NAN]);
        assert_eq!(t.labels(), ["1e-6", "1e-5", "1e-4", "1e-3"]);
        let t = Ticks::new(Scale::Log, [2e-17, 3.0]);
        assert_eq!(
            t.labels(),
            ["1e-16", "1e-14", "1e-12", "1e-10", "1e-8", "1e-6", "1e-4", "1e-2", "1"]
        );
        assert_eq!(t.minor().len(), 10, "the decades between the labels");
        assert_eq!(t.bounds(), (1e-17, 10.0));
        let t = Ticks::new(Scale::Log, [1e-300, 1e300]);
        assert!(t.labels().len() <= MAX_TICKS);
        assert!(t.labels().iter().all(|l| l == "1" || l.starts_with("1e")));
    }

    #[test]
    fn a_label_is_asked_for_by_value() {
        let t = Ticks::new(Scale::Linear, [-0.545, 0.545]);
        for (v, label) in t.major().into_iter().zip(t.labels()) {
            assert_eq!(t.label(v), label);
        }
        let t = Ticks::new(Scale::Log, [1e-6, 1e-3]);
        assert_eq!(t.label(1e-6), "1e-6");
        assert_eq!(t.label(1.0001e-4), "1e-4");
    }
}
