//! Build script: model files (`models/`, `test_models/`) → derivations
//! (`mechlab-derive`, with Symbolica, build time only) → generated Rust in
//! `OUT_DIR/generated`, included by `src/models.rs` and `src/test_models.rs`.

fn main() {
    mechlab_derive::build_models();
}
