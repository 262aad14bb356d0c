"""Bad input for `cargo xtask derive --check`: a mass whose default is negative."""

from sympy import symbols
from sympy.physics.mechanics import dynamicsymbols

m, k = symbols("m k")
params = {m: (-1.0, "positive"), k: (1.0, "positive")}
x = dynamicsymbols("x")
q = [x]
t = dynamicsymbols._t
T = m * x.diff(t) ** 2 / 2
V = k * x**2 / 2
