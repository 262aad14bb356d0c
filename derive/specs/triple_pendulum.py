"""Three point masses `m1`, `m2`, `m3` on massless rods `l1`, `l2`, `l3` in gravity `g`, a
planar chain from a fixed pivot: the three-link case of the n-link pendulum. `th1`, `th2`,
`th3` are absolute angles from the downward vertical. Its mass matrix is 3x3: the generated
law solves it by Cholesky."""

from sympy import cos, sin, symbols
from sympy.physics.mechanics import dynamicsymbols

name = "TriplePendulum"

m1, m2, m3, l1, l2, l3, g = symbols("m1 m2 m3 l1 l2 l3 g")
params = {
    m1: (1.0, "positive", "first mass, kg"),
    m2: (1.0, "positive", "second mass, kg"),
    m3: (1.0, "positive", "third mass, kg"),
    l1: (1.0, "positive", "first rod length, m"),
    l2: (1.0, "positive", "second rod length, m"),
    l3: (1.0, "positive", "third rod length, m"),
    g: (9.81, "non_negative", "gravity, m/s^2"),
}

th1, th2, th3 = dynamicsymbols("th1 th2 th3")
q = [th1, th2, th3]
t = dynamicsymbols._t

T, V = 0, 0
x, y = 0, 0
# Each rod's frame for shapes in a world (Links): from its pivot, turned by its angle, the rod
# along the frame's -y axis.
links = []
for m, l, th in [(m1, l1, th1), (m2, l2, th2), (m3, l3, th3)]:
    links.append((x, y, th))
    x, y = x + l * sin(th), y - l * cos(th)
    T += m * (x.diff(t) ** 2 + y.diff(t) ** 2) / 2
    V += m * g * y
