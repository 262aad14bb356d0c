//! Two-stage Radau IIA, order 3, L-stable.

use crate::implicit_rk::{ImplicitRungeKutta, ImplicitTableau};

/// The tableau of the two-stage Radau IIA method.
///
/// ```text
/// 1/3 | 5/12  -1/12
///  1  | 3/4    1/4
/// ----+------------
///     | 3/4    1/4
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RadauIIA2Tableau;

impl ImplicitTableau<2> for RadauIIA2Tableau {
    const NAME: &'static str = "Radau IIA 2";
    const ORDER: u32 = 3;
    const A: [[f64; 2]; 2] = [[5.0 / 12.0, -1.0 / 12.0], [0.75, 0.25]];
    const B: [f64; 2] = [0.75, 0.25];
    const C: [f64; 2] = [1.0 / 3.0, 1.0];
}

/// Two-stage Radau IIA collocation.
///
/// Order 3, implicit (Newton on `2 N` unknowns: one acceleration Jacobian per step, then two
/// accelerations per iteration), fixed step, L-stable and stiffly accurate (the new state is
/// the last stage): the stability function `(1 + z/3) / (1 - 2z/3 + z^2/6)` goes to zero for
/// very stiff components, so a spring with `h w = 100` loses ~98% of its amplitude per step
/// instead of ringing or blowing up. Not symplectic: it damps slightly at every step
/// (`O(h^4)` per step for a smooth oscillation). The method for stiff mechanisms (stiff
/// springs, contact penalties, fast dampers) when order 1 is not enough.
///
/// ```
/// use lagrange_core::State;
/// use lagrange_integrators::{Integrator, RadauIIA2};
/// use lagrange_systems::SimplePendulum;
/// let p = SimplePendulum::new(1.0, 1.0, 9.81, 0.0)?;
/// let end = RadauIIA2::default().integrate(&p, &State::at_rest([0.5]), 1e-2, 100)?;
/// assert!(end.is_finite());
/// # Ok::<(), lagrange_core::Error>(())
/// ```
pub type RadauIIA2<T> = ImplicitRungeKutta<T, 2, RadauIIA2Tableau>;
