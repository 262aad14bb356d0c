"""Bad input for `cargo xtask derive --check`: a syntax error (an unclosed parenthesis)."""

from sympy import cos, symbols
from sympy.physics.mechanics import dynamicsymbols

m, l, g = symbols("m l g")
params = {m: (1.0, "positive"), l: (1.0, "positive"), g: (9.81, "non_negative")}
th = dynamicsymbols("th")
q = [th]
t = dynamicsymbols._t
T = m * (l * th.diff(t) ** 2 / 2
V = -m * g * l * cos(th)
