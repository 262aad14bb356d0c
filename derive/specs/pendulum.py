"""The origin's pendulum: a point mass `m` on a massless rod of length `l` about a fixed pivot,
in gravity `g`, with viscous damping `b` at the pivot. `th` is the angle from the downward
vertical: the bob is at (l sin th, -l cos th)."""

from sympy import cos, sin, symbols
from sympy.physics.mechanics import dynamicsymbols

name = "Pendulum"

m, l, g, b = symbols("m l g b")
params = {
    m: (1.0, "positive", "bob mass, kg"),
    l: (1.0, "positive", "rod length, m"),
    g: (9.81, "non_negative", "gravity, m/s^2"),
    b: (0.0, "non_negative", "viscous damping at the pivot, N m s/rad"),
}

th = dynamicsymbols("th")
q = [th]
t = dynamicsymbols._t

# The bob's position, differentiated: T = m |v|^2 / 2.
x, y = l * sin(th), -l * cos(th)
T = m * (x.diff(t) ** 2 + y.diff(t) ** 2) / 2
V = m * g * y
Q = [-b * th.diff(t)]

# The rod's frame for shapes in a world (Links): its origin at the pivot, turned by th, the
# rod along the frame's -y axis (the bob at (0, -l) in it).
links = [(0, 0, th)]
