"""Bad input for `cargo xtask derive --check`: a power with a parameter as its exponent."""

from sympy import symbols
from sympy.physics.mechanics import dynamicsymbols

m, k, n = symbols("m k n")
params = {m: (1.0, "positive"), k: (1.0, "positive"), n: (3.0, "positive")}
x = dynamicsymbols("x")
q = [x]
t = dynamicsymbols._t
T = m * x.diff(t) ** 2 / 2
V = k * x**n
