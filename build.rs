//! Build script: the model files of `models/` → derivations
//! (`mechlab-derive`, with Symbolica, build time only) → generated Rust in
//! `OUT_DIR/generated`, included by `src/models.rs`.

fn main() {
    mechlab_derive::build_models(".", "models");
}
