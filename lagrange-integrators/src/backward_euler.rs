//! Backward (implicit) Euler, the simplest L-stable method.

use crate::implicit_rk::{ImplicitRungeKutta, ImplicitTableau};

/// The tableau of backward Euler.
///
/// ```text
/// 1 | 1
/// --+--
///   | 1
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BackwardEulerTableau;

impl ImplicitTableau<1> for BackwardEulerTableau {
    const NAME: &'static str = "backward Euler";
    const ORDER: u32 = 1;
    const A: [[f64; 1]; 1] = [[1.0]];
    const B: [f64; 1] = [1.0];
    const C: [f64; 1] = [1.0];
}

/// Backward Euler, `y1 = y0 + h F(y1)` on `y = (q, q')`.
///
/// Order 1, implicit (Newton on `N` unknowns: one acceleration Jacobian per step, then one
/// acceleration per iteration), fixed step, L-stable: stiff components (a stiff spring, a
/// fast damper) are damped out at any step instead of blowing up. Not symplectic: it removes
/// energy from every oscillation (by a factor `1 / (1 + (h w)^2)` per step for a linear one),
/// so use it for stiff, dissipative systems where stability matters more than accuracy; for
/// more accuracy at the same robustness use [`RadauIIA2`](crate::RadauIIA2).
///
/// ```
/// use lagrange_core::State;
/// use lagrange_integrators::{BackwardEuler, Integrator};
/// use lagrange_systems::SimplePendulum;
/// let p = SimplePendulum::new(1.0_f64, 1.0, 9.81, 0.0)?;
/// let start = State::at_rest([0.5]);
/// let end = BackwardEuler::default().integrate(&p, &start, 1e-2, 100)?;
/// assert!(end.q[0].abs() < start.q[0]);
/// # Ok::<(), lagrange_core::Error>(())
/// ```
pub type BackwardEuler<T> = ImplicitRungeKutta<T, 1, BackwardEulerTableau>;
