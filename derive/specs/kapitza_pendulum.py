"""Kapitza's pendulum: a point mass `m` on a massless rod of length `l` whose pivot is driven up
and down, `y_pivot = a cos(w t)`, in gravity `g`. `th` is the angle from the downward vertical.
Time enters T explicitly (the pivot moves), so T + V is not conserved; fast enough driving
(`a w > sqrt(2 g l)`) makes the upright position stable."""

from sympy import Function, cos, sin, symbols

name = "KapitzaPendulum"

m, l, g, a, w = symbols("m l g a w")
params = {
    m: (1.0, "positive", "bob mass, kg"),
    l: (1.0, "positive", "rod length, m"),
    g: (9.81, "non_negative", "gravity, m/s^2"),
    a: (0.05, "non_negative", "amplitude of the pivot's motion, m"),
    w: (200.0, "non_negative", "angular frequency of the pivot's motion, rad/s"),
}

t = symbols("t")
th = Function("th")(t)
q = [th]

x, y = l * sin(th), a * cos(w * t) - l * cos(th)
T = m * (x.diff(t) ** 2 + y.diff(t) ** 2) / 2
V = m * g * y
