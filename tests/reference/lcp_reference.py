"""A reference of the active-set method of lagrange's `Delassus::complementary_from`
(lagrange-core/src/constraints/contact/lcp.rs), written from its documentation in plain
Python, in IEEE double precision as the Rust is: the multipliers and the passes of the
method, which `a_dependent_row_joins_along_the_ray_as_documented` asserts on five sets.

    python3 tests/reference/lcp_reference.py    prints them

A row is 'U' (unilateral) or a number b (bounded, |lambda| <= b). W = J J^T (one unit mass).
"""
import math

INF = float('inf')
EPS = 2.220446049250313e-16


class Dependent(Exception):
    def __init__(self, row):
        self.row = row


def div(a, b):
    """a / b as IEEE arithmetic gives it (a zero divisor: an infinity, or NaN)."""
    try:
        return a / b
    except ZeroDivisionError:
        return float('nan') if a != a or a == 0 else math.copysign(INF, a) * math.copysign(1, b)


def bounds(kind):
    return (0.0, INF) if kind == 'U' else (-kind, kind)


def solve(W, order, n, r):
    """x = W_AA^-1 r_A over order[:n] by Cholesky in that order; a pivot below sqrt(EPS) of
    its diagonal entry is a row dependent on the ones before it."""
    C = len(r)
    l = [[0.0] * C for _ in range(C)]
    for p in range(n):
        rp = order[p]
        for q in range(p):
            x = W[rp][order[q]]
            for k in range(q):
                x -= l[p][k] * l[q][k]
            l[p][q] = x / l[q][q]
        d = W[rp][rp]
        for k in range(p):
            d -= l[p][k] ** 2
        if d <= abs(W[rp][rp]) * math.sqrt(EPS):
            raise Dependent(rp)
        l[p][p] = math.sqrt(d)
    y = [0.0] * C
    for p in range(n):
        s = r[order[p]]
        for k in range(p):
            s -= l[p][k] * y[k]
        y[p] = s / l[p][p]
    x = [0.0] * C
    for p in reversed(range(n)):
        s = y[p]
        for k in range(p + 1, n):
            s -= l[k][p] * x[order[k]]
        x[order[p]] = s / l[p][p]
    return x


def remove(order, row):
    order.remove(row)


def ray(W, order, lam, B, row, way):
    """The ray step: the row joins moving `way` off its bound, the rows before it moving so
    that W lambda is unchanged, as far as the first bound; the row held there, or None."""
    partners = order[:-1]
    c = solve(W, partners, len(partners), [W[k][row] for k in range(len(lam))])
    lo, hi = B[row]
    limit = (row, hi - lam[row] if way > 0 else lam[row] - lo, hi if way > 0 else lo)
    for k in partners:
        rate = -way * c[k]
        klo, khi = B[k]
        if rate < 0:
            t, at = div(lam[k] - klo, -rate), klo
        elif rate > 0:
            t, at = div(khi - lam[k], rate), khi
        else:
            continue
        if t < limit[1]:
            limit = (k, t, at)
    held, t, at = limit
    if not math.isfinite(t):
        return None
    for k in partners:
        lam[k] -= way * c[k] * t
    lam[row] += way * t
    lam[held] = at
    return held


def complementary(W, b, kinds, guess):
    """The multipliers and the passes taken."""
    C = len(b)
    B = [bounds(k) for k in kinds]
    order = [i for i in range(C) if (guess[i] if kinds[i] == 'U' else kinds[i] > 0)]
    free = [i in order for i in range(C)]
    blocked, lam, joined = [False] * C, [0.0] * C, None
    for p in range(1, 4 * C + 5):
        rhs = [0.0] * C
        for i in range(C):
            if free[i]:
                rhs[i] = -b[i] - sum(W[i][k] * lam[k] for k in range(C) if not free[k] and lam[k] != 0)
        try:
            x = solve(W, order, len(order), rhs)
        except Dependent as e:
            row = e.row
            if joined is not None and joined[0] == row:
                _, way, beyond = joined
                joined = None
                held = ray(W, order, lam, B, row, way) if beyond else None
                if held is not None:
                    free[held] = False
                    remove(order, held)
                    blocked = [False] * C
                elif beyond and kinds[row] == 'U':
                    raise RuntimeError('no solution')
                else:
                    remove(order, row)
                    free[row], blocked[row] = False, True
                continue
            remove(order, row)
            free[row], lam[row] = False, 0.0
            continue
        joined, stop = None, None
        for i in order:
            lo, hi = B[i]
            if x[i] < lo:
                reach, at = (lam[i] - lo) / (lam[i] - x[i]), lo
            elif x[i] > hi:
                reach, at = (hi - lam[i]) / (x[i] - lam[i]), hi
            else:
                continue
            if stop is None or reach < stop[1]:
                stop = (i, reach, at)
        if stop is not None:
            row, reach, at = stop
            for i in order:
                lam[i] = lam[i] + (x[i] - lam[i]) * reach
            lam[row], free[row] = at, False
            remove(order, row)
            blocked = [False] * C
            continue
        for i in order:
            lam[i] = x[i]
        join = None
        for i in range(C):
            if free[i] or blocked[i]:
                continue
            lo, hi = B[i]
            if lo == hi:
                continue
            a, size = b[i], abs(b[i])
            for k in range(C):
                if lam[k] != 0:
                    a += W[i][k] * lam[k]
                    size += abs(W[i][k] * lam[k])
            pull = -a if lam[i] <= lo else (a if lam[i] >= hi else abs(a))
            if pull > 64 * EPS * size and (join is None or pull > join[1]):
                join = (i, pull, size)
        if join is None:
            return lam, p
        row, pull, size = join
        free[row] = True
        order.append(row)
        lo, hi = B[row]
        a = sum(W[row][k] * lam[k] for k in range(C)) + b[row]
        way = 1.0 if lam[row] <= lo else (-1.0 if lam[row] >= hi or a > 0 else 1.0)
        joined = (row, way, pull > EPS ** 0.25 * size)
    raise RuntimeError('no convergence')


CASES = [
    ([[-1, 0], [1, 1], [2, 0], [1, 0]], [-0.3, -2.0, 0.9, 0.6], ['U', 'U', 1.5, 0.6], [True, False, False, True]),
    ([[1, 1], [2, 1], [0, 1]], [-2.0, -3.0, -1.5], [0.5, 0.3, 0.9], [True, False, False]),
    ([[1, 1], [1, 0], [1, 0], [1, 1]], [-3.8, -2.2, -2.7, -3.9], [2.0, 1.5, 'U', 0.5], [True, False, False, False]),
    ([[1, 0], [0, 1], [-1, 0], [1, 0]], [-1.1, -2.1, 1.2, -1.2], [1.5, 'U', 1.8, 'U'], [False, False, False, True]),
    ([[1, 1], [2, 2], [2, 1]], [-1.2, -2.6, -0.5], ['U', 0.3, 'U'], [True, False, False]),
]

if __name__ == '__main__':
    for J, b, kinds, guess in CASES:
        W = [[float(sum(x * y for x, y in zip(ri, rj))) for rj in J] for ri in J]
        print(*complementary(W, b, kinds, guess))
