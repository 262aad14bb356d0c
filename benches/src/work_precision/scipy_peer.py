"""SciPy on one problem of the lagrange bench (`cargo xtask bench --peers`).

Reads a job as JSON on stdin:
    {"rhs": "<Python source defining rhs(t, y)>", "y0": [...], "t_end": T,
     "tolerances": [...], "budget_seconds": s, "min_runs": n, "max_runs": n, "max_solve": s}
and prints one CSV line per method and tolerance (rtol = atol = tol):
    method,tol,steps,evaluations,seconds,runs,failure,y_1,...,y_n
where seconds is the median wall time of one whole solve over [0, T] (as many runs as fit the
budget, within min_runs..max_runs) and y the final state. A method's sweep ends after a solve
slower than max_solve (that one solve is its point). The right-hand side is plain Python,
called by SciPy once per evaluation: the way the origin's pendulum script integrated.
"""

import json
import math
import statistics
import sys
import time

import numpy as np
from scipy.integrate import odeint, solve_ivp


def ivp(method):
    def solve(f, y0, t_end, tol):
        sol = solve_ivp(f, (0.0, t_end), y0, method=method, rtol=tol, atol=tol)
        if not sol.success:
            raise RuntimeError(sol.message)
        return sol.y[:, -1], sol.t.size - 1, sol.nfev

    return solve


def lsoda(f, y0, t_end, tol):
    y, info = odeint(f, y0, [0.0, t_end], rtol=tol, atol=tol, tfirst=True,
                     full_output=True, mxstep=10**7)
    if info["message"] != "Integration successful.":
        raise RuntimeError(info["message"])
    return y[-1], int(info["nst"][-1]), int(info["nfe"][-1])


METHODS = [
    ("SciPy solve_ivp RK45", ivp("RK45")),
    ("SciPy solve_ivp DOP853", ivp("DOP853")),
    ("SciPy odeint (LSODA)", lsoda),
]


def main():
    job = json.load(sys.stdin)
    namespace = {"math": math}
    exec(job["rhs"], namespace)
    rhs = namespace["rhs"]
    y0 = np.array(job["y0"], dtype=float)
    t_end = job["t_end"]
    for name, solve in METHODS:
        for tol in job["tolerances"]:
            start = time.perf_counter()
            try:
                y, steps, evals = solve(rhs, y0, t_end, tol)
            except Exception as e:  # a solver's own failure, reported as the point's
                reason = str(e).replace(",", ";").replace("\n", " ")
                print(f"{name},{tol},0,0,nan,0,{reason}" + ",nan" * y0.size, flush=True)
                continue
            times = [time.perf_counter() - start]
            spent = times[0]
            slow = spent > job["max_solve"]
            while not slow and (len(times) < job["min_runs"] or (
                spent < job["budget_seconds"] and len(times) < job["max_runs"]
            )):
                start = time.perf_counter()
                solve(rhs, y0, t_end, tol)
                times.append(time.perf_counter() - start)
                spent += times[-1]
            state = ",".join(repr(float(v)) for v in y)
            print(f"{name},{tol},{steps},{evals},{statistics.median(times)},{len(times)},,{state}",
                  flush=True)
            if slow:
                break


if __name__ == "__main__":
    main()
