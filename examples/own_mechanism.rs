//! Your own mechanism in about 20 lines: a pendulum hanging from a cart held by a spring,
//! written as `T` and `V` on paper; its equations of motion by automatic differentiation;
//! damping added by wrapping; stepped by RK4 and by the symplectic variational integrator.
//!
//! `cargo run --example own_mechanism`

use lagrange_integrators::prelude::*;

/// A cart of mass `m_cart` on a spring of stiffness `k`, with a pendulum of length `l` and bob
/// mass `m` hanging from it, in gravity `g`. `q = [x, th]`: the cart's position and the
/// pendulum's angle from the downward vertical.
struct SpringCartPendulum {
    m_cart: f64,
    m: f64,
    k: f64,
    l: f64,
    g: f64,
}

impl Lagrangian<f64, 2> for SpringCartPendulum {
    /// The cart's `M x'^2 / 2` and the bob's `m |v|^2 / 2`, `v = (x' + l cos th th', l sin th th')`.
    fn kinetic<S: Scalar<Real = f64>>(&self, _t: S, q: &SVector<S, 2>, qd: &SVector<S, 2>) -> S {
        let (sin, cos) = q[1].sin_cos();
        let vx = qd[0] + cos * qd[1] * self.l;
        let vy = sin * qd[1] * self.l;
        qd[0] * qd[0] * (0.5 * self.m_cart) + (vx * vx + vy * vy) * (0.5 * self.m)
    }
    /// The spring's `k x^2 / 2` and the bob's `-m g l cos th`.
    fn potential<S: Scalar<Real = f64>>(&self, _t: S, q: &SVector<S, 2>) -> S {
        q[0] * q[0] * (0.5 * self.k) - q[1].cos() * (self.m * self.g * self.l)
    }
}

fn main() -> Result<(), Error> {
    let params = SpringCartPendulum {
        m_cart: 2.0,
        m: 0.5,
        k: 20.0,
        l: 0.8,
        g: 9.81,
    };
    let free = EulerLagrange::new(params);
    let start = State::new(0.0, [0.1, 1.0], [0.0, 0.0]);
    let (dt, steps) = (1e-3, 10_000);

    // Conservative: energy kept by both, RK4 to its truncation error, the variational
    // integrator bounded (it is symplectic for any Lagrangian).
    let e0 = free.energy(&start);
    let rk4 = Rk4.integrate(&free, &start, dt, steps)?;
    let vi = VariationalMidpoint::default().integrate(&free, &start, dt, steps)?;
    println!("spring-cart pendulum, 10 s at dt = 1e-3: E0 = {e0:.6} J");
    println!(
        "  RK4:                  x = {:+.6} m, th = {:+.6} rad, dE = {:+.2e} J",
        rk4.q[0],
        rk4.q[1],
        free.energy(&rk4) - e0
    );
    println!(
        "  variational midpoint: x = {:+.6} m, th = {:+.6} rad, dE = {:+.2e} J",
        vi.q[0],
        vi.q[1],
        free.energy(&vi) - e0
    );

    // Damped: a force added by wrapping, never by editing the mechanism.
    let damped = free.with_force(ViscousDamping::new([0.5, 0.05])?);
    let end = Rk4.integrate(&damped, &start, dt, 5 * steps)?;
    println!(
        "  damped, after 50 s:   E = {:.6} J (from {e0:.6} J)",
        damped.energy(&end)
    );
    Ok(())
}
