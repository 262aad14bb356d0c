"""Bad input for `cargo xtask derive --check`: a link given as a point (x, y) with no angle."""

from sympy import cos, sin, symbols
from sympy.physics.mechanics import dynamicsymbols

m, l, g = symbols("m l g")
params = {m: (1.0, "positive"), l: (1.0, "positive"), g: (9.81, "non_negative")}
th = dynamicsymbols("th")
q = [th]
t = dynamicsymbols._t
x, y = l * sin(th), -l * cos(th)
T = m * (x.diff(t) ** 2 + y.diff(t) ** 2) / 2
V = m * g * y
links = [(x, y)]
