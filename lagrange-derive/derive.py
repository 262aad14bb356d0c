"""lagrange-derive's derivation: from a spec (T, V, Q, phi written with SymPy) derive the
Euler-Lagrange equations and print a no_std Rust mechanism on stdout.

Run by `lagrange-derive SPEC.py [--out FILE.rs] [--name TypeName] [--tests]` (and by
`cargo xtask derive` in the lagrange workspace), which carries this file, makes the virtual
environment with the pinned SymPy, formats the output with rustfmt and writes the file only
when everything succeeded. By hand:

    python derive.py SPEC.py [--name TypeName] [--tests] [--spec-path PATH] [--file-name NAME]

## The spec

A Python file that defines, at module level:

- `q`: the generalized coordinates, a list of `dynamicsymbols("name")` (or `Function("name")(t)`
  for a time symbol `t` of your own, with any assumptions: `t = symbols("t", positive=True)`).
- `params`: a dict from each parameter's SymPy symbol to its default, or to a tuple
  `(default, kind)` or `(default, kind, "description, unit")`; `kind` is `"positive"` (masses,
  lengths, stiffnesses), `"non_negative"` (gravity, damping) or `"finite"` (the default). The
  dict's order is the constructor's argument order.
- `T`: the kinetic energy, in the coordinates, their first time derivatives, the time and the
  parameters; quadratic in the velocities (`q'^T M(t, q) q' / 2 + b(t, q)^T q' + T0(t, q)`).
- `V`: the potential energy, in the coordinates, the time and the parameters.
- `Q` (optional): the generalized non-conservative forces, a list of `len(q)` expressions in
  the coordinates, velocities, time and parameters.
- `phi` (optional): holonomic constraint rows `phi(q) = 0`, a list of expressions in `q` and
  the parameters.
- `links` (optional): each link's frame, a list of `(origin x, origin y, angle)` triples in
  `q` and the parameters (no velocity, no time): the type then implements `Links`, whose
  `pose` is these and whose points' Jacobians come from dual numbers.
- `name` (optional): the Rust type's name, CamelCase (else `--name`, else the file name in
  CamelCase).
- `doc` (optional): what the mechanism is (else the module's docstring).
- `ranges` (optional): a dict from coordinates to `(low, high)`, where the generated test draws
  its random states and the mass-matrix check samples (default `(-3, 3)`).
- `simplify` (optional, default `True`): `trigsimp` T and V before deriving (seconds for a
  few links, minutes for long chains).

Time is the symbol the coordinates are functions of (`dynamicsymbols._t`, named `t`, or your
own); any symbol of the same name, whatever its assumptions, is that time. It may enter T, V
and Q explicitly (a driven mechanism).

Names are the paper's: any SymPy name for a parameter or a coordinate (`M`, `m`, `s`, `I`,
`theta_1`, `θ₂`, `lambda`). Each becomes a Rust identifier by the rule of `rust_name`; two
names that become one are refused, naming both. The generated code's own names (the state
`s`, the vectors `q` and `qd`, temporaries, constants, methods) give way to the spec's. The
only reserved names are the spec's keys above, as Python variables, and the time's name (a
symbol of that name is the time, not a parameter).

Supported in the expressions: `+ - * /`, integer and half-integer powers, `sqrt`, `sin`,
`cos`, `tan`, `exp`, `log`, `atan2`, `pi`. Everything else is refused with a message.

## What it derives

```text
M = d2T/dq'dq'                                    the mass matrix (not solved symbolically)
f = dL/dq - (d2L/dq'dq) q' - d2L/dq'dt            L = T - V, so that M q'' = f + Q
J = dphi/dq,  J'q' = d/dq (J q') q'               where phi is given
```

Each entry is expanded and its terms grouped by their state-dependent part, so that every
product of parameters becomes one quantity formed once by the constructor; then common
subexpressions are eliminated (`sympy.cse`), and sines and cosines of one argument share one
`sin_cos`. Everything is deterministic: the same spec and SymPy version give the same bytes.

Bad input (a syntax error, an unknown symbol, a T not quadratic in the velocities, a singular
mass matrix, an unsupported function, two names that collide, ...) prints one message on
stderr and exits with 1.
"""

import argparse
import itertools
import os
import random
import re
import sys
import traceback
import unicodedata

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
    "positive": "> 0",
    "non_negative": ">= 0",
    "finite": "finite",
}

# --------------------------------------------------------------------------------------------
# Names: the spec's, as Rust identifiers

# Rust's strict and reserved keywords (2015 to 2024), and the variants of the prelude that a
# binding may not shadow.
RUST_KEYWORDS = set(
    "as async await break const continue crate dyn else enum extern false fn for if impl in "
    "let loop match mod move mut pub ref return self static struct super trait true type "
    "unsafe use where while abstract become box do final macro override priv typeof unsized "
    "virtual yield try gen Self Ok Err Some None".split()
)

# The methods a mechanism has besides its parameters' accessors: an accessor of that name
# would shadow it (inherent methods come first).
RESERVED_METHODS = set(
    "new from_valid default clone clone_from eq ne fmt into try_into from try_from to_owned "
    "clone_into borrow borrow_mut type_id "
    "mass_matrix rhs solve_mass law law_jacobian law_force reads_velocities acceleration "
    "acceleration_with acceleration_jacobian velocity_jump velocity_jumps gather with_force "
    "held_by kinetic potential non_conservative_force kinetic_energy potential_energy energy "
    "mass_formula rhs_formula equations constant_mass position_residual jacobian "
    "velocity_product residual check_state phi pose point".split()
)

