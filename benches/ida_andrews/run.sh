#!/usr/bin/env bash
# Andrews' squeezing mechanism: mechlab against SUNDIALS' IDA at equal
# error, in one run. Not part of CI; install the peer first (Debian):
#
#   apt-get install libsundials-dev gcc
#   bash benches/ida_andrews/run.sh
#
# IDA integrates the mechanism as written in andrews_ida.c (its index-1
# form, its dense solver, tolerances 1e-4 … 1e-10); mechlab runs
# test_models/andrews_squeezer.toml with DOP853 and projection (the
# `constraints` benchmark, tolerances 1e-4 … 1e-12). Both measure the
# largest error of the seven positions at t = 0.03 against the Test Set's
# reference and the best of five runs' wall time, one core. For each IDA
# row the ratio is IDA's time over mechlab's fastest run that is at least
# as accurate (equal error or better).
set -euo pipefail
cd "$(dirname "$0")/../.."
build=$(mktemp -d)
trap 'rm -rf "$build"' EXIT
gcc -O3 -march=native -o "$build/andrews_ida" benches/ida_andrews/andrews_ida.c \
    -lsundials_ida -lsundials_nvecserial -lsundials_sunlinsoldense -lsundials_sunmatrixdense -lm
"$build/andrews_ida" 2>"$build/ida.log" >"$build/ida.jsonl"
out=$PWD/crates/test-models/out/ida_andrews
cargo bench -p mechlab-test-models --bench constraints -- --out "$out" >"$build/mechlab.log"
python3 - "$build/ida.jsonl" "$out/summary.json" <<'PY'
import json, sys
ida = [json.loads(line) for line in open(sys.argv[1])]
ours = sorted((e, s) for _, e, s in json.load(open(sys.argv[2]))["andrews"])
def ours_at(error):
    """mechlab's fastest run at least as accurate as `error` (None: none is)."""
    return min((s for e, s in ours if e <= error), default=None)
print("Andrews' squeezing mechanism to t = 0.03, one core (best of five):")
print("  mechlab (DOP853 with projection):")
for e, s in ours:
    print(f"    error {e:.1e}: {s * 1e3:8.3f} ms")
print("  IDA (index 1, dense, difference-quotient Jacobian) and mechlab at IDA's error:")
for row in ida:
    if row.get("failed"):
        print(f"    tol {row['tol']:.0e}: IDA failed")
        continue
    e, s = row["error"], row["seconds"]
    at = ours_at(e)
    ratio = f"IDA / mechlab = {s / at:6.1f}" if at else "(no mechlab run this accurate)"
    print(f"    tol {row['tol']:.0e}: error {e:.1e}, IDA {s * 1e3:8.3f} ms  {ratio}")
PY
