"""The origin's workflow, derive symbolically: from a spec (T, V, Q, phi written with SymPy)
derive the Euler-Lagrange equations and print a no_std Rust mechanism on stdout.

Run by `cargo xtask derive SPEC.py [--out FILE.rs] [--name TypeName] [--tests]`, which makes
the virtual environment with the pinned SymPy, formats the output with rustfmt and writes the
file only when everything succeeded. By hand:

    python derive.py SPEC.py --source LABEL [--name TypeName] [--tests] [--command TEXT]

## The spec

A Python file that defines, at module level:

- `params`: a dict from each parameter's SymPy symbol to its default, or to a tuple
  `(default, kind)` or `(default, kind, "description, unit")`; `kind` is `"positive"` (masses,
  lengths, stiffnesses), `"non_negative"` (gravity, damping) or `"finite"` (the default).
  The dict's order is the constructor's argument order. Names must be snake_case.
- `q`: the coordinates, a list of `dynamicsymbols("name")` (or `Function("name")(t)`).
- `T`: the kinetic energy, in the coordinates, their first time derivatives and the
  parameters; quadratic in the velocities (`q'^T M(q) q' / 2 + b(q)^T q' + T0(q)`).
- `V`: the potential energy, in the coordinates (and time, for a driven mechanism).
- `Q` (optional): the generalized non-conservative forces, a list of `len(q)` expressions.
- `phi` (optional): holonomic constraint rows `phi(q) = 0`, a list of expressions in `q`.
- `name` (optional): the Rust type's name (else `--name`, else the file name in CamelCase).
- `doc` (optional): what the mechanism is (else the module's docstring).
- `ranges` (optional): a dict from coordinates to `(low, high)`, where the generated test
  draws its random states and the mass-matrix check samples (default `(-3, 3)`).
- `simplify` (optional, default `True`): `trigsimp` T and V before deriving (seconds for a
  few links, minutes for long chains).

Supported in the expressions: `+ - * /`, integer and half-integer powers, `sqrt`, `sin`,
`cos`, `tan`, `exp`, `log`, `atan2`, `pi`. Everything else is refused with a message.

## What it derives

```text
M = d2T/dq'dq'                                    the mass matrix (not solved symbolically)
f = dL/dq - (d2L/dq'dq) q' - d2L/dq'dt            L = T - V, so that M q'' = f + Q
J = dphi/dq,  J'q' = d/dq (J q') q'               where phi is given
```

Each entry is expanded and its terms grouped by their state-dependent part, so that every
product of parameters becomes one constant formed once by the constructor; then common
subexpressions are eliminated (`sympy.cse`), and sines and cosines of one argument share one
`sin_cos`. Everything is deterministic: the same spec and SymPy version give the same bytes.

Bad input (a syntax error, an unknown symbol, a T not quadratic in the velocities, a singular
mass matrix, an unsupported function, ...) prints one message on stderr and exits with 1.
"""

import argparse
import keyword
import random
import re
import sys
import traceback

import mpmath
import sympy as sp
from sympy.core.function import AppliedUndef

# --------------------------------------------------------------------------------------------
# Errors


class SpecError(Exception):
    """Bad input: the message names the problem."""


SUPPORTED = (
    "supported are + - * /, integer and half-integer powers, sqrt, sin, cos, tan, exp, log, "
    "atan2 and pi"
)

KINDS = {
    "positive": ("positive", "> 0"),
    "non_negative": ("non_negative", ">= 0"),
    "finite": ("finite", "finite"),
}

RUST_KEYWORDS = set(
    "as async await break const continue crate dyn else enum extern false fn for if impl in "
    "let loop match mod move mut pub ref return self static struct super trait true type "
    "unsafe use where while abstract become box do final macro override priv typeof unsized "
    "virtual yield try gen Self".split()
)

# Names the generated code uses itself: locals beside the coordinates, and the methods a
# parameter's accessor would shadow.
RESERVED_LOCALS = {"s", "t", "q", "qd"}
RESERVED_LOCAL_PATTERN = re.compile(r"^(e\d+|m\d+_\d+|sin\d*|cos\d*|sin_.*|cos_.*)$")
RESERVED_METHODS = {
    "new", "default", "from_valid", "equations", "kinetic", "potential", "energy",
    "kinetic_energy", "potential_energy", "non_conservative_force", "mass_matrix", "rhs",
    "solve_mass", "law", "law_jacobian", "law_force", "acceleration", "acceleration_with",
    "acceleration_jacobian", "velocity_jump", "with_force", "held_by", "position_residual",
    "jacobian", "velocity_product", "residual", "check_state", "phi", "clone", "eq", "fmt",
}
RESERVED_FIELD_PATTERN = re.compile(r"^k\d+$")
SNAKE = re.compile(r"^[a-z][a-z0-9_]*$")


def check_name(name, what):
    """A parameter's or coordinate's name as a Rust identifier that clashes with nothing."""
    if not SNAKE.match(name) or name in RUST_KEYWORDS or keyword.iskeyword(name):
        raise SpecError(
            f"{what} `{name}` is not a Rust variable name: use snake_case letters, digits "
            f"and `_` (e.g. symbols('m_cart'))"
        )
    if what == "coordinate":
        clash = name in RESERVED_LOCALS or RESERVED_LOCAL_PATTERN.match(name)
    else:
        clash = name in RESERVED_METHODS or RESERVED_FIELD_PATTERN.match(name)
    if clash:
        raise SpecError(
            f"{what} `{name}` clashes with a name the generated code uses; rename it"
        )


def load_spec(path):
    """Runs the spec file and returns its module namespace."""
    try:
        with open(path, encoding="utf-8") as f:
            source = f.read()
    except OSError as e:
        raise SpecError(f"cannot read {path}: {e.strerror}") from None
    try:
        code = compile(source, path, "exec")
    except SyntaxError as e:
        text = (e.text or "").rstrip()
        caret = " " * max((e.offset or 1) - 1, 0) + "^"
        raise SpecError(
            f"{path}:{e.lineno}:{e.offset}: syntax error: {e.msg}\n    {text}\n    {caret}"
        ) from None
    namespace = {"__name__": "__spec__", "__file__": path}
    try:
        exec(code, namespace)  # noqa: S102 - running the user's spec is the point
    except Exception as e:  # noqa: BLE001 - any failure of the spec is reported, not raised
        frames = [f for f in traceback.extract_tb(e.__traceback__) if f.filename == path]
        where = f"{path}:{frames[-1].lineno}" if frames else path
        hint = ""
        if isinstance(e, NameError):
            hint = (
                " (an unknown symbol: make it with symbols(...) and list it in params, or "
                "with dynamicsymbols(...) and list it in q)"
            )
        raise SpecError(f"{where}: {type(e).__name__}: {e}{hint}") from None
    return namespace


def camel_case(stem):
    return "".join(part[:1].upper() + part[1:] for part in re.split(r"[_\-\s]+", stem) if part)