# Type names the generated file uses itself (imports, generics, the prelude).
RESERVED_TYPES = set(
    "T S Self ClosedForm ConstantMass Constraints HolonomicConstraints Links Pose SMatrix SVector "
    "Lagrangian Real Scalar State Option Result Default Clone Copy Debug PartialEq Send Sync "
    "Sized String Vec Box".split()
)

# Marks of combining characters, as words (`ẋ` is `x_dot`).
MARKS = {
    "COMBINING DOT ABOVE": "dot",
    "COMBINING DIAERESIS": "ddot",
    "COMBINING MACRON": "bar",
    "COMBINING TILDE": "tilde",
    "COMBINING CIRCUMFLEX ACCENT": "hat",
}


def rust_name(name, method=False):
    """The Rust identifier of a SymPy name (the rule the documentation states):

    1. A name that is already an ASCII identifier (letters, digits, `_`) keeps its letters and
       case: `M` is `M`, `theta_1` is `theta_1`.
    2. Otherwise, after Unicode compatibility decomposition: a Greek letter becomes its name
       (`θ` is `theta`, `Ω` is `Omega`, `ς` is `varsigma`), joined to a neighbouring letter by
       `_` (`mθ` is `m_theta`); a subscript or superscript digit becomes `_` and the digit
       (`θ₂` is `theta_2`); the marks dot, diaeresis, macron, tilde and circumflex become
       `_dot`, `_ddot`, `_bar`, `_tilde`, `_hat` (`ẋ` is `x_dot`); `'` becomes `_prime`;
       LaTeX's `\\`, `{` and `}` are dropped (`\\theta_{1}` is `theta_1`); any other letter or
       digit becomes `u` and its code point in hex; anything else becomes `_`. Runs of `_` are
       one, and `_` at either end is dropped.
    3. A name that is then empty or does not start with a letter or `_` and a letter (`1x`,
       `_1`) gets the prefix `n_`.
    4. A Rust keyword (`type`, `self`, `fn`, ...) or prelude variant (`Ok`, `None`, ...) gets
       `_` at its end (`type_`); so does a parameter named like a method the mechanism already
       has (`energy_`, `new_`), since its accessor would hide that method.
    """
    if re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
        out = name
    else:
        parts = []  # (text, kind): kind "word" for a Greek name, "text" otherwise
        for ch in unicodedata.normalize("NFKD", name.replace("\\", "").replace("{", "").replace("}", "")):
            if ch.isascii():
                if ch.isalnum() or ch == "_":
                    parts.append((ch, "text"))
                elif ch == "'":
                    parts.append(("_prime", "text"))
                elif ch == "^":
                    parts.append(("_", "text"))
                else:
                    parts.append(("_", "text"))
                continue
            uname = unicodedata.name(ch, "")
            greek = re.fullmatch(r"GREEK (SMALL|CAPITAL) LETTER (FINAL )?([A-Z]+)", uname)
            if greek:
                word = greek.group(3).lower()
                if greek.group(2):
                    word = "var" + word
                if greek.group(1) == "CAPITAL":
                    word = word.capitalize()
                parts.append((word, "word"))
            elif "SUBSCRIPT" in uname or "SUPERSCRIPT" in uname:
                digit = unicodedata.normalize("NFKC", ch)
                parts.append(("_" + digit if digit.isalnum() else "_", "text"))
            elif uname in MARKS:
                parts.append(("_" + MARKS[uname], "text"))
            elif unicodedata.category(ch).startswith("M"):
                continue  # an accent: dropped
            elif ch.isalnum():
                parts.append((f"u{ord(ch):x}", "word"))
            else:
                parts.append(("_", "text"))
        out = ""
        for i, (text, kind) in enumerate(parts):
            before = out[-1:] if out else ""
            if kind == "word" and before.isalpha():
                out += "_"
            elif kind == "text" and i and parts[i - 1][1] == "word" and text[:1].isalpha():
                out += "_"
            out += text
        out = re.sub(r"_+", "_", out).strip("_")
    if not re.match(r"[A-Za-z]|_[A-Za-z]", out):
        out = "n_" + out if out else "n"
    if out in RUST_KEYWORDS:
        out += "_"
    elif method and out in RESERVED_METHODS:
        out += "_"
    return out


def is_snake(name):
    """Whether rustc's `non_snake_case` accepts `name`: no capital, and no run of `_` inside
    (at either end they are allowed)."""
    core = name.strip("_")
    return not re.search(r"[A-Z]", core) and "__" not in core


class Names:
    """Identifiers the generated code gives itself, each different from every name of the spec
    and from each other: `fresh("s")` is `s`, or `s_`, `s__`, ... when `s` is taken."""

    def __init__(self, taken):
        self.taken = set(taken) | RUST_KEYWORDS

    def fresh(self, base):
        # A run of `_` inside a name (`self_` + `_d`) is one: rustc's non_snake_case refuses it.
        name = re.sub(r"(?<=[^_])_{2,}(?=[^_])", "_", base)
        while name in self.taken:
            name += "_"
        self.taken.add(name)
        return name

    def child(self):
        """A scope of its own (a function body) that sees everything taken so far."""
        return Names(self.taken)


# --------------------------------------------------------------------------------------------
# The spec


