#!/usr/bin/env bash
# The Python module's check: the module built into a virtual environment
# (target/python-env) with the README's install command, its tests, then
# the notebooks of docs/notebooks/ run cell by cell against the Rust
# scenes' summaries (the scenes run first).
#
#   bash crates/python/check.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
python3 -m venv target/python-env
PY=target/python-env/bin/python
$PY -m pip install -q --upgrade pip
$PY -m pip install -q ./crates/python
$PY -m pip install -q nbclient nbformat ipykernel matplotlib
(cd target && ../$PY -m unittest discover -s ../crates/python/tests)
# The scenes whose numbers the notebooks check.
cargo run --release --quiet --example stability
cargo run --release --quiet --example averaging
cargo run --release --quiet --example explore -- --set model=painleve_klein
cargo run --release --quiet --example linkage
$PY docs/notebooks/check.py
