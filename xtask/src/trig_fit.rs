//! `cargo xtask trig-fit`: derives the constants of `lagrange_core::fast_trig` from scratch and
//! checks them against the library's.
//!
//! - The sine and cosine polynomials are weighted minimax fits by the Remez exchange algorithm,
//!   in `f64`, on `[0, (pi/4)^2]` in `u = r^2`, minimising the *relative* error of `sin r` and
//!   `cos r` over `|r| <= pi/4`:
//!
//!   ```text
//!   sin r = r + r^3 g(u),           g(u) = sum_{k>=1} (-1)^k u^(k-1) / (2k+1)!   ~ S(u)
//!   cos r = 1 - u/2 + u^2 h(u),     h(u) = sum_{k>=2} (-1)^k u^(k-2) / (2k)!     ~ C(u)
//!   ```
//!
//!   The series converge fast on the interval, so `g` and `h` are evaluated without the
//!   cancellation that `(sin r - r) / r^3` would suffer.
//! - The bits of `2/pi` (for the argument reduction of large inputs) come from `pi` by Machin's
//!   formula `pi = 16 atan(1/5) - 4 atan(1/239)` in fixed point on a small big-integer type, then
//!   a restoring binary division.
//!
//! Coefficients are fitted in `f64` and rounded once to `f32`; the unit test below asserts that
//! the library's constants are exactly these roundings, so the library cannot drift from its
//! derivation. The accuracy the rounded polynomials reach is measured by the dense sweeps of
//! `lagrange-core/tests/fast_trig.rs`, not assumed from the fit.

use lagrange_core::fast_trig;

/// Terms of the `g` and `h` series: the next term is below `1e-40` on the interval.
const SERIES_TERMS: i32 = 20;

/// Points of the grid on which the error's extrema are searched, per Remez iteration.
const GRID: usize = 20_000;

/// Remez iterations: the levelled error settles to `f64` rounding within five or six.
const ITERATIONS: usize = 12;

/// The upper end of the fitted interval in `u = r^2`.
fn u_max() -> f64 {
    let quarter = std::f64::consts::FRAC_PI_4;
    quarter * quarter
}

/// `g(u) = (sin r - r) / r^3` for `u = r^2`, by its series.
fn g(u: f64) -> f64 {
    // term_k = (-1)^k u^(k-1) / (2k+1)!, from term_1 = -1/6.
    let mut term = -1.0 / 6.0;
    let mut sum = 0.0;
    for k in 1..=SERIES_TERMS {
        sum += term;
        let k = f64::from(k);
        term *= -u / ((2.0 * k + 2.0) * (2.0 * k + 3.0));
    }
    sum
}

/// `h(u) = (cos r - 1 + r^2/2) / r^4` for `u = r^2`, by its series.
fn h(u: f64) -> f64 {
    // term_k = (-1)^k u^(k-2) / (2k)!, from term_2 = 1/24.
    let mut term = 1.0 / 24.0;
    let mut sum = 0.0;
    for k in 2..=SERIES_TERMS {
        sum += term;
        let k = f64::from(k);
        term *= -u / ((2.0 * k + 1.0) * (2.0 * k + 2.0));
    }
    sum
}

/// The weight that turns an error in `g` into a relative error of `sin r`: `r^3 / sin r`.
fn sin_weight(u: f64) -> f64 {
    let r = u.sqrt();
    if r == 0.0 {
        0.0
    } else {
        r * r * r / r.sin()
    }
}

/// The weight that turns an error in `h` into a relative error of `cos r`: `r^4 / cos r`.
fn cos_weight(u: f64) -> f64 {
    let r = u.sqrt();
    u * u / r.cos()
}

/// `sum_j c_j u^j` by Horner.
fn horner(c: &[f64], u: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &cj| acc * u + cj)
}

/// Solves the square system `a x = b` by Gaussian elimination with partial pivoting.
fn solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Result<Vec<f64>, String> {
    let n = b.len();
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .ok_or("empty system")?;
        if a[pivot][col] == 0.0 {
            return Err("singular Remez system".into());
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        let pivot_row = a[col].clone();
        for row in col + 1..n {
            let factor = a[row][col] / pivot_row[col];
            for (x, p) in a[row][col..].iter_mut().zip(&pivot_row[col..]) {
                *x -= factor * p;
            }
            b[row] -= factor * b[col];
        }
    }
    let mut x = vec![0.0; n];
    for row in (0..n).rev() {
        let tail: f64 = (row + 1..n).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - tail) / a[row][row];
    }
    Ok(x)
}

