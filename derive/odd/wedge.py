"""A block sliding on a moving wedge, in the paper's names: the wedge of mass `M` slides along
the floor (position `X`), the block of mass `m` slides without friction down the wedge's face,
inclined at `α` to the horizontal, `s` along the face from its top, in gravity `g` (> 0). The
time is a symbol of the spec's own, positive as many SymPy users write it."""

from sympy import Function, cos, sin, symbols

t = symbols("t", positive=True)
M, m, alpha, g = symbols("M m α g")
params = {
    M: (3.0, "positive", "wedge mass, kg"),
    m: (1.0, "positive", "block mass, kg"),
    alpha: (0.5, "positive", "inclination of the face, rad"),
    g: (9.81, "non_negative", "gravity, m/s^2"),
}

X = Function("X")(t)
s = Function("s")(t)
q = [X, s]

bx, by = X + s * cos(alpha), -s * sin(alpha)
T = M * X.diff(t) ** 2 / 2 + m * (bx.diff(t) ** 2 + by.diff(t) ** 2) / 2
V = m * g * by
