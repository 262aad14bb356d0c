//! The exact motion of a linear damped oscillator driven by a harmonic force `F0 cos(w t)`.

use super::damped_oscillator;
use lagrange_core::{validate, Error, Real};

/// The linear oscillator `m x'' + c x' + k x = F0 cos(w t)` (a
/// [`SpringMassDamper`](crate::SpringMassDamper) with the force `F0 cos(w t)` added), whose
/// exact motion from `x(0) = x0`, `x'(0) = v0` at `t = 0` is [`DrivenOscillator::state`].
///
/// With damping (`c > 0`) it is the steady state plus the free motion from the shifted start:
///
/// ```text
/// D      = (k - m w^2)^2 + (c w)^2
/// A      = F0 (k - m w^2) / D,    B = F0 c w / D
/// x_p(t) = A cos(w t) + B sin(w t)                   (the steady state)
/// x(t)   = x_p(t) + h(t),   h the free motion from h(0) = x0 - A, h'(0) = v0 - w B
/// ```
///
/// with `h` from [`damped_oscillator`]. Without damping (`c = 0`, `w0^2 = k / m`) the forced
/// part is written as a product, which has no cancellation near resonance and holds at it:
///
/// ```text
/// x(t) = h(t) + (2 F0 / m) sin((w0 + w) t / 2) / (w0 + w) * sin((w0 - w) t / 2) / (w0 - w)
///      = h(t) + F0 (cos(w t) - cos(w0 t)) / (m (w0^2 - w^2))
///      = h(t) + F0 t sin(w t) / (2 m w)                              at w = w0
/// ```
///
/// with `h` the free motion from `(x0, v0)`. Accuracy: a few ulps of the largest term, except
/// with light damping close to resonance, where the steady-state amplitude `|A| + |B|` is much
/// larger than `x(t)` at early times and the sum loses about `EPSILON (|A| + |B|) / |x|` of
/// relative accuracy.
///
/// ```
/// use lagrange_systems::exact::DrivenOscillator;
/// // m = 1, k = 4 (w0 = 2), c = 0.5, driven by 2 cos(3 t), from x0 = 1 at rest.
/// let osc = DrivenOscillator::new(1.0_f64, 4.0, 0.5, 2.0, 3.0)?;
/// let (x, v) = osc.state(1.0, 0.0, 0.0)?;
/// assert!((x - 1.0).abs() < 1e-15 && v.abs() < 1e-15);
/// // Long after the start only the steady state A cos(w t) + B sin(w t) is left.
/// let (p, q) = (4.0 - 9.0, 0.5 * 3.0);
/// let (a, b) = (2.0 * p / (p * p + q * q), 2.0 * q / (p * p + q * q));
/// let (x, v) = osc.state(1.0, 0.0, 100.0)?;
/// assert!((x - (a * 300.0f64.cos() + b * 300.0f64.sin())).abs() < 1e-10);
/// assert!((v - 3.0 * (b * 300.0f64.cos() - a * 300.0f64.sin())).abs() < 1e-10);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
///
/// It solves the equation: its velocity is the derivative of its position and
/// `m x'' + c x' + k x - F0 cos(w t)`, with `x''` from central differences of the velocity,
/// is zero to the differences' error (`h^2 x''''/6` and `EPSILON |x'| / h`):
///
/// ```
/// use lagrange_systems::exact::DrivenOscillator;
/// let (m, k, c, f0, w) = (2.0_f64, 8.0, 0.3, 5.0, 1.3);
/// let osc = DrivenOscillator::new(m, k, c, f0, w)?;
/// let h = 1e-4;
/// for i in 0..50 {
///     let t = 0.37 * f64::from(i);
///     let (x, v) = osc.state(0.4, -1.0, t)?;
///     let (xp, vp) = osc.state(0.4, -1.0, t + h)?;
///     let (xm, vm) = osc.state(0.4, -1.0, t - h)?;
///     assert!(((xp - xm) / (2.0 * h) - v).abs() < 1e-7, "x' at t = {t}");
///     let residual = m * (vp - vm) / (2.0 * h) + c * v + k * x - f0 * (w * t).cos();
///     assert!(residual.abs() < 1e-7, "residual {residual} at t = {t}");
/// }
/// # Ok::<(), lagrange_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DrivenOscillator<T: Real> {
    mass: T,
    stiffness: T,
    damping: T,
    amplitude: T,
    omega: T,
}

