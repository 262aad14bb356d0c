"""A pendulum on a spring-held cart with every kind of name a paper uses: a cart of mass `M`
on a spring of stiffness `k` > 0 with damping `c` >= 0 (a damper whose force is - c v, i.e.
> 0 against the motion); a rod of length `l` and inertia `I` about its centre, whose angle is
`θ₁`, carrying a bob of mass `m`; gravity `g`. Parameters named like Rust keywords (`type`),
like the mechanism's methods (`energy`, `new`), like the generated code's own names (`s`, `q`,
`qd`, `T`, `S`, `k0`), and a long one, all become valid Rust.

> A line that Markdown would read as a quote, and a list:

- 1. numbered, # not a heading, | not a table |
+ another, 2) and 3. and ``` a fence"""

from sympy import Function, cos, sin, symbols

t = symbols("t", real=True)
M, m, k, c, l, I, g = symbols("M m k c l I g")
typ, energy, new, s_, q_, qd_, T_, S_, k0 = symbols("type energy new s q qd T S k0")
long_name = symbols("the_length_of_the_spring_when_it_is_relaxed_measured_from_the_wall")
name = "OddNames"
params = {
    M: (2.0, "positive", "cart mass, kg"),
    m: (0.5, "positive", "bob mass, kg"),
    k: (20.0, "positive"),
    c: (0.1, "non_negative", "damping, N s/m: the force is -c v, > 0 against the motion"),
    l: (0.8, "positive", "rod length, m"),
    I: (0.01, "non_negative", "the rod's inertia about its centre, kg m^2"),
    g: (9.81, "non_negative"),
    typ: (1.0, "positive", "a factor on the spring: a name that is a Rust keyword"),
    energy: (0.0, "finite", "a constant added to V: a name that is a method of the mechanism"),
    new: (1.0, "positive", "a factor on gravity: a name that is the constructor's"),
    s_: (0.0, "finite", "a constant force on the cart, N"),
    q_: (1.0, "positive", "a factor on the bob's mass"),
    qd_: (0.0, "non_negative", "a damping of the rod, N m s/rad"),
    T_: (1.0, "positive", "a factor on the cart's mass"),
    S_: (0.0, "finite", "a constant torque on the rod, N m"),
    k0: (1.0, "positive", "a factor on the rod's inertia"),
    long_name: (0.3, "finite", "where the spring is relaxed, m"),
}

x = Function("x")(t)
th = Function("θ₁")(t)
q = [x, th]

bob_x, bob_y = x + l * sin(th), -l * cos(th)
T = (
    T_ * M * x.diff(t) ** 2 / 2
    + q_ * m * (bob_x.diff(t) ** 2 + bob_y.diff(t) ** 2) / 2
    + k0 * I * th.diff(t) ** 2 / 2
)
V = typ * k * (x - long_name) ** 2 / 2 + new * q_ * m * g * bob_y + energy
Q = [-c * x.diff(t) + s_, -qd_ * th.diff(t) + S_]
ranges = {x: (-1.0, 1.0)}
