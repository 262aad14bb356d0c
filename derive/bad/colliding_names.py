"""Bad input for `cargo xtask derive --check`: the parameters `θ` and `theta` are both `theta`
in Rust."""

from sympy import cos, symbols
from sympy.physics.mechanics import dynamicsymbols

m, theta_greek, theta = symbols("m θ theta")
params = {m: (1.0, "positive"), theta_greek: 1.0, theta: 2.0}
x = dynamicsymbols("x")
q = [x]
t = dynamicsymbols._t
T = m * x.diff(t) ** 2 / 2
V = m * cos(theta_greek) * cos(theta) * x**2 / 2
