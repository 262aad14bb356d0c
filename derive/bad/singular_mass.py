"""Bad input for `cargo xtask derive --check`: a singular mass matrix. T holds the velocities
only through their sum, so the difference x' - y' has no inertia."""

from sympy import symbols
from sympy.physics.mechanics import dynamicsymbols

m, k = symbols("m k")
params = {m: (1.0, "positive"), k: (1.0, "positive")}
x, y = dynamicsymbols("x y")
q = [x, y]
t = dynamicsymbols._t
T = m * (x.diff(t) + y.diff(t)) ** 2 / 2
V = k * (x**2 + y**2) / 2
