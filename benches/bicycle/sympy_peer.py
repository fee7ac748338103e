#!/usr/bin/env python3
"""The bicycle benchmark's derivation: mechlab against SymPy's mechanics.

SymPy ships the Whipple bicycle of Meijaard et al. (2007) as a test of
its Kane's-method code (`sympy.physics.mechanics.tests.test_kane3.
test_bicycle`): it builds the bicycle from frames, points and rigid
bodies, derives Kane's equations with the constraints, linearises them
symbolically about the upright motion and checks the linearised lean and
steer matrix against the benchmark's at speeds 0 to 5 m/s to 1e-12. This
script runs that test as SymPy wrote it and times it, then times mechlab
on its own model file of the same bicycle (`test_models/whipple_bicycle.toml`)
from the model file to the benchmark's eigenvalues: the derivation (the
test models' build script deriving that file alone, in a process of its
own, as `cargo build` does) and the linearisation at 201 speeds with the
stability boundaries (`cargo run --example bicycle`, already built).

The two do different amounts of work: SymPy derives the equations and
their linearisation symbolically (the speed a symbol) and never generates
code; mechlab derives the nonlinear equations, generates their compiled
code (run by every analysis) and linearises numerically at each speed.
The figure compared is what a user waits for, file to eigenvalues.

Not part of CI. Install the peer first (any recent Python 3):
    python3 -m pip install sympy
then, from the repository root, after `cargo build --release -p
mechlab-test-models --example bicycle`:
    python3 benches/bicycle/sympy_peer.py
"""
import glob
import os
import subprocess
import sys
import tempfile
import time

import sympy
from sympy.physics.mechanics.tests import test_kane3


def sympy_seconds():
    started = time.perf_counter()
    test_kane3.test_bicycle()
    return time.perf_counter() - started


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


def mechlab_linearisation_seconds():
    started = time.perf_counter()
    run = subprocess.run(
        ["target/release/examples/bicycle"], check=True, capture_output=True, text=True
    )
    seconds = time.perf_counter() - started
    return seconds, run.stdout


def main():
    print(f"SymPy {sympy.__version__}, Python {sys.version.split()[0]}")
    print(f"SymPy: derivation, symbolic linearisation and check: {sympy_seconds():.1f} s")
    print(f"mechlab: derivation of the model file: {mechlab_derivation_seconds():.1f} s")
    seconds, report = mechlab_linearisation_seconds()
    print(f"mechlab: 201 speeds' eigenvalues and the two boundaries: {seconds:.2f} s")
    print(report)


if __name__ == "__main__":
    main()
