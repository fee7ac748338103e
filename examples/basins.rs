//! Scene `basins`: the basins of attraction of any model's period map by
//! name (Duffing's driven double well by default): each start of a grid
//! on a plane labelled by the attractor its orbit ends on, the attractors
//! found from the orbits themselves (their kind, a representative point,
//! their share of the starts with its standard error); diverged starts a
//! class of their own.
//!
//! `cargo run --release --example basins`
//! `cargo run --release --example basins -- --set gamma=0.0 --set pixels=100`

fn main() {
    mechlab::scene::run(|| mechlab::scenes::basins_scene(mechlab::models::MODELS, None));
}
