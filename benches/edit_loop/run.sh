#!/usr/bin/env bash
# The edit loop, measured as a user meets it: a model file is edited or
# added, and `cargo run --release --example explore` on that model runs
# (build and a short run, until the figures are written). Each case is
# timed on an already-built tree, as after `cargo test --release`.
#
#   bash benches/edit_loop/run.sh        # CI runs this last
#
# Prints one row per case with its target (docs/building.md). A case over
# its target prints NOT MET; one over fifteen times its target fails the
# script, so that a return to the minutes this loop took before (444 s to
# add a 1-degree model, over 15 minutes for a 6-link chain) cannot pass
# unnoticed on a slow or busy runner.
# With the Python module's environment (crates/python/check.sh), it times
# the module's rebuild after an edit too.
# The model files it adds come from this folder (written for the check,
# not for mechlab's studies) and from models/extra; every file it adds to
# or changes in models/ is restored when it ends, however it ends.
set -euo pipefail
cd "$(dirname "$0")/../.."
here=benches/edit_loop

added=()
edited=""
log=$(mktemp)
restore() {
    rm -f "$log"
    for f in "${added[@]}"; do rm -f "$f"; done
    if [ -n "$edited" ]; then mv "$edited.edit-loop-backup" "$edited"; fi
}
trap restore EXIT

now() { date +%s.%N; }
failures=0
printf '%-58s %8s %8s  %s\n' "case" "seconds" "target" "verdict"

# Times `explore` on model $1 (build included) for case $2 with target $3 s.
measure() {
    local model=$1 case=$2 target=$3
    timed "$case" "$target" cargo run --release --quiet --example explore -- --set model="$model" \
        --set t_end=5 --set samples=200 --set periods=20
}

# Times the command $3... for case $1 with target $2 s.
timed() {
    local case=$1 target=$2 start end seconds verdict
    shift 2
    start=$(now)
    if ! "$@" >"$log" 2>&1; then
        cat "$log" >&2
        echo "$case: failed (above)" >&2
        exit 1
    fi
    end=$(now)
    seconds=$(awk "BEGIN { print $end - $start }")
    verdict=$(awk "BEGIN { s = $seconds; t = $target; print (s > 15 * t) ? \"FAILED (over 15x)\" : (s > t) ? \"NOT MET\" : \"met\" }")
    if [ "${verdict#FAILED}" != "$verdict" ]; then failures=$((failures + 1)); fi
    printf '%-58s %8.1f %8s  %s\n' "$case" "$seconds" "$target" "$verdict"
}

# Copies a model file into models/ under a new name (the `name` key must
# equal the file name).
add_model() {
    local source=$1 name=$2
    sed "0,/^name = \".*\"/s//name = \"$name\"/" "$source" >"models/$name.toml"
    added+=("models/$name.toml")
}

cargo build --release --quiet --example explore

edited=models/kapitza.toml
cp "$edited" "$edited.edit-loop-backup"
sed -i 's/^default = 0.1$/default = 0.11/' "$edited"
measure kapitza "edit: a default of kapitza.toml" 20

# The Python module, where crates/python/check.sh has made its environment:
# another default edited, the module rebuilt with the README's command and
# the new value read from Python.
python=target/python-env/bin/python
if [ -x "$python" ]; then
    sed -i 's/^default = 0.11$/default = 0.12/' "$edited"
    python_loop() {
        "$python" -m pip install -q ./crates/python &&
            "$python" -c "import mechlab; assert mechlab.model('kapitza').parameters['eps'] == 0.12"
    }
    timed "python: the same edit, pip install ./crates/python" 30 python_loop
fi

add_model "$here/slider_pendulum.toml" slider_pendulum
measure slider_pendulum "add: slider_pendulum (1 degree of freedom)" 20
sed -i 's|^lagrangian = "\(.*\)"$|lagrangian = "\1 + dot(q)^2/100"|' models/slider_pendulum.toml
measure slider_pendulum "edit: a term added to its Lagrangian" 20

add_model "$here/spring_pendulum.toml" spring_pendulum
measure spring_pendulum "add: spring_pendulum (2, a singular point at r = 0)" 20

add_model models/slider_crank.toml slider_crank_copy
measure slider_crank_copy "add: slider_crank (constrained: 3 coordinates, 2 closures)" 20
sed -i 's/^default = 2.0$/default = 2.5/' models/slider_crank_copy.toml
measure slider_crank_copy "edit: a default of the constrained model" 20

add_model "$here/chain4_horizontal.toml" chain4_horizontal
measure chain4_horizontal "add: chain4_horizontal (4)" 40
add_model models/extra/six_link_pendulum.toml six_link_pendulum
measure six_link_pendulum "add: six_link_pendulum (6)" 90

# Each copy's generated module is its original's but for the name: a
# model's code depends on its file alone, not on which other models were
# derived before it (each is derived in a process of its own).
same_code_as_originals() {
    local generated copy original k
    generated=$(dirname "$(ls -t target/release/build/mechlab-*/out/generated/other_0.rs | head -1)")
    for ((k = 0; k < made; k++)); do
        copy=other_$k
        original=$(basename "${others[$((k % ${#others[@]}))]}" .toml)
        # (Compared without white space: rustfmt breaks lines by length.)
        if [ "$(sed "s/\b$copy\b/$original/g" "$generated/$copy.rs" | tr -d '[:space:]')" != \
            "$(tr -d '[:space:]' <"$generated/$original.rs")" ]; then
            echo "$copy: its generated code differs from $original's beyond the name" >&2
            exit 1
        fi
    done
}

# The same with 10, then 20, other models in models/ (copies of the
# shipped ones under other names), built first and not timed.
others=(models/kapitza.toml models/circle_pendulum.toml models/elastic_pendulum.toml
    models/inclined_pendulum.toml models/horizontal_pendulum.toml)
made=0
for count in 10 20; do
    while [ "$made" -lt "$count" ]; do
        add_model "${others[$((made % ${#others[@]}))]}" "other_$made"
        made=$((made + 1))
    done
    cargo build --release --quiet --example explore
    same_code_as_originals
    add_model "$here/slider_pendulum.toml" "slider_with_$count"
    measure "slider_with_$count" "add: a 1-degree model with $count other models added" 20
done

if [ "$failures" -gt 0 ]; then
    echo "$failures case(s) over fifteen times their target" >&2
    exit 1
fi
