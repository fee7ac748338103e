#!/usr/bin/env python3
"""The three heyoka comparisons run RUNS times each; the minimum ratio per row.

A ratio measured once moves with the machine (±20 % seen on these 2-core
machines), so a lead is claimed only if it holds in every run: this runs
`heyoka_peer.py` (one orbit, at heyoka's errors), `heyoka_batch_peer.py`
(the FLI chaos map, on one and on two threads) and `heyoka_section_peer.py` (a section's MEGNO map)
RUNS times in turn and prints, per workload and tolerance, the ratio
mechlab/heyoka of every run and their minimum. It writes
out/heyoka_min_ratio/summary.json.

Not part of CI. Install the peer first (any recent Python 3):
    python3 -m pip install heyoka numpy
then, from the repository root, after
`cargo build --release --example kapitza_chaos_map --example section`:
    python3 benches/heyoka_min_ratio.py [RUNS] [WORKLOAD]
RUNS is 5 by default; WORKLOAD ("one orbit", "batch chaos map" or
"section MEGNO map") runs that one alone.
"""
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import heyoka_batch_peer  # noqa: E402
import heyoka_peer  # noqa: E402
import heyoka_section_peer  # noqa: E402

WORKLOADS = [
    ("one orbit", heyoka_peer.main),
    ("batch chaos map", heyoka_batch_peer.main),
    ("section MEGNO map", heyoka_section_peer.main),
]
OUT = Path(__file__).resolve().parent.parent / "out" / "heyoka_min_ratio"


def main():
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    chosen = [w for w in WORKLOADS if len(sys.argv) < 3 or w[0] == sys.argv[2]]
    if not chosen:
        sys.exit(f"unknown workload {sys.argv[2]!r}: one of {[w[0] for w in WORKLOADS]}")
    ratios = {}
    for run in range(runs):
        for name, measure in chosen:
            print(f"\n--- run {run + 1} of {runs}: {name}")
            for row in measure():
                label = f"{name}, {row['threads']} thr" if "threads" in row else name
                ratios.setdefault((label, row["tol"]), []).append(row["speedup"])
    print(f"\nmechlab/heyoka over {runs} runs (minimum first; '-': no run reached heyoka's error)")
    table = []
    for (name, tol), values in ratios.items():
        known = [v for v in values if v is not None]
        low = min(known) if len(known) == len(values) else None
        shown = " ".join(f"{v:.2f}" if v is not None else "-" for v in values)
        print(f"{name:24} {tol:7.0e}  min {low if low is None else f'{low:.2f}'}   [{shown}]")
        table.append({"workload": name, "tol": tol, "min": low, "runs": values})
    OUT.mkdir(parents=True, exist_ok=True)
    name = "summary.json" if len(chosen) == len(WORKLOADS) else f"summary_{chosen[0][0].replace(' ', '_')}.json"
    (OUT / name).write_text(json.dumps({"runs": runs, "rows": table}, indent=2))


if __name__ == "__main__":
    main()
