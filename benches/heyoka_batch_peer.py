#!/usr/bin/env python3
"""Kapitza chaos map: mechlab's batch Taylor method against heyoka's batch mode, in one run.

Problem (the `kapitza_chaos_map` scene): A = 1, ε = 0.1, μ = 0, a 100×100
grid of pixel centres on (q, p) ∈ [−π, π] × [−3, 3], 180 periods T = 2πε,
the state and one tangent vector w₀ = (1, 1)/√2; the FLI of a pixel is the
largest ln‖w‖/‖w₀‖ after a whole period. Both sides run on one thread at
tolerances 1e-6, 1e-8 and 1e-10, and on two threads at 1e-6 and 1e-8
(RAYON_NUM_THREADS for mechlab; for heyoka, the batches split between two
Python threads, each with its own integrator: heyoka releases the GIL while
it propagates). heyoka runs `taylor_adaptive_batch` over its recommended
SIMD width and one `propagate_grid` per batch over the 180 period ends;
mechlab its `kapitza_chaos_map` scene (8 lanes, each period's end sampled
from the step across it, no tiles). Each time is the best of `REPEAT` runs
made in rounds spread over the whole run (every row of both solvers in
turn in each round), so that both see the same spells of load and a slow
spell takes one chance of a row, not all of them; the
maps are compared pixel by pixel (median and 99th percentile of |ΔFLI|).

Not part of CI. Install the peer first (any recent Python 3):
    python3 -m pip install heyoka numpy
then, from the repository root, after `cargo build --release --example kapitza_chaos_map`:
    python3 benches/heyoka_batch_peer.py
It writes out/heyoka_batch_peer/summary.json and prints a table.
"""
import json
import math
import os
import subprocess
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import heyoka as hy

A, EPS, MU = 1.0, 0.1, 0.0
PIXELS = 100
PERIODS = 180
PERIOD = 2.0 * math.pi * EPS
ROWS = [(1, 1e-6), (1, 1e-8), (1, 1e-10), (2, 1e-6), (2, 1e-8)]  # (threads, tol)
REPEAT = 3
ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "out" / "heyoka_batch_peer"


def equations():
    """The Kapitza field and its tangent equations w' = J w (by hy.diff)."""
    q, p, wq, wp = hy.make_vars("q", "p", "wq", "wp")
    theta = hy.time / EPS
    qd = p - A * hy.sin(q) * hy.sin(theta)
    pd = qd * (A * hy.cos(q) * hy.sin(theta) - MU) + hy.sin(q)
    tangent = [hy.diff(f, q) * wq + hy.diff(f, p) * wp for f in (qd, pd)]
    return [(q, qd), (p, pd), (wq, tangent[0]), (wp, tangent[1])]


def pixel_centres():
    """(q, p) of every pixel, q fastest, as mechlab orders them."""
    k = np.arange(PIXELS * PIXELS)
    q = -math.pi + (k % PIXELS + 0.5) * 2.0 * math.pi / PIXELS
    p = -3.0 + (k // PIXELS + 0.5) * 6.0 / PIXELS
    return q, p


def heyoka_map(tol, batch, threads):
    """FLI of every pixel by heyoka's batch mode on `threads` threads; (seconds, values)."""
    q, p = pixel_centres()
    n = q.size
    w0 = 1.0 / math.sqrt(2.0)
    integrators = [
        hy.taylor_adaptive_batch(equations(), np.zeros((4, batch)), tol=tol, compact_mode=False)
        for _ in range(threads)
    ]
    grid = np.repeat((np.arange(0, PERIODS + 1) * PERIOD)[:, None], batch, axis=1)
    fli = np.empty(n)

    def run_batches(worker):
        ta = integrators[worker]
        for b in range(worker * batch, n, threads * batch):
            idx = np.arange(b, b + batch) % n
            ta.set_time(np.zeros(batch))
            ta.state[:] = np.array([q[idx], p[idx], np.full(batch, w0), np.full(batch, w0)])
            out = ta.propagate_grid(grid)[-1][1:]  # (periods, 4, batch) after t = 0
            norms = np.sqrt(out[:, 2, :] ** 2 + out[:, 3, :] ** 2)
            values = np.log(norms).max(axis=0)
            count = min(batch, n - b)
            fli[b : b + count] = values[:count]

    start = time.perf_counter()
    with ThreadPoolExecutor(threads) as pool:
        list(pool.map(run_batches, range(threads)))
    return time.perf_counter() - start, fli


def mechlab_map(tol, threads):
    """The scene's FLI map on `threads` threads; (seconds reported by the scene, values).

    Without the map's class check (`check=0`: a sample rerun at a tighter
    tolerance), which heyoka's side does not do."""
    out = OUT / f"mechlab_{tol:g}"
    cmd = [
        str(ROOT / "target" / "release" / "examples" / "kapitza_chaos_map"),
        "--set", f"pixels={PIXELS}", "--set", f"periods={PERIODS}",
        "--set", f"tol={tol}", "--set", "tile_rows=0", "--set", "check=0",
        "--out", str(out),
    ]
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    subprocess.run(cmd, check=True, env=env, capture_output=True)
    summary = json.loads((out / "summary.json").read_text())
    values = np.loadtxt(out / "chaos_map.csv", delimiter=",", skiprows=1)[:, 2]
    return summary["seconds"], values


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    batch = hy.recommended_simd_size()
    rows = []
    # Rounds spread over the run, each timing every row of both solvers in
    # turn: a slow spell of the machine (seconds long) then costs a row one
    # of its REPEAT chances, not all of them.
    hey = {row: [] for row in ROWS}
    mine = {row: [] for row in ROWS}
    for _ in range(REPEAT):
        for threads, tol in ROWS:
            hey[(threads, tol)].append(heyoka_map(tol, batch, threads))
            mine[(threads, tol)].append(mechlab_map(tol, threads))
    for threads, tol in ROWS:
        t_hey, fli_hey = min(hey[(threads, tol)], key=lambda r: r[0])
        t_mine, fli_mine = min(mine[(threads, tol)], key=lambda r: r[0])
        diff = np.abs(fli_hey - fli_mine)
        rows.append({
            "threads": threads,
            "tol": tol,
            "heyoka_batch_seconds": t_hey,
            "mechlab_batch_seconds": t_mine,
            "speedup": t_hey / t_mine,
            "pixel_periods_per_second_mechlab": PIXELS**2 * PERIODS / t_mine,
            "pixel_periods_per_second_heyoka": PIXELS**2 * PERIODS / t_hey,
            "median_abs_fli_difference": float(np.median(diff)),
            "p99_abs_fli_difference": float(np.percentile(diff, 99)),
        })
    summary = {
        "problem": f"Kapitza chaos map A={A}, eps={EPS}, {PIXELS}x{PIXELS}, {PERIODS} periods",
        "heyoka": hy.__version__,
        "heyoka_batch_size": batch,
        "mechlab_lanes": 8,
        "rows": rows,
    }
    (OUT / "summary.json").write_text(json.dumps(summary, indent=2))
    print(f"heyoka {hy.__version__}, batch of {batch}; mechlab 8 lanes")
    print("threads tol      heyoka s  mechlab s  speed-up  median|dFLI|  p99|dFLI|")
    for r in rows:
        print(f"{r['threads']:<7} {r['tol']:<8g} {r['heyoka_batch_seconds']:8.3f}  {r['mechlab_batch_seconds']:9.3f}"
              f"  {r['speedup']:8.2f}  {r['median_abs_fli_difference']:12.2e}  {r['p99_abs_fli_difference']:9.2e}")
    return rows


if __name__ == "__main__":
    main()
