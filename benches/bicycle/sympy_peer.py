#!/usr/bin/env python3
"""The bicycle benchmark: mechlab against SymPy's mechanics and PyDy.

SymPy ships the Whipple bicycle of Meijaard et al. (2007) as a test of
its Kane's-method code (`sympy.physics.mechanics.tests.test_kane3.
test_bicycle`): it builds the bicycle from frames, points and rigid
bodies, derives Kane's equations with the constraints, linearises them
symbolically about the upright motion (the speed v a symbol) and checks
the lean-and-steer matrix against the benchmark's at 0 to 5 m/s to
1e-12. This script runs that test as SymPy wrote it and times it, keeping
what it built (its Kane's method object and its matrix A(v)); then

- the eigenvalues: of SymPy's A(5) and its weave and capsize speeds
  (where the largest real part of A(v)'s eigenvalues crosses zero, by
  Brent's method), beside mechlab's (`cargo run --example bicycle`,
  which writes `out/bicycle/summary.json`) and the paper's;
- the generated code: PyDy generates Cython code for SymPy's nonlinear
  equations (its full mass matrix and forcing, 10 states) and this script
  times one evaluation of the field x' = f(x), called from Python as
  PyDy's users call it; mechlab's generated field of its model file
  (16 states: it keeps the contact point, the yaw and the wheels'
  angles) is timed by `cargo bench -p mechlab-test-models --bench
  bicycle_field`;
- the derivation: mechlab's is the test models' build script deriving
  `test_models/whipple_bicycle.toml` alone, as `cargo build` does.

The two derivations do different work: SymPy's derives the equations and
their linearisation symbolically and generates no code; mechlab's derives
the nonlinear equations and generates their compiled code (run by every
analysis), and linearises numerically at each speed.

Not part of CI. Install the peers first (any recent Python 3):
    python3 -m pip install sympy pydy cython numpy scipy
then, from the repository root:
    cargo build --release -p mechlab-test-models --example bicycle
    python3 benches/bicycle/sympy_peer.py
"""
import glob
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
import pydy
import sympy
from pydy.codegen.ode_function_generators import generate_ode_function
from scipy.optimize import brentq
from sympy.physics.mechanics.tests import test_kane3

# Meijaard et al. (2007), Table 2 and Section 5.
PUBLISHED = {
    "castering": -14.07838969279822,
    "weave": complex(-0.77534188219585, 4.46486771378823),
    "capsize": -0.32286642900409,
    "weave speed": 4.29238253634111,
    "capsize speed": 6.02426201538837,
}


def run_sympy_test():
    """Runs SymPy's bicycle test, timed, and keeps its local variables.

    The test ends by building its reference matrix with `Matrix`; a
    stand-in for that name records the test's variables at each call.
    """
    kept = {}
    matrix = test_kane3.Matrix

    def recording_matrix(*args, **kwargs):
        kept.update(sys._getframe(1).f_locals)
        return matrix(*args, **kwargs)

    test_kane3.Matrix = recording_matrix
    try:
        started = time.perf_counter()
        test_kane3.test_bicycle()
        seconds = time.perf_counter() - started
    finally:
        test_kane3.Matrix = matrix
    return seconds, kept


def named_eigenvalues(values):
    """castering, weave (upper of the pair) and capsize of a 4x4 spectrum."""
    values = sorted(values, key=lambda z: z.real)
    pair = [z for z in values if abs(z.imag) > 1e-9]
    real = [z.real for z in values if abs(z.imag) <= 1e-9]
    return {
        "castering": min(real),
        "weave": max(pair, key=lambda z: z.imag) if pair else None,
        "capsize": max(real),
    }


def sympy_eigenvalues(kept):
    """SymPy's A(5) eigenvalues and its weave and capsize speeds."""
    v = kept["v"]
    a_of_v = sympy.lambdify(v, kept["A"], "numpy")
    growth = lambda speed: max(np.linalg.eigvals(np.array(a_of_v(speed), dtype=float)).real)
    named = named_eigenvalues(np.linalg.eigvals(np.array(a_of_v(5.0), dtype=float)))
    named["weave speed"] = brentq(growth, 3.0, 5.0, xtol=1e-14, rtol=1e-15)
    named["capsize speed"] = brentq(growth, 5.5, 7.0, xtol=1e-14, rtol=1e-15)
    return named


def mechlab_eigenvalues():
    """mechlab's, from the bicycle example's summary."""
    summary = json.load(open("out/bicycle/summary.json"))
    values = [complex(re, im) for re, im in summary["motion"]["eigenvalues"]]
    named = named_eigenvalues(values)
    boundaries = summary["sweep"]["boundaries"]
    named["weave speed"], named["capsize speed"] = (b["speed"] for b in boundaries)
    return named


