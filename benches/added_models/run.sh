#!/usr/bin/env bash
# Any valid model file added to models/ keeps `cargo test --release`
# green: the tests that iterate over models assert what holds for every
# model, pick their settings from the model's own scales, or skip with a
# printed reason. This adds model files written for the check (those of
# benches/edit_loop/, one of them without an `amplitude` key and one with a
# moving constraint, and the
# 6- and 12-link chains of models/extra/, the first chapter's model of
# docs/first_model/, whose commands the docs test then checks, and two
# models defined only near their start: the bead on a circle in its
# horizontal coordinate and the Test Set's car axis, and a slider-crank
# whose connecting rod has no mass) to models/, runs the test
# command, checks the 12-link chain's threshold from `stability` against
# its closed form, and restores models/ however it ends.
#
#   bash benches/added_models/run.sh     # CI runs this after the edit loop
#
# Then it writes their snapshots with the command tests/snapshots_derivations.rs
# documents, checks that every added model got some, and removes them.
set -euo pipefail
cd "$(dirname "$0")/../.."

added=()
restore() {
    for f in "${added[@]}"; do
        rm -f "$f" tests/snapshots/snapshots_derivations__"$(basename "$f" .toml)"__*.snap.new
    done
}
trap restore EXIT

# Copies a model file into models/ under its file's name (the `name` key
# must equal the file name).
add_model() {
    local source=$1 name
    name=$(basename "$source" .toml)
    if [ -e "models/$name.toml" ]; then
        echo "models/$name.toml exists: not replaced" >&2
        exit 1
    fi
    sed "0,/^name = \".*\"/s//name = \"$name\"/" "$source" >"models/$name.toml"
    added+=("models/$name.toml")
}

for f in benches/edit_loop/*.toml models/extra/six_link_pendulum.toml \
    models/extra/twelve_link_pendulum.toml docs/first_model/my_pendulum.toml \
    test_models/bead_on_circle.toml test_models/car_axis.toml \
    test_models/massless_slider_crank.toml; do
    add_model "$f"
done
echo "added to models/: ${added[*]}"
cargo test --release
echo "cargo test --release passed with ${#added[@]} model files added"

# A model past 8 degrees of freedom gets its analyses too (the equilibria
# from a sample of the grid of starts): the upright chain's threshold
# against the hanging chain's normal modes. The binary is the one the
# tests built (`cargo run` would build it again with other features).
mkdir -p out/added_models
if ! target/release/examples/stability --set model=twelve_link_pendulum \
    --out out/added_models/stability >out/added_models/stability.log 2>&1; then
    tail -20 out/added_models/stability.log >&2
    exit 1
fi
python3 benches/added_models/chain_threshold.py 12 out/added_models/stability/summary.json

# The documented command writes every derived expression of each new model
# as a snapshot for review (and fails, as insta does, until they are
# accepted).
if INSTA_UPDATE=new cargo test --release --test snapshots_derivations >/dev/null 2>&1; then
    echo "the snapshot test passed with new models: no snapshots written for review" >&2
    exit 1
fi
for f in "${added[@]}"; do
    name=$(basename "$f" .toml)
    count=$(find tests/snapshots -name "snapshots_derivations__${name}__*.snap.new" | wc -l)
    if [ "$count" -eq 0 ]; then
        echo "$name: no snapshots written for review" >&2
        exit 1
    fi
    echo "$name: $count snapshots written for review"
done
