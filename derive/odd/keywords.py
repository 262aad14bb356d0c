"""A particle on a plane, in names that Rust or the generated code would trip on: the
coordinates are named `self` and `q`, the parameters `lambda` (a Python keyword, made with
`symbols`), `a__b` (a run of underscores), `_x` (a leading underscore) and `Self`."""

from sympy import Function, sin, symbols

t = symbols("t", positive=True)
m, lam, ab, ux, big_self = symbols("m lambda a__b _x Self")
params = {
    m: (1.0, "positive", "mass, kg"),
    lam: (2.0, "non_negative", "stiffness along `self`, N/m"),
    ab: (0.5, "finite", "a force along `q`, N"),
    ux: (1.0, "positive", "a factor on the mass"),
    big_self: (0.25, "non_negative", "a damping along both, N s/m"),
}
x = Function("self")(t)
y = Function("q")(t)
q = [x, y]
T = ux * m * (x.diff(t) ** 2 + y.diff(t) ** 2) / 2
V = lam * x**2 / 2 - ab * sin(y)
Q = [-big_self * x.diff(t), -big_self * y.diff(t)]
