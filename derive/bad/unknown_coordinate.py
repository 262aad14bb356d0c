"""Bad input for `cargo xtask derive --check`: T uses a coordinate `y` not listed in q."""

from sympy import symbols
from sympy.physics.mechanics import dynamicsymbols

m, g = symbols("m g")
params = {m: (1.0, "positive"), g: (9.81, "non_negative")}
x, y = dynamicsymbols("x y")
q = [x]
t = dynamicsymbols._t
T = m * (x.diff(t) ** 2 + y.diff(t) ** 2) / 2
V = m * g * x