class Spec:
    """The spec, read and checked: coordinates as plain symbols, energies, forces, rows."""

    def __init__(self, path, name_override):
        ns = load_spec(path)
        self.path = path
        stem = re.sub(r"\.py$", "", path.replace("\\", "/").split("/")[-1])
        self.name = name_override or ns.get("name") or camel_case(stem)
        if not isinstance(self.name, str) or not re.match(r"^[A-Z][A-Za-z0-9]*$", self.name):
            raise SpecError(f"type name `{self.name}` is not a Rust type name in CamelCase")
        doc = ns.get("doc") or ns.get("__doc__") or f"The mechanism of `{stem}.py`."
        # Paragraphs kept, each paragraph's lines joined (the output wraps them again).
        self.doc = [" ".join(p.split()) for p in re.split(r"\n\s*\n", str(doc)) if p.strip()]
        self.simplify = bool(ns.get("simplify", True))
        for required in ("params", "q", "T", "V"):
            if required not in ns:
                raise SpecError(f"{path}: the spec defines no `{required}`")
        self.read_coordinates(ns["q"])
        self.read_params(ns["params"])
        self.read_ranges(ns.get("ranges", {}))
        self.t_name = "t"
        # The expressions as written, for the docs, and in plain symbols.
        self.T_written = self.sympify(ns["T"], "T")
        self.V_written = self.sympify(ns["V"], "V")
        self.T = self.plain(self.T_written, "T")
        self.V = self.plain(self.V_written, "V", velocities=False)
        self.Q_written = None
        self.Q = None
        if ns.get("Q") is sp.Q:
            del ns["Q"]  # SymPy's assumptions object, from `from sympy import *`: no forces
        if ns.get("Q") is not None:
            rows = self.as_list(ns["Q"], "Q")
            if len(rows) != self.n:
                raise SpecError(
                    f"Q has {len(rows)} entries but there are {self.n} coordinates: one "
                    f"generalized force per coordinate"
                )
            self.Q_written = [self.sympify(e, f"Q[{i}]") for i, e in enumerate(rows)]
            self.Q = [self.plain(e, f"Q[{i}]") for i, e in enumerate(self.Q_written)]
        self.phi_written = None
        self.phi = None
        if ns.get("phi") is not None:
            rows = self.as_list(ns["phi"], "phi")
            if not rows:
                raise SpecError("phi is empty: give at least one constraint row, or no phi")
            self.phi_written = [self.sympify(e, f"phi[{i}]") for i, e in enumerate(rows)]
            self.phi = [
                self.plain(e, f"phi[{i}]", velocities=False, time=False)
                for i, e in enumerate(self.phi_written)
            ]

    # -- pieces --

    @staticmethod
    def as_list(value, what):
        if isinstance(value, (list, tuple)):
            return list(value)
        if isinstance(value, sp.MatrixBase):
            return list(value)
        raise SpecError(f"{what} must be a list of expressions, not {type(value).__name__}")

    @staticmethod
    def sympify(value, what):
        try:
            return sp.sympify(value, strict=True)
        except (sp.SympifyError, TypeError):
            raise SpecError(
                f"{what} is not a SymPy expression ({type(value).__name__}: {value!r})"
            ) from None

    def read_coordinates(self, q):
        q = self.as_list(q, "q") if not isinstance(q, sp.Basic) else [q]
        if not q:
            raise SpecError("q is empty: list the generalized coordinates")
        self.time = None
        self.q_functions = []
        for c in q:
            if isinstance(c, sp.Symbol):
                raise SpecError(
                    f"q lists `{c}`, a plain symbol: a coordinate is a function of time, "
                    f"{c} = dynamicsymbols('{c}')"
                )
            if not isinstance(c, AppliedUndef) or len(c.args) != 1 or not c.args[0].is_Symbol:
                raise SpecError(
                    f"q lists `{c}`, which is not a coordinate: use dynamicsymbols('name') or "
                    f"Function('name')(t)"
                )
            if self.time is None:
                self.time = c.args[0]
            elif c.args[0] != self.time:
                raise SpecError(f"coordinate `{c}` is a function of another time variable")
            if c in self.q_functions:
                raise SpecError(f"q lists `{c}` twice")
            self.q_functions.append(c)
        self.n = len(q)
        self.q_names = [type(c).__name__ for c in self.q_functions]
        for name in self.q_names:
            check_name(name, "coordinate")
        for name in self.q_names:
            if name.endswith("_d") and name[:-2] in self.q_names:
                raise SpecError(
                    f"coordinate `{name}` has the name the velocity of `{name[:-2]}` gets"
                )
        self.qs = [sp.Symbol(name) for name in self.q_names]
        self.qds = [sp.Symbol(name + "_d") for name in self.q_names]
        self.t = sp.Symbol("t")
        self.state_symbols = set(self.qs) | set(self.qds) | {self.t}

    def read_params(self, params):
        if not isinstance(params, dict) or not params:
            raise SpecError(
                "params must be a non-empty dict {symbol: default} or "
                "{symbol: (default, kind, description)}"
            )
        self.params = []  # (symbol, default, kind, description)
        for sym, spec in params.items():
            if not isinstance(sym, sp.Symbol):
                raise SpecError(f"params key `{sym}` is not a symbol: make it with symbols(...)")
            check_name(sym.name, "parameter")
            if sym.name == "t" or sym == self.time:
                raise SpecError(f"parameter `{sym.name}` has the name of the time")
            if sym.name in self.q_names or sym.name in {d.name for d in self.qds}:
                raise SpecError(
                    f"parameter `{sym.name}` has the name of a coordinate or of a velocity"
                )
            if isinstance(spec, tuple):
                if not 1 <= len(spec) <= 3:
                    raise SpecError(f"params[{sym}] must be (default, kind, description)")
                default = spec[0]
                kind = spec[1] if len(spec) > 1 else "finite"
                description = spec[2] if len(spec) > 2 else None
            else:
                default, kind, description = spec, "finite", None
            if kind not in KINDS:
                raise SpecError(
                    f"params[{sym}]: kind `{kind}` is none of {', '.join(KINDS)}"
                )
            try:
                default = float(default)
            except (TypeError, ValueError):
                raise SpecError(f"params[{sym}]: default `{default}` is not a number") from None
            ok = {
                "positive": default > 0 and mpmath.isfinite(default),
                "non_negative": default >= 0 and mpmath.isfinite(default),
                "finite": mpmath.isfinite(default),
            }[kind]
            if not ok:
                raise SpecError(
                    f"params[{sym}]: the default {default!r} is not {KINDS[kind][1]} ({kind})"
                )
            self.params.append((sym, default, kind, description))
        self.param_symbols = [p[0] for p in self.params]

    def read_ranges(self, ranges):
        self.ranges = [(-3.0, 3.0)] * self.n
        if not isinstance(ranges, dict):
            raise SpecError("ranges must be a dict {coordinate: (low, high)}")
        for c, r in ranges.items():
            if c not in self.q_functions:
                raise SpecError(f"ranges names `{c}`, which is not in q")
            try:
                low, high = float(r[0]), float(r[1])
            except (TypeError, ValueError, IndexError):
                raise SpecError(f"ranges[{c}] must be (low, high)") from None
            if not low < high:
                raise SpecError(f"ranges[{c}] = {r}: low must be below high")
            self.ranges[self.q_functions.index(c)] = (low, high)

    def plain(self, expr, what, velocities=True, time=True):
        """`expr` in plain symbols: q_i(t) -> q_i, q_i'(t) -> q_i_d, the time -> t."""
        derivatives = {sp.Derivative(c, self.time): d for c, d in zip(self.q_functions, self.qds)}
        out = expr.xreplace(derivatives)
        for d in sorted(out.atoms(sp.Derivative), key=sp.default_sort_key):
            f = d.expr
            if f in self.q_functions:
                raise SpecError(
                    f"{what} uses {sp.sstr(d)}: only the coordinates and their first time "
                    f"derivatives may appear"
                )
            if isinstance(f, AppliedUndef) and f.args == (self.time,):
                raise SpecError(
                    f"{what} uses the velocity of {f}, a function of time that is not listed "
                    f"in q (an unknown coordinate)"
                )
            raise SpecError(f"{what} uses the derivative {sp.sstr(d)}: {SUPPORTED}")
        out = out.xreplace(dict(zip(self.q_functions, self.qs)))
        for f in sorted(out.atoms(AppliedUndef), key=sp.default_sort_key):
            if f.args == (self.time,):
                raise SpecError(
                    f"{what} uses {f}, a function of time that is not listed in q (an unknown "
                    f"coordinate)"
                )
            raise SpecError(
                f"{what} uses the unknown function {type(f).__name__}: {SUPPORTED}"
            )
        out = out.xreplace({self.time: self.t}) if self.time != self.t else out
        allowed = set(self.param_symbols) | set(self.qs)
        if velocities:
            allowed |= set(self.qds)
        if time:
            allowed.add(self.t)
        for sym in sorted(out.free_symbols - allowed, key=lambda s: s.name):
            if sym in self.qds:
                why = (
                    "the rows are holonomic, phi(q) = 0"
                    if what.startswith("phi")
                    else "velocity-dependent terms belong in T or Q"
                )
                raise SpecError(
                    f"{what} depends on the velocity {sym.name[:-2]}': it may depend on the "
                    f"coordinates only ({why})"
                )
            if sym == self.t:
                raise SpecError(f"{what} depends on time t: constraint rows must not")
            raise SpecError(
                f"{what} uses the unknown symbol `{sym}`: it is neither a parameter (params), "
                f"a coordinate (q) nor the time"
            )
        check_supported(out, what)
        return out


