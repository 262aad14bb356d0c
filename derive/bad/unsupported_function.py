"""Bad input for `cargo xtask derive --check`: a function the scalar traits do not have."""

from sympy import sinh, symbols
from sympy.physics.mechanics import dynamicsymbols

m, k = symbols("m k")
params = {m: (1.0, "positive"), k: (1.0, "positive")}
x = dynamicsymbols("x")
q = [x]
t = dynamicsymbols._t
T = m * x.diff(t) ** 2 / 2
V = k * sinh(x)
