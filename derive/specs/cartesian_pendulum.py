"""The simple pendulum in Cartesian coordinates, held by a constraint: a point mass `m` at
`(x, y)` from a fixed pivot (y up), in gravity `g`, kept at distance `l` by a massless rod. The
row `phi = (x^2 + y^2 - l^2) / (2 l)` is `r - l` near the circle, a length in m, and its
multiplier is minus the rod's tension."""

from sympy import symbols
from sympy.physics.mechanics import dynamicsymbols

name = "CartesianPendulum"

m, l, g = symbols("m l g")
params = {
    m: (1.0, "positive", "bob mass, kg"),
    l: (1.0, "positive", "rod length, m"),
    g: (9.81, "non_negative", "gravity, m/s^2"),
}

x, y = dynamicsymbols("x y")
q = [x, y]
t = dynamicsymbols._t

T = m * (x.diff(t) ** 2 + y.diff(t) ** 2) / 2
V = m * g * y
phi = [(x**2 + y**2 - l**2) / (2 * l)]
ranges = {x: (-1.5, 1.5), y: (-1.5, 1.5)}

# The bob's frame for shapes in a world (Links): at (x, y), unturned.
links = [(x, y, 0)]