def check_supported(expr, what):
    """Refuses any node the generated code cannot evaluate through the scalar traits."""
    if expr.is_Symbol or expr.is_Integer or expr.is_Rational or expr.is_Float:
        return
    if expr in (sp.pi, sp.E):
        return
    if isinstance(expr, (sp.Add, sp.Mul)):
        for a in expr.args:
            check_supported(a, what)
        return
    if isinstance(expr, sp.Pow):
        e = expr.exp
        if not (e.is_Integer or (e.is_Rational and e.q == 2)):
            raise SpecError(
                f"{what} uses the power {sp.sstr(expr)}: only integer and half-integer "
                f"exponents are supported"
            )
        check_supported(expr.base, what)
        return
    if isinstance(expr, (sp.sin, sp.cos, sp.tan, sp.exp, sp.log, sp.atan2)):
        for a in expr.args:
            check_supported(a, what)
        return
    if expr.is_Number or expr.is_NumberSymbol or expr is sp.I:
        raise SpecError(f"{what} uses the number {sp.sstr(expr)}, which is not real or supported")
    name = getattr(expr.func, "__name__", str(expr.func))
    raise SpecError(
        f"{what} uses the unsupported function {name} (in {sp.sstr(expr)}): {SUPPORTED}"
    )


# --------------------------------------------------------------------------------------------
# The derivation


class Derivation:
    """M, f, Q, J, J'q' and the energies, each entry a sum of constants times state terms."""

    def __init__(self, spec):
        self.spec = spec
        s = spec
        n = s.n
        T, V = s.T, s.V
        if s.simplify:
            T = sp.trigsimp(sp.expand(T))
            V = sp.trigsimp(sp.expand(V))
        check_quadratic(T, s.qds, s.q_names)
        L = T - V
        self.M = sp.Matrix(n, n, lambda i, j: sp.diff(T, s.qds[i], s.qds[j]))
        f = []
        for i in range(n):
            dl = sp.diff(L, s.qds[i])
            fi = sp.diff(L, s.qs[i]) - sum(sp.diff(dl, s.qs[j]) * s.qds[j] for j in range(n))
            fi -= sp.diff(dl, s.t)
            f.append(fi)
        self.f = [self.group(e) for e in f]
        self.M = self.M.applyfunc(self.group)
        self.T = self.group(T)
        self.V = self.group(V)
        self.Q = [self.group(e) for e in s.Q] if s.Q is not None else None
        for what, e in [("M", x) for x in self.M] + [("f", x) for x in self.f]:
            check_supported(e, what)
        self.explicit_time = s.t in T.free_symbols
        self.driven = self.explicit_time or s.t in V.free_symbols or (
            self.Q is not None and any(s.t in e.free_symbols for e in self.Q)
        )
        self.fixed_mass = all(not (e.free_symbols & s.state_symbols) for e in self.M)
        # The library's CONSTANT_MASS means more than a constant M: T must not depend on q or
        # t at all (the automatic path then takes f = -dV/dq and never differentiates T).
        self.constant_mass = not (T.free_symbols & (set(s.qs) | {s.t}))
        check_mass_matrix(self.M, s)
        if s.phi is not None:
            qv = sp.Matrix(s.qs)
            qdv = sp.Matrix(s.qds)
            phi = sp.Matrix(s.phi)
            J = phi.jacobian(qv)
            jqd = (J * qdv).jacobian(qv) * qdv
            self.phi = [self.group(e) for e in phi]
            self.J = J.applyfunc(self.group)
            self.Jqd = [self.group(e) for e in jqd]
            for what, e in [("J", x) for x in self.J] + [("J'q'", x) for x in self.Jqd]:
                check_supported(e, what)
        else:
            self.phi = self.J = self.Jqd = None

    def group(self, expr):
        """`expr` expanded, its terms grouped by their state-dependent factor: a sum of
        (product of parameters) x (state term), the form hoisting turns into constants."""
        expr = sp.expand(expr)
        terms = {}
        for term in sp.Add.make_args(expr):
            const, var = term.as_independent(*sorted(self.spec.state_symbols, key=str), as_Add=False)
            terms[var] = terms.get(var, 0) + const
        return sp.Add(*[sp.factor_terms(c) * v for v, c in terms.items()])


def check_quadratic(T, qds, names):
    """T must be a polynomial of degree at most 2 in the velocities."""
    if not T.free_symbols & set(qds):
        raise SpecError(
            "T does not depend on any velocity: the mass matrix d2T/dq'2 would be zero "
            "(singular)"
        )
    for qd, name in zip(qds, names):
        if not T.is_polynomial(qd):
            raise SpecError(
                f"T is not quadratic in the velocities: it is not a polynomial in {name}' "
                f"(T must be q'^T M(q) q' / 2 + b(q)^T q' + T0(q))"
            )
    degree = sp.Poly(T, *qds).total_degree()
    if degree > 2:
        raise SpecError(
            f"T is not quadratic in the velocities: it has degree {degree} in them "
            f"(T must be q'^T M(q) q' / 2 + b(q)^T q' + T0(q))"
        )


def check_mass_matrix(M, spec):
    """M must be positive definite somewhere: refused when singular or indefinite at every one
    of a few configurations drawn (deterministically) from the ranges, parameters at their
    defaults."""
    symbols = list(spec.qs) + list(spec.qds) + [spec.t] + list(spec.param_symbols)
    evaluate = sp.lambdify(symbols, M, modules="mpmath")
    rng = random.Random(16)
    mpmath.mp.dps = 30
    failures = []
    for _ in range(8):
        q = [rng.uniform(lo, hi) for lo, hi in spec.ranges]
        qd = [rng.uniform(-1.0, 1.0) for _ in spec.qds]
        args = q + qd + [rng.uniform(0.0, 10.0)] + [p[1] for p in spec.params]
        try:
            m = mpmath.matrix(evaluate(*args))
            if any(not isinstance(x, mpmath.mpf) or not mpmath.isfinite(x) for x in m):
                failures.append(("not finite", q, None))
                continue
            eig, vectors = mpmath.eigsy(m)
        except (ZeroDivisionError, ValueError, TypeError):
            failures.append(("not finite", q, None))
            continue
        values = [eig[i] for i in range(spec.n)]
        largest = max(abs(v) for v in values)
        smallest = min(range(spec.n), key=lambda i: values[i])
        if values[smallest] > largest * mpmath.mpf("1e-12"):
            return
        null = [vectors[i, smallest] for i in range(spec.n)]
        kind = "singular" if abs(values[smallest]) <= largest * mpmath.mpf("1e-12") else (
            "not positive definite"
        )
        failures.append((kind, q, null))
    kind, q, null = next((f for f in failures if f[2] is not None), failures[0])
    if null is None:
        raise SpecError(
            "the mass matrix d2T/dq'2 is not finite at any sampled configuration "
            "(see `ranges`)"
        )
    scale = max(abs(x) for x in null)
    combo = ""
    for x, name in zip(null, spec.q_names):
        c = float(x / scale)
        if abs(c) <= 1e-6:
            continue
        sign = "-" if c < 0 else "+"
        size = "" if abs(abs(c) - 1) < 1e-9 else f"{abs(c):.3g} "
        combo += f" {sign} {size}{name}'" if combo else f"{'-' if c < 0 else ''}{size}{name}'"
    if kind == "singular":
        raise SpecError(
            f"the mass matrix d2T/dq'2 is singular at every sampled configuration: T gives no "
            f"inertia to the velocity combination {combo} (does every coordinate's velocity "
            f"appear in T?)"
        )
    raise SpecError(
        f"the mass matrix d2T/dq'2 is not positive definite at any sampled configuration: "
        f"T < 0 along the velocity combination {combo}"
    )


# --------------------------------------------------------------------------------------------
# Hoisting: products of parameters become constants formed once


