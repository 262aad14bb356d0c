"""A pendulum on a vertically driven pivot (Kapitza's), with short and Greek names: `ω` the
drive's angular frequency, `A` its amplitude, `φ` the angle from the downward vertical, `ℓ` the
rod, `μ` the bob's mass; time `τ` enters T explicitly."""

from sympy import Function, cos, sin, symbols

tau = symbols("τ", positive=True)
mu, ell, g, A, omega = symbols("μ ℓ g A ω")
params = {
    mu: 1.0,
    ell: (1.0, "positive"),
    g: (9.81, "non_negative"),
    A: (0.05, "non_negative"),
    omega: (200.0, "non_negative"),
}
phi_ = Function("φ")(tau)
q = [phi_]
x, y = ell * sin(phi_), A * cos(omega * tau) - ell * cos(phi_)
T = mu * (x.diff(tau) ** 2 + y.diff(tau) ** 2) / 2
V = mu * g * y
