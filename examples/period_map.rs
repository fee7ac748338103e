//! Scene `period_map`: orbits of the period map of any model with a fast
//! phase, on the cylinder (q, p) or on a plane of two state components.
//!
//! `cargo run --release --example period_map -- --set model=circle_pendulum`
//! `cargo run --release --example period_map -- --set model=double_pendulum --set axes=0,2 --set seeds="0.1,0,0,0;0.5,0.2,0,0"`

fn main() {
    mechlab::scene::run(|| {
        mechlab::scenes::period_map_scene(mechlab::models::MODELS, "period_map", &[])
    });
}