class Constants:
    """The parameter-only subexpressions, each a constant `k<i>` formed by the constructor."""

    def __init__(self, params):
        self.params = set(params)
        self.table = {}  # expression -> symbol
        self.order = []  # (symbol, expression)

    def is_constant(self, e):
        return not (e.free_symbols - self.params)

    @staticmethod
    def worth(c):
        if c.is_Number or c.is_Symbol:
            return False
        # -m is as cheap as m; anything else saves work per evaluation.
        return not (c.is_Mul and len(c.args) == 2 and c.args[0] == -1 and c.args[1].is_Symbol)

    def symbol(self, c):
        """`c` as a constant symbol, its sign kept outside."""
        if c.could_extract_minus_sign():
            return -self.symbol(-c)
        if not self.worth(c):
            return c
        if c not in self.table:
            k = sp.Symbol(f"k{len(self.order)}")
            self.table[c] = k
            self.order.append((k, c))
        return self.table[c]

    def hoist(self, e):
        if e.is_Atom:
            return e
        if self.is_constant(e):
            return self.symbol(e)
        if isinstance(e, (sp.Add, sp.Mul)):
            const = [a for a in e.args if self.is_constant(a)]
            rest = [self.hoist(a) for a in e.args if not self.is_constant(a)]
            if len(const) > 1 or (const and self.worth(const[0])):
                c = self.symbol(e.func(*const))
                return e.func(c, *rest)
            return e.func(*const, *rest)
        return e.func(*[self.hoist(a) for a in e.args])


# --------------------------------------------------------------------------------------------
# Emitting Rust: typed, so that scalar-generic code multiplies a scalar by a real on its right

ATOM, NEG, MUL, ADD = 4, 3, 2, 1


def float_literal(x):
    r = repr(float(x))
    if "inf" in r or "nan" in r:
        raise SpecError(f"the number {x} is not finite")
    if "." not in r and "e" not in r:
        r += ".0"
    return r


class Emitter:
    """Rust code for SymPy expressions. `generic`: scalar-generic (state symbols are `S`,
    parameters and constants `T`); else everything is `T`."""

    def __init__(self, generic, names):
        self.generic = generic
        self.kinds = {}  # symbol -> "S" | "T"
        self.names = names  # symbol -> Rust code

    def real_literal(self, x):
        x = sp.nsimplify(x) if x.is_Float and float(x).is_integer() else x
        if x == 0:
            return "T::zero()"
        if x == 1:
            return "T::one()"
        if x == 2:
            return "T::TWO"
        if x == sp.Rational(1, 2):
            return "T::HALF"
        return f"T::from_f64({float_literal(x)})"

    def lift(self, code, prec, kind):
        """`code` as an `S` when generic."""
        if self.generic and kind != "S":
            return f"S::from_real({code})", ATOM
        return code, prec

    @staticmethod
    def paren(code, prec, at_least):
        return code if prec >= at_least else f"({code})"

    def emit(self, e):
        """(code, precedence, kind) with kind "S" (state-dependent, generic only) or "T"."""
        if e.is_Symbol:
            return self.names[e], ATOM, self.kinds.get(e, "T")
        if e.is_Number:
            if e < 0:
                code, _, _ = self.emit(-e)
                return f"-{code}", NEG, "T"
            return self.real_literal(e), ATOM, "T"
        if e == sp.pi:
            return "T::PI", ATOM, "T"
        if e == sp.E:
            return "T::one().exp()", ATOM, "T"
        if isinstance(e, sp.Add):
            return self.emit_add(e)
        if isinstance(e, sp.Mul):
            return self.emit_mul(e)
        if isinstance(e, sp.Pow):
            return self.emit_pow(e)
        method = {sp.tan: "tan", sp.exp: "exp", sp.log: "ln", sp.sin: "sin", sp.cos: "cos"}
        for cls, name in method.items():
            if isinstance(e, cls):
                code, prec, kind = self.emit(e.args[0])
                return f"{self.paren(code, prec, ATOM)}.{name}()", ATOM, kind
        if isinstance(e, sp.atan2):
            (y, py, ky), (x, px, kx) = self.emit(e.args[0]), self.emit(e.args[1])
            kind = "S" if "S" in (ky, kx) else "T"
            if kind == "S":
                y, py = self.lift(y, py, ky)
                x, px = self.lift(x, px, kx)
            return f"{self.paren(y, py, ATOM)}.atan2({x})", ATOM, kind
        raise SpecError(f"cannot emit {sp.sstr(e)}: {SUPPORTED}")

    def emit_add(self, e):
        terms = []
        for a in sp.Add.make_args(e):
            negative = a.could_extract_minus_sign()
            code, prec, kind = self.emit(-a if negative else a)
            terms.append((kind != "S", a.is_Number, negative, code, prec, kind))
        # Scalars first (an S may be added a T on its right, not the other way), then reals,
        # then numbers; stable otherwise.
        terms.sort(key=lambda x: (x[0], x[1]))
        kind = "S" if any(t[5] == "S" for t in terms) else "T"
        out = ""
        for i, (_, _, negative, code, prec, _) in enumerate(terms):
            if i == 0:
                out = f"-{self.paren(code, prec, MUL)}" if negative else code
                if negative and len(terms) == 1:
                    return out, NEG, kind
            else:
                out += f" - {self.paren(code, prec, MUL)}" if negative else f" + {self.paren(code, prec, MUL)}"
        return out, ADD, kind

    def emit_factor_product(self, factors):
        """Codes of the factors, scalars first: (code, prec, kind) or None when empty."""
        items = []
        for f in factors:
            code, prec, kind = self.emit(f)
            items.append((kind != "S", f.is_Number, code, prec, kind))
        items.sort(key=lambda x: (x[0], x[1]))
        if not items:
            return None
        if len(items) == 1:
            return items[0][2], items[0][3], items[0][4]
        kind = "S" if any(i[4] == "S" for i in items) else "T"
        return " * ".join(self.paren(i[2], i[3], NEG) for i in items), MUL, kind

    def emit_mul(self, e):
        coeff, factors = e.as_coeff_mul()
        negative = coeff < 0
        coeff = abs(coeff)
        num, den = [], []
        for f in factors:
            base, ex = f.as_base_exp()
            if ex.is_Number and ex < 0:
                den.append(base ** (-ex))
            else:
                num.append(f)
        if coeff != 1:
            if coeff.is_Rational and coeff.p == 1 and coeff.q != 2:
                den.append(sp.Integer(coeff.q))
            else:
                num.append(coeff)
        top = self.emit_factor_product(num)
        bottom = self.emit_factor_product(den)
        if bottom is None:
            code, prec, kind = top
        else:
            if top is None:
                top = ("T::one()", ATOM, "T")
            code, prec, kind = top
            bcode, bprec, bkind = bottom
            if bkind == "S" and kind != "S":
                code, prec = self.lift(code, prec, kind)
                kind = "S"
            code = f"{self.paren(code, prec, MUL)} / {self.paren(bcode, bprec, ATOM)}"
            prec = MUL
        if negative:
            return f"-{self.paren(code, prec, MUL)}", (MUL if prec == MUL else NEG), kind
        return code, prec, kind

    def emit_pow(self, e):
        base, ex = e.base, e.exp
        code, prec, kind = self.emit(base)
        b = self.paren(code, prec, ATOM)
        if ex.is_Integer:
            n = int(ex)
            if n == -1:
                return f"{b}.recip()", ATOM, kind
            if prec == ATOM and not code.endswith(")") and n in (2, 3):
                return " * ".join([b] * n), MUL, kind
            return f"{b}.powi({n})", ATOM, kind
        # Half-integer: sqrt, then an integer power.
        k = int(ex * 2)
        root = f"{b}.sqrt()"
        if k == 1:
            return root, ATOM, kind
        if k == -1:
            return f"{root}.recip()", ATOM, kind
        return f"{root}.powi({k})", ATOM, kind


