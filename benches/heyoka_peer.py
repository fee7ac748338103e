#!/usr/bin/env python3
"""Kapitza period map: mechlab's `taylor` and `dop853` against heyoka, in one run.

Problem (deliverable 1.2's single-orbit mode): ε = 0.1, A = 1.5, μ = 0, from
(q, p) = (π − 0.5, 0), 1000 periods T = 2πε, one core. The error is the
max-norm distance of the final state from a reference computed by heyoka in
80-bit extended precision (tolerance 1e-19). heyoka advances with
`propagate_grid` over the period grid; mechlab samples each period's end from
the step across it, as propagate_grid does, the time restarting at 0 there
(`kapitza_period_map --set start=q,p`).

One orbit takes milliseconds, and on the shared 2-core machines both
solvers run about 35 % slower in spells of a fraction of a second (the
same process, pinned to either core, with the address space fixed, runs
in 4.1 or in 5.6 ms at 1e-12 from one launch to the next; heyoka in 7.1
or in 9–11 ms): every repeat within one launch shares its spell. Each
row's time is therefore the best over ROUNDS rounds spread over the run,
each timing every row of both solvers in turn (REPEAT runs per row per
round), so that both solvers and all tolerances get the same chances of
a quiet spell.

Not part of CI. Install the peer first (any recent Python 3):
    python3 -m pip install heyoka numpy
then, from the repository root:
    python3 benches/heyoka_peer.py
"""
import json
import math
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import heyoka as hy

A, EPS, MU = 1.5, 0.1, 0.0
Q0, P0 = math.pi - 0.5, 0.0
PERIODS = 1000
PERIOD = 2.0 * math.pi * EPS
REPEAT = 7
ROUNDS = 15
ROOT = Path(__file__).resolve().parent.parent


def equations():
    q, p = hy.make_vars("q", "p")
    theta = hy.time / EPS
    qd = p - A * hy.sin(q) * hy.sin(theta)
    return [(q, qd), (p, qd * (A * hy.cos(q) * hy.sin(theta) - MU) + hy.sin(q))]


def wrap(q):
    return (q + math.pi) % (2.0 * math.pi) - math.pi


def error(state, reference):
    dq = abs(wrap(float(state[0]) - float(reference[0])))
    return max(dq, abs(float(state[1]) - float(reference[1])))


def reference():
    ta = hy.taylor_adaptive(
        equations(),
        np.array([Q0, P0], dtype=np.longdouble),
        fp_type=np.longdouble,
        tol=np.longdouble(1e-19),
    )
    out = ta.propagate_grid(np.arange(PERIODS + 1, dtype=np.longdouble) * np.longdouble(PERIOD))
    return out[-1][-1]


def heyoka_row(tol, ref):
    ta = hy.taylor_adaptive(equations(), [Q0, P0], tol=tol)
    grid = np.arange(PERIODS + 1) * PERIOD
    best = math.inf
    for _ in range(REPEAT):
        ta.time = 0.0
        ta.state[:] = [Q0, P0]
        start = time.perf_counter()
        out = ta.propagate_grid(grid)
        best = min(best, time.perf_counter() - start)
    return error(out[-1][-1], ref), best


def mechlab_row(method, tol, ref):
    args = [
        "cargo", "run", "--release", "--quiet", "--example", "kapitza_period_map", "--",
        "--set", f"A={A}", "--set", f"eps={EPS}", "--set", f"mu={MU}",
        "--set", f"start={Q0!r},{P0!r}", "--set", f"periods={PERIODS}",
        "--set", f"method={method}", "--set", f"tol={tol}", "--set", f"repeat={REPEAT}",
    ]
    subprocess.run(args, cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
    summary = json.loads((ROOT / "out" / "kapitza_period_map" / "summary.json").read_text())
    return error(summary["final_state"], ref), summary["seconds"]


def rate_at(curve, target):
    """Periods/s of a (error, rate) curve at error `target`, log-log interpolated."""
    points = sorted(curve)
    for (e0, r0), (e1, r1) in zip(points, points[1:]):
        if e0 <= target <= e1 and e0 > 0:
            w = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp((1 - w) * math.log(r0) + w * math.log(r1))
    return None


SOLVERS = [
    ("heyoka", [1e-6, 1e-8, 1e-10, 1e-12, 1e-14, 1e-15], heyoka_row),
    ("taylor", [1e-6, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13, 1e-14, 1e-15, 1e-16],
     lambda tol, ref: mechlab_row("taylor", tol, ref)),
    ("dop853", [1e-9, 1e-11, 1e-13], lambda tol, ref: mechlab_row("dop853", tol, ref)),
]


def timed_rows(ref):
    """(solver, tol, error, periods/s) per row, each the best over ROUNDS rounds."""
    errors, seconds = {}, {}
    for _ in range(ROUNDS):
        for name, tolerances, measure in SOLVERS:
            for tol in tolerances:
                err, time_taken = measure(tol, ref)
                errors[name, tol] = err
                seconds[name, tol] = min(seconds.get((name, tol), math.inf), time_taken)
    return [(name, tol, errors[name, tol], PERIODS / seconds[name, tol]) for name, tol in errors]


def main():
    ref = reference()
    rows = timed_rows(ref)
    print(f"Kapitza period map, {PERIODS} periods, one core; error vs 80-bit reference\n")
    print(f"{'solver':8} {'tol':>7} {'error':>9} {'periods/s':>11}")
    for name, tol, err, rate in rows:
        print(f"{name:8} {tol:7.0e} {err:9.2e} {rate:11.4g}")
    ours = [(e, r) for n, _, e, r in rows if n == "taylor"]
    dop = [(e, r) for n, _, e, r in rows if n == "dop853"]
    print("\nAt heyoka's error: mechlab taylor (and dop853) periods/s over heyoka's")
    print(f"{'tol':>7} {'error':>9} {'taylor/heyoka':>14} {'dop853/heyoka':>14}")
    ratios = []
    for name, tol, err, rate in rows:
        if name != "heyoka":
            continue
        t, d = rate_at(ours, err), rate_at(dop, err)
        fmt = lambda x: f"{x / rate:14.2f}" if x else f"{'-':>14}"
        print(f"{tol:7.0e} {err:9.2e} {fmt(t)} {fmt(d)}")
        ratios.append({"tol": tol, "speedup": t / rate if t else None})
    return ratios


if __name__ == "__main__":
    main()