impl<T: Real> DrivenOscillator<T> {
    /// A `mass` (> 0) on a spring of `stiffness` (>= 0) with `damping` (>= 0), driven by the
    /// force `amplitude cos(omega t)` (`amplitude` finite, `omega` > 0, rad/s).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first parameter out of range or not finite, or
    /// the one most responsible when a quantity formed from them leaves the range of `T`: the
    /// free motion's `c / (2 m)`, `k / m` and `(c / (2 m))^2`, the drive's `m w^2`, `c w`
    /// (which the steady state divides by when `c > 0`) and `F0 / m`.
    pub fn new(mass: T, stiffness: T, damping: T, amplitude: T, omega: T) -> Result<Self, Error> {
        let mass = validate::positive("mass", mass)?;
        let stiffness = validate::non_negative("stiffness", stiffness)?;
        let damping = validate::non_negative("damping", damping)?;
        let amplitude = validate::finite("amplitude", amplitude)?;
        let omega = validate::positive("omega", omega)?;
        let f = |name, x, power| (name, x, power);
        let (m, k, c, w) = (
            f("mass", mass, 1),
            f("stiffness", stiffness, 1),
            f("damping", damping, 1),
            f("omega", omega, 1),
        );
        let per_mass = f("mass", mass, -1);
        let gamma = validate::derived(damping / (T::TWO * mass), &[c, per_mass])?;
        validate::derived(
            gamma * gamma,
            &[f("damping", damping, 2), f("mass", mass, -2)],
        )?;
        validate::derived(stiffness / mass, &[k, per_mass])?;
        validate::derived(mass * omega * omega, &[m, f("omega", omega, 2)])?;
        if damping > T::zero() {
            validate::divisor(damping * omega, &[c, w])?;
        }
        validate::derived(amplitude / mass, &[f("amplitude", amplitude, 1), per_mass])?;
        Ok(Self {
            mass,
            stiffness,
            damping,
            amplitude,
            omega,
        })
    }

    /// The exact `(x(t), x'(t))` from `x(0) = x0`, `x'(0) = v0`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `x0`, `v0` or `t` when not finite, `t` when so large
    /// that a phase `w t` overflows; [`Error::NonFiniteState`] when the motion overflows (a
    /// damping so light that the steady-state amplitude at resonance exceeds the largest
    /// finite value, a start so large that the free motion does, a negative time of a damped
    /// motion).
    pub fn state(&self, x0: T, v0: T, t: T) -> Result<(T, T), Error> {
        let x0 = validate::finite("x0", x0)?;
        let v0 = validate::finite("v0", v0)?;
        let t = validate::finite("t", t)?;
        for phase in [self.omega * t, (self.stiffness / self.mass).sqrt() * t] {
            if !phase.is_finite() {
                return Err(Error::InvalidParameter {
                    name: "t",
                    reason: "so large that the phase w t overflows",
                });
            }
        }
        let (x, v) = if self.damping > T::zero() {
            self.damped(x0, v0, t)
        } else {
            self.undamped(x0, v0, t)
        }
        // The free part is the damped oscillator from a start of its own: a quantity it
        // refuses overflowed here, from this call's arguments.
        .map_err(|e| match e {
            Error::InvalidParameter { name: "t", .. } => e,
            _ => Error::NonFiniteState,
        })?;
        if x.is_finite() && v.is_finite() {
            Ok((x, v))
        } else {
            Err(Error::NonFiniteState)
        }
    }

    /// The steady state `A cos(w t) + B sin(w t)` plus the free motion from the shifted start.
    fn damped(&self, x0: T, v0: T, t: T) -> Result<(T, T), Error> {
        let (m, k, c, w) = (self.mass, self.stiffness, self.damping, self.omega);
        let p = k - m * w * w;
        let q = c * w;
        // D = p^2 + q^2 scaled by the larger of the two, so that neither overflows nor
        // underflows: A = F0 (p / s) / (s d), B = F0 (q / s) / (s d), d = D / s^2 in [1, 2].
        let s = p.abs().max(q);
        let (ps, qs) = (p / s, q / s);
        let sd = s * (ps * ps + qs * qs);
        let (a, b) = (self.amplitude * ps / sd, self.amplitude * qs / sd);
        let (h0, hd0) = (x0 - a, v0 - w * b);
        if !(h0.is_finite() && hd0.is_finite()) {
            return Err(Error::NonFiniteState);
        }
        let (sin, cos) = (w * t).sin_cos();
        let (xh, vh) = damped_oscillator(m, k, c, h0, hd0, t)?;
        Ok((xh + a * cos + b * sin, vh + w * (b * cos - a * sin)))
    }

