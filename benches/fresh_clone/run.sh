#!/usr/bin/env bash
# A fresh clone's two commands, timed as a new user meets them: the
# README's main scene, then its test command, on a tree with no build yet
# (the crates are downloaded first and not timed).
#
#   bash benches/fresh_clone/run.sh      # CI runs this first, on its fresh clone
#
# Prints one row per command with its target (docs/building.md). A command
# over its target prints NOT MET; one over fifteen times its target, or a
# failing command, fails the script.
set -euo pipefail
cd "$(dirname "$0")/../.."
if [ -e target/release ]; then
    echo "target/release exists: run this on a fresh clone (or remove target/)" >&2
    exit 1
fi
cargo fetch --quiet

now() { date +%s.%N; }
failures=0

# Runs command $2... for row $1 against target $3 s.
measure() {
    local row=$1 target=$2 start end seconds verdict
    shift 2
    start=$(now)
    "$@"
    end=$(now)
    seconds=$(awk "BEGIN { print $end - $start }")
    verdict=$(awk "BEGIN { s = $seconds; t = $target; print (s > 15 * t) ? \"FAILED (over 15x)\" : (s > t) ? \"NOT MET\" : \"met\" }")
    if [ "${verdict#FAILED}" != "$verdict" ]; then failures=$((failures + 1)); fi
    rows+=("$(printf '%-50s %8.1f %8s  %s' "$row" "$seconds" "$target" "$verdict")")
}

rows=()
measure "cargo run --release --example kapitza_period_map" 180 \
    cargo run --release --quiet --example kapitza_period_map
measure "cargo test --release (after it)" 180 cargo test --release
printf '%-50s %8s %8s  %s\n' "command" "seconds" "target" "verdict"
printf '%s\n' "${rows[@]}"
if [ "$failures" -gt 0 ]; then
    echo "$failures command(s) over fifteen times their target" >&2
    exit 1
fi
