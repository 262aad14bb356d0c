"""Bad input for `cargo xtask derive --check`: V uses a Python name `k` never defined."""

from sympy import symbols
from sympy.physics.mechanics import dynamicsymbols

m = symbols("m")
params = {m: (1.0, "positive")}
x = dynamicsymbols("x")
q = [x]
t = dynamicsymbols._t
T = m * x.diff(t) ** 2 / 2
V = k * x**2 / 2  # noqa: F821 - the error under test
