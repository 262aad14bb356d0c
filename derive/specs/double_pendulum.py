"""Point masses `m1`, `m2` on massless rods `l1`, `l2`, in gravity `g`: the first hangs from a
fixed pivot, the second from the first mass. `th1`, `th2` are absolute angles from the downward
vertical: mass 1 is at l1 (sin th1, -cos th1), mass 2 at that plus l2 (sin th2, -cos th2)."""

from sympy import cos, sin, symbols
from sympy.physics.mechanics import dynamicsymbols

name = "DoublePendulum"

m1, m2, l1, l2, g = symbols("m1 m2 l1 l2 g")
params = {
    m1: (1.0, "positive", "first mass, kg"),
    m2: (1.0, "positive", "second mass, kg"),
    l1: (1.0, "positive", "first rod length, m"),
    l2: (1.0, "positive", "second rod length, m"),
    g: (9.81, "non_negative", "gravity, m/s^2"),
}

th1, th2 = dynamicsymbols("th1 th2")
q = [th1, th2]
t = dynamicsymbols._t

x1, y1 = l1 * sin(th1), -l1 * cos(th1)
x2, y2 = x1 + l2 * sin(th2), y1 - l2 * cos(th2)
T = m1 * (x1.diff(t) ** 2 + y1.diff(t) ** 2) / 2 + m2 * (x2.diff(t) ** 2 + y2.diff(t) ** 2) / 2
V = m1 * g * y1 + m2 * g * y2

# The rods' frames for shapes in a world (Links): each from its pivot (the first mass for the
# second), turned by its angle, the rod along the frame's -y axis.
links = [(0, 0, th1), (x1, y1, th2)]
