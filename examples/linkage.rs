//! Scene `linkage`: a constrained model held by vibration (the four-bar
//! linkage standing upside down on its vibrating base by default): the
//! averaged equilibrium on the constraints, the amplitude that stabilises
//! it, and the exact Floquet window.
//!
//! `cargo run --release --example linkage`
//! `cargo run --release --example linkage -- --set c=0.4 --set max_amplitude=3`

fn main() {
    mechlab::scene::run(|| mechlab::scenes::linkage_scene(mechlab::models::MODELS, "linkage", &[]));
}