/// A weighted minimax fit: the coefficients of `p` (degree `n - 1` in `u`) minimising
/// `max |w(u) (f(u) - p(u))|` on `[0, u_max]`, and that levelled maximum.
///
/// # Errors
/// When a Remez system is singular or the error fails to alternate.
pub fn remez(f: fn(f64) -> f64, w: fn(f64) -> f64, n: usize) -> Result<(Vec<f64>, f64), String> {
    let hi = u_max();
    let err = |c: &[f64], u: f64| w(u) * (f(u) - horner(c, u));
    // Chebyshev nodes as the first reference: n + 1 interior points (the weight of the sine
    // vanishes at u = 0, where no reference point may sit).
    let mut reference: Vec<f64> = (0..=n)
        .map(|i| {
            let theta = std::f64::consts::PI * (i as f64 + 0.5) / (n as f64 + 1.0);
            0.5 * hi * (1.0 - theta.cos())
        })
        .collect();
    let mut coeffs = vec![0.0; n];
    let mut levelled = 0.0;
    for _ in 0..ITERATIONS {
        let rows: Vec<Vec<f64>> = reference
            .iter()
            .enumerate()
            .map(|(i, &u)| {
                let mut row: Vec<f64> = (0..n).map(|j| w(u) * u.powi(j as i32)).collect();
                row.push(if i % 2 == 0 { 1.0 } else { -1.0 });
                row
            })
            .collect();
        let rhs: Vec<f64> = reference.iter().map(|&u| w(u) * f(u)).collect();
        let x = solve(rows, rhs)?;
        coeffs = x[..n].to_vec();
        levelled = x[n].abs();
        // New reference: the extremum of each run of equal sign of the error on a fine grid.
        let grid: Vec<(f64, f64)> = (0..=GRID)
            .map(|i| {
                let u = hi * i as f64 / GRID as f64;
                (u, err(&coeffs, u))
            })
            .collect();
        let mut extrema: Vec<(f64, f64)> = Vec::new();
        for &(u, e) in &grid {
            match extrema.last_mut() {
                Some(last) if (last.1 >= 0.0) == (e >= 0.0) => {
                    if e.abs() > last.1.abs() {
                        *last = (u, e);
                    }
                }
                _ => extrema.push((u, e)),
            }
        }
        // Keep the n + 1 largest consecutive alternating extrema.
        while extrema.len() > n + 1 {
            let first = extrema.first().map_or(0.0, |p| p.1.abs());
            let last = extrema.last().map_or(0.0, |p| p.1.abs());
            if first < last {
                extrema.remove(0);
            } else {
                extrema.pop();
            }
        }
        if extrema.len() != n + 1 {
            return Err(format!(
                "the error alternates {} times, not {}",
                extrema.len(),
                n + 1
            ));
        }
        reference = extrema.iter().map(|p| p.0).collect();
    }
    Ok((coeffs, levelled))
}

/// The `f32` coefficients of `S(u)` (degree `n - 1`) and the levelled relative error.
///
/// # Errors
/// As [`remez`].
pub fn sin_coefficients(n: usize) -> Result<(Vec<f32>, f64), String> {
    let (c, e) = remez(g, sin_weight, n)?;
    Ok((c.iter().map(|&x| x as f32).collect(), e))
}

/// The `f32` coefficients of `C(u)` (degree `n - 1`) and the levelled relative error.
///
/// # Errors
/// As [`remez`].
pub fn cos_coefficients(n: usize) -> Result<(Vec<f32>, f64), String> {
    let (c, e) = remez(h, cos_weight, n)?;
    Ok((c.iter().map(|&x| x as f32).collect(), e))
}

/// A fixed-point number of [`LIMBS`] 32-bit limbs, most significant first, with the binary
/// point after the first limb: just enough big-integer arithmetic for Machin's formula.
const LIMBS: usize = 14;

/// See [`LIMBS`].
type Fixed = [u32; LIMBS];

/// `a + b`, wrapping.
fn add(a: &Fixed, b: &Fixed) -> Fixed {
    let mut out = [0; LIMBS];
    let mut carry = 0u64;
    for i in (0..LIMBS).rev() {
        let s = u64::from(a[i]) + u64::from(b[i]) + carry;
        out[i] = s as u32;
        carry = s >> 32;
    }
    out
}

