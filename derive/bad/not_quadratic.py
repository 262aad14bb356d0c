"""Bad input for `cargo xtask derive --check`: a T of degree 4 in the velocity."""

from sympy import symbols
from sympy.physics.mechanics import dynamicsymbols

m, a = symbols("m a")
params = {m: (1.0, "positive"), a: (0.1, "positive")}
x = dynamicsymbols("x")
q = [x]
t = dynamicsymbols._t
T = m * x.diff(t) ** 2 / 2 + a * x.diff(t) ** 4
V = x**2 / 2
