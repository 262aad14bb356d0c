//! [`Kernel`]: the math functions a step spends its time in, called over fixed sets of inputs,
//! so that the firmware can count instructions per call and host and firmware can compare
//! every result bit for bit (as a digest).

use core::hint::black_box;

use lagrange_core::fast_trig;

/// Calls of each kernel per measurement.
pub const KERNEL_CALLS: u32 = 1000;

/// One function over one input set.
#[derive(Debug, Clone, Copy)]
pub struct Kernel {
    /// The function, e.g. `"fast_trig::sin"`.
    pub name: &'static str,
    /// The inputs, e.g. `"|x| <= pi/4"`.
    pub inputs: &'static str,
    runner: fn(u32) -> u64,
}

impl Kernel {
    /// Calls the function on `calls` inputs spread over the set; a digest of every result's
    /// bits (equal digests mean, in all likelihood, equal results).
    #[must_use]
    pub fn run(&self, calls: u32) -> u64 {
        (self.runner)(calls)
    }
}

/// Folds one result's bits into a digest.
fn fold(digest: u64, bits: u64) -> u64 {
    (digest.rotate_left(7) ^ bits).wrapping_mul(0x9e37_79b9_7f4a_7c15)
}

/// `f` at `calls` points spread evenly over `[lo, hi)`, in `f32`.
#[inline(always)]
fn sweep32(calls: u32, lo: f32, hi: f32, f: impl Fn(f32) -> f32) -> u64 {
    #[allow(clippy::cast_precision_loss)] // a count far below 2^24
    let step = (hi - lo) / calls as f32;
    let mut digest = 0;
    for i in 0..calls {
        #[allow(clippy::cast_precision_loss)]
        let x = black_box(lo + step * i as f32);
        digest = fold(digest, u64::from(f(x).to_bits()));
    }
    digest
}

/// `f` at `calls` points spread evenly over `[lo, hi)`, in `f64`.
#[inline(always)]
fn sweep64(calls: u32, lo: f64, hi: f64, f: impl Fn(f64) -> f64) -> u64 {
    let step = (hi - lo) / f64::from(calls);
    let mut digest = 0;
    for i in 0..calls {
        let x = black_box(lo + step * f64::from(i));
        digest = fold(digest, f(x).to_bits());
    }
    digest
}

/// `|x| <= pi/4`: no reduction.
const QUARTER: (f32, f32) = (-0.785, 0.785);
/// `|x| <= 8`: both paths, as a mechanism's angles.
const WIDE: (f32, f32) = (-8.0, 8.0);
/// Up to `500`: mostly the medium reduction, with quadrant counts up to 318.
const HUNDREDS: (f32, f32) = (-500.0, 500.0);
/// Up to `1e30`: the reduction with bits of 2/pi far from the point.
const HUGE: (f32, f32) = (-1e30, 1e30);

/// The kernels measured, in order (the index is the kernel's id in the firmware's log). Each
/// "identity" entry is the cost of the loop itself, subtracted from the kernels of its type.
pub const KERNELS: [Kernel; 13] = [
    Kernel {
        name: "identity f32",
        inputs: "-",
        runner: |n| sweep32(n, WIDE.0, WIDE.1, |x| x),
    },
    Kernel {
        name: "fast_trig::sin",
        inputs: "|x| <= pi/4",
        runner: |n| sweep32(n, QUARTER.0, QUARTER.1, fast_trig::sin),
    },
    Kernel {
        name: "fast_trig::sin",
        inputs: "|x| <= 8",
        runner: |n| sweep32(n, WIDE.0, WIDE.1, fast_trig::sin),
    },
    Kernel {
        name: "fast_trig::sin",
        inputs: "|x| <= 500",
        runner: |n| sweep32(n, HUNDREDS.0, HUNDREDS.1, fast_trig::sin),
    },
    Kernel {
        name: "fast_trig::sin",
        inputs: "|x| <= 1e30",
        runner: |n| sweep32(n, HUGE.0, HUGE.1, fast_trig::sin),
    },
    Kernel {
        name: "fast_trig::cos",
        inputs: "|x| <= 8",
        runner: |n| sweep32(n, WIDE.0, WIDE.1, fast_trig::cos),
    },
    Kernel {
        name: "fast_trig::sin_cos (sum)",
        inputs: "|x| <= 8",
        runner: |n| {
            sweep32(n, WIDE.0, WIDE.1, |x| {
                let (s, c) = fast_trig::sin_cos(x);
                s + c
            })
        },
    },
    Kernel {
        name: "libm::sinf",
        inputs: "|x| <= pi/4",
        runner: |n| sweep32(n, QUARTER.0, QUARTER.1, libm::sinf),
    },
    Kernel {
        name: "libm::sinf",
        inputs: "|x| <= 8",
        runner: |n| sweep32(n, WIDE.0, WIDE.1, libm::sinf),
    },
    Kernel {
        name: "libm::sqrtf",
        inputs: "0 <= x <= 100",
        runner: |n| sweep32(n, 0.0, 100.0, libm::sqrtf),
    },
    Kernel {
        name: "identity f64",
        inputs: "-",
        runner: |n| sweep64(n, -8.0, 8.0, |x| x),
    },
    Kernel {
        name: "libm::sin",
        inputs: "|x| <= pi/4",
        runner: |n| sweep64(n, -0.785, 0.785, libm::sin),
    },
    Kernel {
        name: "libm::sqrt",
        inputs: "0 <= x <= 100",
        runner: |n| sweep64(n, 0.0, 100.0, libm::sqrt),
    },
];
