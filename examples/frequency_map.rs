//! Scene `frequency_map`: Laskar's frequency map by model name. For an
//! autonomous model of 2 degrees of freedom (Hénon–Heiles at E = 1/8 by
//! default), of its section at a fixed energy: each orbit of a grid of the
//! section's accessible region analysed by NAFF, its fundamental
//! frequencies (ν₁, ν₂) and its diffusion index (their drift between the
//! orbit's halves), the index over the section beside the frequency map
//! where the resonances show as lines (the `section` scene's knobs). For a
//! model with a fast phase, of its period map on a plane (the chaos map's
//! knobs): each orbit's tunes and diffusion index.
//!
//! `cargo run --release --example frequency_map`
//! `cargo run --release --example frequency_map -- --set frequencies=200 --set map_time=2000`
//! `cargo run --release --example frequency_map -- --set model=kapitza --set A=1.5`

fn main() {
    mechlab::scene::run(|| mechlab::scenes::frequency_map_scene(mechlab::models::MODELS));
}
