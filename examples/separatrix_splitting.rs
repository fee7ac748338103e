//! Scene `separatrix_splitting`: the hyperbolic fixed point of the period
//! map of any 1-degree-of-freedom model with a fast phase, its unstable and
//! stable manifolds, two primary homoclinic points, the splitting angle and
//! the lobe area (action difference and polygon).
//!
//! `cargo run --release --example separatrix_splitting -- --set A=1 --set eps=0.1`
//! `cargo run --release --example separatrix_splitting -- --set model=circle_pendulum`

fn main() {
    mechlab::scene::run(|| {
        mechlab::scenes::separatrix_scene(
            mechlab::models::MODELS,
            "separatrix_splitting",
            &[("A", "1")],
        )
    });
}