class Block:
    """A function body: common subexpressions of some outputs, with sines and cosines of one
    argument computed together, as `let` statements in dependency order."""

    def __init__(self, emitter, exprs, inputs):
        """`inputs`: symbol -> (Rust binding code, kind), bound only when used."""
        self.emitter = emitter
        self.lines = []
        # Sines and cosines, innermost first, become placeholder symbols.
        trig = {}  # argument -> [sin symbol, cos symbol, used sin, used cos]
        exprs = list(exprs)
        names = emitter.names

        def placeholders(e):
            if e.is_Atom:
                return e
            args = [placeholders(a) for a in e.args]
            if isinstance(e, (sp.sin, sp.cos)):
                arg = args[0]
                if arg not in trig:
                    if arg.is_Symbol:
                        stem = names.get(arg, arg.name)
                        stem = stem.replace("self.", "")
                        pair = (sp.Symbol(f"sin_{stem}"), sp.Symbol(f"cos_{stem}"))
                    else:
                        i = sum(1 for a in trig if not a.is_Symbol)
                        pair = (sp.Symbol(f"sin{i}"), sp.Symbol(f"cos{i}"))
                    trig[arg] = [pair[0], pair[1], False, False]
                entry = trig[arg]
                if isinstance(e, sp.sin):
                    entry[2] = True
                    return entry[0]
                entry[3] = True
                return entry[1]
            return e.func(*args)

        exprs = [placeholders(e) for e in exprs]
        trig_args = list(trig)
        replacements, reduced = sp.cse(
            exprs + trig_args, symbols=sp.numbered_symbols("e"), order="canonical"
        )
        outputs, reduced_args = reduced[: len(exprs)], reduced[len(exprs):]
        definitions = {}  # symbol -> ("let", expr) | ("trig", arg index)
        for sym, expr in replacements:
            definitions[sym] = ("let", expr)
        for i, arg in enumerate(trig_args):
            s_sym, c_sym, _, _ = trig[arg]
            definitions[s_sym] = ("trig", i)
            definitions[c_sym] = ("trig", i)
        emitted = set()
        self.used_inputs = set()

        def ensure(sym):
            if sym in emitted:
                return
            if sym in inputs:
                emitted.add(sym)
                self.used_inputs.add(sym)
                emitter.kinds[sym] = inputs[sym][1]
                return
            if sym not in definitions:
                emitted.add(sym)  # a parameter or constant: self.<name>
                return
            how, what = definitions[sym]
            if how == "let":
                for dep in sorted(what.free_symbols, key=sp.default_sort_key):
                    ensure(dep)
                code, prec, kind = emitter.emit(what)
                emitter.names[sym] = sym.name
                emitter.kinds[sym] = kind
                self.lines.append(f"let {sym.name} = {code};")
                emitted.add(sym)
                return
            arg = reduced_args[what]
            s_sym, c_sym, use_s, use_c = trig[trig_args[what]]
            for dep in sorted(arg.free_symbols, key=sp.default_sort_key):
                ensure(dep)
            code, prec, kind = emitter.emit(arg)
            x = emitter.paren(code, prec, ATOM)
            for sym2 in (s_sym, c_sym):
                emitter.names[sym2] = sym2.name
                emitter.kinds[sym2] = kind
                emitted.add(sym2)
            if use_s and use_c:
                self.lines.append(f"let ({s_sym.name}, {c_sym.name}) = {x}.sin_cos();")
            elif use_s:
                self.lines.append(f"let {s_sym.name} = {x}.sin();")
            else:
                self.lines.append(f"let {c_sym.name} = {x}.cos();")

        self.outputs = []
        for out in outputs:
            for dep in sorted(out.free_symbols, key=sp.default_sort_key):
                ensure(dep)
            self.outputs.append(emitter.emit(out))
        self.inputs = inputs

    def bindings(self):
        """The `let` lines binding the used inputs, in the inputs' order."""
        return [
            f"let {self.emitter.names[sym]} = {code};"
            for sym, (code, _) in self.inputs.items()
            if sym in self.used_inputs and self.emitter.names[sym] != code
        ]

    def body(self):
        return self.bindings() + self.lines

    def output(self, i, want):
        """Output `i` as a `want` ("S" or "T") expression."""
        code, prec, kind = self.outputs[i]
        if want == "S" and kind != "S":
            if code == "T::zero()":
                return "S::zero()"
            return f"S::from_real({code})"
        return code


# --------------------------------------------------------------------------------------------
# The Rust file


def doc_lines(text, prefix="/// "):
    out = []
    for line in text.splitlines():
        out.append((prefix + line).rstrip())
    return out


def capital(text):
    return text[:1].upper() + text[1:]


def wrap(text, width=96):
    words, lines, line = text.split(), [], ""
    for w in words:
        if line and len(line) + 1 + len(w) > width:
            lines.append(line)
            line = w
        else:
            line = f"{line} {w}" if line else w
    if line:
        lines.append(line)
    return "\n".join(lines)