def load_spec(path):
    """Runs the spec file and returns its module namespace."""
    try:
        with open(path, encoding="utf-8") as f:
            source = f.read()
    except OSError as e:
        raise SpecError(f"cannot read {path}: {e.strerror}") from None
    except UnicodeDecodeError as e:
        raise SpecError(f"cannot read {path}: not UTF-8 ({e.reason})") from None
    try:
        code = compile(source, path, "exec")
    except SyntaxError as e:
        text = (e.text or "").rstrip()
        caret = " " * max((e.offset or 1) - 1, 0) + "^"
        raise SpecError(
            f"{path}:{e.lineno}:{e.offset}: syntax error: {e.msg}\n    {text}\n    {caret}"
        ) from None
    namespace = {"__name__": "__spec__", "__file__": path}
    # A spec may import a module beside it, from whatever folder the command runs.
    sys.path.insert(0, os.path.dirname(os.path.abspath(path)))
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
    return "".join(part[:1].upper() + part[1:] for part in re.split(r"[_\-\s.]+", stem) if part)


class Spec:
    """The spec, read and checked: coordinates as plain symbols, energies, forces, rows."""

    def __init__(self, path, name_override):
        ns = load_spec(path)
        self.path = path
        self.namespace = ns
        stem = re.sub(r"\.py$", "", path.replace("\\", "/").split("/")[-1])
        self.name = name_override or ns.get("name") or camel_case(stem)
        if not isinstance(self.name, str) or not re.fullmatch(r"[A-Z][A-Za-z0-9]*", self.name):
            raise SpecError(
                f"type name `{self.name}` is not a Rust type name in CamelCase (set `name = "
                f"\"MyMechanism\"` in the spec, or --name)"
            )
        if self.name in RESERVED_TYPES:
            raise SpecError(
                f"type name `{self.name}` is a name the generated file uses for something "
                f"else; choose another (`name = ...` in the spec, or --name)"
            )
        doc = ns.get("doc") or ns.get("__doc__") or f"The mechanism of `{stem}.py`."
        # Paragraphs kept, each paragraph's lines joined (the output wraps them again).
        self.doc = [" ".join(p.split()) for p in re.split(r"\n\s*\n", str(doc)) if p.strip()]
        if not self.doc:
            self.doc = [f"The mechanism of `{stem}.py`."]
        self.simplify = bool(ns.get("simplify", True))
        for required in ("params", "q", "T", "V"):
            if required not in ns:
                raise SpecError(f"{path}: the spec defines no `{required}`")
        self.read_coordinates(ns["q"])
        self.read_params(ns["params"])
        self.assign_names()
        self.read_ranges(ns.get("ranges", {}))
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
        self.links = None
        if ns.get("links") is not None:
            self.links = self.read_links(ns["links"])

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
            elif c.args[0].name != self.time.name:
                raise SpecError(
                    f"coordinate `{c}` is a function of `{c.args[0]}`, but "
                    f"`{self.q_functions[0]}` of `{self.time}`: one time for all"
                )
            if c in self.q_functions:
                raise SpecError(f"q lists `{c}` twice")
            self.q_functions.append(c)
        self.n = len(q)
        self.q_written = [type(c).__name__ for c in self.q_functions]
        self.time_name = self.time.name

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
            if sym.name == self.time_name:
                raise SpecError(
                    f"parameter `{sym.name}` has the name of the time (the coordinates are "
                    f"functions of `{self.time_name}`): rename one of them"
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
                    f"params[{sym}]: the default {default!r} is not {KINDS[kind]} ({kind})"
                )
            if description is not None and not isinstance(description, str):
                raise SpecError(f"params[{sym}]: the description must be a string")
            self.params.append((sym, default, kind, description))
        self.param_symbols = [p[0] for p in self.params]

    def assign_names(self):
        """Rust names for every name of the spec, refusing two that are one; then the state's
        symbols, named by their Rust locals."""
        seen = {}  # Rust name -> (what, written)
        written = {}  # name as written -> what

        def claim(what, name, rust):
            if name in written:
                raise SpecError(
                    f"{written[name]} `{name}` and {what} `{name}` have the same name: rename "
                    f"one of them"
                )
            written[name] = what
            if rust in seen:
                other_what, other = seen[rust]
                raise SpecError(
                    f"{other_what} `{other}` and {what} `{name}` both become `{rust}` in Rust "
                    f"(see the naming rule in the docs): rename one of them"
                )
            seen[rust] = (what, name)

        self.time_rust = rust_name(self.time_name)
        claim("the time", self.time_name, self.time_rust)
        self.q_rust = []
        for name in self.q_written:
            rust = rust_name(name)
            claim("coordinate", name, rust)
            self.q_rust.append(rust)
        self.param_rust = {}
        for sym in self.param_symbols:
            rust = rust_name(sym.name, method=True)
            claim("parameter", sym.name, rust)
            self.param_rust[sym] = rust
        # Everything the spec names, as written and in Rust: the generated code's own names
        # give way to these.
        self.names = Names(set(written) | set(seen))
        self.qs = [sp.Symbol(name) for name in self.q_rust]
        self.qds = [sp.Symbol(self.names.fresh(name + "_d")) for name in self.q_rust]
        self.t = sp.Symbol(self.time_rust)
        self.state_symbols = set(self.qs) | set(self.qds) | {self.t}
        for sym in self.qs + [self.t]:
            self.names.taken.add(sym.name)
        self.rust_names = {sym: sym.name for sym in self.qs + self.qds + [self.t]}

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
            if not (mpmath.isfinite(low) and mpmath.isfinite(high)):
                raise SpecError(f"ranges[{c}] = {r}: both ends must be finite")
            if not low < high:
                raise SpecError(f"ranges[{c}] = {r}: low must be below high")
            self.ranges[self.q_functions.index(c)] = (low, high)

    def read_links(self, links):
        """`links`: each link's frame as (origin x, origin y, angle), functions of q only."""
        rows = self.as_list(links, "links")
        if not rows:
            raise SpecError("links is empty: give each link's (x, y, angle), or no links")
        out = []
        for k, row in enumerate(rows):
            if not isinstance(row, (list, tuple)) or len(row) != 3:
                raise SpecError(
                    f"links[{k}] is not a triple: give each link's frame as (origin x, "
                    f"origin y, angle), the angle counter-clockwise from the world's x axis"
                )
            out.append(
                [
                    self.plain(
                        self.sympify(e, f"links[{k}]"),
                        f"links[{k}]",
                        velocities=False,
                        time=False,
                    )
                    for e in row
                ]
            )
        return out

    def time_hint(self):
        """A note when the spec holds a symbol named like the time that is not the time the
        coordinates are functions of: a derivative by it is zero."""
        for value in self.namespace.values():
            if isinstance(value, sp.Symbol) and value.name == self.time_name and value != self.time:
                return (
                    f" (note: the spec's `{value.name}` is not the symbol the coordinates are "
                    f"functions of, so x.diff({value.name}) is 0: make the coordinates with "
                    f"Function('x')({value.name}), or use dynamicsymbols._t)"
                )
        return ""

    def plain(self, expr, what, velocities=True, time=True):
        """`expr` in plain symbols: q_i(t) -> q_i, q_i'(t) -> q_i_d, the time -> t."""
        times = {
            s for s in expr.free_symbols if isinstance(s, sp.Symbol) and s.name == self.time_name
        } | {self.time}
        derivatives = {}
        for c, d in zip(self.q_functions, self.qds):
            for tau in times:
                f = c.func(tau)
                derivatives[sp.Derivative(f, tau)] = d
        out = expr.xreplace(derivatives)
        for d in sorted(out.atoms(sp.Derivative), key=sp.default_sort_key):
            f = d.expr
            if f.func in {c.func for c in self.q_functions}:
                raise SpecError(
                    f"{what} uses {sp.sstr(d)}: only the coordinates and their first time "
                    f"derivatives may appear"
                )
            if isinstance(f, AppliedUndef) and len(f.args) == 1 and f.args[0] in times:
                raise SpecError(
                    f"{what} uses the velocity of {f}, a function of time that is not listed "
                    f"in q (an unknown coordinate)"
                )
            raise SpecError(f"{what} uses the derivative {sp.sstr(d)}: {SUPPORTED}")
        replace = {}
        for c, s in zip(self.q_functions, self.qs):
            for tau in times:
                replace[c.func(tau)] = s
        out = out.xreplace(replace)
        for f in sorted(out.atoms(AppliedUndef), key=sp.default_sort_key):
            if len(f.args) == 1 and f.args[0] in times:
                raise SpecError(
                    f"{what} uses {f}, a function of time that is not listed in q (an unknown "
                    f"coordinate)"
                )
            raise SpecError(
                f"{what} uses the unknown function {type(f).__name__}: {SUPPORTED}"
            )
        out = out.xreplace({tau: self.t for tau in times})
        allowed = set(self.param_symbols) | set(self.qs)
        if velocities:
            allowed |= set(self.qds)
        if time:
            allowed.add(self.t)
        for sym in sorted(out.free_symbols - allowed, key=lambda s: s.name):
            if sym in self.qds:
                name = self.q_written[self.qds.index(sym)]
                why = (
                    "the rows are holonomic, phi(q) = 0"
                    if what.startswith("phi")
                    else "a link's place is a function of q"
                    if what.startswith("links")
                    else "velocity-dependent terms belong in T or Q"
                )
                raise SpecError(
                    f"{what} depends on the velocity {name}': it may depend on the "
                    f"coordinates only ({why})"
                )
            if sym == self.t:
                rule = (
                    "a link's place is a function of q alone (Links::pose takes no time)"
                    if what.startswith("links")
                    else "constraint rows must not"
                )
                raise SpecError(f"{what} depends on the time {self.time_name}: {rule}")
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
        check_quadratic(T, s.qds, s.q_written, s.time_hint())
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
        # READS_TIME's default is true (the safe answer); a Lagrangian free of t says false.
        self.reads_time = s.t in (T.free_symbols | V.free_symbols)
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
        self.links = [[self.group(e) for e in row] for row in s.links] if s.links else None

    def group(self, expr):
        """`expr` expanded, its terms grouped by their state-dependent factor: a sum of
        (product of parameters) x (state term), the form hoisting turns into constants."""
        expr = sp.expand(expr)
        terms = {}
        for term in sp.Add.make_args(expr):
            const, var = term.as_independent(*sorted(self.spec.state_symbols, key=str), as_Add=False)
            terms[var] = terms.get(var, 0) + const
        return sp.Add(*[sp.factor_terms(c) * v for v, c in terms.items()])


