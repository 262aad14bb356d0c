//! The implicit midpoint rule: the one-stage Gauss-Legendre method.

use crate::implicit_rk::{ImplicitRungeKutta, ImplicitTableau};

/// The tableau of the implicit midpoint rule.
///
/// ```text
/// 1/2 | 1/2
/// ----+----
///     |  1
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MidpointTableau;

impl ImplicitTableau<1> for MidpointTableau {
    const NAME: &'static str = "implicit midpoint";
    const ORDER: u32 = 2;
    const A: [[f64; 1]; 1] = [[0.5]];
    const B: [f64; 1] = [1.0];
    const C: [f64; 1] = [0.5];
}

/// The implicit midpoint rule, `y1 = y0 + h F((y0 + y1) / 2)` on `y = (q, q')`.
///
/// Order 2, implicit (Newton on `N` unknowns: one acceleration Jacobian per step, then one
/// acceleration per iteration), fixed step. Symmetric and A-stable but not L-stable: an
/// undamped linear oscillator keeps its amplitude exactly at any step. Symplectic where the
/// mass matrix is constant (then `(q, q')` is a linear image of `(q, p)`), for any forces of
/// `q`; with a configuration-dependent mass matrix it is still symmetric (time-reversible),
/// which keeps the energy error of regular (quasi-periodic) motion bounded without drift; for
/// a symplectic method on such systems use the
/// [`VariationalMidpoint`](crate::VariationalMidpoint) integrator.
///
/// ```
/// use lagrange_core::State;
/// use lagrange_integrators::{ImplicitMidpoint, Integrator};
/// use lagrange_systems::SimplePendulum;
/// let p = SimplePendulum::new(1.0, 1.0, 9.81, 0.0)?;
/// let end = ImplicitMidpoint::default().integrate(&p, &State::at_rest([0.5]), 1e-2, 100)?;
/// assert!(end.is_finite());
/// # Ok::<(), lagrange_core::Error>(())
/// ```
pub type ImplicitMidpoint<T> = ImplicitRungeKutta<T, 1, MidpointTableau>;
