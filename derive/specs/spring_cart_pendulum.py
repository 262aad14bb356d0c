"""A pendulum hanging from a cart held by a spring: a cart of mass `m_cart` slides along x on a
spring of stiffness `k` with viscous damping `c`; from it hangs a massless rod of length `l`
with a bob of mass `m`, in gravity `g`. `x` is the cart's position (the spring relaxed at
`x = 0`), `th` the rod's angle from the downward vertical: the bob is at
(x + l sin th, -l cos th)."""

from sympy import cos, sin, symbols
from sympy.physics.mechanics import dynamicsymbols

name = "SpringCartPendulum"

m_cart, m, k, c, l, g = symbols("m_cart m k c l g")
params = {
    m_cart: (2.0, "positive", "cart mass, kg"),
    m: (0.5, "positive", "bob mass, kg"),
    k: (20.0, "positive", "spring stiffness, N/m"),
    c: (0.0, "non_negative", "viscous damping of the cart, N s/m"),
    l: (0.8, "positive", "rod length, m"),
    g: (9.81, "non_negative", "gravity, m/s^2"),
}

x, th = dynamicsymbols("x th")
q = [x, th]
t = dynamicsymbols._t

bob_x, bob_y = x + l * sin(th), -l * cos(th)
T = m_cart * x.diff(t) ** 2 / 2 + m * (bob_x.diff(t) ** 2 + bob_y.diff(t) ** 2) / 2
V = k * x**2 / 2 + m * g * bob_y
Q = [-c * x.diff(t), 0]
ranges = {x: (-1.0, 1.0)}

# Frames for shapes in a world (Links): the cart at (x, 0), unturned; the rod from the cart,
# turned by th, along the frame's -y axis.
links = [(x, 0, 0), (x, 0, th)]