def check_quadratic(T, qds, names, hint):
    """T must be a polynomial of degree at most 2 in the velocities."""
    if not T.free_symbols & set(qds):
        raise SpecError(
            "T does not depend on any velocity: the mass matrix d2T/dq'2 would be zero "
            "(singular)" + hint
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
    for x, name in zip(null, spec.q_written):
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
            f"appear in T?)" + spec.time_hint()
        )
    raise SpecError(
        f"the mass matrix d2T/dq'2 is not positive definite at any sampled configuration: "
        f"T < 0 along the velocity combination {combo}"
    )


# --------------------------------------------------------------------------------------------
# Hoisting: products of parameters become constants formed once


class Constants:
    """The parameter-only subexpressions, each a constant `k<i>` formed by the constructor
    (named so that no name of the spec is taken)."""

    def __init__(self, params, names):
        self.params = set(params)
        self.names = names
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
            k = sp.Symbol(self.names.fresh(f"k{len(self.order)}"))
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


# Every float literal written, for the `approx_constant` check of the header.
LITERALS = []


def float_literal(x):
    r = repr(float(x))
    if "inf" in r or "nan" in r:
        raise SpecError(f"the number {x} is not finite")
    if "." not in r and "e" not in r:
        r += ".0"
    LITERALS.append(r)
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

    def __init__(self, emitter, exprs, inputs, scope):
        """`inputs`: symbol -> (Rust binding code, kind), bound only when used. `scope`: the
        function's names, from which its temporaries are drawn."""
        self.emitter = emitter
        self.scope = scope
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
                        pair = (
                            sp.Symbol(scope.fresh(f"sin_{stem}")),
                            sp.Symbol(scope.fresh(f"cos_{stem}")),
                        )
                    else:
                        i = sum(1 for a in trig if not a.is_Symbol)
                        pair = (
                            sp.Symbol(scope.fresh(f"sin{i}")),
                            sp.Symbol(scope.fresh(f"cos{i}")),
                        )
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
            exprs + trig_args,
            symbols=(sp.Symbol(scope.fresh(f"e{i}")) for i in itertools.count()),
            order="canonical",
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
# Docs: Markdown that reads as written


