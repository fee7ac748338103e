#!/usr/bin/env python3
"""The upright N-link chain's threshold from `stability`'s summary against
the closed form of the hanging chain's normal modes.

At the model's defaults (equal masses m = 1 on rods of length l = 1,
g = 1) the hanging chain has A₀ᵢⱼ = N − max(i, j) and D = diag(N − i)
(0-based i), and the vibration stabilises the inverted chain above
a* = √(2 / λ_min(A₀⁻¹D)). λ_min is the inverse of the largest eigenvalue
of D⁻¹A₀, found by power iteration (the matrix is positive). Plain
Python, no packages.

    python3 benches/added_models/chain_threshold.py N out/stability/summary.json
"""
import json
import math
import sys


def closed_form(n):
    a = [[float(n - max(i, j)) for j in range(n)] for i in range(n)]
    d = [float(n - i) for i in range(n)]
    m = [[a[i][j] / d[i] for j in range(n)] for i in range(n)]
    v = [1.0] * n
    largest = 0.0
    for _ in range(5000):
        w = [sum(m[i][j] * v[j] for j in range(n)) for i in range(n)]
        norm = math.sqrt(sum(x * x for x in w))
        v = [x / norm for x in w]
        rayleigh = sum(v[i] * sum(m[i][j] * v[j] for j in range(n)) for i in range(n))
        if abs(rayleigh - largest) < 1e-15 * rayleigh:
            break
        largest = rayleigh
    # v converges to the dominant eigenvector, so v·Mv (with |v| = 1)
    # converges to its eigenvalue.
    return math.sqrt(2.0 * largest)


def main():
    n, path = int(sys.argv[1]), sys.argv[2]
    summary = json.load(open(path))
    upright = [e for e in summary["equilibria"] if all(abs(x) < 1e-9 for x in e["q"])]
    if not upright or upright[0]["a_star"] is None:
        sys.exit(f"{path}: no threshold for the upright chain")
    found, expected = upright[0]["a_star"], closed_form(n)
    print(f"{n}-link chain upright: a* = {found!r}, closed form {expected!r}")
    if abs(found - expected) > 1e-9 * expected:
        sys.exit("the threshold differs from the closed form")


if __name__ == "__main__":
    main()