class Generator:
    def __init__(self, spec, derivation, source, command, tests):
        self.s = spec
        self.d = derivation
        self.source = source
        self.command = command
        self.tests = tests
        self.consts = Constants(spec.param_symbols)
        self.out = []
        self.uses = set()

    # -- printing the formulas for the docs --

    def pretty(self, e):
        sub = {qd: sp.Symbol(name + "'") for qd, name in zip(self.s.qds, self.s.q_names)}
        return sp.sstr(e.xreplace(sub)).replace("**", "^")

    def written(self, e):
        """An expression as the spec wrote it, velocities as th'."""
        return self.pretty(self.s.plain(e, "doc"))

    # -- names --

    def names(self, generic):
        """Symbol -> Rust code for parameters, constants and state."""
        names = {p: f"self.{p.name}" for p in self.s.param_symbols}
        for k, _ in self.consts.order:
            names[k] = f"self.{k.name}"
        for sym in self.s.qs + self.s.qds:
            names[sym] = sym.name
        names[self.s.t] = "t"
        return names

    def state_inputs(self, generic, vectors=("s.q", "s.qd"), time="s.t"):
        kind = "S" if generic else "T"
        inputs = {}
        for i, sym in enumerate(self.s.qs):
            inputs[sym] = (f"{vectors[0]}[{i}]", kind)
        if vectors[1] is not None:
            for i, sym in enumerate(self.s.qds):
                inputs[sym] = (f"{vectors[1]}[{i}]", kind)
        if time is not None:
            inputs[self.s.t] = (time, kind)
        return inputs

    def block(self, exprs, generic, **kw):
        exprs = [self.consts.hoist(e) for e in exprs]
        emitter = Emitter(generic, self.names(generic))
        return Block(emitter, exprs, self.state_inputs(generic, **kw))

    # -- pieces of the file --

    def generate(self):
        s, d = self.s, self.d
        n = s.n
        # Everything is hoisted before the struct is written, so that it knows its constants.
        m_entries = [d.M[i, j] for i in range(n) for j in range(i, n)]
        forces = d.f if d.Q is None else [a + b for a, b in zip(d.f, d.Q)]
        blocks = {}
        blocks["mass"] = self.block(m_entries, False)
        blocks["rhs"] = self.block(d.f, False)
        if d.fixed_mass:
            # M^-1 (or its factor) is formed once by the constructor: the law needs f + Q.
            blocks["law"] = self.block(forces, False)
        else:
            blocks["law"] = self.block(m_entries + forces, False)
        self.m_entries = m_entries
        blocks["kinetic"] = self.block([d.T], True, vectors=("q", "qd"), time="t")
        blocks["potential"] = self.block([d.V], True, vectors=("q", None), time="t")
        if d.Q is not None:
            blocks["force"] = self.block(d.Q, False)
        if d.phi is not None:
            blocks["phi"] = self.block(d.phi, False, vectors=("q", None), time=None)
            blocks["phi_generic"] = self.block(d.phi, True, vectors=("q", None), time=None)
            blocks["jacobian"] = self.block(list(d.J), False, vectors=("q", None), time=None)
            blocks["jqd"] = self.block(d.Jqd, False, vectors=("q", "qd"), time=None)
        self.blocks = blocks
        self.header()
        self.struct()
        self.constructors()
        self.mechanism()
        self.lagrangian()
        if d.phi is not None:
            self.constraints()
        self.solver()
        if self.tests:
            self.test_module()
        return self.imports() + "\n".join(self.out) + "\n"

    def imports(self):
        core = sorted(self.uses, key=lambda x: (not x[0].islower(), x))
        na = sorted(self.uses_na)
        lines = []
        if self.d.phi is not None:
            lines.append("use lagrange_core::constraints::{Constraints, HolonomicConstraints};")
        lines.append(f"use lagrange_core::nalgebra::{{{', '.join(na)}}};")
        lines.append(f"use lagrange_core::{{{', '.join(core)}}};")
        return self.header_text + "\n".join(lines) + "\n\n"

    def header(self):
        s = self.s
        line1 = f"//! [`{s.name}`]: generated by `cargo xtask derive` from `{self.source}`."
        needs = "; its test module needs `lagrange-tests`" if self.tests else ""
        self.header_text = (
            f"{line1}\n//!\n"
            f"//! Do not edit: change the spec and regenerate this file (SymPy {sp.__version__}{needs}):\n"
            f"//!\n//! ```text\n//! {self.command}\n//! ```\n\n"
        )
        self.uses = {"Error", "Lagrangian", "Mechanism", "Real", "Scalar", "State", "validate"}
        self.uses.add("GeneralizedForce")
        self.uses_na = {"SMatrix", "SVector"}

    def formulas(self):
        s, d = self.s, self.d
        lines = []
        lines.append(f"q    = [{', '.join(s.q_names)}]")
        for name, written, derived in (("T", s.T_written, d.T), ("V", s.V_written, d.V)):
            text = self.written(written)
            lines.append(f"{name}    = {text}")
            if self.pretty(derived) != text:
                lines.append(f"     = {self.pretty(derived)}")
        if s.Q_written is not None:
            lines.append(f"Q    = [{', '.join(self.written(e) for e in s.Q_written)}]")
        if s.phi_written is not None:
            lines.append(
                f"phi  = [{', '.join(self.pretty(e) for e in s.phi)}] = 0"
            )
        lines.append("")
        lines.append("M q'' = f + Q" + (" + J^T lambda,   J q'' = -J'q'" if d.phi is not None else ""))
        m = [[self.pretty(d.M[i, j]) for j in range(s.n)] for i in range(s.n)]
        f = [self.pretty(e) for e in d.f]
        if sum(len(x) for row in m for x in row) + sum(len(x) for x in f) < 900:
            lines.append("M    = [" + "; ".join(", ".join(row) for row in m) + "]")
            lines.append(f"f    = [{', '.join(f)}]")
            if d.phi is not None:
                lines.append(
                    "J    = [" + "; ".join(", ".join(self.pretty(d.J[i, j]) for j in range(s.n)) for i in range(len(d.phi))) + "]"
                )
                lines.append(f"J'q' = [{', '.join(self.pretty(e) for e in d.Jqd)}]")
        else:
            lines.append("(M and f are long: see mass_matrix and rhs)")
        return lines

    def solve_text(self):
        n = self.s.n
        if self.d.fixed_mass:
            how = "its inverse" if n <= 2 else "its Cholesky factor"
            return f"`M` is constant: {how} formed once by the constructor"
        return "closed form" if n <= 2 else "Cholesky"

    def struct(self):
        s = self.s
        o = self.out
        for i, paragraph in enumerate(s.doc):
            if i:
                o.append("///")
            o.extend(doc_lines(wrap(paragraph)))
        o.append("///")
        o.append("/// ```text")
        o.extend(doc_lines("\n".join(self.formulas())))
        o.append("/// ```")
        o.append("///")
        params = ", ".join(
            f"`{p.name}` = {default!r}" for p, default, _, _ in s.params
        )
        o.extend(doc_lines(wrap(
            f"Derived by SymPy from `{self.source}` (`cargo xtask derive`): the mass matrix "
            f"and the rest of the Euler-Lagrange equations in closed form, the linear solve "
            f"numeric ({self.solve_text()}). Defaults ([`Default`]): "
            f"{params}."
        )))
        if self.d.phi is not None:
            o.append("///")
            o.extend(doc_lines(wrap(
                f"As a [`Mechanism`] this is the free mechanism; as [`Constraints`] it is "
                f"the rows `phi` ({len(self.d.phi)}). The constrained mechanism is "
                f"`Constrained::new({s.name}::default())` "
                f"([`Constrained`](lagrange_core::Constrained))."
            )))
        o.append("#[derive(Debug, Clone, Copy, PartialEq)]")
        o.append(f"pub struct {s.name}<T: Real> {{")
        for p, _, _, desc in s.params:
            o.append(f"    /// {capital(desc) if desc else 'Parameter `' + p.name + '`'}.")
            o.append(f"    {p.name}: T,")
        for k, expr in self.consts.order:
            o.append(f"    /// `{self.pretty(expr)}`.")
            o.append(f"    {k.name}: T,")
        n = s.n
        if self.d.fixed_mass and n <= 2:
            o.append("    /// `M^-1`, formed once (`M` is constant), or why `M` has none.")
            o.append(f"    inverse: Result<SMatrix<T, {n}, {n}>, Error>,")
        elif self.d.fixed_mass:
            self.uses.add("Cholesky")
            o.append("    /// The Cholesky factor of `M`, formed once (`M` is constant), or why `M` has none.")
            o.append(f"    factor: Result<Cholesky<T, {n}>, Error>,")
        o.append("}")
        o.append("")

    def constructors(self):
        s = self.s
        o = self.out
        args = ", ".join(f"{p.name}: T" for p in s.param_symbols)
        names = ", ".join(p.name for p in s.param_symbols)
        many = len(s.params) > 7
        o.append(f"impl<T: Real> {s.name}<T> {{")
        o.extend(doc_lines(wrap(
            "A mechanism of these parameters: "
            + ", ".join(
                f"`{p.name}` ({(desc + ', ') if desc else ''}{KINDS[kind][1]})"
                for p, _, kind, desc in s.params
            )
            + ".",
            92,
        ), "    /// "))
        o.append("    ///")
        o.append("    /// # Errors")
        o.append("    /// [`Error::InvalidParameter`] naming the first parameter out of range or not finite.")
        if many:
            o.append("    #[allow(clippy::too_many_arguments)]")
        o.append(f"    pub fn new({args}) -> Result<Self, Error> {{")
        o.append("        Ok(Self::from_valid(")
        for p, _, kind, _ in s.params:
            o.append(f'            validate::{KINDS[kind][0]}("{p.name}", {p.name})?,')
        o.append("        ))")
        o.append("    }")
        o.append("")
        o.append("    /// The mechanism of parameters already checked, its constants formed once.")
        if many:
            o.append("    #[allow(clippy::too_many_arguments)]")
        o.append(f"    fn from_valid({args}) -> Self {{")
        names_map = {p: p.name for p in s.param_symbols}
        emitter = Emitter(False, dict(names_map))
        for k, expr in self.consts.order:
            code, _, _ = emitter.emit(expr)
            o.append(f"        let {k.name} = {code};")
        fields = [names] + [k.name for k, _ in self.consts.order]
        if self.d.fixed_mass:
            # The constant M from the same constants the mass matrix returns.
            local = dict(names_map)
            local.update({k: k.name for k, _ in self.consts.order})
            mass = Block(Emitter(False, local), [self.consts.hoist(e) for e in self.m_entries], {})
            matrix = self.matrix_from_upper(mass, 0)
            for line in mass.lines:
                o.append(f"        {line}")
            o.append(f"        let mass = {matrix};")
            if s.n <= 2:
                fields.append("inverse: inverse(&mass)")
            else:
                fields.append("factor: Cholesky::factor(&mass)")
        o.append(f"        Self {{ {', '.join(fields)} }}")
        o.append("    }")
        for p, _, kind, desc in s.params:
            o.append("")
            o.append(f"    /// {capital(desc) if desc else 'Parameter `' + p.name + '`'}.")
            o.append("    #[must_use]")
            o.append(f"    pub fn {p.name}(&self) -> T {{")
            o.append(f"        self.{p.name}")
            o.append("    }")
        o.append("}")
        o.append("")
        emitter = Emitter(False, {})
        o.append(f"impl<T: Real> Default for {s.name}<T> {{")
        o.append("    /// The spec's defaults: " + ", ".join(f"`{p.name}` = {v!r}" for p, v, _, _ in s.params) + ".")
        o.append("    fn default() -> Self {")
        o.append("        Self::from_valid(")
        for p, v, _, _ in s.params:
            o.append(f"            {emitter.real_literal(sp.Float(v) if not float(v).is_integer() else sp.Integer(int(v)))},")
        o.append("        )")
        o.append("    }")
        o.append("}")
        o.append("")

    def fn(self, signature, block, result, doc=None, indent="    "):
        """A function: `{s}` in `signature` is the state's name, `_s` when unused."""
        o = self.out
        if doc:
            o.extend(doc_lines(doc, indent + "/// "))
        signature = signature.replace("{s}", "s" if block.used_inputs else "_s")
        o.append(f"{indent}{signature} {{")
        for line in block.body():
            o.append(f"{indent}    {line}")
        o.append(f"{indent}    {result}")
        o.append(f"{indent}}}")

    def vector(self, block, start, count, want="T"):
        entries = [block.output(start + i, want) for i in range(count)]
        return f"SVector::from([{', '.join(entries)}])"

    def matrix_from_upper(self, block, start):
        n = self.s.n
        index = {}
        k = start
        for i in range(n):
            for j in range(i, n):
                index[(i, j)] = index[(j, i)] = k
                k += 1
        # An off-diagonal entry is written twice: bound once when it is not a plain name.
        entry = {}
        for i in range(n):
            for j in range(i, n):
                code = block.output(index[(i, j)], "T")
                if i != j and block.outputs[index[(i, j)]][1] < ATOM:
                    block.lines.append(f"let m{i}_{j} = {code};")
                    code = f"m{i}_{j}"
                entry[(i, j)] = entry[(j, i)] = code
        # Column arrays: From<[[T; R]; C]>.
        columns = ["[" + ", ".join(entry[(i, j)] for i in range(n)) + "]" for j in range(n)]
        return f"SMatrix::from([{', '.join(columns)}])"

    def mechanism(self):
        s, d = self.s, self.d
        n = s.n
        b = self.blocks
        o = self.out
        o.append(f"impl<T: Real> {s.name}<T> {{")
        if d.fixed_mass:
            self.fn(
                f"fn forces(&self, {{s}}: &State<T, {n}>) -> SVector<T, {n}>",
                b["law"],
                self.vector(b["law"], 0, n),
                doc="`f + Q`: what the law needs besides the constant `M^-1`.",
            )
        else:
            self.fn(
                f"fn equations(&self, {{s}}: &State<T, {n}>) -> (SMatrix<T, {n}, {n}>, SVector<T, {n}>)",
                b["law"],
                f"({self.matrix_from_upper(b['law'], 0)}, {self.vector(b['law'], n * (n + 1) // 2, n)})",
                doc="`M` and `f + Q`, their common subexpressions shared: what the law needs.",
            )
        o.append("}")
        o.append("")
        o.append(f"impl<T: Real> Mechanism<T, {n}> for {s.name}<T> {{")
        self.fn(
            f"fn mass_matrix(&self, {{s}}: &State<T, {n}>) -> SMatrix<T, {n}, {n}>",
            b["mass"],
            self.matrix_from_upper(b["mass"], 0),
        )
        o.append("")
        self.fn(
            f"fn rhs(&self, {{s}}: &State<T, {n}>) -> SVector<T, {n}>",
            b["rhs"],
            self.vector(b["rhs"], 0, n),
        )
        o.append("")
        if d.fixed_mass:
            apply = "finite(self.inverse? * b)" if n <= 2 else "finite(self.factor?.solve(b))"
            o.append("    /// With the constant `M`'s inverse (or factor) formed once; finite or an error.")
            o.append(f"    fn solve_mass(&self, _s: &State<T, {n}>, b: &SVector<T, {n}>) -> Result<SVector<T, {n}>, Error> {{")
            o.append(f"        {apply}")
            o.append("    }")
            o.append("")
            o.append("    /// `M^-1 (f + Q + extra)`, `M^-1` formed once.")
            o.append(f"    fn law<F: GeneralizedForce<T, {n}>>(&self, s: &State<T, {n}>, extra: &F) -> Result<SVector<T, {n}>, Error> {{")
            o.append("        self.solve_mass(s, &extra.added_to(s, self.forces(s)))")
            o.append("    }")
        else:
            o.append(f"    fn solve_mass(&self, s: &State<T, {n}>, b: &SVector<T, {n}>) -> Result<SVector<T, {n}>, Error> {{")
            o.append("        solve(&self.mass_matrix(s), b)")
            o.append("    }")
            o.append("")
            o.append("    /// `M^-1 (f + Q + extra)`, with `M` and `f + Q` formed together.")
            o.append(f"    fn law<F: GeneralizedForce<T, {n}>>(&self, s: &State<T, {n}>, extra: &F) -> Result<SVector<T, {n}>, Error> {{")
            o.append("        let (m, f) = self.equations(s);")
            o.append("        solve(&m, &extra.added_to(s, f))")
            o.append("    }")
        o.append("}")
        o.append("")

    def lagrangian(self):
        s, d = self.s, self.d
        n = s.n
        b = self.blocks
        o = self.out
        o.append(f"impl<T: Real> Lagrangian<T, {n}> for {s.name}<T> {{")
        if d.explicit_time:
            o.append("    const EXPLICIT_TIME: bool = true;")
        if d.constant_mass:
            o.append("    const CONSTANT_MASS: bool = true;")
        if d.driven and not d.explicit_time:
            o.append("    const DRIVEN: bool = true;")
        used = b["kinetic"].used_inputs
        t = "t" if s.t in used else "_t"
        qv = "q" if used & set(s.qs) else "_q"
        o.append("")
        self.fn(
            f"fn kinetic<S: Scalar<Real = T>>(&self, {t}: S, {qv}: &SVector<S, {n}>, qd: &SVector<S, {n}>) -> S",
            b["kinetic"],
            b["kinetic"].output(0, "S"),
        )
        o.append("")
        used = b["potential"].used_inputs
        t = "t" if s.t in used else "_t"
        qv = "q" if used & set(s.qs) else "_q"
        self.fn(
            f"fn potential<S: Scalar<Real = T>>(&self, {t}: S, {qv}: &SVector<S, {n}>) -> S",
            b["potential"],
            b["potential"].output(0, "S"),
        )
        if d.Q is not None:
            o.append("")
            self.fn(
                f"fn non_conservative_force(&self, {{s}}: &State<T, {n}>) -> SVector<T, {n}>",
                b["force"],
                self.vector(b["force"], 0, n),
            )
        o.append("}")
        o.append("")

    def constraints(self):
        s, d = self.s, self.d
        n, c = s.n, len(d.phi)
        b = self.blocks
        o = self.out
        o.append(f"impl<T: Real> Constraints<T, {n}, {c}> for {s.name}<T> {{")
        qv = "q" if b["phi"].used_inputs else "_q"
        self.fn(
            f"fn position_residual(&self, {qv}: &SVector<T, {n}>) -> SVector<T, {c}>",
            b["phi"],
            self.vector(b["phi"], 0, c),
        )
        o.append("")
        qv = "q" if b["jacobian"].used_inputs else "_q"
        columns = [
            "[" + ", ".join(b["jacobian"].output(i * n + j, "T") for i in range(c)) + "]"
            for j in range(n)
        ]
        self.fn(
            f"fn jacobian(&self, {qv}: &SVector<T, {n}>) -> SMatrix<T, {c}, {n}>",
            b["jacobian"],
            f"SMatrix::from([{', '.join(columns)}])",
        )
        o.append("")
        used = b["jqd"].used_inputs
        qv = "q" if used & set(s.qs) else "_q"
        qdv = "qd" if used & set(s.qds) else "_qd"
        self.fn(
            f"fn velocity_product(&self, {qv}: &SVector<T, {n}>, {qdv}: &SVector<T, {n}>) -> SVector<T, {c}>",
            b["jqd"],
            self.vector(b["jqd"], 0, c),
        )
        o.append("}")
        o.append("")
        o.append("/// The rows written generic over the scalar, for the automatic path (`Holonomic`).")
        o.append(f"impl<T: Real> HolonomicConstraints<T, {n}, {c}> for {s.name}<T> {{")
        qv = "q" if b["phi_generic"].used_inputs else "_q"
        self.fn(
            f"fn phi<S: Scalar<Real = T> + 'static>(&self, {qv}: &SVector<S, {n}>) -> SVector<S, {c}>",
            b["phi_generic"],
            self.vector(b["phi_generic"], 0, c, want="S"),
        )
        o.append("}")
        o.append("")

    def solver(self):
        n = self.s.n
        o = self.out
        # The finiteness rule of every function that returns a `Result` (issue 15): the solves,
        # and so the law, return `Ok` only with finite values. Parameters that are each valid
        # may still form products that overflow or underflow (a mass of 1e-308: an infinite
        # inverse), and a finite state may be extreme.
        o.extend([
            "/// `x` when every component is finite, else [`Error::NonFiniteState`]: the solves, and so",
            "/// the law, return `Ok` only with finite values, whatever the parameters' products and the",
            "/// state.",
            "fn finite<T: Real, const N: usize>(x: SVector<T, N>) -> Result<SVector<T, N>, Error> {",
            "    if x.iter().all(|v| v.is_finite()) {",
            "        Ok(x)",
            "    } else {",
            "        Err(Error::NonFiniteState)",
            "    }",
            "}",
            "",
        ])
        if self.d.fixed_mass and n >= 3:
            return  # the Cholesky factor of lagrange_core does it
        if self.d.fixed_mass:
            o.append("/// `m^-1`, column by column, or why there is none (as [`solve`] would refuse `m`).")
            o.append(f"fn inverse<T: Real>(m: &SMatrix<T, {n}, {n}>) -> Result<SMatrix<T, {n}, {n}>, Error> {{")
            if n == 1:
                o.append("    let c0 = solve(m, &SVector::from([T::one()]))?;")
                o.append("    Ok(SMatrix::from([[c0[0]]]))")
            else:
                o.append("    let c0 = solve(m, &SVector::from([T::one(), T::zero()]))?;")
                o.append("    let c1 = solve(m, &SVector::from([T::zero(), T::one()]))?;")
                o.append("    Ok(SMatrix::from([[c0[0], c0[1]], [c1[0], c1[1]]]))")
            o.append("}")
            o.append("")
        if n == 1:
            o.extend([
                "/// Solves `m x = b` (1x1), refusing a mass that is not positive as the Cholesky solve",
                "/// would.",
                "fn solve<T: Real>(m: &SMatrix<T, 1, 1>, b: &SVector<T, 1>) -> Result<SVector<T, 1>, Error> {",
                "    let d = m[(0, 0)];",
                "    if !d.is_finite() {",
                "        return Err(Error::NonFiniteState);",
                "    }",
                "    if d <= T::zero() {",
                "        return Err(Error::SingularMassMatrix { pivot: 0 });",
                "    }",
                "    finite(b / d)",
                "}",
            ])
        elif n == 2:
            o.extend([
                "/// Solves the symmetric 2x2 system `m x = b` by its closed-form inverse, refusing a mass",
                "/// matrix that is singular or not positive definite as the Cholesky solve would.",
                "fn solve<T: Real>(m: &SMatrix<T, 2, 2>, b: &SVector<T, 2>) -> Result<SVector<T, 2>, Error> {",
                "    let (a, c, d) = (m[(0, 0)], m[(1, 0)], m[(1, 1)]);",
                "    let det = a * d - c * c;",
                "    if !det.is_finite() {",
                "        return Err(Error::NonFiniteState);",
                "    }",
                "    if a <= T::zero() {",
                "        return Err(Error::SingularMassMatrix { pivot: 0 });",
                "    }",
                "    if det <= a * d.abs() * T::EPSILON {",
                "        return Err(Error::SingularMassMatrix { pivot: 1 });",
                "    }",
                "    let inv = T::one() / det;",
                "    finite(SVector::from([(d * b[0] - c * b[1]) * inv, (a * b[1] - c * b[0]) * inv]))",
                "}",
            ])
        else:
            self.uses.add("solve_spd")
            o.extend([
                f"/// Solves `m x = b` by the fixed-size Cholesky solve.",
                f"fn solve<T: Real>(m: &SMatrix<T, {n}, {n}>, b: &SVector<T, {n}>) -> Result<SVector<T, {n}>, Error> {{",
                "    finite(solve_spd(m, b)?)",
                "}",
            ])

    def test_module(self):
        s, d = self.s, self.d
        n = s.n
        o = self.out
        o.append("")
        o.append("/// The generated equations against the automatic path of the same `T` and `V`.")
        o.append("#[cfg(test)]")
        o.append("mod tests {")
        o.append("    use super::*;")
        if d.phi is not None:
            o.append("    use lagrange_core::constraints::Holonomic;")
            o.append("    use lagrange_core::{Constrained, EulerLagrange};")
            o.append("    use lagrange_tests::{agrees_with_automatic, relative, Rng, Scales};")
        else:
            o.append("    use lagrange_tests::{agrees_with_automatic, Rng, Scales};")
        o.append("")
        o.append("    /// Relative agreement in `f64`.")
        o.append("    const F64_TOLERANCE: f64 = 1e-12;")
        o.append("    /// Relative agreement in `f32`.")
        o.append("    const F32_TOLERANCE: f64 = 1e-4;")
        o.append("    /// Random states compared.")
        o.append("    const STATES: usize = 1000;")
        o.append("    /// Natural sizes added to the compared values' (see `Scales`).")
        o.append("    const SCALES: Scales = Scales { acceleration: 1.0, energy: 1.0 };")
        o.append("")
        ranges = ", ".join(f"rng.uniform({float_literal(lo)}, {float_literal(hi)})" for lo, hi in s.ranges)
        vel = ", ".join("rng.uniform(-3.0, 3.0)" for _ in range(n))
        o.append("    /// A state drawn from the spec's ranges, velocities in `(-3, 3)`, time in `(0, 10)`.")
        o.append(f"    fn sample<T: Real>(rng: &mut Rng) -> State<T, {n}> {{")
        o.append("        let t = rng.uniform(0.0, 10.0);")
        o.append(f"        let q = [{ranges}];")
        o.append(f"        let qd = [{vel}];")
        o.append("        State::new(t, q, qd)")
        o.append("    }")
        o.append("")
        o.append("    fn agrees<T: Real>(tolerance: f64) -> Result<(), Error> {")
        o.append(f"        let mechanism = {s.name}::<T>::default();")
        o.append("        let mut rng = Rng::new(16);")
        o.append("        agrees_with_automatic(&mechanism, SCALES, tolerance, STATES, &mut rng, sample::<T>)?;")
        if d.phi is not None:
            o.append("        // The rows against their dual-number derivatives, and the constrained motion.")
            o.append("        let rows = Holonomic::new(mechanism);")
            o.append("        let constrained = Constrained::new(mechanism);")
            o.append("        let automatic = EulerLagrange::new(mechanism).held_by(rows);")
            o.append("        for _ in 0..STATES {")
            o.append("            let s = sample::<T>(&mut rng);")
            o.append("            let checks = [")
            o.append("                (\"phi\", relative(mechanism.position_residual(&s.q).iter().copied(), rows.position_residual(&s.q).iter().copied(), 1.0)),")
            o.append("                (\"J\", relative(mechanism.jacobian(&s.q).iter().copied(), rows.jacobian(&s.q).iter().copied(), 1.0)),")
            o.append("                (\"J'q'\", relative(mechanism.velocity_product(&s.q, &s.qd).iter().copied(), rows.velocity_product(&s.q, &s.qd).iter().copied(), 1.0)),")
            o.append("                (\"q''\", relative(constrained.acceleration(&s)?.iter().copied(), automatic.acceleration(&s)?.iter().copied(), 1.0)),")
            o.append("            ];")
            o.append("            for (what, e) in checks {")
            o.append("                assert!(e < tolerance, \"{what} at {s:?}: {e:e}\");")
            o.append("            }")
            o.append("        }")
        o.append("        Ok(())")
        o.append("    }")
        o.append("")
        o.append("    #[test]")
        o.append("    fn agrees_with_automatic_f64() -> Result<(), Error> {")
        o.append("        agrees::<f64>(F64_TOLERANCE)")
        o.append("    }")
        o.append("")
        o.append("    #[test]")
        o.append("    fn agrees_with_automatic_f32() -> Result<(), Error> {")
        o.append("        agrees::<f32>(F32_TOLERANCE)")
        o.append("    }")
        o.append("}")


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("spec")
    parser.add_argument("--name")
    parser.add_argument("--source", help="the spec's path as the header names it")
    parser.add_argument("--command", help="the command that regenerates the file")
    parser.add_argument("--tests", action="store_true", help="add a test module (lagrange-tests)")
    args = parser.parse_args(argv)
    source = args.source or args.spec
    command = args.command or f"cargo xtask derive {source}"
    try:
        spec = Spec(args.spec, args.name)
        derivation = Derivation(spec)
        code = Generator(spec, derivation, source, command, args.tests).generate()
    except SpecError as e:
        message = str(e)
        if not message.startswith(args.spec):
            message = f"{source}: {message}"
        print(f"error: {message}", file=sys.stderr)
        return 1
    sys.stdout.write(code)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