# A word that Markdown would read as the start of a block (a quote, a list item, a heading, a
# fence, a table, HTML, a rule) when a line starts with it.
RISKY = re.compile(r"^(>|\||<|```|~~~|[-+*]$|#{1,6}$|\d{1,9}[.)]$|[-=*_+]+$)")


def escape_start(word):
    """`word` escaped so that a line may start with it."""
    m = re.fullmatch(r"(\d{1,9})([.)])", word)
    if m:
        return f"{m.group(1)}\\{m.group(2)}"
    return "\\" + word


def wrap(text, width=92):
    """`text` wrapped into lines of at most `width` (a longer word stands alone), never starting
    a line with what Markdown reads as a block marker: such a word stays on the line before,
    or, first in the paragraph, is escaped."""
    words, lines, line = text.split(), [], ""
    for w in words:
        if not line:
            line = escape_start(w) if RISKY.match(w) else w
        elif len(line) + 1 + len(w) > width and not RISKY.match(w):
            lines.append(line)
            line = w
        else:
            line = f"{line} {w}"
    if line:
        lines.append(line)
    return lines


def doc_lines(lines, indent):
    return [f"{indent}/// {line}".rstrip() for line in lines]


def capital(text):
    return text[:1].upper() + text[1:]


# --------------------------------------------------------------------------------------------
# Literals that clippy's `approx_constant` would read as an approximation of a constant


KNOWN_CONSTANTS = [
    mpmath.e, 1 / mpmath.pi, 1 / mpmath.sqrt(2), 2 / mpmath.pi, 2 / mpmath.sqrt(mpmath.pi),
    mpmath.pi / 2, mpmath.pi / 3, mpmath.pi / 4, mpmath.pi / 6, mpmath.pi / 8, mpmath.ln(2),
    mpmath.ln(10), mpmath.log(10, 2), mpmath.log(mpmath.e, 2), mpmath.log(2, 10),
    mpmath.log(mpmath.e, 10), mpmath.pi, mpmath.sqrt(2), 2 * mpmath.pi,
]


def looks_like_constant(literal):
    """True when `literal` (a float literal as written) agrees with a known constant to all
    its digits, as clippy's `approx_constant` judges."""
    text = literal.lstrip("-")
    if "e" in text or "." not in text:
        return False
    decimals = len(text.split(".")[1])
    if decimals < 2:
        return False
    value = float(text)
    return any(abs(value - float(c)) < 10.0 ** -decimals for c in KNOWN_CONSTANTS)


# --------------------------------------------------------------------------------------------
# The Rust file


