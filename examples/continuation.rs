//! Scene `continuation`: the periodic orbits of a model's period map
//! followed in one parameter by pseudo-arclength, with their folds, branch
//! points, period doublings and Neimark–Sacker points located, the branches
//! born at period doublings followed in turn (a cascade, with its Feigenbaum
//! ratios), and the brute-force orbit diagram beside them.
//!
//! `cargo run --release --example continuation`
//! `cargo run --release --example continuation -- --set model=kapitza --set parameter=A --set A=0.5 --set to=3 --set start=0,0`

fn main() {
    mechlab::scene::run(|| mechlab::scenes::continuation_scene(mechlab::models::MODELS));
}
