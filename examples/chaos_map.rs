//! Scene `chaos_map`: the FLI chaos map of the period map of any model with
//! a fast phase, on the cylinder (q, p) for one degree of freedom or on a
//! plane of two state components through a given state.
//!
//! `cargo run --release --example chaos_map -- --set model=double_pendulum --set axes=0,2 --set pixels=120`

fn main() {
    mechlab::scene::run(|| {
        mechlab::scenes::chaos_map_scene(mechlab::models::MODELS, "chaos_map", &[], None)
    });
}
