#!/usr/bin/env python3
"""Hénon–Heiles MEGNO map of a section: mechlab's batch Taylor method against heyoka's batch mode, in one run.

Problem (the `section` scene's map): Hénon–Heiles at E = 1/8 on the plane
x = 0 (x rising), a PIXELS² grid over the accessible region, every pixel's
orbit from (x, y, p_x, p_y) = (0, y, √(2E − y² − p_y² + 2y³/3), p_y) with one
tangent vector w₀ = (½, ½, ½, ½) over T; MEGNO ⟨Y⟩ from L = ln‖w‖ sampled
every 0.5: Y = 2(L − (1/t)∫L) and its mean over [0, T], both integrals by
the trapezoid rule, as mechlab computes it. The seeds are the pixels the
scene found accessible (read from its CSV), so both sides run the same
orbits. Both run on ONE thread (RAYON_NUM_THREADS=1 for mechlab), heyoka
with `taylor_adaptive_batch` over its recommended SIMD width and one
`propagate_grid` per batch, mechlab with its 8 lanes. Each time is the best
of REPEAT runs; the maps are compared pixel by pixel (median |Δ⟨Y⟩| and the
share of pixels both call chaotic, ⟨Y⟩ > 4, or both regular).

Not part of CI. Install the peer first (any recent Python 3):
    python3 -m pip install heyoka numpy
then, from the repository root, after `cargo build --release --example section`:
    python3 benches/heyoka_section_peer.py
It writes out/heyoka_section_peer/summary.json and prints a table.
"""
import json
import math
import os
import subprocess
import time
from pathlib import Path

import numpy as np
import heyoka as hy

ENERGY = 0.125
PIXELS = 100
T_MAX = 1000.0
CHUNK = 2.0
TOLERANCES = [1e-9, 1e-12]
REPEAT = 3
ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "out" / "heyoka_section_peer"


def equations():
    """Hénon–Heiles and its tangent equations w' = J w (by hy.diff)."""
    x, y, px, py = hy.make_vars("x", "y", "px", "py")
    w = hy.make_vars("wx", "wy", "wpx", "wpy")
    field = [px, py, -x - 2.0 * x * y, -y - x * x + y * y]
    state = [x, y, px, py]
    tangent = [sum(hy.diff(f, s) * v for s, v in zip(state, w)) for f in field]
    return list(zip(state, field)) + list(zip(w, tangent))


def megno(log_norms):
    """⟨Y⟩ at T from ln‖w‖ at t = 0, CHUNK, …, T (rows: times)."""
    t = np.arange(log_norms.shape[0])[:, None] * CHUNK
    integral = np.concatenate(
        [np.zeros((1, log_norms.shape[1])),
         np.cumsum(0.5 * CHUNK * (log_norms[1:] + log_norms[:-1]), axis=0)])
    y = np.zeros_like(log_norms)
    y[1:] = 2.0 * (log_norms[1:] - integral[1:] / t[1:])
    mean = np.sum(0.5 * CHUNK * (y[1:] + y[:-1]), axis=0) / (t[-1, 0])
    return mean


def heyoka_map(tol, batch, seeds):
    """⟨Y⟩ of every seed (y, p_y) by heyoka's batch mode; (seconds, values)."""
    n = len(seeds)
    ta = hy.taylor_adaptive_batch(equations(), np.zeros((8, batch)), tol=tol, compact_mode=False)
    steps = int(round(T_MAX / CHUNK))
    grid = np.repeat((np.arange(0, steps + 1) * CHUNK)[:, None], batch, axis=1)
    values = np.empty(n)
    start = time.perf_counter()
    for b in range(0, n, batch):
        idx = np.arange(b, b + batch) % n
        y, py = seeds[idx, 0], seeds[idx, 1]
        px = np.sqrt(2.0 * ENERGY - py**2 - y**2 + 2.0 * y**3 / 3.0)
        ta.set_time(np.zeros(batch))
        ta.state[:] = np.array([np.zeros(batch), y, px, py] + [np.full(batch, 0.5)] * 4)
        out = ta.propagate_grid(grid)[-1]  # (times, 8, batch)
        log_norms = 0.5 * np.log(np.sum(out[:, 4:, :] ** 2, axis=1))
        count = min(batch, n - b)
        values[b : b + count] = megno(log_norms)[:count]
    return time.perf_counter() - start, values


def mechlab_map(tol):
    """The scene's MEGNO map on one thread; (seconds, seeds, values)."""
    out = OUT / f"mechlab_{tol:g}"
    cmd = [
        str(ROOT / "target" / "release" / "examples" / "section"),
        "--set", f"energy={ENERGY}", "--set", "orbits=1", "--set", "crossings=2",
        "--set", f"map={PIXELS}", "--set", f"map_time={T_MAX}", "--set", f"tol={tol}",
        "--out", str(out),
    ]
    env = dict(os.environ, RAYON_NUM_THREADS="1")
    subprocess.run(cmd, check=True, env=env, capture_output=True)
    summary = json.loads((out / "summary.json").read_text())
    table = np.genfromtxt(out / "section_megno.csv", delimiter=",", skip_header=1)
    accessible = np.isfinite(table[:, 2])
    return summary["megno_map"]["seconds"], table[accessible, :2], table[accessible, 2]


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    batch = hy.recommended_simd_size()
    rows = []
    for tol in TOLERANCES:
        mine = [mechlab_map(tol) for _ in range(REPEAT)]
        t_mine, seeds, y_mine = min(mine, key=lambda r: r[0])
        hey = [heyoka_map(tol, batch, seeds) for _ in range(REPEAT)]
        t_hey, y_hey = min(hey, key=lambda r: r[0])
        diff = np.abs(y_hey - y_mine)
        agree = np.mean((y_hey > 4.0) == (y_mine > 4.0))
        rows.append({
            "tol": tol,
            "orbits": int(len(seeds)),
            "heyoka_batch_seconds": t_hey,
            "mechlab_batch_seconds": t_mine,
            "speedup": t_hey / t_mine,
            "median_abs_megno_difference": float(np.median(diff)),
            "same_verdict_share": float(agree),
            "chaotic_fraction_mechlab": float(np.mean(y_mine > 4.0)),
            "chaotic_fraction_heyoka": float(np.mean(y_hey > 4.0)),
        })
    summary = {
        "problem": f"Hénon–Heiles MEGNO map at E={ENERGY}, {PIXELS}² pixels, T={T_MAX}, one thread",
        "heyoka": hy.__version__,
        "heyoka_batch_size": batch,
        "mechlab_lanes": 8,
        "rows": rows,
    }
    (OUT / "summary.json").write_text(json.dumps(summary, indent=2))
    print(f"heyoka {hy.__version__}, batch of {batch}; mechlab 8 lanes; one thread each")
    print("tol      orbits  heyoka s  mechlab s  speed-up  median|dY|  same verdict  chaotic (m / h)")
    for r in rows:
        print(f"{r['tol']:<8g} {r['orbits']:6d}  {r['heyoka_batch_seconds']:8.2f}  {r['mechlab_batch_seconds']:9.2f}"
              f"  {r['speedup']:8.2f}  {r['median_abs_megno_difference']:10.2e}  {r['same_verdict_share']:12.3f}"
              f"  {r['chaotic_fraction_mechlab']:.3f} / {r['chaotic_fraction_heyoka']:.3f}")
    return rows


if __name__ == "__main__":
    main()