/// `a - b`, wrapping.
fn sub(a: &Fixed, b: &Fixed) -> Fixed {
    let mut out = [0; LIMBS];
    let mut borrow = 0i64;
    for i in (0..LIMBS).rev() {
        let mut d = i64::from(a[i]) - i64::from(b[i]) - borrow;
        borrow = 0;
        if d < 0 {
            d += 1 << 32;
            borrow = 1;
        }
        out[i] = d as u32;
    }
    out
}

/// `a / d` for a small divisor, truncated.
fn div_small(a: &Fixed, d: u32) -> Fixed {
    let mut out = [0; LIMBS];
    let mut rem = 0u64;
    for i in 0..LIMBS {
        let cur = (rem << 32) | u64::from(a[i]);
        out[i] = (cur / u64::from(d)) as u32;
        rem = cur % u64::from(d);
    }
    out
}

/// `atan(1/x)` by its alternating series, in [`Fixed`].
fn atan_inv(x: u32) -> Fixed {
    let mut one = [0; LIMBS];
    one[0] = 1;
    let mut power = div_small(&one, x); // x^-(2k+1)
    let mut sum = [0; LIMBS];
    let mut k = 0u32;
    while power.iter().any(|&limb| limb != 0) {
        let term = div_small(&power, 2 * k + 1);
        sum = if k % 2 == 0 {
            add(&sum, &term)
        } else {
            sub(&sum, &term)
        };
        power = div_small(&power, x * x);
        k += 1;
    }
    sum
}

/// `pi` in [`Fixed`], by Machin's formula (truncation error a few units of the last limb).
fn pi_fixed() -> Fixed {
    let a = atan_inv(5);
    let b = atan_inv(239);
    let a16 = (0..16).fold([0; LIMBS], |acc, _| add(&acc, &a));
    let b4 = (0..4).fold([0; LIMBS], |acc, _| add(&acc, &b));
    sub(&a16, &b4)
}

/// The first `32 * words` bits after the binary point of `2/pi`, by restoring division of `2`
/// by `pi` (both in [`Fixed`]).
pub fn frac_2_pi_bits(words: usize) -> Vec<u32> {
    let pi = pi_fixed();
    let mut rem = [0; LIMBS];
    rem[0] = 2; // 2 / pi < 1, so the integer part is zero and the remainder starts at 2.
    let mut bits = vec![0u32; words];
    for i in 0..32 * words {
        // rem = 2 rem; a bit is 1 when rem >= pi.
        rem = add(&rem, &rem);
        if rem >= pi {
            rem = sub(&rem, &pi);
            bits[i / 32] |= 1 << (31 - i % 32);
        }
    }
    bits
}

/// `pi/2` in unsigned fixed point with 62 fractional bits, rounded to nearest.
pub fn frac_pi_2_fixed() -> u64 {
    let pi = pi_fixed();
    // pi/2 * 2^62 = pi * 2^61: the integer limb shifted up by 61 plus the top 61 fractional bits.
    let int = u64::from(pi[0]);
    let frac = (u64::from(pi[1]) << 32) | u64::from(pi[2]);
    let kept = (int << 61) | (frac >> 3);
    kept + ((frac >> 2) & 1)
}

/// `pi/2` split as `P1 + P2 + P3 + P4`: three consecutive 15-bit slices of its binary
/// expansion (`P1` holds the integer bit and 14 fractional ones), then the rest rounded to
/// `f32`.
pub fn frac_pi_2_parts() -> [f32; 4] {
    let pi = pi_fixed();
    // pi/2 * 2^126 in a u128: pi * 2^125, from the integer limb and 125 fractional bits.
    let frac = (u128::from(pi[1]) << 96)
        | (u128::from(pi[2]) << 64)
        | (u128::from(pi[3]) << 32)
        | u128::from(pi[4]);
    let v = (u128::from(pi[0]) << 125) | (frac >> 3);
    let slice = |end: u32| ((v >> (126 - end)) & 0x7fff) as f32 * 2f32.powi(-(end as i32));
    let rest = v & ((1u128 << (126 - 44)) - 1);
    [
        slice(14),
        slice(29),
        slice(44),
        rest as f32 * 2f32.powi(-126),
    ]
}

