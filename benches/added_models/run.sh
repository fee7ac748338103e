#!/usr/bin/env bash
# Any valid model file added to models/ keeps `cargo test --release`
# green: the tests that iterate over models assert what holds for every
# model, pick their settings from the model's own scales, or skip with a
# printed reason. This adds model files written for the check (those of
# benches/edit_loop/, one of them without an `amplitude` key, and the
# 6-link chain of models/extra/) to models/, runs the test command, and
# restores models/ however it ends.
#
#   bash benches/added_models/run.sh     # CI runs this after the edit loop
set -euo pipefail
cd "$(dirname "$0")/../.."

added=()
restore() {
    for f in "${added[@]}"; do rm -f "$f"; done
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

for f in benches/edit_loop/*.toml models/extra/six_link_pendulum.toml; do
    add_model "$f"
done
echo "added to models/: ${added[*]}"
cargo test --release
echo "cargo test --release passed with ${#added[@]} model files added"
