//! Scene `attractor`: the strange attractor of the period map of a forced,
//! damped model of one degree of freedom, by name: the density of 2·10⁵
//! points, the Lyapunov spectrum with its convergence and an error from a
//! second start, Σλ against the flow's divergence, and the box-counting and
//! Kaplan–Yorke dimensions.
//!
//! `cargo run --release --example attractor`
//! `cargo run --release --example attractor -- --set model=kapitza --set A=1.5 --set eps=0.7 --set mu=0.4`

fn main() {
    mechlab::scene::run(|| mechlab::scenes::attractor_scene(mechlab::models::MODELS));
}