    /// The free motion from `(x0, v0)` plus the forced motion from rest in product form.
    fn undamped(&self, x0: T, v0: T, t: T) -> Result<(T, T), Error> {
        let (m, k, w) = (self.mass, self.stiffness, self.omega);
        let (xh, vh) = damped_oscillator(m, k, T::zero(), x0, v0, t)?;
        let w0 = (k / m).sqrt();
        let (sum, diff) = (w0 + w, w0 - w);
        let (sin_s, cos_s) = (sum * t * T::HALF).sin_cos();
        let (sin_d, cos_d) = (diff * t * T::HALF).sin_cos();
        // sin((w0 - w) t / 2) / (w0 - w): accurate for any small diff, t / 2 at resonance.
        let ratio_d = if diff == T::zero() {
            t * T::HALF
        } else {
            sin_d / diff
        };
        let f = self.amplitude / m;
        let x = xh + T::TWO * f * sin_s / sum * ratio_d;
        let v = vh + f * (cos_s * ratio_d + sin_s * cos_d / sum);
        Ok((x, v))
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::DrivenOscillator;
    use lagrange_core::Error;
    use std::println;

    /// `(x, x')` at `t_end` of classical RK4 on `m x'' + c x' + k x = f0 cos(w t)` with `steps`
    /// steps, written out here so that the reference owes nothing to the library's integrators.
    fn rk4(p: [f64; 5], x0: f64, v0: f64, t_end: f64, steps: u32) -> (f64, f64) {
        let [m, k, c, f0, w] = p;
        let acc = |t: f64, x: f64, v: f64| (f0 * (w * t).cos() - c * v - k * x) / m;
        let h = t_end / f64::from(steps);
        let (mut x, mut v) = (x0, v0);
        for i in 0..steps {
            let t = h * f64::from(i);
            let (k1x, k1v) = (v, acc(t, x, v));
            let (k2x, k2v) = (
                v + 0.5 * h * k1v,
                acc(t + 0.5 * h, x + 0.5 * h * k1x, v + 0.5 * h * k1v),
            );
            let (k3x, k3v) = (
                v + 0.5 * h * k2v,
                acc(t + 0.5 * h, x + 0.5 * h * k2x, v + 0.5 * h * k2v),
            );
            let (k4x, k4v) = (v + h * k3v, acc(t + h, x + h * k3x, v + h * k3v));
            x += h / 6.0 * (k1x + 2.0 * (k2x + k3x) + k4x);
            v += h / 6.0 * (k1v + 2.0 * (k2v + k3v) + k4v);
        }
        (x, v)
    }

    /// `[m, k, c, F0, w]` in every regime: under-, critically and over-damped, undamped off
    /// resonance, at it exactly (`w = w0 = 2`), a hair from it, damped at resonance, and
    /// without a spring.
    const CASES: [[f64; 5]; 9] = [
        [1.0, 4.0, 0.5, 2.0, 3.0],
        [1.0, 4.0, 4.0, 2.0, 3.0],
        [1.0, 4.0, 10.0, 2.0, 0.7],
        [2.0, 8.0, 0.0, 5.0, 1.3],
        [1.0, 4.0, 0.0, 2.0, 2.0],
        [1.0, 4.0, 0.0, 2.0, 2.0 + 1e-9],
        [1.0, 4.0, 0.2, 2.0, 2.0],
        [0.5, 0.0, 0.3, 1.0, 4.0],
        [0.5, 0.0, 0.0, 1.0, 4.0],
    ];

    /// The closed form against RK4 at 2e4 steps over 10 s (`h w <= 2e-3`: RK4's own error is
    /// below 1e-12 of the motion's size), from two starts each. Measured worst difference:
    /// 3.4e-13 relative to the largest `|x|, |x'|` of the case; bound 1e-11.
    #[test]
    fn matches_a_fine_runge_kutta_run() -> Result<(), Error> {
        let mut worst: f64 = 0.0;
        for p in CASES {
            let osc = DrivenOscillator::new(p[0], p[1], p[2], p[3], p[4])?;
            for (x0, v0) in [(1.0, 0.0), (-0.3, 2.0)] {
                for t_end in [0.5, 3.0, 10.0] {
                    let (x, v) = osc.state(x0, v0, t_end)?;
                    let (xr, vr) = rk4(p, x0, v0, t_end, (2000.0 * t_end) as u32);
                    let scale = 1.0 + xr.abs().max(vr.abs());
                    let diff = (x - xr).abs().max((v - vr).abs()) / scale;
                    worst = worst.max(diff);
                    assert!(
                        diff < 1e-11,
                        "{p:?} from ({x0}, {v0}) at {t_end}: ({x}, {v}) vs RK4 ({xr}, {vr})"
                    );
                }
            }
        }
        println!("driven oscillator vs fine RK4: worst relative difference {worst:.2e}");
        Ok(())
    }

    /// The f32 solution follows the f64 one to a few ulps of the motion's size (measured worst
    /// 2.4e-7 relative, about 2 ulps; bound 2e-6), at resonance too.
    #[test]
    fn single_precision_follows_double() -> Result<(), Error> {
        let mut worst: f64 = 0.0;
        for p in CASES.into_iter().filter(|p| p[4] != 2.0 + 1e-9) {
            let osc64 = DrivenOscillator::new(p[0], p[1], p[2], p[3], p[4])?;
            let [m, k, c, f0, w] = p.map(|x| x as f32);
            let osc32 = DrivenOscillator::new(m, k, c, f0, w)?;
            for i in 0..=40 {
                let t = 0.25 * f64::from(i);
                let (x, v) = osc64.state(1.0, 0.5, t)?;
                let (x32, v32) = osc32.state(1.0, 0.5, t as f32)?;
                let scale = 1.0 + x.abs().max(v.abs());
                let diff = (f64::from(x32) - x).abs().max((f64::from(v32) - v).abs()) / scale;
                worst = worst.max(diff);
                assert!(
                    diff < 2e-6,
                    "{p:?} at {t}: f32 ({x32}, {v32}), f64 ({x}, {v})"
                );
            }
        }
        println!("driven oscillator, f32 vs f64: worst relative difference {worst:.2e}");
        Ok(())
    }

    /// Every parameter is validated by name; nothing non-finite is ever returned as `Ok`.
    #[test]
    fn refuses_bad_parameters() -> Result<(), Error> {
        let named = |r: Result<DrivenOscillator<f64>, Error>, name: &str| matches!(r, Err(Error::InvalidParameter { name: n, .. }) if n == name);
        for bad in [f64::NAN, f64::INFINITY, -1.0, 0.0] {
            assert!(named(
                DrivenOscillator::new(bad, 1.0, 1.0, 1.0, 1.0),
                "mass"
            ));
            assert!(named(
                DrivenOscillator::new(1.0, 1.0, 1.0, 1.0, bad),
                "omega"
            ));
        }
        for bad in [f64::NAN, f64::NEG_INFINITY, -1.0] {
            assert!(named(
                DrivenOscillator::new(1.0, bad, 1.0, 1.0, 1.0),
                "stiffness"
            ));
            assert!(named(
                DrivenOscillator::new(1.0, 1.0, bad, 1.0, 1.0),
                "damping"
            ));
        }
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert!(named(
                DrivenOscillator::new(1.0, 1.0, 1.0, bad, 1.0),
                "amplitude"
            ));
            let osc = DrivenOscillator::new(1.0, 1.0, 1.0, 1.0, 1.0)?;
            for (r, name) in [
                (osc.state(bad, 0.0, 1.0), "x0"),
                (osc.state(0.0, bad, 1.0), "v0"),
                (osc.state(0.0, 0.0, bad), "t"),
            ] {
                assert!(
                    matches!(r, Err(Error::InvalidParameter { name: n, .. }) if n == name),
                    "{name}: {r:?}"
                );
            }
        }
        // A damping of 1e-30 at resonance: a steady-state amplitude of 5e39, beyond f32.
        let light = DrivenOscillator::new(1.0f32, 4.0, 1e-30, 1e10, 2.0)?;
        assert_eq!(light.state(0.0, 0.0, 1.0), Err(Error::NonFiniteState));
        Ok(())
    }
}