/// Prints the derived constants as Rust source and compares them with the library's.
pub fn run() -> Result<(), String> {
    let (s, se) = sin_coefficients(fast_trig::SIN_POLY.len())?;
    let (c, ce) = cos_coefficients(fast_trig::COS_POLY.len())?;
    println!("// sin r = r + r^3 S(r^2); levelled relative error of the f64 fit {se:.3e}");
    println!("pub const SIN_POLY: [f32; {}] = {s:?};", s.len());
    println!("// cos r = 1 - r^2/2 + r^4 C(r^2); levelled relative error of the f64 fit {ce:.3e}");
    println!("pub const COS_POLY: [f32; {}] = {c:?};", c.len());
    let bits = frac_2_pi_bits(fast_trig::FRAC_2_PI_BITS.len());
    let hex: Vec<String> = bits.iter().map(|b| format!("0x{b:08x}")).collect();
    println!(
        "pub const FRAC_2_PI_BITS: [u32; {}] = [{}];",
        bits.len(),
        hex.join(", ")
    );
    println!(
        "pub const FRAC_PI_2_FIXED: u64 = 0x{:016x};",
        frac_pi_2_fixed()
    );
    println!(
        "pub const FRAC_PI_2_PARTS: [f32; 4] = {:?};",
        frac_pi_2_parts()
    );
    let same = s == fast_trig::SIN_POLY
        && frac_pi_2_parts() == fast_trig::FRAC_PI_2_PARTS
        && c == fast_trig::COS_POLY
        && bits == fast_trig::FRAC_2_PI_BITS
        && frac_pi_2_fixed() == fast_trig::FRAC_PI_2_FIXED;
    if same {
        println!("xtask trig-fit: lagrange_core::fast_trig holds exactly these constants");
        Ok(())
    } else {
        Err("lagrange_core::fast_trig differs from the derivation: paste the lines above".into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The library's constants are the ones this derivation computes, bit for bit.
    #[test]
    fn library_constants_are_derived() -> Result<(), String> {
        let (s, _) = sin_coefficients(fast_trig::SIN_POLY.len())?;
        let (c, _) = cos_coefficients(fast_trig::COS_POLY.len())?;
        assert_eq!(s, fast_trig::SIN_POLY);
        assert_eq!(c, fast_trig::COS_POLY);
        assert_eq!(
            frac_2_pi_bits(fast_trig::FRAC_2_PI_BITS.len()),
            fast_trig::FRAC_2_PI_BITS
        );
        assert_eq!(frac_pi_2_fixed(), fast_trig::FRAC_PI_2_FIXED);
        assert_eq!(frac_pi_2_parts(), fast_trig::FRAC_PI_2_PARTS);
        Ok(())
    }

    /// The big-integer `pi` agrees with `f64`'s, and the leading bits of `2/pi` with
    /// `f64`'s `FRAC_2_PI` (an independent check of the arithmetic).
    #[test]
    fn big_integer_constants_agree_with_f64() {
        let pi = pi_fixed();
        let approx = f64::from(pi[0]) + f64::from(pi[1]) / 2f64.powi(32);
        assert!((approx - std::f64::consts::PI).abs() < 1e-9);
        let bits = frac_2_pi_bits(2);
        let top53 = ((u64::from(bits[0]) << 32) | u64::from(bits[1])) >> 11;
        let f = top53 as f64 / 2f64.powi(53);
        assert!((f - std::f64::consts::FRAC_2_PI).abs() <= 2f64.powi(-53));
        let pio2 = frac_pi_2_fixed() as f64 / 2f64.powi(62);
        assert_eq!(pio2, std::f64::consts::FRAC_PI_2);
        let parts = frac_pi_2_parts();
        let sum: f64 = parts.iter().map(|&p| f64::from(p)).sum();
        assert!((sum - std::f64::consts::FRAC_PI_2).abs() <= 2f64.powi(-52));
        // The first three have at most 17 significant bits: k P is exact for k < 2^7.
        for p in &parts[..3] {
            assert_eq!(
                p.to_bits() & 0x7f,
                0,
                "{p:e} has more than 17 significant bits"
            );
        }
    }

    /// The fits level the error: the Remez error is far below an `f32` ulp (2^-24 ~ 6e-8).
    #[test]
    fn fits_are_well_below_f32_rounding() -> Result<(), String> {
        let (_, se) = remez(g, sin_weight, fast_trig::SIN_POLY.len())?;
        let (_, ce) = remez(h, cos_weight, fast_trig::COS_POLY.len())?;
        assert!(se < 2f64.powi(-26), "sin fit {se:e}");
        assert!(ce < 2f64.powi(-26), "cos fit {ce:e}");
        Ok(())
    }
}
