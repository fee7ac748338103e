#!/usr/bin/env python3
"""NAFF: mechlab against nafflib on the same signals, in one run.

Each signal is f_j = exp(2πi Q1 j) + 0.4 exp(2πi Q2 j + 0.3i), j = 0 … n−1,
n = 1024, 4096, 16384, analysed for two terms with a Hann window of order
1 and 2 (nafflib's default); each side's error in both tunes and its best
time of 20 runs, then the ratio nafflib / mechlab (one core, both
measured in this run; mechlab through `cargo bench --bench naff`).

Not part of CI. Install the peer first (any recent Python 3):
    python3 -m pip install nafflib numpy
then, from the repository root:
    python3 benches/nafflib_peer.py
"""
import json
import math
import subprocess
import time

import nafflib
import numpy as np

Q1 = 0.3123456789
Q2 = 0.1234567890 * math.sqrt(2.0)


def nafflib_row(window_order, n):
    j = np.arange(n)
    z = np.exp(2j * np.pi * Q1 * j) + 0.4 * np.exp(2j * np.pi * Q2 * j + 0.3j)
    best = math.inf
    for _ in range(20):
        start = time.perf_counter()
        _, frequencies = nafflib.harmonics(z.real, z.imag, num_harmonics=2, window_order=window_order)
        best = min(best, time.perf_counter() - start)
    # nafflib's tunes are of exp(−2πiQj): their magnitudes are ours.
    tunes = sorted(np.abs(frequencies), key=lambda q: -abs(q - Q2))  # Q1 first
    return abs(tunes[0] - Q1), abs(tunes[1] - Q2), best


def main():
    out = subprocess.run(
        ["cargo", "bench", "--quiet", "--bench", "naff"],
        check=True, capture_output=True, text=True,
    ).stdout
    ours = [json.loads(line) for line in out.splitlines() if line.startswith("{")]
    print("window  n       mechlab errors (Q1, Q2)   nafflib errors (Q1, Q2)   mechlab   nafflib   nafflib / mechlab")
    for row in ours:
        e1, e2, seconds = nafflib_row(row["window_order"], row["n"])
        print(f"{row['window_order']:>6}  {row['n']:<6}  {row['error1']:.1e}, {row['error2']:.1e}"
              f"          {e1:.1e}, {e2:.1e}          {row['seconds'] * 1e3:7.3f} ms {seconds * 1e3:7.3f} ms"
              f"   {seconds / row['seconds']:6.1f}")


if __name__ == "__main__":
    main()