def pydy_field(kept):
    """PyDy's Cython field of SymPy's equations: seconds to generate, ns per call."""
    kane = kept["KM"]
    values = kept["val_dict"]
    constants = [s for s in values if isinstance(s, sympy.Symbol)]
    constant_values = np.array([float(values[s]) for s in constants])
    started = time.perf_counter()
    field = generate_ode_function(
        kane.forcing_full,
        list(kane.q),
        list(kane.u),
        constants,
        mass_matrix=kane.mass_matrix_full,
        generator="cython",
    )
    generation = time.perf_counter() - started
    # q1, q2, q5, q4 then u2, u3, u5, u1, u4, u6: near the upright motion at 5 m/s.
    states = np.zeros((1000, 10))
    rng = np.random.default_rng(1)
    states[:, 1] = 0.05 * rng.uniform(-1, 1, 1000)
    states[:, 2] = 0.05 * rng.uniform(-1, 1, 1000)
    states[:, 4] = 0.5 * rng.uniform(-1, 1, 1000)
    states[:, 5] = 5.0 / 0.3
    states[:, 6] = 0.5 * rng.uniform(-1, 1, 1000)
    states[:, 9] = 5.0 / 0.35
    best = np.inf
    for _ in range(5):
        started = time.perf_counter()
        for x in states:
            field(x, 0.0, constant_values)
        best = min(best, (time.perf_counter() - started) / len(states))
    return generation, best * 1e9


def mechlab_derivation_seconds():
    """The build script of the test models, run on the bicycle's file alone."""
    scripts = sorted(
        glob.glob("target/release/build/mechlab-test-models-*/build-script-build"),
        key=os.path.getmtime,
    )
    if not scripts:
        sys.exit("build the test models first: cargo build --release -p mechlab-test-models")
    with tempfile.TemporaryDirectory() as out:
        env = dict(
            os.environ,
            MECHLAB_DERIVE_FILE="test_models/whipple_bicycle.toml",
            MECHLAB_DERIVE_OUT=os.path.join(out, "whipple_bicycle.rs"),
        )
        started = time.perf_counter()
        subprocess.run([scripts[-1]], env=env, check=True, capture_output=True)
        return time.perf_counter() - started


def mechlab_example_seconds():
    started = time.perf_counter()
    subprocess.run(["target/release/examples/bicycle"], check=True, capture_output=True)
    return time.perf_counter() - started


def mechlab_field_ns():
    run = subprocess.run(
        ["cargo", "bench", "-q", "-p", "mechlab-test-models", "--bench", "bicycle_field"],
        check=True,
        capture_output=True,
        text=True,
    )
    return json.loads(run.stdout.strip().splitlines()[-1])["field_ns_per_call"]


def show(value):
    if isinstance(value, complex):
        return f"{value.real:.15g} ± {abs(value.imag):.15g} i"
    return f"{value:.15g}"


def difference(value, published):
    if isinstance(value, complex):
        return f"{abs(value.real - published.real):.0e}, {abs(abs(value.imag) - published.imag):.0e}"
    return f"{abs(value - published):.0e}"


def main():
    print(f"SymPy {sympy.__version__}, PyDy {pydy.__version__}, Python {sys.version.split()[0]}")
    sympy_seconds, kept = run_sympy_test()
    generation, pydy_ns = pydy_field(kept)
    derivation = mechlab_derivation_seconds()
    example = mechlab_example_seconds()
    field_ns = mechlab_field_ns()
    print("\n| | SymPy and PyDy | mechlab |\n|---|---|---|")
    print(f"| model to equations | {sympy_seconds:.1f} s (Kane's method and symbolic linearisation) "
          f"| {derivation:.1f} s (derivation and generated code of the nonlinear equations) |")
    print(f"| generated code | {generation:.1f} s (PyDy's Cython, compiled) | (compiled with the crate) |")
    print(f"| one evaluation of the field | {pydy_ns / 1000:.2f} µs (10 states, from Python) "
          f"| {field_ns / 1000:.2f} µs (16 states) |")
    print(f"| eigenvalues at 201 speeds, the two boundaries | — | {example:.2f} s |")
    sympy_values, mechlab_values = sympy_eigenvalues(kept), mechlab_eigenvalues()
    print("\n| | Meijaard et al. (2007) | SymPy | difference | mechlab | difference |")
    print("|---|---|---|---|---|---|")
    for name, published in PUBLISHED.items():
        s, m = sympy_values[name], mechlab_values[name]
        print(f"| {name} | {show(published)} | {show(s)} | {difference(s, published)} "
              f"| {show(m)} | {difference(m, published)} |")


if __name__ == "__main__":
    main()
