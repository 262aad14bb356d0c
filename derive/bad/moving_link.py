"""Bad input for `cargo xtask derive --check`: a link whose frame moves with the time (a pivot
driven up and down), which `Links::pose` cannot say: it takes the coordinates alone."""

from sympy import cos, sin, symbols
from sympy.physics.mechanics import dynamicsymbols

m, l, g, a, w = symbols("m l g a w")
params = {
    m: (1.0, "positive"),
    l: (1.0, "positive"),
    g: (9.81, "non_negative"),
    a: (0.1, "non_negative"),
    w: (50.0, "positive"),
}
th = dynamicsymbols("th")
q = [th]
t = dynamicsymbols._t
pivot = a * cos(w * t)
x, y = l * sin(th), pivot - l * cos(th)
T = m * (x.diff(t) ** 2 + y.diff(t) ** 2) / 2
V = m * g * y
links = [(0, pivot, th)]