class Generator:
    def __init__(self, spec, derivation, spec_path, file_name, options):
        self.s = spec
        self.d = derivation
        self.source = spec_path.replace("\\", "/").rsplit("/", 1)[-1]
        self.spec_path = spec_path
        self.file_name = file_name
        self.options = options
        self.tests = "--tests" in options
        self.n = spec.n
        names = spec.names
        # The generated code's own names: they give way to the spec's.
        self.state = names.fresh("s")
        self.q = names.fresh("q")
        self.qd = names.fresh("qd")
        self.consts = Constants(spec.param_symbols, names)
        self.out = []

    # -- printing the formulas for the docs --

    def pretty(self, e):
        s = self.s
        sub = {sym: sp.Symbol(name) for sym, name in zip(s.qs, s.q_written)}
        sub.update({qd: sp.Symbol(name + "'") for qd, name in zip(s.qds, s.q_written)})
        sub[s.t] = sp.Symbol(s.time_name)
        return sp.sstr(e.xreplace(sub)).replace("**", "^")

    def written(self, e):
        """An expression as the spec wrote it, velocities as th'."""
        return self.pretty(self.s.plain(e, "doc"))

    # -- names --

    def code_names(self, constructor=False):
        """Symbol -> Rust code for parameters, constants and state."""
        prefix = "" if constructor else "self."
        names = {p: prefix + self.s.param_rust[p] for p in self.s.param_symbols}
        for k, _ in self.consts.order:
            names[k] = prefix + k.name
        names.update(self.s.rust_names)
        return names

    def state_inputs(self, generic, vectors, time):
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

    def block(self, exprs, generic, vectors=None, time=None):
        if vectors is None:
            vectors = (f"{self.state}.q", f"{self.state}.qd")
            time = f"{self.state}.t"
        exprs = [self.consts.hoist(e) for e in exprs]
        emitter = Emitter(generic, self.code_names())
        return Block(emitter, exprs, self.state_inputs(generic, vectors, time), self.s.names.child())

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
        blocks["equations"] = self.block(m_entries + forces, False)
        self.m_entries = m_entries
        qv = (self.q, self.qd)
        blocks["kinetic"] = self.block([d.T], True, vectors=qv, time=s.t.name)
        blocks["potential"] = self.block([d.V], True, vectors=(self.q, None), time=s.t.name)
        if d.Q is not None:
            blocks["force"] = self.block(d.Q, False)
        if d.phi is not None:
            blocks["phi"] = self.block(d.phi, False, vectors=(self.q, None), time=None)
            blocks["phi_generic"] = self.block(d.phi, True, vectors=(self.q, None), time=None)
            blocks["jacobian"] = self.block(list(d.J), False, vectors=(self.q, None), time=None)
            blocks["jqd"] = self.block(d.Jqd, False, vectors=qv, time=None)
        if d.links is not None:
            entries = [e for row in d.links for e in row]
            blocks["links"] = self.block(entries, True, vectors=(self.q, None), time=None)
        self.blocks = blocks
        if d.fixed_mass:
            self.mass_field = s.names.fresh("mass")
        self.reads_velocities = any(
            e.free_symbols & set(s.qds) for e in forces
        )
        self.parameters()
        self.lagrangian()
        self.closed_form()
        if d.phi is not None:
            self.constraints()
        if d.links is not None:
            self.link_poses()
        if self.tests:
            self.test_module()
        return self.header() + "\n".join(self.out) + "\n"

    def header(self):
        s = self.s
        options = " ".join(self.options) if self.options else "none"
        lines = [
            f"//! [`{s.name}`]: generated by `lagrange-derive` (SymPy {sp.__version__}). Do not edit:",
            "//! change the spec and regenerate this file from any folder, naming it by its path there:",
            "//!",
            "//! ```text",
            f"//! lagrange-derive --update {self.file_name}",
            "//! ```",
            "//!",
            f"//! Spec: `{self.spec_path}` (relative to this file). Options: `{options}`.",
            "",
        ]
        allow = []
        identifiers = list(s.param_rust.values()) + s.q_rust + [s.time_rust]
        if not all(is_snake(x) for x in identifiers):
            allow.append("non_snake_case")
        if re.search(r"[A-Z]{2}", s.name):
            allow.append("clippy::upper_case_acronyms")
        if any(x.strip("_") in ("foo", "baz", "quux") for x in identifiers):
            allow.append("clippy::disallowed_names")
        if any(looks_like_constant(x) for x in LITERALS):
            allow.append("clippy::approx_constant")
        if allow:
            lines.append(f"#![allow({', '.join(allow)})]")
            lines.append("")
        closed = ["ClosedForm"] + (["ConstantMass"] if self.d.fixed_mass else [])
        lines.append(f"use lagrange_core::closed_form::{{{', '.join(closed)}}};")
        if self.d.phi is not None:
            lines.append("use lagrange_core::constraints::{Constraints, HolonomicConstraints};")
        if self.d.links is not None:
            lines.append("use lagrange_core::links::{Links, Pose};")
        lines.append("use lagrange_core::nalgebra::{SMatrix, SVector};")
        lines.append("use lagrange_core::{Lagrangian, Real, Scalar, State};")
        lines.append("")
        return "\n".join(lines) + "\n"

    def formulas(self):
        s, d = self.s, self.d
        lines = []
        lines.append(f"q    = [{', '.join(s.q_written)}]")
        for name, written, derived in (("T", s.T_written, d.T), ("V", s.V_written, d.V)):
            text = self.written(written)
            lines.append(f"{name}    = {text}")
            if self.pretty(derived) != text:
                lines.append(f"     = {self.pretty(derived)}")
        if s.Q_written is not None:
            lines.append(f"Q    = [{', '.join(self.written(e) for e in s.Q_written)}]")
        if s.phi_written is not None:
            lines.append(f"phi  = [{', '.join(self.pretty(e) for e in s.phi)}] = 0")
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
            lines.append("(M and f are long: see mass_formula and rhs_formula)")
        return lines

    def solve_text(self):
        n = self.s.n
        if self.d.fixed_mass:
            return "`M` is constant: factored once by the constructor"
        return "closed form" if n <= 2 else "Cholesky"

    def parameters(self):
        s, d = self.s, self.d
        o = self.out
        o.append("lagrange_core::parameters! {")
        ind = "    "
        for i, paragraph in enumerate(s.doc):
            if i:
                o.append(f"{ind}///")
            o.extend(doc_lines(wrap(paragraph), ind))
        o.append(f"{ind}///")
        o.append(f"{ind}/// ```text")
        o.extend(f"{ind}/// {line}".rstrip() for line in self.formulas())
        o.append(f"{ind}/// ```")
        o.append(f"{ind}///")
        o.extend(doc_lines(wrap(
            f"Derived by SymPy from `{self.source}` (`lagrange-derive`): `M` and `f` in "
            f"closed form, the linear solve numeric ({self.solve_text()}); a [`Mechanism`]"
            f"(lagrange_core::Mechanism) by "
            f"[`closed_form_mechanism!`](lagrange_core::closed_form_mechanism)."
        ), ind))
        renamed = [
            f"`{p.name}` is `{s.param_rust[p]}`" for p in s.param_symbols
            if p.name != s.param_rust[p]
        ]
        if renamed:
            o.append(f"{ind}///")
            o.extend(doc_lines(wrap(
                "The spec's names in Rust (see lagrange-derive's naming rule): "
                + ", ".join(renamed) + "."
            ), ind))
        if d.phi is not None:
            o.append(f"{ind}///")
            o.extend(doc_lines(wrap(
                f"As a [`Mechanism`](lagrange_core::Mechanism) this is the free mechanism; as "
                f"[`Constraints`] it is the rows `phi` ({len(d.phi)}). The constrained "
                f"mechanism is `Constrained::new({s.name}::default())` "
                f"([`Constrained`](lagrange_core::Constrained))."
            ), ind))
        o.append(f"{ind}pub struct {s.name} {{")
        for p, default, kind, desc in s.params:
            text = capital(" ".join(desc.split())) if desc and desc.strip() else f"Parameter `{p.name}`"
            if not text.endswith("."):
                text += "."
            o.extend(doc_lines(wrap(text, 88), ind * 2))
            o.append(f"{ind * 2}{s.param_rust[p]}: {kind} = {float_literal(default)},")
        o.append(f"{ind}}}")
        formed = []
        names = self.code_names(constructor=True)
        emitter = Emitter(False, dict(names))
        for k, expr in self.consts.order:
            code, _, _ = emitter.emit(expr)
            formed.append((f"`{self.pretty(expr)}`.", f"{k.name}: T = {code}"))
        if d.fixed_mass:
            mass = Block(
                Emitter(False, dict(names)),
                [self.consts.hoist(e) for e in self.m_entries],
                {},
                s.names.child(),
            )
            matrix = self.matrix_from_upper(mass, 0)
            if mass.lines:
                matrix = "{ " + " ".join(mass.lines) + f" {matrix} }}"
            formed.append((
                "`M`, the same at every state: factored once.",
                f"{self.mass_field}: ConstantMass<T, {s.n}> = ConstantMass::new(&{matrix})",
            ))
        if formed:
            o.append(f"{ind}formed {{")
            for doc, line in formed:
                o.append(f"{ind * 2}/// {doc}")
                o.append(f"{ind * 2}{line},")
            o.append(f"{ind}}}")
        o.append("}")
        o.append("")

    def fn(self, signature, block, result, doc=None, indent="    "):
        """A function: `{s}` in `signature` is the state's name, `_s` when unused."""
        o = self.out
        if doc:
            o.extend(doc_lines([doc], indent))
        signature = signature.replace("{s}", self.state if block.used_inputs else "_" + self.state)
        o.append(f"{indent}{signature} {{")
        lines = block.body()
        # `let x = ...; x` is clippy's `let_and_return`: return the value itself.
        last = lines[-1] if lines else ""
        m = re.fullmatch(r"let ([A-Za-z_][A-Za-z0-9_]*) = (.*);", last)
        if m and m.group(1) == result:
            lines, result = lines[:-1], m.group(2)
        for line in lines:
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
                    local = block.scope.fresh(f"m{i}_{j}")
                    block.lines.append(f"let {local} = {code};")
                    code = local
                entry[(i, j)] = entry[(j, i)] = code
        # Column arrays: From<[[T; R]; C]>.
        columns = ["[" + ", ".join(entry[(i, j)] for i in range(n)) + "]" for j in range(n)]
        return f"SMatrix::from([{', '.join(columns)}])"

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
        if not d.reads_time:
            o.append("    const READS_TIME: bool = false;")
        if d.explicit_time or d.constant_mass or d.driven or not d.reads_time:
            o.append("")

        def arg(name, block, symbols):
            return name if block.used_inputs & set(symbols) else "_" + name

        t = s.t.name
        kin = b["kinetic"]
        self.fn(
            f"fn kinetic<S: Scalar<Real = T>>(&self, {arg(t, kin, [s.t])}: S, "
            f"{arg(self.q, kin, s.qs)}: &SVector<S, {n}>, {arg(self.qd, kin, s.qds)}: "
            f"&SVector<S, {n}>) -> S",
            kin,
            kin.output(0, "S"),
        )
        o.append("")
        pot = b["potential"]
        self.fn(
            f"fn potential<S: Scalar<Real = T>>(&self, {arg(t, pot, [s.t])}: S, "
            f"{arg(self.q, pot, s.qs)}: &SVector<S, {n}>) -> S",
            pot,
            pot.output(0, "S"),
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

    def closed_form(self):
        s, d = self.s, self.d
        n = s.n
        b = self.blocks
        o = self.out
        o.append(f"impl<T: Real> ClosedForm<T, {n}> for {s.name}<T> {{")
        if not self.reads_velocities:
            o.append("    const READS_VELOCITIES: bool = false;")
            o.append("")
        self.fn(
            f"fn mass_formula(&self, {{s}}: &State<T, {n}>) -> SMatrix<T, {n}, {n}>",
            b["mass"],
            self.matrix_from_upper(b["mass"], 0),
        )
        o.append("")
        self.fn(
            f"fn rhs_formula(&self, {{s}}: &State<T, {n}>) -> SVector<T, {n}>",
            b["rhs"],
            self.vector(b["rhs"], 0, n),
        )
        o.append("")
        eq = b["equations"]
        self.fn(
            f"fn equations(&self, {{s}}: &State<T, {n}>) -> (SMatrix<T, {n}, {n}>, SVector<T, {n}>)",
            eq,
            f"({self.matrix_from_upper(eq, 0)}, {self.vector(eq, n * (n + 1) // 2, n)})",
        )
        if d.fixed_mass:
            o.append("")
            o.append(f"    fn constant_mass(&self) -> Option<&ConstantMass<T, {n}>> {{")
            o.append(f"        Some(&self.{self.mass_field})")
            o.append("    }")
        o.append("}")
        o.append("")
        o.append(f"lagrange_core::closed_form_mechanism!({s.name}, {n});")
        o.append("")

    def link_poses(self):
        s, d = self.s, self.d
        n, count = s.n, len(d.links)
        b = self.blocks["links"]
        o = self.out
        o.append(f"impl<T: Real> Links<T, {n}> for {s.name}<T> {{")
        o.append(f"    const LINKS: usize = {count};")
        o.append("")
        arms = []
        for k in range(count):
            x, y, angle = (b.output(3 * k + i, "S") for i in range(3))
            pattern = str(k) if k + 1 < count else "_"
            arms.append(f"{pattern} => Pose {{ origin: [{x}, {y}], angle: {angle} }},")
        q = self.q if b.used_inputs & set(s.qs) else "_" + self.q
        link = "link" if count > 1 else "_link"
        result = "match link {\n" + "\n".join("        " + a for a in arms) + "\n    }"
        if count == 1:
            result = arms[0].split(" => ", 1)[1].rstrip(",")
        self.fn(
            f"fn pose<S: Scalar<Real = T> + 'static>(&self, {q}: &SVector<S, {n}>, {link}: usize) -> Pose<S>",
            b,
            result,
            doc="The frame of each link (the last answers for a link out of range).",
        )
        o.append("}")
        o.append("")

    def constraints(self):
        s, d = self.s, self.d
        n, c = s.n, len(d.phi)
        b = self.blocks
        o = self.out

        def arg(name, block, symbols):
            return name if block.used_inputs & set(symbols) else "_" + name

        o.append(f"impl<T: Real> Constraints<T, {n}, {c}> for {s.name}<T> {{")
        self.fn(
            f"fn position_residual(&self, {arg(self.q, b['phi'], s.qs)}: &SVector<T, {n}>) -> SVector<T, {c}>",
            b["phi"],
            self.vector(b["phi"], 0, c),
        )
        o.append("")
        columns = [
            "[" + ", ".join(b["jacobian"].output(i * n + j, "T") for i in range(c)) + "]"
            for j in range(n)
        ]
        self.fn(
            f"fn jacobian(&self, {arg(self.q, b['jacobian'], s.qs)}: &SVector<T, {n}>) -> SMatrix<T, {c}, {n}>",
            b["jacobian"],
            f"SMatrix::from([{', '.join(columns)}])",
        )
        o.append("")
        jqd = b["jqd"]
        self.fn(
            f"fn velocity_product(&self, {arg(self.q, jqd, s.qs)}: &SVector<T, {n}>, "
            f"{arg(self.qd, jqd, s.qds)}: &SVector<T, {n}>) -> SVector<T, {c}>",
            jqd,
            self.vector(jqd, 0, c),
        )
        o.append("}")
        o.append("")
        o.append("/// The rows written generic over the scalar, for the automatic path (`Holonomic`).")
        o.append(f"impl<T: Real> HolonomicConstraints<T, {n}, {c}> for {s.name}<T> {{")
        pg = b["phi_generic"]
        self.fn(
            f"fn phi<S: Scalar<Real = T> + 'static>(&self, {arg(self.q, pg, s.qs)}: &SVector<S, {n}>) -> SVector<S, {c}>",
            pg,
            self.vector(pg, 0, c, want="S"),
        )
        o.append("}")
        o.append("")

    def test_module(self):
        s, d = self.s, self.d
        n = s.n
        o = self.out
        check = "check_held" if d.phi is not None else "check"
        ranges = ", ".join(f"({float_literal(lo)}, {float_literal(hi)})" for lo, hi in s.ranges)
        o.extend([
            "/// The closed form against the automatic path of its own `T` and `V`, in `f64` and `f32`",
            "/// (`lagrange_core::agreement`).",
            "#[cfg(test)]",
            "mod tests {",
            f"    use lagrange_core::agreement::{{{check}, Disagreement}};",
            "",
            "    /// Where the states are drawn: the spec's ranges of the coordinates.",
            f"    const RANGES: [(f64, f64); {n}] = [{ranges}];",
            "",
            "    #[test]",
            f"    fn agrees_with_automatic_f64() -> Result<(), Disagreement<f64, {n}>> {{",
            f"        {check}(&super::{s.name}::<f64>::default(), &RANGES)",
            "    }",
            "",
            "    #[test]",
            f"    fn agrees_with_automatic_f32() -> Result<(), Disagreement<f32, {n}>> {{",
            f"        {check}(&super::{s.name}::<f32>::default(), &RANGES)",
            "    }",
            "}",
        ])
        o.append("")
        if o[-1] == "":
            o.pop()


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("spec")
    parser.add_argument("--name")
    parser.add_argument(
        "--spec-path", help="the spec's path as the header records it (relative to the output)"
    )
    parser.add_argument("--file-name", help="the output's file name, for the header's command")
    parser.add_argument("--tests", action="store_true", help="add a test module")
    args = parser.parse_args(argv)
    options = (["--name", args.name] if args.name else []) + (["--tests"] if args.tests else [])
    spec_path = args.spec_path or args.spec
    file_name = args.file_name or "FILE.rs"
    try:
        spec = Spec(args.spec, args.name)
        derivation = Derivation(spec)
        code = Generator(spec, derivation, spec_path, file_name, options).generate()
    except SpecError as e:
        message = str(e)
        if not message.startswith(args.spec):
            message = f"{args.spec}: {message}"
        print(f"error: {message}", file=sys.stderr)
        return 1
    sys.stdout.write(code)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
