//! Scene `frequency_map`: Laskar's frequency map of a section at a fixed
//! energy, for any autonomous model of 2 degrees of freedom by name
//! (Hénon–Heiles at E = 1/8 by default): each orbit of a grid of the
//! section's accessible region analysed by NAFF, its fundamental
//! frequencies (ν₁, ν₂) and its diffusion index (their drift between the
//! orbit's halves): the index over the section beside the frequency map,
//! where the resonances show as lines. The `section` scene's knobs.
//!
//! `cargo run --release --example frequency_map`
//! `cargo run --release --example frequency_map -- --set frequencies=200 --set map_time=2000`

fn main() {
    mechlab::scene::run(|| {
        mechlab::scenes::section_scene(
            mechlab::models::MODELS,
            "frequency_map",
            &[("frequencies", "100"), ("orbits", "0")],
        )
    });
}
